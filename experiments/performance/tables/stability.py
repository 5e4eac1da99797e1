"""Stability table: every hard case x model, with the error, volume ratio, inverted elements and how it broke."""


import numpy as np

from msslib.results import read_result, write_text
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def _md(text):
    """Text for a Markdown table cell (a bare pipe would split the cell)."""
    return text.replace("|", "\\|")


def cell(r):
    text = _md(" ".join(str(r.outcome.values).split()))
    if not int(r.ran):
        return text[:70] if text else "-"
    parts = []
    step = int(r.stop_step) if "stop_step" in r else -1
    if step >= 0:  # an explicit step over the limit: refused, then stopped by the divergence detector
        parts.append(f"**refused**; with allow_unstable stopped at step {step}, "
                     f"max displacement {float(r.stop_displacement):.2g} x static")
    elif not int(r.converged):
        parts.append(f"**{text[:70]}**" if text else "**no convergence**")
    e, v, inv = float(r.error), float(r.volume_ratio), int(r.n_inverted)
    if np.isfinite(e):
        parts.append(f"err {100 * e:.2g} %")
    if np.isfinite(v):
        parts.append(f"V/V0 {v:.4g}")
    if inv > 0:
        parts.append(f"**{inv} inverted**")
    return ", ".join(parts) or str(r.outcome.values)[:60]


def _readings(d):
    """The sentence naming the reading of Baudet's correction of each column that has one."""
    if "reading" not in d:
        return ""
    named = [f"{m}: {r} reading" for m, r in zip(d.model.values, d.reading.values) if str(r)]
    return (" Baudet's correction force: " + "; ".join(named) + " (element: each cube from the forces it receives "
            "from outside; boundary: from the loaded surface).") if named else ""


def main():
    a = script.args(__doc__)
    d = read_result(INPUTS[0])
    models = [str(m) for m in d.model.values]
    lines = [f"Hard cases (E = {d.attrs['E']:g} Pa). *err*: largest node error relative to the largest displacement of "
             "neo-Hookean FEM on the same mesh (explicit_*: distance of the last state before the stop from a stable run, "
             "relative to the static maximum displacement; implicit_1.5x: maximum over static maximum displacement; "
             "unloaded: maximum displacement over edge length; slender_beam: tip deflection over Euler-Bernoulli's, "
             "minus 1); *V/V0*: volume ratio. Explicit steps over the stability limit of the model at rest are "
             "refused; the table shows where the divergence detector stops them when the scene asks to run anyway "
             "(allow_unstable)." + _readings(d), "",
             "| case | " + " | ".join(models) + " |", "|---" * (len(models) + 1) + "|"]
    for c in d.case.values:
        lines.append(f"| {c} | " + " | ".join(cell(d.sel(case=c, model=m)) for m in models) + " |")
    lines += ["", "How each run ended (first words of the outcome):", ""]
    for c in d.case.values:
        for m in models:
            text = " ".join(str(d.outcome.sel(case=c, model=m).values).split())
            if text and not text.startswith("ok"):
                lines.append(f"- {c}, {m}: {_md(text[:200])}")
    lines += ["", "Bad tetrahedra: Lloyd's equivalent-edge constant vs the element-wise least-squares optimum "
              "(N/m, E as above):", "", "| shape | Lloyd k | least-squares k per edge | negative |", "|---|---|---|---|"]
    for s in d.shape.values:
        k = d.k_lsq.sel(shape=s).values
        lines.append(f"| {s} | {float(d.k_lloyd.sel(shape=s)):.4g} | {', '.join(f'{v:.3g}' for v in k)} | {int((k < 0).sum())} |")
    write_text(a.out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

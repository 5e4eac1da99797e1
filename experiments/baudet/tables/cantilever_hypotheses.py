"""Cantilever: what Baudet's M / SD / MAX may measure, each reading against the published numbers."""

import numpy as np

from experiments import script
from experiments.baudet import baudet_common as C

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
LEVELS = ("4x1x1", "8x2x2", "16x4x4")


def pc(v):
    return "-" if v is None or not np.isfinite(v) else f"{100 * float(v):.3g}"


def ratio(v):
    return "-" if v is None or not np.isfinite(v) else f"{float(v):.2f}"


def main():
    args = script.args(__doc__)
    fl, ld, cmp = (C.open_result(f) for f in INPUTS)
    levels = [r for r in LEVELS if r in fl.resolution.values]
    nxt = dict(zip(levels[:-1], levels[1:]))
    pub = {r: {s: float(cmp["published_relative_" + s].sel(case="gravity", variant=f"mss_{r}")) for s in ("mean", "std", "max")}
           for r in levels}

    def row(reading, quantity, ours, published, fmt=pc):
        cells = " | ".join(f"{fmt(ours(r))} | {published(r)}" for r in levels)
        return f"| {reading} | {quantity} | {cells} |"

    def meas(r, k):
        return float(fl["mss_measures"].sel(resolution=r, measure=k))

    def pubs(s):
        return lambda r: f"{100 * pub[r][s]:g}"

    def large(reading, reference, k):
        sel = ld["reading_error"].sel(reading=reading, reference=reference, stat=k)
        return lambda r: float(sel.sel(model=f"mss_{r}")) if f"mss_{r}" in ld.model.values else None

    head = " | ".join(f"{r} ours | {r} published" for r in levels)
    lines = ["**Cantilever: readings of Baudet's M / SD / MAX** (%, all per node; 'largest': error divided by the largest "
             "reference displacement, 'local': by the node's own reference displacement, the clamped nodes left out). "
             f"Reference: linear FEM {fl.attrs['reference']} for the printed density; for the two large-mass readings "
             f"Q1 {ld.attrs['fem_mesh']}, linear (as Baudet's) and neo-Hookean.", "",
             f"| reading | quantity | {head} |", "|---|---|" + "---|---|" * len(levels)]
    lines += [
        row("as today: density 0.0125 kg/m^3, largest", "M", lambda r: meas(r, "max_mean"), pubs("mean")),
        row("", "SD", lambda r: meas(r, "max_sd"), pubs("std")),
        row("", "MAX", lambda r: meas(r, "max_max"), pubs("max")),
        row("SD as printed (a standard deviation)", "SD / M (ratio)", lambda r: meas(r, "max_sd") / meas(r, "max_mean"),
            lambda r: f"{pub[r]['std'] / pub[r]['mean']:.2f}", fmt=ratio),
        row("SD printed as a variance (of the fractions)", "SD^2 (fraction x 100)", lambda r: meas(r, "max_variance"), pubs("std")),
        row("", "sqrt(SD^2) / M vs sqrt(published SD) / M (ratio)", lambda r: meas(r, "max_sd") / meas(r, "max_mean"),
            lambda r: f"{np.sqrt(pub[r]['std']) / pub[r]['mean']:.2f}", fmt=ratio),
        row("SD printed as the second moment mean(e^2)", "mean(e^2) (fraction x 100)", lambda r: meas(r, "max_second_moment"),
            pubs("std")),
        row("0.68 a misprint of 1.68", "M", lambda r: meas(r, "max_mean"),
            lambda r: "1.68" if r == "16x4x4" else f"{100 * pub[r]['mean']:g}"),
        row("", "floor of the lattice, M", lambda r: float(fl["error_floor"].sel(resolution=r, stat="mean")),
            lambda r: "1.68" if r == "16x4x4" else f"{100 * pub[r]['mean']:g}"),
        row("", "M at this level / M at the next finer (ratio; published M 0.68 / 1.68)",
            lambda r: meas(r, "max_mean") / meas(nxt[r], "max_mean") if r in nxt else None,
            lambda r: ("-" if r not in nxt else f"{pub[r]['mean'] / pub[nxt[r]]['mean']:.2f}"
                       + (f" / {pub[r]['mean'] / 0.0168:.2f}" if nxt[r] == "16x4x4" else "")), fmt=ratio),
        row("", "MAX at this level / MAX at the next finer (ratio)",
            lambda r: meas(r, "max_max") / meas(nxt[r], "max_max") if r in nxt else None,
            lambda r: f"{pub[r]['max'] / pub[nxt[r]]['max']:.2f}" if r in nxt else "-", fmt=ratio),
        row("local (error / own displacement)", "M", lambda r: meas(r, "local_mean"), pubs("mean")),
        row("", "SD", lambda r: meas(r, "local_sd"), pubs("std")),
        row("", "MAX", lambda r: meas(r, "local_max"), pubs("max")),
        row("reference: linear FEM on the MSS mesh", "M", lambda r: float(fl["error_mss_vs_fem_same_mesh"].sel(resolution=r, stat="mean")),
            pubs("mean")),
        row("", "MAX", lambda r: float(fl["error_mss_vs_fem_same_mesh"].sel(resolution=r, stat="max")), pubs("max")),
        row("(for scale) linear FEM Q1 on the MSS mesh vs the reference", "M",
            lambda r: float(fl["error_fem_same_mesh"].sel(resolution=r, stat="mean")), pubs("mean")),
        row("", "MAX", lambda r: float(fl["error_fem_same_mesh"].sel(resolution=r, stat="max")), pubs("max")),
    ]
    for reading, text in (("linear_density", "linear density 0.0125 kg/m"), ("total_mass", "total mass 0.0125 kg")):
        rho = float(ld[f"reading_{reading}"])
        tip = float(ld["reading_tip_ratio"].sel(reading=reading, tip_model="fem_nonlinear"))
        for ref, rl in (("linear", "vs linear FEM"), ("nonlinear", "vs neo-Hookean FEM")):
            lab = f"{text} (density {rho:g} kg/m^3, tip {100 * tip:.0f} % of L), {rl}"
            lines.append(row(lab, "M", large(reading, ref, "max_mean"), pubs("mean")))
            lines.append(row("", "SD", large(reading, ref, "max_sd"), pubs("std")))
            lines.append(row("", "MAX", large(reading, ref, "max_max"), pubs("max")))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()

"""Tip deflection of the cantilever's neutral axis: MSS resolutions and FEM against eq. 10."""

from experiments import script
from experiments.baudet import baudet_common as C
from experiments.baudet.baudet_common import CANTILEVER_RES as RES

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    eq = C.open_result(INPUTS[-1])
    tip, tip_s = float(eq["tip_eq10"]), float(eq["tip_timoshenko"])
    lines = script.head(
        "**Cantilever: tip deflection of the neutral axis** (mean vertical displacement of the free end section)",
        ["model", "tip deflection (mm)", "vs eq. 10 (%)", "vs eq. 10 + shear (%)"])
    lines += [script.row("eq. 10 (Euler-Bernoulli, nu = 0)", f"{tip * 1e3:.4g}", 0, f"{100 * (tip / tip_s - 1):+.3g}"),
              script.row("eq. 10 + Timoshenko shear", f"{tip_s * 1e3:.4g}", f"{100 * (tip_s / tip - 1):+.3g}", 0)]
    n = len(RES)
    for name, path in [("FEM linear 48x12x12", INPUTS[n])] + [(f"MSS {r}", q) for r, q in zip(RES, INPUTS[:n])]:
        _, w = C.section_deflection(C.open_result(path))
        lines.append(script.row(name, f"{w[-1] * 1e3:.4g}", f"{100 * (w[-1] / tip - 1):+.3g}",
                                f"{100 * (w[-1] / tip_s - 1):+.3g}"))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()

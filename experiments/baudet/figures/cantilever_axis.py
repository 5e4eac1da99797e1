"""Baudet Figs. 9-10: deflection of the cantilever's neutral axis, MSS (and 32x8x8 beyond the paper) and FEM against eq. 10."""

from experiments.baudet import baudet_common as C
from experiments import script
from experiments.baudet.baudet_common import CANTILEVER_RES as RES
from experiments import plotting

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    eq = C.open_result(INPUTS[-1])
    fig = plotting.figure(figsize=(6.0, 3.6))
    ax = fig.add_subplot()
    ax.plot(eq["x"] * 1e3, eq["deflection_eq10"] * 1e3, "k-", lw=2, label="eq. 10 (Euler-Bernoulli)")
    ax.plot(eq["x"] * 1e3, eq["deflection_timoshenko"] * 1e3, "k:", lw=1.5, label="eq. 10 + shear (Timoshenko)")
    x, w = C.section_deflection(C.open_result(INPUTS[-2]))
    ax.plot(x * 1e3, w * 1e3, color="0.5", lw=3, alpha=0.6, label="FEM (linear, 48x12x12)")
    for r, p, c in zip(RES, INPUTS[:len(RES)], ("tab:red", "tab:orange", "tab:blue", "tab:purple")):
        x, w = C.section_deflection(C.open_result(p))
        ax.plot(x * 1e3, w * 1e3, "o-", color=c, ms=4, label=f"MSS {r}")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("neutral-axis deflection,\ndownwards (mm)")  # two lines: the label fits the figure
    ax.invert_yaxis()
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

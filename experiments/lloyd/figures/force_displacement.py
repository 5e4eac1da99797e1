"""Lloyd et al. Fig. 1: force-displacement non-linearity of a triangle and a square MSS (edge 1 m).

Circles: the computed MSS equilibria; solid lines: straight lines through the origin fitted to the
compression and to the stretch points; dashed: linear FEM of the same element.

    python -m experiments.lloyd.figures.force_displacement --out paper/figures/lloyd_force_displacement
"""

from pathlib import Path

import xarray as xr

from experiments import script
from experiments import plotting

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
TITLES = {"triangle": "a) equilateral triangle", "square": "b) square"}


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    fig = plotting.figure(figsize=(8.0, 3.6))
    axes = fig.subplots(1, 2, sharey=True)
    F = ds.force.values
    for ax, shape in zip(axes, ds.shape.values):
        r = ds.sel(shape=shape)
        d = r.displacement.values
        ax.plot(F, d * 1e2, "o", mfc="none", color="tab:red", label="MSS (computed)")
        for side, sel, ls in (("compression", F <= 0, "-"), ("stretch", F >= 0, "-")):
            k = float(r[f"slope_{side}"])
            ax.plot(F[sel], k * F[sel] * 1e2, ls, color="tab:blue" if side == "compression" else "tab:green",
                    label=f"fit, {side}: {k * 1e2:.3g} cm/N")
        ax.plot(F, r.fem_displacement.values * 1e2, "--", color="k", lw=1, label="linear FEM")
        ax.axhline(0, color="0.8", lw=0.5, zorder=0)
        ax.axvline(0, color="0.8", lw=0.5, zorder=0)
        ax.set_title(f"{TITLES[str(shape)]} (ratio {float(r.slope_ratio):.2f})")
        ax.set_xlabel("force on each top node (N)")
        ax.legend(loc="upper left")
    axes[0].set_ylabel("vertical displacement of the top node(s) (cm)")
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

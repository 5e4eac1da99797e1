"""Lloyd et al. Fig. 3: maximum and mean error of the equilateral-triangle MSS against FEM, vs nu.

A regular hexagon 1.7 cm high; one panel per load case; the dotted line marks nu = 1/3, where
Lloyd's eq. 8 is exact.

    python -m experiments.lloyd.figures.poisson_error --out paper/figures/lloyd_poisson_error
"""

from pathlib import Path

import xarray as xr

from experiments import script
from experiments import plotting

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
TITLES = {"stretch": "a) stretch, 10 % of E", "shear": "b) shear, 4 % of E", "small_stretch": "c) stretch, 1 % of E"}


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    cases = list(ds.case.values)
    fig = plotting.figure(figsize=(3.3 * len(cases), 3.4))
    axes = fig.subplots(1, len(cases), squeeze=False)[0]
    for ax, case in zip(axes, cases):
        r = ds.sel(case=case)
        ax.plot(ds.nu, r.error_max * 1e3, "o-", color="tab:red", label="max error")
        ax.plot(ds.nu, r.error_mean * 1e3, "s--", color="tab:blue", label="mean error")
        ax.axvline(1 / 3, color="k", ls=":", lw=1, label=r"$\nu = 1/3$")
        ax.set_xlabel(r"Poisson's ratio $\nu$ of the FEM reference")
        ax.set_title(TITLES.get(str(case), str(case)))
        ax.set_ylim(bottom=0)
        ax.legend()
    axes[0].set_ylabel("node distance MSS - FEM (mm)")
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

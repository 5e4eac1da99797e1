"""Lloyd et al. Sec. 5: maximum node distance MSS - reference against the deformation, every experiment.

One panel per experiment (shared axes): solid lines the maximum, dashed the mean error, one colour
per load case, one marker per MSS variant; grey band: the deformation the paper states for the
experiment; stars: the published maximum error, drawn across the stated range.

    python -m experiments.lloyd.figures.load_sweep --out paper/figures/lloyd_load_sweep
"""

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from experiments import script
from experiments import plotting

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
TITLES = {
    "membrane_equilateral": "Sec. 5.1 equilateral membrane", "membrane_arbitrary": "Sec. 5.2 arbitrary triangles",
    "membrane_square": "Sec. 5.3 square mesh", "resolutions": "Sec. 5.4 resolutions (shear)",
    "two_layer": "Sec. 5.5 two layers", "cylinder": "Sec. 5.6 cylinder", "cylinder_hole": "Sec. 5.6 cylinder with hole",
    "cone": "Sec. 5.7 cone (shear; ref. non-linear FEM)", "cylinder_volume": "Sec. 5.8 cylinder, volume forces",
}
COLORS = {"stretch": "tab:blue", "compression": "tab:orange", "shear": "tab:green"}
MARKERS = ["o", "s", "^", "D"]


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    done = np.isfinite(ds.error_max.values).any(axis=1)  # the quick build leaves most experiments out
    names = list(dict.fromkeys(str(e) for e, ok in zip(ds.experiment.values, done) if ok))
    ncol = 3 if len(names) > 2 else len(names)
    nrow = int(np.ceil(len(names) / ncol))
    fig = plotting.figure(figsize=(3.4 * ncol, 2.9 * nrow + 0.8))
    axes = np.atleast_1d(fig.subplots(nrow, ncol, sharex=True, sharey=True, squeeze=False)).ravel()
    for ax, name in zip(axes, names):
        runs = [i for i, e in enumerate(ds.experiment.values) if str(e) == name]
        variants = list(dict.fromkeys(str(ds.variant.values[i]) for i in runs))
        lo = float(np.nanmin(ds.stated_low.values[runs]))
        hi = float(np.nanmax(ds.stated_high.values[runs]))
        ax.axvspan(100 * lo, 100 * hi, color="0.88", zorder=0)
        notes = []
        for i in runs:
            r = ds.isel(run=i)
            case, var = str(r.case.values), str(r.variant.values)
            c, mk = COLORS[case], MARKERS[variants.index(var) % len(MARKERS)]
            d = 100 * r.deformation.values
            ax.plot(d, 1e3 * r.error_max.values, "-", color=c, marker=mk, ms=3.5)
            ax.plot(d, 1e3 * r.error_mean.values, "--", color=c, marker=mk, ms=2.5, mfc="none", lw=1)
            if np.isfinite(float(r.published_max)):
                a, b = 100 * float(r.stated_low), 100 * float(r.stated_high)
                ax.plot([a, b], [1e3 * float(r.published_max)] * 2, "-", color=c, lw=2.5, alpha=0.6)
                ax.plot([np.sqrt(a * b)], [1e3 * float(r.published_max)], "*", color=c, ms=10, mec="k", mew=0.5)
            if len(variants) > 1:
                notes.append((mk, var))
        title = TITLES.get(name, name)
        ax.set_title(title, fontsize=9)
        if notes:
            handles = [Line2D([], [], color="0.3", marker=m, ls="none", label=v) for m, v in dict.fromkeys(notes)]
            ax.legend(handles=handles, fontsize=7, loc="upper left", title="variant", title_fontsize=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
    for ax in axes[len(names):]:
        ax.set_visible(False)
    for ax in axes[:len(names)]:
        plotting.label_log_axis(ax)
    for k, ax in enumerate(axes[:len(names)]):
        if k + ncol >= len(names):  # no panel below
            ax.set_xlabel("deformation of the top face (% of height)")
            ax.xaxis.set_tick_params(labelbottom=True)
    for k in range(nrow):
        axes[k * ncol].set_ylabel("node distance to the reference (mm)")
    handles = [Line2D([], [], color=c, label=k) for k, c in COLORS.items()]
    handles += [Line2D([], [], color="k", ls="-", label="max error"), Line2D([], [], color="k", ls="--", label="mean error"),
                Line2D([], [], color="0.5", marker="*", ms=10, mec="k", ls="-", lw=2.5, alpha=0.8, label="published max"),
                Patch(color="0.88", label="deformation stated in the paper")]
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

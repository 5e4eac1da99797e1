"""Error against wall time (log-log) for every model and resolution of the three scenes."""

import argparse

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from msslib.io import read_result  # noqa: E402
from msslib.plotting import save  # noqa: E402

SCENES = ["cantilever", "cylinder", "membrane"]
INPUTS = [f"results/performance/studies/front_{s}.nc" for s in SCENES]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", required=True)
    a = p.parse_args()
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), constrained_layout=True)
    markers = "osD^v<>p"
    for ax, scene, path in zip(axes, SCENES, INPUTS):
        f = read_result(path)
        for k, m in enumerate(f.model.values):
            t = f.wall_time.sel(model=m).values
            e = f.error_max.sel(model=m).values
            ok = np.isfinite(t) & np.isfinite(e)
            ax.loglog(t[ok], 100 * e[ok], marker=markers[k % len(markers)], label=str(m))
            for lv, ti, ei in zip(f.level.values[ok], t[ok], e[ok]):
                ax.annotate(str(lv), (ti, 100 * ei), textcoords="offset points", xytext=(3, 3), fontsize=7)
        ax.set_title(f"{scene} (reference: {f.attrs['reference_model']}, level {f.attrs['reference_level']})", fontsize=9)
        ax.set_xlabel("median wall time (s)")
        ax.set_ylabel("max node error / max displacement (%)")
        ax.grid(True, which="both", alpha=0.3)
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.legend(fontsize=7)
    save(fig, a.out)


if __name__ == "__main__":
    main()

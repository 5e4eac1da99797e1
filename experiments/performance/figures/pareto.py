"""Error against wall time (log-log) for every model and resolution of the three scenes, with the
Pareto front (the runs no other run beats in both time and error) drawn through them."""

import argparse

import numpy as np

from msslib import plotting
from msslib.io import read_result

SCENES = ["cantilever", "cylinder", "membrane"]
INPUTS = [f"results/performance/studies/front_{s}.nc" for s in SCENES]
MARKERS = "osD^v<>p"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    a = p.parse_args()
    fig = plotting.figure(figsize=(13, 4.4))
    axes = fig.subplots(1, 3)
    for ax, scene, path in zip(axes, SCENES, INPUTS):
        f = read_result(path)
        T, Y = [], []
        for k, m in enumerate(f.model.values):
            t = f.wall_time.sel(model=m).values
            e = 100 * f.error_max.sel(model=m).values
            ok = np.isfinite(t) & np.isfinite(e) & (e > 0)
            ax.plot(t[ok], e[ok], marker=MARKERS[k % len(MARKERS)], ms=6, lw=1, label=str(m), zorder=3)
            for lv, ti, ei in zip(f.level.values[ok], t[ok], e[ok]):
                ax.annotate(str(lv), (ti, ei), textcoords="offset points", xytext=(4, 3), fontsize=7)
            T += list(t[ok])
            Y += list(e[ok])
        T, Y = np.array(T), np.array(Y)
        front = plotting.pareto_front(T, Y)
        ax.plot(T[front], Y[front], color="k", ls="--", lw=1.2, marker="o", ms=12, mfc="none", mew=1.0,
                zorder=2, alpha=0.8, label=f"Pareto front ({len(front)} run{'s' if len(front) != 1 else ''})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.margins(0.15)
        ax.set_title(f"{scene} (reference: {f.attrs['reference_model']}, level {f.attrs['reference_level']})",
                     fontsize=9)
        ax.set_xlabel("median wall time (s)")
        ax.set_ylabel("max node error / max displacement (%)")
        ax.grid(True, which="major", alpha=0.3)
        plotting.label_log_axis(ax)
        plotting.unique_legend(ax, fontsize=7, loc="best")
    plotting.save(fig, a.out)


if __name__ == "__main__":
    main()

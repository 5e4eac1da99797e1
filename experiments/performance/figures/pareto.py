"""Error against wall time (log-log) for every model variant on nested meshes of each scene, the
Pareto front (the runs no other run beats in both time and error), the reference's own estimated
error as a band and the crossover error budget (FEM fastest below it, an MSS above it), drawn only
where the fronts cross once (not where they interleave)."""


import numpy as np

from experiments import plotting
from msslib.results import read_result
from experiments import script

SCENES = ["cantilever", "cantilever on tetrahedra", "cylinder", "membrane"]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
MARKERS = "osD^v<>p"


def _style(name, k):
    """MSS models: one colour each, solid non-linear and dashed linear; FEM: black/grey."""
    if name == "fem_linear":
        return {"color": "0.45", "ls": "--", "marker": "s"}
    if name.startswith("fem"):
        return {"color": "0.1", "ls": "-", "marker": "s"}
    colour = f"C{k // 2}"
    return {"color": colour, "ls": "--" if name.endswith("_linear") else "-", "marker": "o" if k % 2 == 0 else "^"}


def main():
    a = script.args(__doc__)
    fig = plotting.figure(figsize=(14, 13.2))
    axes = fig.subplots(2, 2).ravel()
    for ax, scene, path in zip(axes, SCENES, INPUTS):
        f = read_result(path)
        T, Y = [], []
        for k, m in enumerate(f.model.values):
            t = f.wall_time.sel(model=m).values
            e = 100 * f.error_max.sel(model=m).values
            ok = np.isfinite(t) & np.isfinite(e) & (e > 0)
            ax.plot(t[ok], e[ok], ms=5, lw=1.2, label=str(m), zorder=3, **_style(str(m), k))
            for lv, ti, ei in zip(f.level.values[ok], t[ok], e[ok]):
                ax.annotate(str(lv), (ti, ei), textcoords="offset points", xytext=(3, 2), fontsize=6)
            T += list(t[ok])
            Y += list(e[ok])
        T, Y = np.array(T), np.array(Y)
        front = plotting.pareto_front(T, Y)
        ax.plot(T[front], Y[front], color="k", ls=":", lw=1.0, marker="o", ms=11, mfc="none", mew=0.9,
                zorder=2, alpha=0.8, label=f"Pareto front ({len(front)} runs)")
        ref_err = 100 * float(f.attrs["reference_error"])
        if np.isfinite(ref_err) and ref_err > 0:
            ax.axhspan(1e-9, ref_err, color="0.85", zorder=0, label=f"reference's own error ({ref_err:.2g} %)")
        gap = 100 * float(f.attrs["linearisation_gap"])
        ax.axhline(gap, color="tab:purple", ls="-.", lw=0.9, label=f"linear vs non-linear ref. ({gap:.2g} %)")
        cross = float(f.attrs["crossover_error"])
        kind = str(f.attrs.get("crossover_kind", ""))
        if np.isfinite(cross) and kind in ("single crossover", "mss window"):
            ax.axhline(100 * cross, color="tab:red", lw=0.9, ls=(0, (6, 3)),
                       label=f"crossover budget {100 * cross:.2g} % (FEM fastest below)")
        else:  # no budget separates the methods: no line, the legend says why
            ax.plot([], [], " ", label=f"no crossover line: {kind or 'no MSS on the front'}")
        ax.set_xscale("log")
        ax.set_yscale("log")
        lo = max(min(Y.min(), ref_err if np.isfinite(ref_err) else np.inf) / 2, 1e-4)
        ax.set_ylim(lo, Y.max() * 2)
        ax.set_xlim(T.min() / 2, T.max() * 2)
        ax.set_title(f"{scene} (reference: {str(f.attrs['reference_model']).split()[0]}, quadratic elements, "
                     f"level {f.attrs['reference_level']})", fontsize=9)
        ax.set_xlabel("CPU time of the run, 1 thread, best of repeats (s)")
        ax.set_ylabel("max node error / max reference displacement (%)")
        ax.grid(True, which="major", alpha=0.3)
        plotting.label_log_axis(ax)
        plotting.unique_legend(ax, fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    plotting.save(fig, a.out)


if __name__ == "__main__":
    main()

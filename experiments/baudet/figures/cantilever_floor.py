"""Baudet Figs. 9-10: the cantilever's errors against the resolution, down to the uncorrected lattice's floor."""

import numpy as np
from matplotlib.ticker import NullLocator

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    cmp = C.open_result(INPUTS[1])
    n = ds["cubes_across"].values
    fig = plotting.figure(figsize=(10.0, 5.0))
    ax1, ax2 = fig.subplots(1, 2)
    m = {"stat": "mean"}
    ax1.plot(n, 100 * ds["error_mss"].sel(**m), "o-", color="tab:red", label="MSS vs FEM reference (Q1 48x12x12)")
    ax1.plot(n, 100 * ds["error_mss_vs_lattice"].sel(**m), "s--", color="tab:red", mfc="w",
             label="MSS vs its own continuum limit (lattice tensor, Q2)")
    ax1.plot(n, 100 * ds["error_fem_same_mesh"].sel(**m), "^-", color="tab:blue", label="linear FEM (Q1) on the MSS mesh")
    ax1.plot(n, 100 * ds["error_floor"].sel(**m), "k-", lw=2, label="floor: lattice continuum vs isotropic")
    pub = [(int(v.split("_")[1].split("x")[1]), float(cmp["published_relative_mean"].sel(case="gravity", variant=v)))
           for v in cmp.variant.values if np.isfinite(cmp["published_relative_mean"].sel(case="gravity", variant=v))]
    ax1.plot([p[0] for p in pub], [100 * p[1] for p in pub], "D", mfc="gold", mec="k", ms=7, ls="", label="Baudet M (published)")
    ax1.set_ylabel("mean per-node error / largest displacement (%)")
    t = {"MSS": ("tip_error_mss", "o-", "tab:red"), "linear FEM (Q1) on the MSS mesh": ("tip_error_fem_same_mesh", "^-", "tab:blue"),
         "floor: lattice continuum vs isotropic": ("tip_error_floor", "-", "k")}
    for lab, (var, st, c) in t.items():
        ax2.plot(n, -100 * ds[var], st, color=c, label=lab, lw=2 if c == "k" else 1.5)
    ax2.axhline(-100 * float(ds["floor_tip_euler_bernoulli"]), color="0.4", ls=":", label="floor, Euler-Bernoulli: 1 - E/E_axis")
    ax2.axhline(-100 * float(ds["floor_tip_timoshenko"]), color="0.4", ls="--", label="floor, Timoshenko (exact G)")
    ax2.set_ylabel("tip deflection too small by (%)")
    for ax in (ax1, ax2):
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xticks(n)
        ax.set_xticklabels([str(r) for r in ds["resolution"].values], rotation=30, ha="right", fontsize=8)
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xlabel("resolution (cubes; axis: cubes across the section, log scale)")
        plotting.label_log_axis(ax, "y")
        ax.grid(alpha=0.3, which="both")
    ax1.plot([4], [1.68], "D", mfc="w", mec="k", ms=7, ls="", label="0.68 read as a misprint of 1.68")
    for ax in (ax1, ax2):
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=2, frameon=False)
    ax1.set_title("mean error (Baudet's M)")
    ax2.set_title("tip deflection")
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

"""Lloyd et al., Figs. 5, 7 and 8: zero patterns of the element stiffness matrices, MSS against FEM.

Black: non-zero at the paper's values; grey: zero at these values only (non-zero for other
constants or another Poisson's ratio); white: zero for every value (structural).  Top: the square
(Fig. 5: springs without and with prestrain, and the bilinear FEM element at nu = 1/3); bottom:
the regular tetrahedron (Fig. 7: springs of eq. 12; Fig. 8: springs and volume term of eq. 14;
the linear FEM element at nu = 1/4).  Thin lines separate the nodes.

    python -m experiments.lloyd.figures.sparsity --out paper/figures/lloyd_sparsity
"""

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

from experiments import plotting
from experiments import script

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
TITLES = {"square_mss_plain": "a) MSS, no prestrain", "square_mss_prestrain": "b) MSS, prestrain (eqs. 10-11)",
          "square_fem": "c) FEM, bilinear, $\\nu$ = 1/3", "tet_mss": "d) MSS, springs (eq. 12)",
          "tet_mss_volume": "e) MSS + volume term (eq. 14)", "tet_fem": "f) FEM, linear, $\\nu$ = 1/4"}
COLOURS = ListedColormap(["white", "0.72", "black"])


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    fig = plotting.figure(figsize=(9.6, 6.9))
    axes = fig.subplots(2, 3)
    for row, (element, dim) in zip(axes, (("square", 2), ("tet", 3))):
        for ax, i in zip(row, range(3)):
            name = str(ds[f"{element}_matrix"].values[i])
            code = ds[f"{element}_structural"].values[i] + ds[f"{element}_numerical"].values[i]
            n = code.shape[0]
            ax.imshow(code, cmap=COLOURS, vmin=0, vmax=2, interpolation="nearest")
            for b in range(dim, n, dim):
                ax.axhline(b - 0.5, color="tab:blue", lw=0.6)
                ax.axvline(b - 0.5, color="tab:blue", lw=0.6)
            ticks = np.arange(0, n, dim)
            ax.set_xticks(ticks, [f"{t // dim}" for t in ticks])
            ax.set_yticks(ticks, [f"{t // dim}" for t in ticks])
            sel = ds.sel(matrix=name)
            ax.set_title(f"{TITLES[name]}\nnon-zeros {int(sel.nnz_numerical)} of {int(sel.size)} "
                         f"(structural {int(sel.nnz_structural)})", fontsize=9)
            ax.set_xlabel("node (columns: x, y" + (", z" if dim == 3 else "") + ")")
        row[0].set_ylabel("node (rows)")
    fig.legend(handles=[Patch(fc="black", ec="k", label="non-zero at the paper's values"),
                        Patch(fc="0.72", ec="k", label="zero at these values only"),
                        Patch(fc="white", ec="k", label="zero for any constants and $\\nu$")],
               loc="outside lower center", ncol=3, frameon=False)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

"""Lloyd et al. Fig. 17 (Sec. 5.7): cone under large shear, MSS (red) over linear and over non-linear FEM, seen along x.

    python -m experiments.lloyd.figures.cone --out paper/figures/lloyd_cone
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [("a) reference: linear FEM", "shear", "mss", "fem_linear"),
           ("b) reference: non-linear FEM (SVK)", "shear", "mss", "fem_svk")]
INPUTS = [f"results/lloyd/cone/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="yz", panel_width=3.6)

"""Lloyd et al. Fig. 13 (Sec. 5.4): square MSS at three resolutions in shear over the 19 x 19 FEM reference.

    python -m experiments.lloyd.figures.resolutions --out paper/figures/lloyd_resolutions
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [("a) 2 x 2", "shear", "mss_2x2", "fem"), ("b) 5 x 5", "shear", "mss_5x5", "fem"),
           ("c) 19 x 19", "shear", "mss_19x19", "fem")]
INPUTS = [f"results/lloyd/resolutions/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="xy", panel_width=3.2)

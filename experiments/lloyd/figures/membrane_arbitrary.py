"""Lloyd et al. Figs. 10-11 (Sec. 5.2): arbitrary triangles, eq. 8 and eq. 9 (red) over linear FEM.

    python -m experiments.lloyd.figures.membrane_arbitrary --out paper/figures/lloyd_membrane_arbitrary
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [("a) eq. 8, stretch", "stretch", "eq8", "fem"), ("b) eq. 8, compression", "compression", "eq8", "fem"),
           ("c) eq. 8, shear", "shear", "eq8", "fem"), ("d) eq. 9, stretch", "stretch", "eq9", "fem"),
           ("e) eq. 9, compression", "compression", "eq9", "fem"), ("f) eq. 9, shear", "shear", "eq9", "fem")]
INPUTS = [f"results/lloyd/membrane_arbitrary/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="xy", panel_width=2.6)

"""Lloyd et al. Fig. 9 (Sec. 5.1): equilateral-triangle MSS (eq. 8, red) over linear FEM.

    python -m experiments.lloyd.figures.membrane_equilateral --out paper/figures/lloyd_membrane_equilateral
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [(f"{k}) {case}", case, "mss", "fem") for k, case in zip("abc", ("stretch", "compression", "shear"))]
INPUTS = [f"results/lloyd/membrane_equilateral/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="xy", panel_width=3.2)

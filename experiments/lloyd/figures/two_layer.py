"""Lloyd et al. Fig. 14 (Sec. 5.5): two-layer plate, square MSS (red) over linear FEM.

    python -m experiments.lloyd.figures.two_layer --out paper/figures/lloyd_two_layer
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [(f"{k}) {case}", case, "mss", "fem") for k, case in zip("abc", ("stretch", "compression", "shear"))]
INPUTS = [f"results/lloyd/two_layer/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="xy", panel_width=3.2)

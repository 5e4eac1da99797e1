"""Lloyd et al. Fig. 15 (Sec. 5.6): tetrahedral cylinder, MSS (eq. 12-13, red) over linear FEM, seen along x.

    python -m experiments.lloyd.figures.cylinder --out paper/figures/lloyd_cylinder
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [(f"{k}) {case}", case, "mss", "fem") for k, case in zip("abc", ("stretch", "compression", "shear"))]
INPUTS = [f"results/lloyd/cylinder/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="yz", panel_width=3.2)

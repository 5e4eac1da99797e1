"""Lloyd et al. Fig. 18 (Sec. 5.8): cylinder, MSS with volume-preserving forces (eq. 14 as printed, red) over linear FEM.

    python -m experiments.lloyd.figures.cylinder_volume --out paper/figures/lloyd_cylinder_volume
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [(f"{k}) {case}", case, "printed", "fem") for k, case in zip("abc", ("stretch", "compression", "shear"))]
INPUTS = [f"results/lloyd/cylinder_volume/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="yz", panel_width=3.2)

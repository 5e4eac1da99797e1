"""Lloyd et al. Fig. 19 (Sec. 5.9): synthetic myoma pushed and pulled from the top, MSS (eq. 12-13, red) over linear FEM, seen along y.

    python -m experiments.lloyd.figures.myoma --out paper/figures/lloyd_myoma
"""

from experiments.lloyd.comparison_figure import main

# (column title, case, variant, reference)
COLUMNS = [("a) push, 300 Pa", "push_300", "mss", "fem"), ("b) pull, 300 Pa", "pull_300", "mss", "fem"),
           ("c) push, 1000 Pa", "push_1000", "mss", "fem"), ("d) pull, 1000 Pa", "pull_1000", "mss", "fem")]
INPUTS = [f"results/lloyd/myoma/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    main(__doc__, COLUMNS, INPUTS, plane="xz", panel_width=3.2)

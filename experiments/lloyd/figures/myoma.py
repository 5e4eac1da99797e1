"""Lloyd et al. Fig. 19 (Sec. 5.9): synthetic myoma pushed and pulled from the top, MSS (eq. 12-13, red) over linear FEM, seen along y.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python myoma.py --out paper/figures/lloyd_myoma
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "myoma"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) push, 300 Pa", "push_300", "mss", "fem"),
    ("b) pull, 300 Pa", "pull_300", "mss", "fem"),
    ("c) push, 1000 Pa", "push_1000", "mss", "fem"),
    ("d) pull, 1000 Pa", "pull_1000", "mss", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="xz", panel_width=3.2)

"""Lloyd et al. Figs. 10-11 (Sec. 5.2): arbitrary triangles, eq. 8 and eq. 9 (red) over linear FEM.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python membrane_arbitrary.py --out paper/figures/lloyd_membrane_arbitrary
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "membrane_arbitrary"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) eq. 8, stretch", "stretch", "eq8", "fem"),
    ("b) eq. 8, compression", "compression", "eq8", "fem"),
    ("c) eq. 8, shear", "shear", "eq8", "fem"),
    ("d) eq. 9, stretch", "stretch", "eq9", "fem"),
    ("e) eq. 9, compression", "compression", "eq9", "fem"),
    ("f) eq. 9, shear", "shear", "eq9", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="xy", panel_width=2.6)

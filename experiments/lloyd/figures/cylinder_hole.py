"""Lloyd et al. Fig. 16 (Sec. 5.6): cylinder with a spherical hole, MSS (red) over linear FEM, seen along x.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python cylinder_hole.py --out paper/figures/lloyd_cylinder_hole
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "cylinder_hole"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) stretch", "stretch", "mss", "fem"),
    ("b) compression", "compression", "mss", "fem"),
    ("c) shear", "shear", "mss", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="yz", panel_width=3.2)

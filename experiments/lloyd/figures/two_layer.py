"""Lloyd et al. Fig. 14 (Sec. 5.5): two-layer plate, square MSS (red) over linear FEM.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python two_layer.py --out paper/figures/lloyd_two_layer
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "two_layer"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) stretch", "stretch", "mss", "fem"),
    ("b) compression", "compression", "mss", "fem"),
    ("c) shear", "shear", "mss", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="xy", panel_width=3.2)

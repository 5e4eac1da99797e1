"""Lloyd et al. Fig. 13 (Sec. 5.4): square MSS at three resolutions in shear over the 19 x 19 FEM reference.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python resolutions.py --out paper/figures/lloyd_resolutions
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "resolutions"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) 2 x 2", "shear", "mss_2x2", "fem"),
    ("b) 5 x 5", "shear", "mss_5x5", "fem"),
    ("c) 19 x 19", "shear", "mss_19x19", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="xy", panel_width=3.2)

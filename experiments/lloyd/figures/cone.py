"""Lloyd et al. Fig. 17 (Sec. 5.7): cone under large shear, MSS (red) over linear and over non-linear FEM, seen along x.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python cone.py --out paper/figures/lloyd_cone
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "cone"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) reference: linear FEM", "shear", "mss", "fem_linear"),
    ("b) reference: non-linear FEM (SVK)", "shear", "mss", "fem_svk"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="yz", panel_width=3.6)

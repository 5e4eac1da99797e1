"""Lloyd et al. Fig. 18 (Sec. 5.8): cylinder, MSS with volume-preserving forces (eq. 14 as printed, red) over linear FEM.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python cylinder_volume.py --out paper/figures/lloyd_cylinder_volume
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from comparison_figure import inputs, main  # noqa: E402

EXPERIMENT = "cylinder_volume"
# (column title, case, variant, reference)
COLUMNS = [
    ("a) stretch", "stretch", "printed", "fem"),
    ("b) compression", "compression", "printed", "fem"),
    ("c) shear", "shear", "printed", "fem"),
]
INPUTS = [f"results/lloyd/{EXPERIMENT}/{case}__{m}.nc" for _, case, var, ref in COLUMNS for m in (var, ref)]

if __name__ == "__main__":
    assert INPUTS == inputs(EXPERIMENT, COLUMNS)
    main(EXPERIMENT, COLUMNS, __doc__.splitlines()[0], plane="yz", panel_width=3.2)

"""Lloyd et al. Figs. 10-11 (Sec. 5.2): arbitrary triangles, eq. 8 and eq. 9 (red) over linear FEM.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python membrane_arbitrary.py --out paper/figures/lloyd_membrane_arbitrary
"""

import argparse
from pathlib import Path

from msslib import plotting
from msslib.io import read_result

ROOT = Path(__file__).resolve().parents[3]
INPUTS = [
    "results/lloyd/membrane_arbitrary/stretch__eq8.nc",
    "results/lloyd/membrane_arbitrary/stretch__fem.nc",
    "results/lloyd/membrane_arbitrary/compression__eq8.nc",
    "results/lloyd/membrane_arbitrary/compression__fem.nc",
    "results/lloyd/membrane_arbitrary/shear__eq8.nc",
    "results/lloyd/membrane_arbitrary/shear__fem.nc",
    "results/lloyd/membrane_arbitrary/stretch__eq9.nc",
    "results/lloyd/membrane_arbitrary/compression__eq9.nc",
    "results/lloyd/membrane_arbitrary/shear__eq9.nc",
]
# (column title, case, variant, reference)
COLUMNS = [
    ("a) eq. 8, stretch", "stretch", "eq8", "fem"),
    ("b) eq. 8, compression", "compression", "eq8", "fem"),
    ("c) eq. 8, shear", "shear", "eq8", "fem"),
    ("d) eq. 9, stretch", "stretch", "eq9", "fem"),
    ("e) eq. 9, compression", "compression", "eq9", "fem"),
    ("f) eq. 9, shear", "shear", "eq9", "fem"),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)

    def load(case, model):
        return read_result(ROOT / "results" / "lloyd" / "membrane_arbitrary" / f"{case}__{model}.nc")

    pairs = {title: (load(case, var), load(case, ref)) for title, case, var, ref in COLUMNS}
    fig = plotting.comparison_figure(pairs, plane="xy", variant_label="MSS",
                                     reference_label="FEM", panel_width=2.6)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

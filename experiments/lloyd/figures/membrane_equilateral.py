"""Lloyd et al. Fig. 9 (Sec. 5.1): equilateral-triangle MSS (eq. 8, red) over linear FEM.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python membrane_equilateral.py --out paper/figures/lloyd_membrane_equilateral
"""

import argparse
from pathlib import Path

from msslib import plotting
from msslib.io import read_result

ROOT = Path(__file__).resolve().parents[3]
INPUTS = [
    "results/lloyd/membrane_equilateral/stretch__mss.nc",
    "results/lloyd/membrane_equilateral/stretch__fem.nc",
    "results/lloyd/membrane_equilateral/compression__mss.nc",
    "results/lloyd/membrane_equilateral/compression__fem.nc",
    "results/lloyd/membrane_equilateral/shear__mss.nc",
    "results/lloyd/membrane_equilateral/shear__fem.nc",
]
# (column title, case, variant, reference)
COLUMNS = [
    ("a) stretch", "stretch", "mss", "fem"),
    ("b) compression", "compression", "mss", "fem"),
    ("c) shear", "shear", "mss", "fem"),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)

    def load(case, model):
        return read_result(ROOT / "results" / "lloyd" / "membrane_equilateral" / f"{case}__{model}.nc")

    pairs = {title: (load(case, var), load(case, ref)) for title, case, var, ref in COLUMNS}
    fig = plotting.comparison_figure(pairs, plane="xy", variant_label="MSS",
                                     reference_label="FEM", panel_width=3.2)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

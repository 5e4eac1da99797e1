"""Lloyd et al. Fig. 17 (Sec. 5.7): cone under large shear, MSS (red) over linear and over non-linear FEM, seen along x.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python cone.py --out paper/figures/lloyd_cone
"""

import argparse
from pathlib import Path

from msslib import plotting
from msslib.io import read_result

ROOT = Path(__file__).resolve().parents[3]
INPUTS = [
    "results/lloyd/cone/shear__mss.nc",
    "results/lloyd/cone/shear__fem_linear.nc",
    "results/lloyd/cone/shear__fem_svk.nc",
]
# (column title, case, variant, reference)
COLUMNS = [
    ("a) reference: linear FEM", "shear", "mss", "fem_linear"),
    ("b) reference: non-linear FEM (SVK)", "shear", "mss", "fem_svk"),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)

    def load(case, model):
        return read_result(ROOT / "results" / "lloyd" / "cone" / f"{case}__{model}.nc")

    pairs = {title: (load(case, var), load(case, ref)) for title, case, var, ref in COLUMNS}
    fig = plotting.comparison_figure(pairs, plane="yz", variant_label="MSS",
                                     reference_label="FEM", panel_width=3.6)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

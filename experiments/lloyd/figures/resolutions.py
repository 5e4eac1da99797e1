"""Lloyd et al. Fig. 13 (Sec. 5.4): square MSS at three resolutions in shear over the 19 x 19 FEM reference.

Top row: the MSS wireframe (red) over the reference, coloured by its displacement magnitude, the
rest shape in grey; bottom row: the distance between MSS and reference at every node.

    python resolutions.py --out paper/figures/lloyd_resolutions
"""

import argparse
from pathlib import Path

from msslib import plotting
from msslib.io import read_result

ROOT = Path(__file__).resolve().parents[3]
INPUTS = [
    "results/lloyd/resolutions/shear__mss_2x2.nc",
    "results/lloyd/resolutions/shear__fem.nc",
    "results/lloyd/resolutions/shear__mss_5x5.nc",
    "results/lloyd/resolutions/shear__mss_19x19.nc",
]
# (column title, case, variant, reference)
COLUMNS = [
    ("a) 2 x 2", "shear", "mss_2x2", "fem"),
    ("b) 5 x 5", "shear", "mss_5x5", "fem"),
    ("c) 19 x 19", "shear", "mss_19x19", "fem"),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)

    def load(case, model):
        return read_result(ROOT / "results" / "lloyd" / "resolutions" / f"{case}__{model}.nc")

    pairs = {title: (load(case, var), load(case, ref)) for title, case, var, ref in COLUMNS}
    fig = plotting.comparison_figure(pairs, plane="xy", variant_label="MSS",
                                     reference_label="FEM", panel_width=3.2)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

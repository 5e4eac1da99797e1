"""Baudet Fig. 6: error of the shear modulus of a cube against the shear angle."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import baudet_common as C  # noqa: E402
from msslib import plotting  # noqa: E402

INPUTS = ["results/baudet/studies/shear.nc"]


def main():
    args = C.figure_args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = {"no correction (paper's definition)": {"factor": "none"},
              "derived factor (msslib load sharing)": {"factor": "derived"},
              "printed factor (msslib load sharing)": {"factor": "printed"}}
    fig = C.curves(ds["G_error"], ds["angle"].values, xlabel="shear angle (degree)", ylabel="G error (%)",
                   panels=panels, xscale=1.0)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

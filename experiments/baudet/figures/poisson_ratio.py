"""Baudet Fig. 5: error of Poisson's ratio (absolute value) against the axial strain."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import baudet_common as C  # noqa: E402
from msslib import plotting  # noqa: E402

INPUTS = ["results/baudet/studies/tension.nc"]


def main():
    args = C.figure_args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = {"derived factor -(4nu-1)/2": {"geometry": "cube", "factor": "derived"},
              "printed factor -(4nu-1)/16": {"geometry": "cube", "factor": "printed"}}
    fig = C.curves(ds["nu_error"], ds["strain"].values, xlabel="axial strain (%)", ylabel="|nu error| (%)",
                   panels=panels, absolute=True, dashed={"beam of 4x4x12 cubes": {"geometry": "beam"}}, ylog=True)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

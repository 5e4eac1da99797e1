"""Baudet Fig. 8: error of the bulk modulus against the volume change (deflation < 0 < inflation), under
the boundary and the element reading of the correction force."""

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = C.CUBE_PANELS
    fig = C.curves(ds["B_error_by_reading"], ds["volume_change"].values, xlabel="volume change dV/V0 (%)", ylabel="B error (%)",
                   panels=panels, dashed={"block of 4x4x4 cubes": {"geometry": "block"}})
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

"""Baudet Fig. 4: error of Young's modulus against the axial strain, derived vs printed factor, and the
correction read at element level (every cube corrected from the forces on it from outside)."""

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
PUBLISHED = [(10.0, 2.7, "0.3"), (10.0, 2.0, "0.4"), (10.0, 1.5, "0.499")]  # Sec. 5 text, nu = 0.5 as 0.499


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = C.CUBE_PANELS
    fig = C.curves(ds["E_error_by_reading"], ds["strain"].values, xlabel="axial strain (%)", ylabel="E error (%)",
                   panels=panels, dashed={"beam of 4x4x12 cubes": {"geometry": "beam"}},
                   marks={k: PUBLISHED for k in panels if "derived" in k})
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

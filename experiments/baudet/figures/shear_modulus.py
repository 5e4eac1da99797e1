"""Baudet Fig. 6: error of the shear modulus of a cube against the shear angle, without correction and
with it under the boundary reading (derived, printed factor) and the element reading (derived)."""

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = {"no correction (paper's definition)": {"factor": "none", "reading": "boundary"},
              "boundary reading, derived factor": {"factor": "derived", "reading": "boundary"},
              "boundary reading, printed factor": {"factor": "printed", "reading": "boundary"},
              "element reading, derived factor": {"factor": "derived", "reading": "element"}}
    fig = C.curves(ds["G_error_by_reading"], ds["angle"].values, xlabel="shear angle (degree)", ylabel="G error (%)",
                   panels=panels, xscale=1.0)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

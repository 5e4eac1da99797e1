"""Baudet Fig. 7: sheared beam, MSS wireframes over the FEM reference and per-node error maps, with the
correction read from the loaded boundary faces and at element level, side by side per resolution."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import baudet_common as C  # noqa: E402
from msslib import plotting  # noqa: E402

RES = ("2x2x6", "4x4x12", "8x8x24")
READINGS = {"boundary": "", "element": "_element"}
INPUTS = ([f"results/baudet/shear_beam/shear__mss_{r}{tag}.nc" for r in RES for tag in READINGS.values()]
          + ["results/baudet/shear_beam/shear__fem.nc"])


def main():
    args = C.figure_args(__doc__)
    ref = C.open_result(INPUTS[-1])
    labels = [f"{r} cubes\n{name} reading" for r in RES for name in READINGS]
    pairs = {k: C.open_result(p) for k, p in zip(labels, INPUTS[:-1])}
    fig = plotting.comparison_figure({k: (ds, ref) for k, ds in pairs.items()}, plane="xz", length_unit="mm",
                                     magnify=10.0, node_errors=True, panel_width=1.9, panel_height=4.2)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

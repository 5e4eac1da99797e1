"""Baudet Fig. 13: L-shaped block, MSS wireframes over the FEM reference and per-node error maps, with the
correction read from the loaded boundary faces and at element level, side by side per resolution."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import baudet_common as C  # noqa: E402
from msslib import plotting  # noqa: E402

RES = (2, 4, 8)
READINGS = {"boundary": "", "element": "_element"}
INPUTS = ([f"results/baudet/l_block/lateral__mss_n{n}{tag}.nc" for n in RES for tag in READINGS.values()]
          + ["results/baudet/l_block/lateral__fem.nc"])


def main():
    args = C.figure_args(__doc__)
    ref = C.open_result(INPUTS[-1])
    labels = [f"n = {n} ({3 * n ** 3 // 4} cubes)\n{name} reading" for n in RES for name in READINGS]
    pairs = {k: C.open_result(p) for k, p in zip(labels, INPUTS[:-1])}
    fig = plotting.comparison_figure({k: (ds, ref) for k, ds in pairs.items()}, plane="xz", length_unit="mm",
                                     magnify=20.0, node_errors=True, panel_width=2.4, panel_height=2.6)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

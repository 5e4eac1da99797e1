"""Baudet Fig. 13: L-shaped block, MSS wireframes over the FEM reference and per-node error maps."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import baudet_common as C  # noqa: E402
from msslib import plotting  # noqa: E402

RES = (2, 4, 8)
INPUTS = [f"results/baudet/l_block/lateral__mss_n{n}.nc" for n in RES] + ["results/baudet/l_block/lateral__fem.nc"]


def main():
    args = C.figure_args(__doc__)
    ref = C.open_result(INPUTS[-1])
    pairs = {f"n = {n} ({3 * n ** 3 // 4} cubes)": C.open_result(p) for n, p in zip(RES, INPUTS[:-1])}
    fig = plotting.comparison_figure({k: (ds, ref) for k, ds in pairs.items()}, plane="xz", length_unit="mm",
                                     magnify=20.0, node_errors=True, panel_width=3.0, panel_height=3.0)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

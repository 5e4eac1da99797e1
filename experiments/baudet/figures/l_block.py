"""Baudet Fig. 13: L-shaped block, MSS wireframes over the FEM reference and per-node error maps, with the
correction read from the loaded boundary faces and at element level, side by side per resolution.

    python -m experiments.baudet.figures.l_block --out paper/figures/baudet_l_block
"""

from experiments.baudet import baudet_common as C

RES = (2, 4, 8)
READINGS = {"boundary": "", "element": "_element"}
INPUTS = ([f"results/baudet/l_block/lateral__mss_n{n}{tag}.nc" for n in RES for tag in READINGS.values()]
          + ["results/baudet/l_block/lateral__fem.nc"])

if __name__ == "__main__":
    C.comparison(__doc__, [f"n = {n} ({3 * n ** 3 // 4} cubes)\n{name} reading" for n in RES for name in READINGS],
                 INPUTS, magnify=20.0, panel_width=2.4, panel_height=2.6)

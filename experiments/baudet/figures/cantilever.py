"""Baudet Fig. 10: cantilever under gravity, MSS wireframes over the FEM reference and per-node error maps.

    python -m experiments.baudet.figures.cantilever --out paper/figures/baudet_cantilever
"""

from experiments.baudet import baudet_common as C

RES = ("4x1x1", "8x2x2", "16x4x4")
INPUTS = [f"results/baudet/cantilever/gravity__mss_{r}.nc" for r in RES] + ["results/baudet/cantilever/gravity__fem.nc"]

if __name__ == "__main__":
    C.comparison(__doc__, [f"{r} cubes" for r in RES], INPUTS, magnify=100.0, panel_width=3.6, panel_height=1.6)

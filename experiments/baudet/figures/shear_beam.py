"""Baudet Fig. 7: sheared beam, MSS wireframes over the FEM reference and per-node error maps, with the
correction read from the loaded boundary faces and at element level, side by side per resolution.

    python -m experiments.baudet.figures.shear_beam --out paper/figures/baudet_shear_beam
"""

from experiments.baudet import baudet_common as C

RES = ("2x2x6", "4x4x12", "8x8x24")
READINGS = {"boundary": "", "element": "_element"}
INPUTS = ([f"results/baudet/shear_beam/shear__mss_{r}{tag}.nc" for r in RES for tag in READINGS.values()]
          + ["results/baudet/shear_beam/shear__fem.nc"])

if __name__ == "__main__":
    C.comparison(__doc__, [f"{r} cubes\n{name} reading" for r in RES for name in READINGS], INPUTS,
                 magnify=10.0, panel_width=1.9, panel_height=4.2)

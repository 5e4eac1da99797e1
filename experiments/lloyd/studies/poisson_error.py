"""Lloyd et al., Fig. 3: error of the equilateral-triangle MSS against FEM as a function of nu.

A regular hexagon 1.7 cm high (flat bottom and top sides) meshed with equilateral triangles (4
rings, 61 nodes), thickness 1 cm, E = 14630 Pa; bottom side fixed, a uniform traction on the top
side: stretch (10 % of E, normal), shear (4 % of E, tangential) and a small stretch (1 % of E,
where the MSS is nearly linear).  Springs from Lloyd's eq. 8
(which does not depend on nu) against linear plane-stress FEM with the same E and nu, for nu from 0
to 0.49.  The paper does not state the load of Fig. 3; the minimum of the error should sit near
nu = 1/3, where eq. 8 is exact.

    python -m experiments.lloyd.studies.poisson_error --out results/lloyd/studies/poisson_error.nc [--quick]
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.results import write_result
from msslib.compare import compare_results
from msslib.scene import run_scene

E, HEIGHT, RINGS, THICKNESS = 14630.0, 0.017, 4, 0.01
LOADS = {"stretch": (0.0, 0.10 * E), "shear": (0.04 * E, 0.0), "small_stretch": (0.0, 0.01 * E)}


def scene(model, nu, traction):
    y = HEIGHT / 2.0
    return {
        "name": f"hexagon_{model}_{nu:g}",
        "geometry": {"generator": "hexagon_equilateral", "args": {"height": HEIGHT, "n_rings": RINGS}},
        "materials": [{"E": E, "nu": float(nu)}],
        "thickness": THICKNESS,
        "model": model,
        "boundary": [{"select": {"plane": ["y", -y]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["y", y]}, "traction": list(traction)}],
        "solver": {"type": "static", "load_steps": 4, "tol": 1e-9},
    }


def main(argv=None):
    args = script.args(__doc__, argv)
    nus = np.array([0.0, 1 / 3, 0.49]) if args.quick else np.append(np.arange(0.0, 0.46, 0.05), [1 / 3, 0.49])
    nus = np.unique(nus)
    cases = list(LOADS)
    shape = (len(cases), len(nus))
    err_max, err_mean, ref_max = np.empty(shape), np.empty(shape), np.empty(shape)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # eq. 8 off nu = 1/3: expected, that is the point
        for i, case in enumerate(cases):
            for j, nu in enumerate(nus):
                mss = run_scene(scene("lloyd_triangle", nu, LOADS[case]), progress=False)
                fem = run_scene(scene("fem_linear", nu, LOADS[case]), progress=False)
                c = compare_results(mss, fem, result_name="lloyd_triangle", reference_name="fem_linear")
                err_max[i, j], err_mean[i, j] = c.error.max, c.error.mean
                ref_max[i, j] = c.reference_max
    best = nus[np.argmin(err_mean, axis=1)]
    third, zero = np.argmin(np.abs(nus - 1 / 3)), np.argmin(np.abs(nus))
    ds = xr.Dataset(
        {
            "error_max": (("case", "nu"), err_max, {"units": "m", "long_name": "maximum node distance MSS - FEM"}),
            "error_mean": (("case", "nu"), err_mean, {"units": "m", "long_name": "mean node distance MSS - FEM"}),
            "reference_max_displacement": (("case", "nu"), ref_max, {"units": "m", "long_name": "largest FEM displacement"}),
            "best_nu": (("case",), best, {"units": "1", "long_name": "nu of the smallest mean error"}),
            "error_max_third": (("case",), err_max[:, third], {"units": "m", "long_name": "maximum error at nu = 1/3"}),
            "error_mean_third": (("case",), err_mean[:, third], {"units": "m", "long_name": "mean error at nu = 1/3"}),
            "error_max_zero": (("case",), err_max[:, zero], {"units": "m", "long_name": "maximum error at nu = 0"}),
            "error_mean_zero": (("case",), err_mean[:, zero], {"units": "m", "long_name": "mean error at nu = 0"}),
        },
        coords={
            "case": ("case", cases, {"units": "1", "long_name": "load case"}),
            "nu": ("nu", nus, {"units": "1", "long_name": "Poisson's ratio of the FEM reference"}),
        },
        attrs={"title": "Lloyd et al. Fig. 3: MSS error against nu", "E": E, "height": HEIGHT, "n_rings": RINGS,
               "thickness": THICKNESS, "quick": int(args.quick)},
    )
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)
    for i, c in enumerate(cases):
        print(c, "nu of smallest mean error:", best[i])
        for j, nu in enumerate(nus):
            print(f"  nu {nu:.3f}: max {err_max[i, j] * 1e3:.3f} mm, mean {err_mean[i, j] * 1e3:.3f} mm")


if __name__ == "__main__":
    main()

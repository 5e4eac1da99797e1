"""Baudet et al. Fig. 8: bulk-modulus error against the volume change (deflation and inflation).

A cube and a block of 4 x 4 x 4 cubes, each modelled as one octant with symmetry planes
x = y = z = 0, under a dead pressure p on the free faces (the same on all six faces of the whole
body; p > 0 compresses). B = -p / (dV/V0) (eq. 5, nominal pressure), V the trilinear volume of the
deformed cubes. Volume changes from -10 % to +10 % (beyond, the
compressed inner lattice of the block buckles and the continuation crawls), nu in {0.1, ..., 0.499}, with the derived and
the printed correction factor. In the block only the cubes with a loaded face get a correction:
the inner cubes are the bare lattice (reading ``boundary``); with the reading ``element`` every cube
is corrected from the forces acting on it from outside (msslib.terms.baudet). Every variable
``V_by_reading`` has the ``reading`` dimension, ``V`` is its ``boundary`` slice.
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C
from msslib.metrics import mesh_volume

GEOMETRIES = {"cube": (1, 1, 1), "block": (2, 2, 2)}
LEVELS = {"dv-10": -0.10, "dv-05": -0.05, "dv-01": -0.01, "dv+01": 0.01, "dv+05": 0.05, "dv+10": 0.10}


def run(n, nu, published, dv_grid, reading="boundary"):
    L = [C.A0 * k for k in n]
    tr = [("x", L[0], [-1.0, 0.0, 0.0]), ("y", L[1], [0.0, -1.0, 0.0]), ("z", L[2], [0.0, 0.0, -1.0])]
    mesh, model = C.block(n, nu, published=published, tractions=tr, reading=reading)
    V0 = mesh_volume(mesh)

    def dv(x):
        return mesh_volume(mesh, x.reshape(-1, 3) - mesh.points) / V0 - 1.0

    B = C.E0 / (3 * (1 - 2 * nu))
    target = np.abs(dv_grid).max() * 1.02
    out, B0 = [], []
    for sign in (+1.0, -1.0):  # deflation (p > 0), inflation (p < 0)
        loads, states = C.follow(model, dv, target, first_step=sign * B * target / 40, tol=1e-8)
        d = np.array([dv(x) for x in states])
        Bm = -loads / d
        out.append((d, Bm))
        B0.append(Bm[0])
    d = np.concatenate([out[1][0][::-1], out[0][0]])
    Bm = np.concatenate([out[1][1][::-1], out[0][1]])
    order = np.argsort(d)
    return np.interp(dv_grid, d[order], Bm[order]), np.mean(B0), B


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    step = 0.005 if not args.quick else 0.01
    pos = np.round(np.arange(step, 0.1001, step), 6)
    dv_grid = np.concatenate([-pos[::-1], pos])
    shape = (len(C.READINGS), len(GEOMETRIES), len(C.FACTORS), len(C.NUS), len(dv_grid))
    Bm = np.full(shape, np.nan)
    B_small = np.full(shape[:4], np.nan)
    B_in = np.array([C.E0 / (3 * (1 - 2 * nu)) for nu in C.NUS])
    for r, reading in enumerate(C.READINGS):
        for g, n in enumerate(GEOMETRIES.values()):
            for f, fac in enumerate(C.FACTORS):
                for k, nu in enumerate(C.NUS):
                    Bm[r, g, f, k], B_small[r, g, f, k], _ = run(n, nu, fac == "printed", dv_grid, reading)
                    print(f"{reading} {list(GEOMETRIES)[g]} {fac} nu={nu}: B(small)/B = "
                          f"{B_small[r, g, f, k] / B_in[k]:.5f}", flush=True)
    ds = xr.Dataset(coords={"reading": list(C.READINGS), "geometry": list(GEOMETRIES), "factor": list(C.FACTORS),
                            "nu": list(C.NU_LABELS), "volume_change": dv_grid})
    ds["reading"].attrs = {"long_name": "correction force driven by the loaded boundary faces or, per cube, by the "
                                        "forces from outside it"}
    ds["volume_change"].attrs = {"units": "1", "long_name": "relative volume change dV/V0"}
    ds["nu"].attrs = {"units": "1", "long_name": "input Poisson's ratio (label)"}
    ds["geometry"].attrs = {"long_name": "cube: one element; block: 4 x 4 x 4 cubes"}
    ds["factor"].attrs = {"long_name": "correction factor: derived -(4nu-1)/2 or printed -(4nu-1)/16"}
    ds["nu_value"] = ("nu", np.array(C.NUS), {"units": "1", "long_name": "input Poisson's ratio"})
    ds["B_input"] = ("nu", B_in, {"units": "Pa", "long_name": "input bulk modulus E/(3(1-2nu))"})
    dims = ("reading", "geometry", "factor", "nu", "volume_change")
    ds["bulk_modulus"] = (dims, Bm, {"units": "Pa", "long_name": "measured B = -p/(dV/V0)"})
    ds["B_error"] = (dims, Bm / B_in[None, None, None, :, None] - 1.0,
                     {"units": "1", "long_name": "relative error of B (signed)"})
    ds["B_small"] = (("reading", "geometry", "factor", "nu"), B_small / B_in[None, None, None, :] - 1.0,
                     {"units": "1", "long_name": "relative error of B at the first load level (mean of both signs)"})
    ds = ds.assign_coords(level=list(LEVELS))
    ds["level"].attrs = {"long_name": "quoted volume change (dv-10 = -10 %)"}
    ds["level_volume_change"] = ("level", np.array(list(LEVELS.values())), {"units": "1", "long_name": "dV/V0 of the level"})
    vals = np.stack([ds["B_error"].interp(volume_change=v).values for v in LEVELS.values()], axis=-1)
    ds["B_error_at"] = (("reading", "geometry", "factor", "nu", "level"), vals,
                        {"units": "1", "long_name": "relative error of B at the quoted volume changes"})
    ds = C.split_readings(ds)
    v = ds["B_error_by_reading"]  # "conserved whatever the composition": largest |block - cube|
    d = abs(v.sel(geometry="block") - v.sel(geometry="cube")).max(("nu", "volume_change"))
    d.attrs = {"units": "1", "long_name": "largest |B error (block) - B error (cube)| over volume changes and nu"}
    ds["B_block_cube_max_difference"] = d
    ds.attrs.update(title="Baudet Fig. 8: B error against the volume change", quick=int(args.quick), cube_edge_m=C.A0)
    C.write(ds, args.out, t0)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()

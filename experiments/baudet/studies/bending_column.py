"""Baudet cantilever: is the lattice's excess over trilinear FEM a bending error per cube?

At 16x4x4 cubes the element reading's cantilever errs by about 2.4 times the error of trilinear
FEM (Q1) on the same mesh. This study isolates the lattice's bending stiffness at equal resolution,
away from the clamp and from gravity: a column of ``4n x n x n`` cubes (400 x 100 x 100 mm, the
cantilever's box; E = 1 kPa, nu = 0.3, as the cantilever) in pure bending. The face x = 0 is a
symmetry plane (u_x = 0; three more dofs remove the rigid motions in it, so that nothing restrains
the anticlastic contraction) and the face x = L carries the consistent nodal forces of the linear
traction sigma_xx = M z / I (a bending moment M about y). The exact solution is Saint-Venant's pure
bending, whose curvature kappa = M / (E I) is uniform; each model's curvature is the slope of u_x
over z on the loaded face (least squares, u_x = kappa L z + c), the same nodes and the same nodal
forces for the linearised MSS (Baudet's cube, derived factor, element reading; also the boundary
reading) and for Q1 (2x2x2 Gauss points), at n = 1, 2, 4 and 8 cubes across. The stiffening
``1 - kappa_model / kappa`` is the model's relative excess of bending stiffness.
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C

E, NU = 1000.0, 0.3
H, L = 0.1, 0.4  # section side, length (m)
M = 1.0e-3  # bending moment (N m): kappa = M / (E I) = 0.012 1/m, a tip rotation of 0.5 mrad
NS = (1, 2, 4, 8)
MODELS = ("mss_element", "mss_boundary", "fem_q1")


def hat_moments(n):
    """(integral of N_k, integral of z N_k) of the 1D hat functions on n intervals over [-H/2, H/2]."""
    a = H / n
    z = -H / 2 + a * np.arange(n + 1)
    w0 = np.full(n + 1, a)
    w1 = a * z
    w0[[0, -1]] = a / 2
    w1[0] = z[0] * a / 2 + a * a / 6
    w1[-1] = z[-1] * a / 2 - a * a / 6
    return z, w0, w1


def scene(model, n):
    """The pure-bending column with ``model`` on 4n x n x n cubes (a scene dict)."""
    s = 1e-9 * H  # selection half-width
    z, w0, w1 = hat_moments(n)
    inertia = H ** 4 / 12
    loads = []
    for yi, wy in zip(z, w0):
        for zj, wz in zip(z, w1):
            f = M / inertia * wy * wz  # the consistent force of sigma_xx = M z / I at node (L, y, z)
            loads.append({"type": "nodal_force", "select": {"box": [[L - s, yi - s, zj - s], [L + s, yi + s, zj + s]]},
                          "total": [float(f), 0.0, 0.0]})
    lo, hi = -H / 2, H / 2
    return {
        "geometry": {"generator": "hex_grid", "args": {"lx": L, "ly": H, "lz": H, "nx": 4 * n, "ny": n, "nz": n,
                                                        "origin": [0.0, lo, lo]}},
        "materials": [{"E": E, "nu": NU}],
        "model": model,
        "boundary": [
            {"select": {"plane": ["x", 0.0]}, "fix": ["x"]},
            {"select": {"box": [[-s, lo - s, lo - s], [s, lo + s, lo + s]]}, "fix": ["y", "z"]},
            {"select": {"box": [[-s, hi - s, lo - s], [s, hi + s, lo + s]]}, "fix": ["z"]},
        ],
        "loads": loads,
        "solver": {"type": "static", "linear": True},
    }


def curvature(ds):
    """The curvature of the loaded face: u_x = kappa L z + c fitted by least squares over its nodes."""
    X = ds["rest_position"].transpose("node", "axis").values
    u = ds["displacement"].transpose("node", "axis").values
    end = np.isclose(X[:, 0], L)
    A = np.column_stack([L * X[end, 2], np.ones(end.sum())])
    return float(np.linalg.lstsq(A, u[end, 0], rcond=None)[0][0])


def run(model, n):
    from msslib.scene import load_scene, run_scene

    return run_scene(load_scene(scene(model, n)), progress=False)


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    ns = NS[:2] if args.quick else NS
    kappa = M / (E * H ** 4 / 12)
    specs = {"mss_element": {"type": "baudet_cube", "correction": "element"},
             "mss_boundary": {"type": "baudet_cube", "correction": "boundary"}, "fem_q1": "fem_linear"}
    k = np.full((len(MODELS), len(NS)), np.nan)
    for j, n in enumerate(ns):
        for i, name in enumerate(MODELS):
            k[i, j] = curvature(run(specs[name], n))
        print(f"n = {n}: stiffening " + ", ".join(f"{m} {1 - k[i, j] / kappa:.5f}" for i, m in enumerate(MODELS)),
              flush=True)
    ds = xr.Dataset(coords={"model": list(MODELS), "n": list(NS)})
    ds["n"].attrs = {"long_name": "cubes across the section (the column has 4n x n x n)"}
    ds["curvature"] = (("model", "n"), k, {"units": "1/m", "long_name": "curvature of the loaded face"})
    ds["stiffening"] = (("model", "n"), 1 - k / kappa, {"units": "1", "long_name": "1 - curvature / exact curvature"})
    ds["excess_ratio"] = (("n",), (1 - k[0] / kappa) / (1 - k[2] / kappa),
                          {"units": "1", "long_name": "stiffening of the element-reading MSS / of Q1, same mesh"})
    ds["excess_ratio_boundary"] = (("n",), (1 - k[1] / kappa) / (1 - k[2] / kappa),
                                   {"units": "1", "long_name": "stiffening of the boundary-reading MSS / of Q1"})
    ds["exact_curvature"] = ((), kappa, {"units": "1/m", "long_name": "M / (E I)"})
    ds.attrs.update(title="Baudet cube and Q1 in pure bending at equal resolution", quick=int(args.quick))
    C.write(ds, args.out, t0)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()

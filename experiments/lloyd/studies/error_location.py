"""Lloyd et al., Secs. 5.2 and 5.4: where the MSS error sits, and at which nodes it is measured.

1. *Sec. 5.2 (Figs. 10-11)*: the paper says eq. 8 errs more than eq. 9 on arbitrary triangles, "at
   the corners". For every case and formula of ``experiments/lloyd/membrane_arbitrary.yaml`` (its
   own loads), the node of the largest node distance between MSS and FEM, its distance from the
   nearest corner of the rectangle and from the nearest corner of the loaded (top) edge, in metres
   and in mean edge lengths of the mesh, and the largest error among the nodes within one mean
   edge length of a corner against the largest elsewhere.
2. *Sec. 5.4 (Fig. 13)*: the coarse square MSS (2 x 2, 5 x 5 elements, ``resolutions.yaml``) is
   compared with the 19 x 19 FEM reference in two ways: at its own nodes (the reference interpolated
   there, as the experiment does) and at all nodes of the reference (the MSS displacement
   interpolated bilinearly over its own squares), max and mean node distance.

    python -m experiments.lloyd.studies.error_location --out results/lloyd/studies/error_location.nc [--quick]
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.compare import interpolate
from msslib.experiment import load_experiment, run
from msslib.results import mesh_from_result, write_result

LLOYD = Path(__file__).resolve().parents[1]
CASES, FORMULAS = ("stretch", "compression", "shear"), ("eq8", "eq9")
COARSE = ("mss_2x2", "mss_5x5")


def arrays(ds):
    return ds["rest_position"].transpose("node", "axis").values, ds["displacement"].transpose("node", "axis").values


def mean_edge_length(mesh) -> float:
    cells = np.asarray(mesh.cells)
    k = cells.shape[1]
    e = np.concatenate([cells[:, [i, (i + 1) % k]] for i in range(k)])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return float(np.linalg.norm(mesh.points[e[:, 0]] - mesh.points[e[:, 1]], axis=1).mean())


def corners_part(quick):
    exp = load_experiment(LLOYD / "membrane_arbitrary.yaml")
    shape = (len(CASES), len(FORMULAS))
    out = {k: np.full(shape, np.nan) for k in (
        "worst_x", "worst_y", "corner_distance", "corner_distance_edges", "top_corner_distance",
        "top_corner_distance_edges", "near_corner_max", "elsewhere_max", "error_max")}
    h = np.nan
    for i, case in enumerate(CASES):
        ref = run(exp, case, "fem", quick=quick)
        X, u_ref = arrays(ref)
        h = mean_edge_length(mesh_from_result(ref))
        lo, hi = X.min(axis=0), X.max(axis=0)
        corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]]])
        d_corner = np.linalg.norm(X[:, None, :] - corners[None], axis=2)
        near = d_corner.min(axis=1) <= h * (1 + 1e-9)
        for j, f in enumerate(FORMULAS):
            X_m, u = arrays(run(exp, case, f, quick=quick))
            assert np.allclose(X_m, X), "the MSS and the FEM share the mesh"
            err = np.linalg.norm(u - u_ref, axis=1)
            w = int(np.argmax(err))
            out["worst_x"][i, j], out["worst_y"][i, j] = X[w]
            out["corner_distance"][i, j] = d_corner[w].min()
            out["top_corner_distance"][i, j] = d_corner[w, 2:].min()
            out["near_corner_max"][i, j] = err[near].max()
            out["elsewhere_max"][i, j] = err[~near].max()
            out["error_max"][i, j] = err.max()
            print(f"5.2 {case} {f}: largest error {err.max() * 1e3:.3g} mm at ({X[w, 0] * 100:.2f}, {X[w, 1] * 100:.2f}) cm, "
                  f"{d_corner[w].min() / h:.2f} edge lengths from the nearest corner", flush=True)
    out["corner_distance_edges"] = out["corner_distance"] / h
    out["top_corner_distance_edges"] = out["top_corner_distance"] / h
    return out, h, (hi - lo)


def resolutions_part(quick):
    exp = load_experiment(LLOYD / "resolutions.yaml")
    ref = run(exp, "shear", "fem", quick=quick)
    ref_mesh = mesh_from_result(ref)
    X_ref, u_ref = arrays(ref)
    out = {k: np.full(len(COARSE), np.nan) for k in ("own_max", "own_mean", "all_max", "all_mean", "n_own", "n_all")}
    for j, v in enumerate(COARSE):
        r = run(exp, "shear", v, quick=quick)
        X, u = arrays(r)
        d_own = np.linalg.norm(u - interpolate(ref_mesh, u_ref, X), axis=1)
        d_all = np.linalg.norm(interpolate(mesh_from_result(r), u, X_ref) - u_ref, axis=1)
        out["own_max"][j], out["own_mean"][j], out["n_own"][j] = d_own.max(), d_own.mean(), len(X)
        out["all_max"][j], out["all_mean"][j], out["n_all"][j] = d_all.max(), d_all.mean(), len(X_ref)
        print(f"5.4 {v}: at its {len(X)} nodes max {d_own.max() * 1e3:.3g} mean {d_own.mean() * 1e3:.3g} mm; "
              f"at the reference's {len(X_ref)} nodes max {d_all.max() * 1e3:.3g} mean {d_all.mean() * 1e3:.3g} mm", flush=True)
    return out


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        corners, h, size = corners_part(args.quick)
        res = resolutions_part(args.quick)
    ds = xr.Dataset(coords={"case": list(CASES), "formula": list(FORMULAS), "model": list(COARSE)})
    long = {"worst_x": "x of the node with the largest error", "worst_y": "y of the node with the largest error",
            "corner_distance": "distance of that node from the nearest corner of the rectangle",
            "corner_distance_edges": "the same, in mean edge lengths of the mesh",
            "top_corner_distance": "distance of that node from the nearest corner of the loaded (top) edge",
            "top_corner_distance_edges": "the same, in mean edge lengths of the mesh",
            "near_corner_max": "largest error at the nodes within one mean edge length of a corner",
            "elsewhere_max": "largest error at the other nodes", "error_max": "largest node distance MSS - FEM"}
    for k, v in corners.items():
        ds[k] = (("case", "formula"), v, {"units": "1" if k.endswith("_edges") else "m", "long_name": long[k]})
    long = {"own_max": "largest node distance at the MSS's own nodes (reference interpolated there)",
            "own_mean": "mean node distance at the MSS's own nodes",
            "all_max": "largest node distance at the reference's nodes (MSS interpolated over its squares)",
            "all_mean": "mean node distance at the reference's nodes", "n_own": "nodes of the MSS",
            "n_all": "nodes of the reference"}
    for k, v in res.items():
        ds[k] = ("model", v, {"units": "1" if k.startswith("n_") else "m", "long_name": long[k]})
    ds["mean_edge_length"] = ((), h, {"units": "m", "long_name": "mean edge length of the Sec. 5.2 mesh"})
    ds["width"] = ((), float(size[0]), {"units": "m", "long_name": "width of the Sec. 5.2 rectangle"})
    ds.attrs.update(study="lloyd_error_location", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()

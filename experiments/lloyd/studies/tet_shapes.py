"""Lloyd et al., Sec. 4.2.1: least-squares springs of badly shaped tetrahedra (slivers, caps, spindles).

The paper states that fitting the six springs of an arbitrarily shaped tetrahedron to its linear FEM
stiffness gives arbitrary constants, and that "especially tetrahedra with unfavorable angles ... so-called
slivers, spindles and caps, result in negative spring parameters", which is why it takes the
regular tetrahedron of the same volume instead (eq. 13). Two runs:

1. *Canonical shapes* (Shewchuk's classes with large dihedral angles), flattened by a parameter t
   (t -> 0: degenerate): a sliver (the corners of a square lifted alternately by +-t), a cap (an
   equilateral triangle and a vertex t above its centroid) and a spindle (a long edge of length 2
   and, t above its midpoint and across it, a short edge of length 2 t), beside the regular
   tetrahedron. For each: the six
   least-squares spring constants (relative Frobenius norm, E = 14630 Pa, nu = 1/4), the smallest
   over the largest, the largest dihedral angle and the fit residual.
2. *The cone of Sec. 5.7* (the experiment file's gmsh mesh): per element, the largest dihedral angle
   and whether its six least-squares constants include a negative one; the fraction of such
   elements among those with a dihedral angle above 150 degrees and among the others.

    python -m experiments.lloyd.studies.tet_shapes --out results/lloyd/studies/tet_shapes.nc [--quick]
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from experiments import script
from experiments.lloyd.studies.tet_refinement import (
    EDGES,
    fem_stiffness,
    gradients,
    spring_basis,
)
from msslib.mesh import unstructured

LLOYD = Path(__file__).resolve().parents[1]
E, NU = 14630.0, 0.25
T = (0.5, 0.2, 0.1, 0.05)
LARGE = 150.0  # degrees: a large dihedral angle


def shape(name, t):
    """The four vertices (4, 3) of a canonical tetrahedron of class ``name``, flatness ``t``."""
    if name == "regular":
        return np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    if name == "sliver":
        return np.array([[1, 0, t], [-1, 0, t], [0, 1, -t], [0, -1, -t]], float)
    if name == "cap":
        a = 2 * np.pi * np.arange(3) / 3
        base = np.column_stack([np.cos(a), np.sin(a), np.zeros(3)])
        return np.vstack([base, [0.0, 0.0, t]])
    if name == "spindle":
        return np.array([[-1, 0, 0], [1, 0, 0], [0, -t, t], [0, t, t]], float)
    raise ValueError(name)


def positive(X):
    """The tetrahedra (m, 4, 3) reordered to positive volume."""
    X = X.copy()
    _, V = gradients(X)
    X[V < 0] = X[V < 0][:, [0, 2, 1, 3]]
    return X


def least_squares_springs(X):
    """Six least-squares constants (m, 6) and the relative residual (m,) of each tetrahedron."""
    Kf = fem_stiffness(X, E, NU)
    S = spring_basis(X)
    G = np.einsum("maij,mbij->mab", S, S)
    k6 = np.linalg.solve(G, np.einsum("maij,mij->ma", S, Kf)[..., None])[..., 0]
    r6 = np.linalg.norm(np.einsum("ma,maij->mij", k6, S) - Kf, axis=(1, 2)) / np.linalg.norm(Kf, axis=(1, 2))
    return k6, r6


def max_dihedral(X):
    g, _ = gradients(X)
    n = g / np.linalg.norm(g, axis=2)[..., None]
    cos = np.stack([-np.sum(n[:, a] * n[:, b], axis=1) for a, b in EDGES], axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max(axis=1)


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()
    names = ("regular", "sliver", "cap", "spindle")
    shape_out = {k: np.full((len(names), len(T)), np.nan) for k in ("k_min_over_max", "max_dihedral", "residual", "negative")}
    for i, name in enumerate(names):
        for j, t in enumerate(T):
            X = positive(shape(name, t)[None])
            k6, r6 = least_squares_springs(X)
            shape_out["k_min_over_max"][i, j] = k6.min() / k6.max()
            shape_out["max_dihedral"][i, j] = max_dihedral(X)[0]
            shape_out["residual"][i, j] = r6[0]
            shape_out["negative"][i, j] = float((k6 < 0).any())
            print(f"{name} t = {t:g}: k_min/k_max {k6.min() / k6.max():+.3f}, largest dihedral "
                  f"{max_dihedral(X)[0]:.1f} deg, residual {r6[0]:.3f}", flush=True)
    args_cone = yaml.safe_load((LLOYD / "cone.yaml").read_text())["scene"]["geometry"]["args"]
    if args.quick:
        args_cone = dict(args_cone, h=0.004)
    mesh = unstructured.cone_mesh(**args_cone)
    X = positive(mesh.points[mesh.cells])
    k6, _ = least_squares_springs(X)
    neg = (k6 < 0).any(axis=1)
    dmax = max_dihedral(X)
    large = dmax > LARGE
    ds = xr.Dataset(coords={"shape": list(names), "t": ("t", np.array(T), {"units": "1", "long_name": "flatness"})})
    meta = {"k_min_over_max": "smallest over largest least-squares spring constant",
            "max_dihedral": "largest dihedral angle (degree)", "residual": "relative Frobenius residual of the six-spring fit",
            "negative": "1 if a least-squares constant is negative"}
    for k, v in shape_out.items():
        ds[k] = (("shape", "t"), v, {"units": "degree" if k == "max_dihedral" else "1", "long_name": meta[k]})
    cone = {"cone_cells": len(X), "cone_large_cells": int(large.sum()),
            "cone_negative_fraction_large": float(neg[large].mean()) if large.any() else np.nan,
            "cone_negative_fraction_other": float(neg[~large].mean()),
            "cone_negative_fraction": float(neg.mean()),
            "cone_large_fraction_of_negative": float(large[neg].mean()) if neg.any() else np.nan}
    for k, v in cone.items():
        ds[k] = ((), v, {"units": "1", "long_name": k.replace("_", " ")})
    print(f"cone ({len(X)} tetrahedra): {int(large.sum())} with a dihedral angle above {LARGE:g} deg, of which "
          f"{cone['cone_negative_fraction_large']:.2f} have a negative constant; of the others {cone['cone_negative_fraction_other']:.2f}",
          flush=True)
    ds.attrs.update(study="lloyd_tet_shapes", quick=int(args.quick), large_dihedral=LARGE, E=E, nu=NU,
                    wall_time_s=time.perf_counter() - t0, description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    from msslib.results import write_result

    write_result(args.out, ds)


if __name__ == "__main__":
    main()

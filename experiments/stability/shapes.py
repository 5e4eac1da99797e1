"""Badly shaped tetrahedra (cases ``sliver``, ``cap``, ``spindle``, ``wedge``): not a run but an
element analysis.  Lloyd's per-element constant (the regular tetrahedron of the same volume)
against the exact element-wise least squares of the element's FEM stiffness by its six spring
matrices, and whether :class:`msslib.terms.Springs` accepts the least-squares constants."""

from __future__ import annotations

import numpy as np

from msslib import fem
from msslib import mesh as M
from msslib import parameters as P
from msslib.models.common import assemble_springs

SHAPES = ("regular", "sliver", "cap", "spindle", "wedge")
#: the local edges (node pairs) of a tetrahedron, in msslib's order (the ``edge`` dimension)
TET_EDGES = np.array([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]])


def shape_coordinates(shape: str, h: float = 0.05) -> np.ndarray:
    """Node coordinates (4, 3) of a test tetrahedron, positively oriented."""
    s = np.sqrt(2.0)
    X = {
        "regular": [[1, 0, -1 / s], [-1, 0, -1 / s], [0, 1, 1 / s], [0, -1, 1 / s]],
        # four nearly coplanar, well separated vertices (a flattened regular tetrahedron)
        "sliver": [[1, 0, -h], [-1, 0, -h], [0, 1, h], [0, -1, h]],
        # one vertex just above the centroid of the opposite face
        "cap": [[1, 0, 0], [-0.5, np.sqrt(3) / 2, 0], [-0.5, -np.sqrt(3) / 2, 0], [0, 0, h]],
        # a small base triangle and a far apex (needle)
        "spindle": [[h, 0, 0], [-h / 2, h * np.sqrt(3) / 2, 0], [-h / 2, -h * np.sqrt(3) / 2, 0], [0, 0, 1]],
        # a long edge with the other two vertices close to its middle
        "wedge": [[0, 0, 0], [1, 0, 0], [0.5, h, 0], [0.5, 0.4 * h, h]],
    }[shape]
    X = np.asarray(X, float)
    if np.linalg.det(X[1:] - X[0]) < 0:
        X = X[[0, 2, 1, 3]]
    return X


def spring_matrices(X) -> np.ndarray:
    """(6, 12, 12) stiffness matrices at rest of unit springs on the 6 edges of tetrahedron X."""
    out = np.zeros((6, 12, 12))
    for i, (a, b) in enumerate(TET_EDGES):
        e = (X[b] - X[a]) / np.linalg.norm(X[b] - X[a])
        g = np.zeros(12)
        g[3 * a:3 * a + 3], g[3 * b:3 * b + 3] = -e, e
        out[i] = np.outer(g, g)
    return out


def elementwise_lsq(X, E, nu):
    """Spring constants (6,) minimising ``||K_fem - sum_i k_i S_i||_F`` and the relative residual."""
    K = fem.element_stiffness("tetra", X, E, nu)
    Sm = spring_matrices(X)
    k, *_ = np.linalg.lstsq(Sm.reshape(6, -1).T, K.ravel(), rcond=None)
    resid = np.linalg.norm(K - np.einsum("i,ijk->jk", k, Sm)) / np.linalg.norm(K)
    return k, float(resid)


def lloyd_constant(X, E, nu) -> float:
    """Lloyd's per-element constant: the regular-tetrahedron optimum for the element's volume."""
    V = np.linalg.det(X[1:] - X[0]) / 6.0
    return float(P.lloyd_tetrahedron(E, l=P.equivalent_edge_length(V), nu=nu).k)


def shape_analysis(shape: str, E: float, nu: float = 0.3):
    """``(outcome text, data)`` of one shape; data: ``k_lloyd``, ``k_lsq`` (6,), ``lsq_residual``."""
    X = shape_coordinates(shape)
    k_lloyd = lloyd_constant(X, E, nu)
    k_lsq, resid = elementwise_lsq(X, E, nu)
    mesh = M.Mesh(X, np.array([[0, 1, 2, 3]]), "tetra")
    neg = np.flatnonzero(k_lsq <= 0)
    try:
        local = {tuple(sorted(e)): i for i, e in enumerate(TET_EDGES.tolist())}
        assemble_springs(mesh, "edges", lambda _c, pairs: k_lsq[[local[tuple(q)] for q in pairs.tolist()]])
        springs = "accepted by Springs"
    except ValueError as exc:
        springs = f"Springs rejects them: {type(exc).__name__}: {' '.join(str(exc).split())}"
    text = (f"Lloyd k = {k_lloyd:.4g} N/m > 0 on all 6 edges; element-wise least squares: {len(neg)} negative of 6 "
            f"(min {k_lsq.min():.4g} N/m, fit residual {resid:.2f}); " + (springs if len(neg) else "all positive"))
    return text, {"k_lloyd": k_lloyd, "k_lsq": k_lsq, "lsq_residual": resid}

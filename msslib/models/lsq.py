"""Springs fitted per element by least squares, for triangles and tetrahedra of any shape.

Each element gets the spring constants (one per edge) that minimise the Frobenius distance between
the linearised stiffness of springs on its edges and its own linear FEM stiffness (the plane-stress
CST of thickness ``t``, the linear tetrahedron), with its own material: irregular meshes no longer
use constants derived for the equilateral triangle or the regular tetrahedron. Per edge, the
constants of the elements sharing it are summed; rest lengths are the mesh distances.

The triangle's constants are a closed form (:mod:`msslib.generated.triangle_lsq`); for the
tetrahedron the generated code gives the 6x6 normal equations ``G k = b``
(:mod:`msslib.generated.tetrahedron_lsq`) and they are solved here, element by element. Both are
derived in ``derivations/elements/triangle_lsq.py`` and ``tetrahedron_lsq.py``. The method is the
per-element fit of S. Natsupakpong and M. C. Cavusoglu, Determination of elasticity parameters in
lumped element (mass-spring) models of deformable objects, Graphical Models 72(6), 2010.

Negative constants: the fit is kept as it is, so an element with a very obtuse angle (triangle)
or a flat shape (tetrahedron) can get a negative constant on one edge, and an edge that only such
elements share gets a negative summed constant. The builders warn once
(:class:`~msslib.models.checks.FormulaValidityWarning`) with how many element constants are
negative. Where a summed constant is not positive, the lattice is simulated only if it is stable
at rest: :func:`check_stable_at_rest` factors its stiffness with the rigid-body modes pinned and
raises ValueError (naming the springs and the smallest pivot) when it is not positive definite.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from msslib.generated import tetrahedron_lsq as _tet
from msslib.generated import triangle_lsq as _tri
from msslib.models.checks import (
    FormulaValidityWarning,
    evaluate,
    poisson,
    positive,
    same_shape,
)
from msslib.models.common import _require, assemble_springs, material_arrays
from msslib.models.delingette import local_coordinates
from msslib.models.spec import Exactness, ModelSpec, split_terms

__all__ = ["TriangleLsqSprings", "TetrahedronLsqSprings", "lsq_triangle", "lsq_tetrahedron", "check_stable_at_rest"]

#: place in the registry's order (after the founding papers and Delingette's triangle)
RANK = 11

#: the fit is the optimum for every nu: no Poisson's ratio to warn about
VALID_NU: dict = {}

REFERENCE = ("S. Natsupakpong, M. C. Cavusoglu, Determination of elasticity parameters in lumped element "
             "(mass-spring) models of deformable objects, Graphical Models 72(6), 2010")

#: local edges of the cells, in the order of the generated constants
TRIANGLE_EDGES = np.array([(0, 1), (1, 2), (0, 2)])
TETRA_EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])


@dataclass(frozen=True)
class TriangleLsqSprings:
    k_01: float  # N/m, per element, edge 0-1
    k_12: float
    k_02: float


@dataclass(frozen=True)
class TetrahedronLsqSprings:
    k: np.ndarray  # (..., 6) N/m, per element, edges 0-1, 0-2, 0-3, 1-2, 1-3, 2-3


def lsq_triangle(E, *, nu, t, a, x2, y2) -> TriangleLsqSprings:
    """Least-squares constants of one triangle with nodes ``(0, 0)``, ``(a, 0)``, ``(x2, y2)``
    (``a > 0``, ``y2 > 0``), Young's modulus ``E``, Poisson's ratio ``nu``, thickness ``t``."""
    positive("E", E), positive("thickness t", t), positive("a", a), positive("y2", y2)
    poisson(nu)
    same_shape("lsq_triangle", E=E, nu=nu, t=t, a=a, x2=x2, y2=y2)
    return evaluate("lsq_triangle", _tri.lsq_triangle, TriangleLsqSprings, E=E, nu=nu, t=t, a=a, x2=x2, y2=y2)


def tetra_frame(points):
    """``(a, x2, y2, x3, y3, z3)`` of tetrahedra ``points`` (..., 4, 3) in their own frame: node 0
    at the origin, node 1 on the x axis, node 2 in the xy plane with y2 > 0 (``z3 > 0`` for a
    positively oriented tetrahedron)."""
    p = np.asarray(points, dtype=float)
    e1, e2, e3 = (p[..., i, :] - p[..., 0, :] for i in (1, 2, 3))
    a = np.linalg.norm(e1, axis=-1)
    u = e1 / a[..., None]
    x2 = np.einsum("...i,...i->...", e2, u)
    w = e2 - x2[..., None] * u
    y2 = np.linalg.norm(w, axis=-1)
    v = w / y2[..., None]
    n = np.cross(u, v)
    return a, x2, y2, np.einsum("...i,...i->...", e3, u), np.einsum("...i,...i->...", e3, v), \
        np.einsum("...i,...i->...", e3, n)


def lsq_tetrahedron(E, *, nu, points) -> TetrahedronLsqSprings:
    """Least-squares constants of tetrahedra with node coordinates ``points`` (4, 3) or (m, 4, 3)
    (positively oriented, VTK order), Young's modulus ``E`` and Poisson's ratio ``nu`` (scalars or
    (m,) arrays): the solution of the generated normal equations ``G k = b`` of each element."""
    positive("E", E), poisson(nu)
    p = np.asarray(points, dtype=float)
    if p.shape[-2:] != (4, 3) or p.ndim not in (2, 3) or not np.isfinite(p).all():
        raise ValueError(f"lsq_tetrahedron: points must be finite, of shape (4, 3) or (m, 4, 3), got {p.shape}")
    frame = tetra_frame(p)
    if np.any(~(frame[2] > 0)) or np.any(~(frame[5] > 0)):
        raise ValueError("lsq_tetrahedron: a tetrahedron is degenerate or inverted (negative orientation)")
    shape = frame[0].shape
    E, nu = np.broadcast_to(np.asarray(E, dtype=float), shape), np.broadcast_to(np.asarray(nu, dtype=float), shape)
    upper = [np.broadcast_to(np.asarray(g, dtype=float), shape) for g in _tet.lsq_tetrahedron_gram(*frame)]
    G = np.empty(shape + (6, 6))
    iu = np.triu_indices(6)
    for value, i, j in zip(upper, *iu):
        G[..., i, j] = G[..., j, i] = value
    b = np.stack(np.broadcast_arrays(*_tet.lsq_tetrahedron_rhs(E, nu, *frame)), axis=-1)
    k = np.linalg.solve(G, b[..., None])[..., 0]
    if not np.isfinite(k).all():
        raise ValueError("lsq_tetrahedron: the constants are not finite (a degenerate tetrahedron?)")
    return TetrahedronLsqSprings(k)


def _local_index(mesh, cells, node_pairs, edges):
    """The local edge (row of ``edges``) of each (cell, node pair) incidence."""
    local = mesh.cells[cells]
    i = np.argmax(local == node_pairs[:, :1], axis=1)
    j = np.argmax(local == node_pairs[:, 1:], axis=1)
    n = local.shape[1]
    table = np.full((n, n), -1)
    for e, (p, q) in enumerate(edges):
        table[p, q] = table[q, p] = e
    out = table[i, j]
    assert (out >= 0).all()
    return out


def _warn_negative(k, model):
    neg = int(np.count_nonzero(k < 0))
    if neg:
        warnings.warn(f"{model}: {neg} of {k.size} per-element spring constants are negative (least-squares fit on "
                      f"badly shaped elements); kept as fitted, summed per edge", FormulaValidityWarning, stacklevel=4)


def rigid_modes(points) -> np.ndarray:
    """The infinitesimal rigid-body motions of nodes ``points`` (n, dim), columns of a
    (dim n, 3) matrix in 2D (two translations, one rotation) or (dim n, 6) in 3D."""
    p = np.asarray(points, dtype=float)
    n, dim = p.shape
    c = p - p.mean(axis=0)
    modes = [np.tile(np.eye(dim)[i], n) for i in range(dim)]
    if dim == 2:
        modes.append(np.column_stack([-c[:, 1], c[:, 0]]).ravel())
    else:
        for i, j in ((0, 1), (1, 2), (2, 0)):
            r = np.zeros_like(c)
            r[:, i], r[:, j] = -c[:, j], c[:, i]
            modes.append(r.ravel())
    return np.column_stack(modes)


BAND_LIMIT = 2e8  # n (bandwidth + 1) above which the sparse LDL^T is used instead of a banded Cholesky


def _not_positive_definite(A, label: str, band_limit: float | None = None) -> int:
    """0 if the symmetric sparse matrix ``A`` is positive definite, else the 1-based index of the
    first pivot that is not positive.  A banded Cholesky (LAPACK ``pbtrf``) in reverse Cuthill-McKee
    order when ``n (bandwidth + 1) <= band_limit`` (default :data:`BAND_LIMIT`; the solvers' band
    plan is not used: it gives up at a factorisation cost meant for repeated solves, while one
    factorisation here is worth a wider band), else SuperLU's LU in a symmetric minimum-degree
    order without pivoting (``diag_pivot_thresh = 0``): then ``U``'s diagonal is ``D`` of ``A =
    L D L^T`` and, by Sylvester's law of inertia, ``A`` is positive definite if and only if it is
    positive.  Raises ValueError if SuperLU had to pivot (a zero diagonal): no verdict then."""
    import scipy.linalg as la
    import scipy.sparse.linalg as spla

    from scipy.sparse.csgraph import reverse_cuthill_mckee

    band_limit = BAND_LIMIT if band_limit is None else band_limit
    A = A.tocsr()
    n = A.shape[0]
    order = reverse_cuthill_mckee(A, symmetric_mode=True)
    B = A[order][:, order].tocoo()
    bw = int(np.max(np.abs(B.row - B.col))) if B.nnz else 0
    if n * (bw + 1.0) <= band_limit:
        ab = np.zeros((bw + 1, n))
        low = B.row >= B.col
        np.add.at(ab, (B.row[low] - B.col[low], B.col[low]), B.data[low])
        return int(la.lapack.dpbtrf(ab, lower=1)[1])
    try:
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:  # an exactly zero pivot: singular, so not positive definite
        return 1
    if not np.array_equal(lu.perm_r, lu.perm_c):
        raise ValueError(f"{label}: cannot check the stability of this lattice at rest (the symmetric "
                         "factorisation needed pivoting)")
    bad = np.flatnonzero(~(lu.U.diagonal() > 0))
    return int(bad[0]) + 1 if len(bad) else 0


def check_stable_at_rest(springs, *, points, label: str) -> None:
    """Raise ValueError unless the springs' stiffness at rest ``K`` (``points`` stress free) is
    positive definite apart from the rigid-body motions.

    ``K`` is positive semi-definite with exactly the rigid-body null space if and only if ``K``
    with the dofs of a rigid-body-pinning set removed (chosen by pivoted QR of the rigid modes)
    is positive definite: a rigid motion is in ``K``'s null space at a stress-free state, and it
    is the only displacement that matches an arbitrary motion on the pinned dofs. That reduced
    matrix is factored by :func:`_not_positive_definite`."""
    import scipy.linalg as la
    import scipy.sparse as sps

    p = np.asarray(points, dtype=float)
    n = p.size
    rows, cols, vals = springs.hessian_coo(p.ravel())
    K = sps.csr_matrix((vals, (rows, cols)), shape=(n, n))
    R = rigid_modes(p)
    pinned = la.qr(R.T, pivoting=True, mode="r")[1][: R.shape[1]]
    keep = np.setdiff1d(np.arange(n), pinned)
    Kr = K[keep][:, keep].tocsr()
    info = _not_positive_definite(Kr, label)
    if info != 0:
        neg = np.flatnonzero(springs.k <= 0)
        raise ValueError(
            f"{label}: the fitted lattice is not stable at rest (its stiffness, rigid-body motions "
            f"removed, is not positive definite: pivot {info} of {Kr.shape[0]}); "
            f"{len(neg)} spring(s) have a non-positive summed constant, e.g. nodes "
            f"{tuple(int(v) for v in springs.conn[neg[0]])} with k = {springs.k[neg[0]]:.4g} N/m. "
            f"Use a mesh without very obtuse (triangle) or flat (tetrahedron) elements, or another model")


def _lsq_springs(mesh, k, edges, label):
    """Springs on the edges of ``mesh`` with the per-element constants ``k`` (m, edges) summed per
    edge, rest lengths the mesh distances; non-positive sums only if the lattice is stable."""
    _warn_negative(k, label)
    springs = assemble_springs(mesh, "edges", lambda c, pairs: k[c, _local_index(mesh, c, pairs, edges)], signed=True)
    if np.any(springs.k <= 0):
        check_stable_at_rest(springs, points=mesh.points, label=label)
    return [springs]


def lsq_triangle_springs(mesh, materials, t: float):
    """Springs on the edges of a triangle mesh (plane stress, thickness ``t`` m), each triangle
    contributing the least-squares constants of its own shape and material."""
    _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    a, x2, y2 = local_coordinates(mesh.points, mesh.cells)
    p = lsq_triangle(E, nu=nu, t=t, a=a, x2=x2, y2=y2)
    k = np.stack([np.broadcast_to(np.asarray(getattr(p, f), dtype=float), a.shape) for f in ("k_01", "k_12", "k_02")],
                 axis=1)
    return _lsq_springs(mesh, k, TRIANGLE_EDGES, "lsq_triangle")


def lsq_tetrahedron_springs(mesh, materials):
    """Springs on the edges of a tetrahedral mesh, each tetrahedron contributing the least-squares
    constants of its own shape and material."""
    _require(mesh, "tetra")
    E, nu = material_arrays(mesh, materials)
    return _lsq_springs(mesh, lsq_tetrahedron(E, nu=nu, points=mesh.points[mesh.cells]).k, TETRA_EDGES, "lsq_tetrahedron")


def _build_triangle(ctx):
    return split_terms(lsq_triangle_springs(ctx.mesh, ctx.materials, ctx.thickness), ctx.options["terms"])


def _build_tetrahedron(ctx):
    return split_terms(lsq_tetrahedron_springs(ctx.mesh, ctx.materials), ctx.options["terms"])


SPECS = (
    ModelSpec("lsq_triangle", "lsq", "mss", ("triangle",), 2,
              "springs fitted per triangle to its own CST by least squares (any shape)",
              REFERENCE + "; closed form derived here", element="triangle_lsq", terms=("springs",),
              parameters=lsq_triangle, build=_build_triangle,
              exact=(Exactness("element", "equilateral", nu=1 / 3,
                               source="on the equilateral triangle at nu = 1/3 the fit is Lloyd's eq. 8, which "
                                      "reproduces the CST (derivations/elements/triangle_lsq.py, triangle.py)"),)),
    ModelSpec("lsq_tetrahedron", "lsq", "mss", ("tetra",), 3,
              "springs fitted per tetrahedron to its own linear element by least squares (any shape)",
              REFERENCE + "; normal equations derived here", element="tetrahedron_lsq", terms=("springs",),
              parameters=lsq_tetrahedron, build=_build_tetrahedron),
)

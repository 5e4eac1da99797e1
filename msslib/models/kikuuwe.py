"""Kikuuwe's tetrahedron: the St Venant-Kirchhoff element written in its edges, on tetrahedra of any shape.

Per tetrahedron, with ``D_i = l_i^2 - L_i^2`` the change of squared length of its edge ``i`` (edges
0-1, 0-2, 0-3, 1-2, 1-3, 2-3 in the cell's node order), the energy is

    W = sum_i k_i / 4 D_i^2 + sum_{i<j} c_ij / 2 D_i D_j,

21 constants per tetrahedron from :mod:`msslib.generated.kikuuwe_tetrahedron`, derived by
``derivations/elements/kikuuwe_tetrahedron.py``: this energy equals the St Venant-Kirchhoff
element's for every tetrahedron of non-zero volume, every deformation and every Poisson's ratio.
R. Kikuuwe, H. Tabuchi, M. Yamamoto, An edge-based computationally efficient formulation of Saint
Venant-Kirchhoff tetrahedral finite elements, ACM Transactions on Graphics 28(1), 2009.
"""

from __future__ import annotations

import numpy as np

from msslib.generated import kikuuwe_tetrahedron as _gen
from msslib.models.checks import poisson, positive, same_shape
from msslib.models.common import _require, material_arrays
from msslib.models.spec import Exactness, ModelSpec
from msslib.terms import Term
from msslib.terms.base import Table, cell_columns, make_column
from msslib.terms.edges import EdgeQuadraticEnergy
from msslib.terms.jit import njit_cached

__all__ = ["kikuuwe_tetrahedron"]

RANK = 12
VALID_NU: dict = {}

EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
NAMES = ("01", "02", "03", "12", "13", "23")
PAIRS = tuple((e, f) for e in range(6) for f in range(e + 1, 6))
OUTPUTS = _gen.OUTPUTS["kikuuwe_tetrahedron"]


def kikuuwe_tetrahedron(E, *, nu, a, x2, y2, x3, y3, z3) -> dict:
    """The 21 constants (N m^-2, name -> array) of one tetrahedron with nodes ``(0, 0, 0)``,
    ``(a, 0, 0)``, ``(x2, y2, 0)``, ``(x3, y3, z3)`` (``a, y2, z3 > 0``)."""
    positive("E", E), positive("a", a), positive("y2", y2), positive("z3", z3)
    poisson(nu)
    same_shape("kikuuwe_tetrahedron", E=E, nu=nu, a=a, x2=x2, y2=y2, x3=x3, y3=y3, z3=z3)
    args = [np.asarray(v, dtype=float) for v in (E, nu, a, x2, y2, x3, y3, z3)]
    return dict(zip(OUTPUTS, (np.broadcast_to(v, np.broadcast(*args).shape) * 1.0
                              for v in _gen.kikuuwe_tetrahedron(*args))))


def local_coordinates(points, cells):
    """``(a, x2, y2, x3, y3, z3)`` of every tetrahedron in its own frame (a mirrored tetrahedron has
    the same constants: they depend on the edge lengths only)."""
    p = points[cells]
    e1, e2, e3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    a = np.linalg.norm(e1, axis=1)
    u = e1 / a[:, None]
    x2 = np.einsum("ij,ij->i", e2, u)
    v = e2 - x2[:, None] * u
    y2 = np.linalg.norm(v, axis=1)
    v /= y2[:, None]
    w = np.cross(u, v)
    return a, x2, y2, np.einsum("ij,ij->i", e3, u), np.einsum("ij,ij->i", e3, v), np.abs(np.einsum("ij,ij->i", e3, w))


class TetrahedronEdges(EdgeQuadraticEnergy):
    """The energy of the module docstring on tetrahedra ``cells`` (m, 4) of a 3D mesh, with the
    constants ``Q`` (m, 6, 6) (``Q_ii = k_i``, ``Q_ij = c_ij``: ``W = 1/4 D^T Q D``) and the rest
    squared lengths ``L2`` (m, 6)."""

    kind = "angular"  # a per-cell edge energy, exported as Delingette's triangle is
    export_name = "kikuuwe_tetrahedron"
    export_label = "Kikuuwe's edge-based St Venant-Kirchhoff tetrahedron energy 1/4 D^T Q D"
    export_energy = ("sum_i k_i/4 D_i^2 + sum_{i<j} c_ij/2 D_i D_j, D_i = |x_b - x_a|^2 - L2_i on edge i = "
                     "(0,1), (0,2), (0,3), (1,2), (1,3), (2,3)")
    cell_constants = tuple((f"k_{n}", f"_k_{n}", "N m-2", f"Kikuuwe's tensile constant k_{n}") for n in NAMES) + tuple(
        (f"c_{NAMES[e]}_{NAMES[f]}", f"_c_{NAMES[e]}_{NAMES[f]}", "N m-2", f"Kikuuwe's coupling constant c_{NAMES[e]}_{NAMES[f]}")
        for e, f in PAIRS)

    def export_tables(self, mesh) -> list[Table]:
        return [Table(self.export_name, "Kikuuwe's tetrahedron per cell: W = sum_i k_i/4 D_i^2 + sum_{i<j} c_ij/2 "
                      "D_i D_j, D_i = |x_b - x_a|^2 - L2_i the change of squared length of edge i = (0,1), (0,2), "
                      "(0,3), (1,2), (1,3), (2,3) (msslib.models.kikuuwe.TetrahedronEdges)", [
                          *cell_columns(self.conn, "tetra"),
                          *[make_column(f"k_{n}", "N/m^2", self.Q[:, i, i], f"tensile constant of edge {n}")
                            for i, n in enumerate(NAMES)],
                          *[make_column(f"c_{NAMES[i]}_{NAMES[j]}", "N/m^2", self.Q[:, i, j],
                                        f"coupling constant of edges {NAMES[i]} and {NAMES[j]}") for i, j in PAIRS],
                          *[make_column(f"L2_{n}", "m^2", self.L2[:, i], f"rest squared length of edge {n}")
                            for i, n in enumerate(NAMES)],
                      ])]

    dim, nodes, n_edges = 3, 4, 6

    @property
    def loops(self):
        return _edges_energy, _edges_gradient, _edges_hessian

    def __init__(self, cells, Q, L2):
        super().__init__(cells, Q, L2)
        for i, n in enumerate(NAMES):
            setattr(self, f"_k_{n}", self.Q[:, i, i])
        for e, f in PAIRS:
            setattr(self, f"_c_{NAMES[e]}_{NAMES[f]}", self.Q[:, e, f])


# The element loops of TetrahedronEdges. Per tetrahedron, edge e = (a, b) of EDGES has the vector
# d_e = x_b - x_a and D_e = |d_e|^2 - L2_e; W = 1/4 D^T Q D, so dW/dx_b = -dW/dx_a = s_e d_e with
# s = Q D, and the Hessian is 1/2 J^T Q J (J = dD/dx: +-2 d_e) plus s_e (+-I) on the node blocks of
# edge e.

@njit_cached
def _edge_state(x, conn, Q, L2, m, d, D, s):
    for e in range(6):
        a, b = conn[m, EDGES[e, 0]], conn[m, EDGES[e, 1]]
        D[e] = -L2[m, e]
        for k in range(3):
            d[e, k] = x[3 * b + k] - x[3 * a + k]
            D[e] += d[e, k] * d[e, k]
    for e in range(6):
        s[e] = 0.0
        for f in range(6):
            s[e] += Q[m, e, f] * D[f]


@njit_cached
def _edges_energy(x, conn, Q, L2):
    d, D, s = np.empty((6, 3)), np.empty(6), np.empty(6)
    w = 0.0
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        for e in range(6):
            w += 0.25 * D[e] * s[e]
    return w


@njit_cached
def _edges_gradient(x, conn, Q, L2, g):
    d, D, s = np.empty((6, 3)), np.empty(6), np.empty(6)
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        for e in range(6):
            a, b = conn[m, EDGES[e, 0]], conn[m, EDGES[e, 1]]
            for k in range(3):
                g[3 * b + k] += s[e] * d[e, k]
                g[3 * a + k] -= s[e] * d[e, k]


@njit_cached
def _edges_hessian(x, conn, Q, L2, out):
    d, D, s = np.empty((6, 3)), np.empty(6), np.empty(6)
    J = np.zeros((6, 12))
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        J[:] = 0.0
        for e in range(6):
            a, b = EDGES[e, 0], EDGES[e, 1]
            for k in range(3):
                J[e, 3 * b + k] = 2.0 * d[e, k]
                J[e, 3 * a + k] = -2.0 * d[e, k]
        base = 144 * m
        for i in range(12):
            for j in range(12):
                h = 0.0
                for e in range(6):
                    for f in range(6):
                        h += J[e, i] * Q[m, e, f] * J[f, j]
                out[base + 12 * i + j] = 0.5 * h
        for e in range(6):
            a, b = EDGES[e, 0], EDGES[e, 1]
            for k in range(3):
                out[base + 12 * (3 * a + k) + 3 * a + k] += s[e]
                out[base + 12 * (3 * b + k) + 3 * b + k] += s[e]
                out[base + 12 * (3 * a + k) + 3 * b + k] -= s[e]
                out[base + 12 * (3 * b + k) + 3 * a + k] -= s[e]


def kikuuwe_springs(mesh, materials) -> list[Term]:
    """Kikuuwe's edge energy on a tetrahedral mesh, each tetrahedron with the constants of its own
    shape and material."""
    _require(mesh, "tetra")
    E, nu = material_arrays(mesh, materials)
    p = kikuuwe_tetrahedron(E, nu=nu, **dict(zip(("a", "x2", "y2", "x3", "y3", "z3"),
                                                  local_coordinates(mesh.points, mesh.cells))))
    Q = np.empty((mesh.n_cells, 6, 6))
    for i, n in enumerate(NAMES):
        Q[:, i, i] = p[f"k_{n}"]
    for e, f in PAIRS:
        Q[:, e, f] = Q[:, f, e] = p[f"c_{NAMES[e]}_{NAMES[f]}"]
    d = mesh.points[mesh.cells[:, EDGES[:, 1]]] - mesh.points[mesh.cells[:, EDGES[:, 0]]]
    return [TetrahedronEdges(mesh.cells, Q, np.einsum("mei,mei->me", d, d))]


def _build(ctx):
    return {"springs": kikuuwe_springs(ctx.mesh, ctx.materials)}


SPECS = (
    ModelSpec("kikuuwe_tetrahedron", "kikuuwe", "mss", ("tetra",), 3,
              "edge-based St Venant-Kirchhoff tetrahedra of any shape (exact for every tetrahedron and nu)",
              "R. Kikuuwe, H. Tabuchi, M. Yamamoto, An edge-based computationally efficient formulation of Saint "
              "Venant-Kirchhoff tetrahedral finite elements, ACM Transactions on Graphics 28(1), 2009; constants "
              "derived here",
              element="kikuuwe_tetrahedron", terms=("springs",), parameters=kikuuwe_tetrahedron, build=_build,
              exact=(Exactness("element", "any", nu=None,
                               source="the 21 constants are the St Venant-Kirchhoff element of every tetrahedron "
                                      "at every nu (derivations/elements/kikuuwe_tetrahedron.py)"),)),
)

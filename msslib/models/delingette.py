"""Delingette's triangle: tensile (biquadratic) and angular springs on triangles of any shape.

Per triangle, with ``D_i = l_i^2 - L_i^2`` the change of squared length of its edge ``i`` (edges
0-1, 1-2, 0-2 in the cell's node order), the energy is

    W = sum_i k_i / 4 D_i^2 + sum_{i<j} c_ij / 2 D_i D_j,

six constants per triangle from :mod:`msslib.generated.triangle_angular`, derived by
``derivations/elements/triangle_angular.py``: linearised at rest, this energy equals the
constant-strain triangle (plane stress, thickness ``t``) for every triangle and every Poisson's
ratio. Under large deformation it is a St Venant-Kirchhoff membrane (the Green strain of a
triangle is linear in the ``D_i``). H. Delingette, Triangular springs for modeling nonlinear
membranes, IEEE Transactions on Visualization and Computer Graphics 14(2), 2008.

This module is the whole model: its parameter function, its force term, its builder and its spec.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from msslib.generated import triangle_angular as _gen
from msslib.models.checks import evaluate, poisson, positive, same_shape
from msslib.models.common import _require, material_arrays
from msslib.models.spec import Exactness, ModelSpec
from msslib.terms import Term
from msslib.terms.base import Table, cell_columns, make_column
from msslib.terms.edges import EdgeQuadraticEnergy
from msslib.terms.jit import njit_cached

__all__ = ["TriangleAngularSprings", "delingette_triangle"]  # the parameters (gathered by msslib.parameters)

#: place in the registry's order (after the founding papers)
RANK = 10

#: exact for every nu: no Poisson's ratio to warn about
VALID_NU: dict = {}

#: local edges (node pairs) of the energy, and the edge pairs of the angular constants
EDGES = np.array([(0, 1), (1, 2), (0, 2)])
PAIRS = ((0, 1), (1, 2), (0, 2))


@dataclass(frozen=True)
class TriangleAngularSprings:
    k_01: float  # tensile constants, N m^-3 (energy k/4 D^2 with D in m^2)
    k_12: float
    k_02: float
    c_01_12: float  # angular constants, N m^-3
    c_12_02: float
    c_01_02: float


def delingette_triangle(E, *, nu, t, a, x2, y2) -> TriangleAngularSprings:
    """The six constants of one triangle with nodes ``(0, 0)``, ``(a, 0)``, ``(x2, y2)``
    (``a > 0``, ``y2 > 0``), Young's modulus ``E``, Poisson's ratio ``nu`` and thickness ``t``."""
    positive("E", E), positive("thickness t", t), positive("a", a), positive("y2", y2)
    poisson(nu)
    same_shape("delingette_triangle", E=E, nu=nu, t=t, a=a, x2=x2, y2=y2)
    return evaluate("delingette_triangle", _gen.delingette_triangle, TriangleAngularSprings,
                    E=E, nu=nu, t=t, a=a, x2=x2, y2=y2)


def local_coordinates(points, cells):
    """``(a, x2, y2)`` of every triangle in its own frame: node 0 at the origin, node 1 on the x
    axis, node 2 above it (a mirrored triangle has the same constants)."""
    p = points[cells]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    a = np.linalg.norm(e1, axis=1)
    x2 = np.einsum("ij,ij->i", e1, e2) / a
    y2 = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / a
    return a, x2, y2


class TriangleAngular(EdgeQuadraticEnergy):
    """The energy of the module docstring on triangles ``cells`` (m, 3) of a 2D mesh, with the
    constants ``Q`` (m, 3, 3) (``Q_ii = k_i``, ``Q_ij = c_ij``: ``W = 1/4 D^T Q D``) and the rest
    squared lengths ``L2`` (m, 3)."""

    kind = "angular"
    export_name = "delingette_triangle"
    export_label = "Delingette's tensile and angular triangle energy 1/4 D^T Q D"
    export_energy = ("sum_i k_i/4 D_i^2 + sum_{i<j} c_ij/2 D_i D_j, D_i = |x_b - x_a|^2 - L2_i on edge i = "
                     "(node_0, node_1), (node_1, node_2), (node_0, node_2)")
    cell_constants = tuple((f"{name}", f"_{name}", "N m-3", f"Delingette's {what} constant {name}")
                           for name, what in (("k_01", "tensile"), ("k_12", "tensile"), ("k_02", "tensile"),
                                              ("c_01_12", "angular"), ("c_12_02", "angular"), ("c_01_02", "angular")))

    @property
    def _k_01(self):
        return self.Q[:, 0, 0]

    @property
    def _k_12(self):
        return self.Q[:, 1, 1]

    @property
    def _k_02(self):
        return self.Q[:, 2, 2]

    @property
    def _c_01_12(self):
        return self.Q[:, 0, 1]

    @property
    def _c_12_02(self):
        return self.Q[:, 1, 2]

    @property
    def _c_01_02(self):
        return self.Q[:, 0, 2]

    def export_tables(self, mesh) -> list[Table]:
        edges = ("01", "12", "02")
        return [Table(self.export_name, "Delingette's triangle per cell: W = sum_i k_i/4 D_i^2 + sum_{i<j} c_ij/2 "
                      "D_i D_j, D_i = |x_b - x_a|^2 - L2_i the change of squared length of edge i = (node_0, node_1), "
                      "(node_1, node_2), (node_0, node_2) (msslib.models.delingette.TriangleAngular; thickness "
                      "included in the constants)", [
                          *cell_columns(self.conn, "triangle"),
                          *[make_column(f"k_{e}", "N/m^3", self.Q[:, i, i], f"tensile constant of edge {e}")
                            for i, e in enumerate(edges)],
                          *[make_column(f"c_{edges[i]}_{edges[j]}", "N/m^3", self.Q[:, i, j],
                                 f"angular constant of edges {edges[i]} and {edges[j]}") for i, j in PAIRS],
                          *[make_column(f"L2_{e}", "m^2", self.L2[:, i], f"rest squared length of edge {e}")
                            for i, e in enumerate(edges)],
                      ])]

    dim, nodes, n_edges = 2, 3, 3

    @property
    def loops(self):
        return _angular_energy, _angular_gradient, _angular_hessian


# The element loops of TriangleAngular. Per triangle, edge e = (a, b) of EDGES has the vector
# d_e = x_b - x_a and D_e = |d_e|^2 - L2_e; W = 1/4 D^T Q D, so dW/dx_b = -dW/dx_a = s_e d_e with
# s = Q D, and the Hessian is 1/2 J^T Q J (J = dD/dx: +-2 d_e) plus s_e (+-I) on the node blocks of
# edge e.

@njit_cached
def _edge_state(x, conn, Q, L2, m, d, D, s):
    for e in range(3):
        a, b = conn[m, EDGES[e, 0]], conn[m, EDGES[e, 1]]
        d[e, 0] = x[2 * b] - x[2 * a]
        d[e, 1] = x[2 * b + 1] - x[2 * a + 1]
        D[e] = d[e, 0] * d[e, 0] + d[e, 1] * d[e, 1] - L2[m, e]
    for e in range(3):
        s[e] = Q[m, e, 0] * D[0] + Q[m, e, 1] * D[1] + Q[m, e, 2] * D[2]


@njit_cached
def _angular_energy(x, conn, Q, L2):
    d, D, s = np.empty((3, 2)), np.empty(3), np.empty(3)
    w = 0.0
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        w += 0.25 * (D[0] * s[0] + D[1] * s[1] + D[2] * s[2])
    return w


@njit_cached
def _angular_gradient(x, conn, Q, L2, g):
    d, D, s = np.empty((3, 2)), np.empty(3), np.empty(3)
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        for e in range(3):
            a, b = conn[m, EDGES[e, 0]], conn[m, EDGES[e, 1]]
            for k in range(2):
                g[2 * b + k] += s[e] * d[e, k]
                g[2 * a + k] -= s[e] * d[e, k]


@njit_cached
def _angular_hessian(x, conn, Q, L2, out):
    d, D, s = np.empty((3, 2)), np.empty(3), np.empty(3)
    J = np.zeros((3, 6))
    for m in range(conn.shape[0]):
        _edge_state(x, conn, Q, L2, m, d, D, s)
        J[:] = 0.0
        for e in range(3):
            a, b = EDGES[e, 0], EDGES[e, 1]
            for k in range(2):
                J[e, 2 * b + k] = 2.0 * d[e, k]
                J[e, 2 * a + k] = -2.0 * d[e, k]
        base = 36 * m
        for i in range(6):
            for j in range(6):
                h = 0.0
                for e in range(3):
                    for f in range(3):
                        h += J[e, i] * Q[m, e, f] * J[f, j]
                out[base + 6 * i + j] = 0.5 * h
        for e in range(3):
            a, b = EDGES[e, 0], EDGES[e, 1]
            for k in range(2):
                out[base + 6 * (2 * a + k) + 2 * a + k] += s[e]
                out[base + 6 * (2 * b + k) + 2 * b + k] += s[e]
                out[base + 6 * (2 * a + k) + 2 * b + k] -= s[e]
                out[base + 6 * (2 * b + k) + 2 * a + k] -= s[e]


def delingette_springs(mesh, materials, t: float) -> list[Term]:
    """Delingette's springs on a triangle mesh (plane stress, thickness ``t`` m), each triangle with
    the constants of its own shape and material."""
    _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    a, x2, y2 = local_coordinates(mesh.points, mesh.cells)
    p = delingette_triangle(E, nu=nu, t=t, a=a, x2=x2, y2=y2)
    Q = np.empty((mesh.n_cells, 3, 3))
    Q[:, [0, 1, 2], [0, 1, 2]] = np.stack([p.k_01, p.k_12, p.k_02], axis=1)
    for value, (e, f) in zip((p.c_01_12, p.c_12_02, p.c_01_02), PAIRS):
        Q[:, e, f] = Q[:, f, e] = value
    d = mesh.points[mesh.cells[:, EDGES[:, 1]]] - mesh.points[mesh.cells[:, EDGES[:, 0]]]
    return [TriangleAngular(mesh.cells, Q, np.einsum("mei,mei->me", d, d))]


def _build(ctx):
    return {"springs": delingette_springs(ctx.mesh, ctx.materials, ctx.thickness)}


SPECS = (
    ModelSpec("delingette_triangle", "delingette", "mss", ("triangle",), 2,
              "tensile and angular springs on triangles of any shape (exact for every triangle and nu)",
              "H. Delingette, Triangular springs for modeling nonlinear membranes, IEEE Transactions on "
              "Visualization and Computer Graphics 14(2), 2008; constants derived here",
              element="triangle_angular", terms=("springs",), parameters=delingette_triangle, build=_build,
              exact=(Exactness("element", "any", nu=None,
                               source="the six constants reproduce the CST of every triangle at every nu "
                                      "(derivations/elements/triangle_angular.py)"),)),
)

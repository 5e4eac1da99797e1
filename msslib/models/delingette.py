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
from msslib.terms.assembly import _block_pattern

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


def delingette_triangle(E, nu, t, a, x2, y2) -> TriangleAngularSprings:
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


class TriangleAngular(Term):
    """The energy of the module docstring on triangles ``cells`` (m, 3) of a 2D mesh, with the
    constants ``Q`` (m, 3, 3) (``Q_ii = k_i``, ``Q_ij = c_ij``: ``W = 1/4 D^T Q D``) and the rest
    squared lengths ``L2`` (m, 3)."""

    def __init__(self, cells, Q, L2):
        self.dim = 2
        self.conn = np.ascontiguousarray(cells, dtype=np.int64)
        self.Q = np.ascontiguousarray(Q, dtype=float)
        self.L2 = np.ascontiguousarray(L2, dtype=float)
        m = len(self.conn)
        if self.conn.shape != (m, 3) or self.Q.shape != (m, 3, 3) or self.L2.shape != (m, 3):
            raise ValueError("TriangleAngular: cells (m, 3), Q (m, 3, 3) and L2 (m, 3) expected")
        if not np.isfinite(self.Q).all():
            raise ValueError("TriangleAngular: the constants must be finite")
        self._pattern = None

    def __len__(self):
        return len(self.conn)

    def max_node(self) -> int:
        return int(self.conn.max()) if self.conn.size else -1

    def _edges(self, x):
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        d = x[self.conn[:, EDGES[:, 1]]] - x[self.conn[:, EDGES[:, 0]]]  # (m, 3, 2)
        return x, d, np.einsum("mei,mei->me", d, d) - self.L2

    def energy(self, x) -> float:
        _, _, D = self._edges(x)
        return float(0.25 * np.einsum("me,mef,mf->", D, self.Q, D))

    def gradient(self, x) -> np.ndarray:
        x, d, D = self._edges(x)
        s = np.einsum("mef,mf->me", self.Q, D)  # 2 dW/dD_e
        g = np.zeros_like(x)
        for e, (a, b) in enumerate(EDGES):
            f = s[:, e, None] * d[:, e]  # dW/dx_b = 2 dW/dD_e d_e
            np.add.at(g, self.conn[:, b], f)
            np.add.at(g, self.conn[:, a], -f)
        return g.ravel()

    def hessian_pattern(self):
        if self._pattern is None:
            self._pattern = _block_pattern(self.conn, 2)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        """Element blocks (m, 6, 6), row-major, in the order of :meth:`hessian_pattern`."""
        _, d, D = self._edges(x)
        m = len(self.conn)
        s = np.einsum("mef,mf->me", self.Q, D)
        J = np.zeros((m, 3, 3, 2))  # dD_e / dx_node
        for e, (a, b) in enumerate(EDGES):
            J[:, e, b] += 2 * d[:, e]
            J[:, e, a] -= 2 * d[:, e]
        J = J.reshape(m, 3, 6)
        H = 0.5 * np.einsum("mei,mef,mfj->mij", J, self.Q, J)
        for e, (a, b) in enumerate(EDGES):
            blk = s[:, e, None, None] * np.eye(2)
            for p, q, sign in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
                H[:, 2 * p:2 * p + 2, 2 * q:2 * q + 2] += sign * blk
        return H.ravel()


def delingette_springs(mesh, materials, t: float) -> list[Term]:
    """Delingette's springs on a triangle mesh (plane stress, thickness ``t`` m), each triangle with
    the constants of its own shape and material."""
    _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    a, x2, y2 = local_coordinates(mesh.points, mesh.cells)
    p = delingette_triangle(E, nu, t, a, x2, y2)
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

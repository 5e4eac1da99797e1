"""Per-cell energies quadratic in the changes of squared edge length: ``W = 1/4 D^T Q D`` per cell,
``D_e = |x_b - x_a|^2 - L2_e`` on each edge ``e = (a, b)`` of the cell.

Delingette's triangle (:mod:`msslib.models.delingette`) and Kikuuwe's tetrahedron
(:mod:`msslib.models.kikuuwe`) are such energies; :class:`EdgeQuadraticEnergy` holds what they
share (the constants and rest lengths per cell, their checks, and the calls of the element loops),
each model its own compiled loops, unrolled for its number of edges and dimension."""

from __future__ import annotations

import numpy as np

from msslib.terms.assembly import block_pattern
from msslib.terms.base import Term


class EdgeQuadraticEnergy(Term):
    """``cells`` (m, ``nodes``), constants ``Q`` (m, ``n_edges``, ``n_edges``) (``Q_ii = k_i``,
    ``Q_ij = c_ij``) and rest squared lengths ``L2`` (m, ``n_edges``).  A subclass sets ``dim``,
    ``nodes``, ``n_edges`` and ``loops = (energy, gradient, hessian)``, the compiled element loops
    ``energy(x, conn, Q, L2) -> float``, ``gradient(x, conn, Q, L2, g)`` (adds into ``g``) and
    ``hessian(x, conn, Q, L2, out)`` (element blocks, row-major)."""

    dim: int
    nodes: int
    n_edges: int
    loops: tuple

    def __init__(self, cells, Q, L2):
        name, m_n, e = type(self).__name__, self.nodes, self.n_edges
        self.conn = np.ascontiguousarray(cells, dtype=np.int64)
        self.Q = np.ascontiguousarray(Q, dtype=float)
        self.L2 = np.ascontiguousarray(L2, dtype=float)
        m = len(self.conn)
        if self.conn.shape != (m, m_n) or self.Q.shape != (m, e, e) or self.L2.shape != (m, e):
            raise ValueError(f"{name}: cells (m, {m_n}), Q (m, {e}, {e}) and L2 (m, {e}) expected")
        if not np.isfinite(self.Q).all():
            raise ValueError(f"{name}: the constants must be finite")
        self._pattern = None

    def __len__(self):
        return len(self.conn)

    def max_node(self) -> int:
        return int(self.conn.max()) if self.conn.size else -1

    def _x(self, x):
        x = np.ascontiguousarray(x, dtype=float).reshape(-1)
        need = self.dim * (self.max_node() + 1)
        if need > len(x):
            raise ValueError(f"{type(self).__name__}: x has {len(x)} entries, the cells need {need}")
        return x

    def energy(self, x) -> float:
        return float(self.loops[0](self._x(x), self.conn, self.Q, self.L2))

    def gradient(self, x) -> np.ndarray:
        x = self._x(x)
        g = np.zeros_like(x)
        self.loops[1](x, self.conn, self.Q, self.L2, g)
        return g

    def hessian_pattern(self):
        if self._pattern is None:
            self._pattern = block_pattern(self.conn, self.dim)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        """Element blocks (m, nodes dim, nodes dim), row-major, in the order of :meth:`hessian_pattern`."""
        size = self.nodes * self.dim
        out = np.empty(size * size * len(self.conn))
        self.loops[2](self._x(x), self.conn, self.Q, self.L2, out)
        return out

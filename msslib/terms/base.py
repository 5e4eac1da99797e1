"""Base classes of the terms (:class:`Term`, element terms with numba loops) and the input
checks they share; the interface is described in :mod:`msslib.terms`."""

from __future__ import annotations

import numpy as np

from .assembly import _block_pattern

# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------


def _as_flat(x) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=float).ravel()


def _per_element(name, values, m) -> np.ndarray:
    values = np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=float), (m,)))
    return values.copy()


def _connectivity(name, conn, nodes) -> np.ndarray:
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    if conn.ndim != 2 or conn.shape[1] != nodes:
        raise ValueError(f"{name} must have shape (m, {nodes}), got {conn.shape}")
    if conn.size and conn.min() < 0:
        raise ValueError(f"{name} holds negative node ids")
    return conn


def _format_bad(ids, values, label, conn=None, max_report=10) -> str:
    parts = []
    for i in ids[:max_report]:
        nodes = f" (nodes {'-'.join(str(int(n)) for n in conn[i])})" if conn is not None else ""
        parts.append(f"{label} {int(i)}{nodes}: {float(values[i])!r}")
    more = f" and {len(ids) - max_report} more" if len(ids) > max_report else ""
    return ", ".join(parts) + more


# --------------------------------------------------------------------------------------------
# base classes
# --------------------------------------------------------------------------------------------


class Term:
    """Base class; see the module docstring for the interface."""

    conservative = True
    scales_with_load = False
    symmetric = True
    dim: int = 3

    def energy(self, x) -> float | None:  # pragma: no cover - abstract
        raise NotImplementedError

    def gradient(self, x) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def max_node(self) -> int:
        """Largest node id the term refers to (-1 if none); used to check it fits a mesh."""
        return -1

    def hessian_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty

    def hessian_values(self, x) -> np.ndarray:
        return np.zeros(0)

    def hessian_coo(self, x):
        rows, cols = self.hessian_pattern()
        return rows, cols, self.hessian_values(x)


class _ElementTerm(Term):
    """A term made of elements with ``conn`` (m, nodes), parameters ``p`` and ``q`` per element,
    and three numba loops."""

    _loops: tuple = ()
    _n_local: int = 0

    def __len__(self):
        return len(self.conn)

    def max_node(self) -> int:
        return int(self.conn.max()) if self.conn.size else -1

    def energy(self, x) -> float:
        if len(self.conn) == 0:
            return 0.0
        return float(self._loops[0](_as_flat(x), self.conn, self._p, self._q))

    def gradient(self, x) -> np.ndarray:
        x = _as_flat(x)
        g = np.zeros(x.size)
        if len(self.conn):
            self._loops[1](x, self.conn, self._p, self._q, g)
        return g

    def hessian_pattern(self):
        if getattr(self, "_pattern", None) is None:
            self._pattern = _block_pattern(self.conn, self.dim)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        out = np.empty((len(self.conn), self._n_local))
        if len(self.conn):
            self._loops[2](_as_flat(x), self.conn, self._p, self._q, out)
        return out.ravel()

"""Internal terms: springs, Lloyd's tetrahedron volume energy, Golec's hexahedron volume
correction."""

from __future__ import annotations

import numpy as np

from .bounds import spring3d_abs_rows
from .base import Table, _as_flat, cell_columns, make_column, _connectivity, ElementTerm, _format_bad, _per_element
from .loops import (
    _hex_energy_loop,
    _hex_gradient_loop,
    _hex_hessian_loop,
    _spring2d_energy_loop,
    _spring2d_gradient_loop,
    _spring2d_hessian_loop,
    _spring3d_energy_fast,
    _spring3d_energy_loop,
    _spring3d_gradient_fast,
    _spring3d_gradient_loop,
    _spring3d_hessian_loop,
    _tet_energy_loop,
    _tet_gradient_loop,
    _tet_hessian_loop,
)


class Springs(ElementTerm):
    """Springs ``k/2 (|x_b - x_a| - L0)^2`` between node pairs.

    Parameters
    ----------
    pairs : (s, 2) int node ids.
    k : (s,) spring constants (N/m), finite and > 0.  A zero or negative constant (typically from
        a sliver or inverted element) raises ValueError naming the offending springs; it is never
        used silently.  ``signed=True`` accepts any finite constant: for models whose fit can give
        negative constants and which check the stability of the assembled lattice themselves
        (:mod:`msslib.models.lsq`).
    rest_length : (s,) rest lengths (m), finite and > 0.  A rest length that differs from the
        distance of the nodes in the mesh prestrains the spring (e.g. Lloyd's squares).
    dim : 2 or 3.
    """

    kind = "springs"
    export_name = "springs"
    export_label = "springs"
    export_energy = "k/2 (|x_j - x_i| - L)^2"
    export_formats = ("csv", "json", "vtu", "mjcf", "sofa", "c")

    def __init__(self, pairs, k, rest_length, dim: int, *, signed: bool = False):
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.dim = dim
        self.conn = _connectivity("pairs", pairs, 2)
        s = len(self.conn)
        self.k = _per_element("k", k, s)
        self.rest_length = _per_element("rest_length", rest_length, s)
        bad = np.flatnonzero(~(np.isfinite(self.k) & ((self.k > 0) | signed)))
        if len(bad):
            raise ValueError(
                f"{len(bad)} spring(s) with a non-positive or non-finite spring constant k (N/m), "
                f"e.g. from degenerate or inverted elements: {_format_bad(bad, self.k, 'spring', self.conn)}"
            )
        bad = np.flatnonzero(~(np.isfinite(self.rest_length) & (self.rest_length > 0)))
        if len(bad):
            raise ValueError(
                f"{len(bad)} spring(s) with a non-positive or non-finite rest length (m): "
                f"{_format_bad(bad, self.rest_length, 'spring', self.conn)}"
            )
        self._p, self._q = self.k, self.rest_length
        self._n_local = (2 * dim) ** 2
        self._loops = (
            (_spring2d_energy_loop, _spring2d_gradient_loop, _spring2d_hessian_loop)
            if dim == 2
            else (_spring3d_energy_loop, _spring3d_gradient_loop, _spring3d_hessian_loop)
        )
        self._layout = None

    def node_layout(self):
        """Node-ordered layout of the springs used by the fast 3D loops (built once, cached).

        Returns ``(order, rowptr, ib, k, L0)``: ``order`` the permutation of the springs sorted by
        first node (then second), ``rowptr`` (n_nodes + 1,) int64 offsets by first node, ``ib``
        int32 second nodes, and the constants in that order (contiguous float64)."""
        if self._layout is None:
            conn = self.conn
            n = int(conn.max()) + 1 if conn.size else 0
            order = np.lexsort((conn[:, 1], conn[:, 0]))
            rowptr = np.zeros(n + 1, dtype=np.int64)
            np.cumsum(np.bincount(conn[:, 0], minlength=n), out=rowptr[1:])
            idx_t = np.int32 if n < 2**31 else np.int64
            self._layout = (order, rowptr, np.ascontiguousarray(conn[order, 1], dtype=idx_t),
                            np.ascontiguousarray(self.k[order]), np.ascontiguousarray(self.rest_length[order]))
        return self._layout

    def lower_node_rows(self, n_nodes: int):
        """The springs in rows by their lower node (built once per node count, cached):
        ``(rowptr, order, ib)``, ``rowptr`` (n_nodes + 1,) offsets, ``order`` the spring of each
        slot and ``ib`` its upper node (int64)."""
        kept = getattr(self, "_lower_rows", None)
        if kept is None or kept[0] != n_nodes:
            lo = np.minimum(self.conn[:, 0], self.conn[:, 1])
            order = np.argsort(lo, kind="stable")
            rowptr = np.zeros(n_nodes + 1, dtype=np.int64)
            np.cumsum(np.bincount(lo, minlength=n_nodes), out=rowptr[1:])
            ib = np.ascontiguousarray(np.maximum(self.conn[:, 0], self.conn[:, 1])[order], dtype=np.int64)
            kept = self._lower_rows = (n_nodes, rowptr, order.astype(np.int64), ib)
        return kept[1:]

    def symmetric_layout(self):
        """Both-ends layout for the fast Hessian: ``(order, rowptr, nb, k, L0)`` with every spring
        listed under each of its two nodes (``order`` indexes the ``2 s`` half-springs: ``i < s``
        is spring ``i`` seen from its first node, ``s + i`` from its second), sorted by node then
        neighbour."""
        if getattr(self, "_sym_layout", None) is None:
            conn = self.conn
            n = int(conn.max()) + 1 if conn.size else 0
            a = np.concatenate([conn[:, 0], conn[:, 1]])
            b = np.concatenate([conn[:, 1], conn[:, 0]])
            order = np.lexsort((b, a))
            rowptr = np.zeros(n + 1, dtype=np.int64)
            np.cumsum(np.bincount(a, minlength=n), out=rowptr[1:])
            idx_t = np.int32 if n < 2**31 else np.int64
            kk = np.concatenate([self.k, self.k])[order]
            ll = np.concatenate([self.rest_length, self.rest_length])[order]
            self._sym_layout = (order, rowptr, np.ascontiguousarray(b[order], dtype=idx_t), kk, ll)
        return self._sym_layout

    def energy(self, x) -> float:
        if self.dim != 3 or len(self.conn) == 0:
            return super().energy(x)
        _, rowptr, ib, k, L0 = self.node_layout()
        return float(_spring3d_energy_fast(_as_flat(x), rowptr, ib, k, L0))

    def gradient(self, x) -> np.ndarray:
        if self.dim != 3 or len(self.conn) == 0:
            return super().gradient(x)
        x = _as_flat(x)
        g = np.zeros(x.size)
        _, rowptr, ib, k, L0 = self.node_layout()
        if 3 * (len(rowptr) - 1) > x.size:
            raise IndexError(f"x has {x.size} entries, the springs refer to node {len(rowptr) - 2}")
        _spring3d_gradient_fast(x, rowptr, ib, k, L0, g)
        return g

    def abs_row_sums(self, x, scale, isq, out) -> bool:
        if self.dim != 3:
            return False
        spring3d_abs_rows(_as_flat(x), self.conn, self.k, self.rest_length, float(scale), isq, out)
        return True

    def gradient_reference(self, x) -> np.ndarray:
        """Gradient through the generated scalar kernel (the plain loop); for tests/benchmarks."""
        return super().gradient(x)

    @property
    def pairs(self) -> np.ndarray:
        return self.conn

    def lengths(self, x) -> np.ndarray:
        """Current length of every spring (m)."""
        p = _as_flat(x).reshape(-1, self.dim)
        return np.linalg.norm(p[self.conn[:, 1]] - p[self.conn[:, 0]], axis=1)

    def tensions(self, x) -> np.ndarray:
        """Spring tensions ``k (l - L0)`` (N), positive when stretched."""
        return self.k * (self.lengths(x) - self.rest_length)


def _check_rest_volumes(name, V0):
    bad = np.flatnonzero(~(np.isfinite(V0) & (V0 > 0)))
    if len(bad):
        raise ValueError(f"{name}: rest volumes V0 must be finite and > 0: {_format_bad(bad, V0, 'cell')}")


class _VolumeTerm(ElementTerm):
    """A volume term of 3D cells with ``nodes`` nodes: one finite coefficient per cell (any
    sign: only finiteness is checked) and rest volumes ``V0`` > 0; the subclasses name the
    coefficient and give the loops."""

    _cells = ""  # name of the connectivity argument
    _nodes = 0
    _coefficient = ""  # name of the coefficient
    kind = "volume"
    _solid = ""
    _coefficient_unit = ""
    _table_description = ""
    _V0_description = ""

    def export_tables(self, mesh) -> list[Table]:
        return [Table(self.export_name, self._table_description, [
            *cell_columns(self.conn, self._solid),
            make_column(self._coefficient, self._coefficient_unit, self._p,
                 f"volume coefficient {self._coefficient} (may be negative)"),
            make_column("V0", "m^3", self.V0, self._V0_description),
        ])]

    def __init__(self, cells, coefficient, V0):
        name = type(self).__name__
        self.dim = 3
        self.conn = _connectivity(self._cells, cells, self._nodes)
        m = len(self.conn)
        self._p = _per_element(self._coefficient, coefficient, m)
        self.V0 = _per_element("V0", V0, m)
        if not np.isfinite(self._p).all():
            raise ValueError(f"{name}: {self._coefficient} must be finite")
        _check_rest_volumes(name, self.V0)
        self._q = self.V0
        self._n_local = (3 * self._nodes) ** 2


class TetVolume(_VolumeTerm):
    """Lloyd's tetrahedron volume energy ``k_v / (2 V0^2) (V - V0)^2`` (V the signed volume).

    ``tets`` (m, 4) positively oriented, ``k_v`` (m,) in J (N m) — it may be negative (Lloyd's
    k_V is negative for nu < 3/13), only finiteness is checked — ``V0`` (m,) rest volumes > 0.
    """

    _cells, _nodes, _coefficient = "tets", 4, "k_v"
    _solid, _coefficient_unit = "tetrahedron", "J"
    export_name = "tet_volume"
    export_label = "Lloyd's tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2"
    export_energy = "k_v/(2 V0^2) (V - V0)^2, V signed tetrahedron volume"
    _table_description = ("Lloyd's tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2, V the signed volume of "
                          "(node_0, ..., node_3) (C: msslib_tet_signed_volume)")
    _V0_description = "rest volume of the cell"
    cell_constants = (("k_volume", "k_v", "J", "volume constant k_V of Lloyd's tetrahedron, energy k_V/(2 V0^2) (V - V0)^2"),
                      ("rest_volume", "V0", "m3", "rest volume of the cell"))
    _loops = (_tet_energy_loop, _tet_gradient_loop, _tet_hessian_loop)

    def __init__(self, tets, k_v, V0):
        super().__init__(tets, k_v, V0)
        self.k_v = self._p


class HexVolume(_VolumeTerm):
    """Golec's hexahedron volume correction ``kappa / (2 V0) (V - V0)^2`` with the averaged-edge
    volume ``V`` (:func:`msslib.generated.kernels.hex_averaged_volume`).

    ``hexes`` (m, 8) in VTK order, ``kappa`` (m,) in Pa, ``V0`` (m,) rest volumes > 0 (use the
    averaged volume of the rest configuration so that the term is unloaded at rest).

    ``kappa`` may be negative: Golec's kappa is negative for nu < 1/4, where the term *lowers*
    the volumetric stiffness the springs give; it is then not convex by itself and only the sum
    with the springs is positive definite.  Only finiteness is checked.
    """

    _cells, _nodes, _coefficient = "hexes", 8, "kappa"
    _solid, _coefficient_unit = "hexahedron", "Pa"
    export_name = "hex_volume"
    export_label = "Golec's volume energy kappa/(2 V0) (V - V0)^2"
    export_energy = "kappa/(2 V0) (V - V0)^2, V averaged-edge-vector hexahedron volume"
    _table_description = ("Golec's volume energy kappa/(2 V0) (V - V0)^2, V the averaged-edge-vector volume of the "
                          "hexahedron (node_0, ..., node_7) in VTK order (C: msslib_hex_averaged_volume)")
    _V0_description = "rest (averaged) volume of the cell"
    cell_constants = (("kappa", "kappa", "Pa", "Golec's volume coefficient kappa, energy kappa/(2 V0) (V - V0)^2"),
                      ("rest_volume", "V0", "m3", "rest (averaged-edge) volume of the cell"))
    _loops = (_hex_energy_loop, _hex_gradient_loop, _hex_hessian_loop)

    def __init__(self, hexes, kappa, V0):
        super().__init__(hexes, kappa, V0)
        self.kappa = self._p

"""Base classes of the terms (:class:`Term`, element terms with numba loops) and the input
checks they share; the interface is described in :mod:`msslib.terms`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .assembly import block_pattern

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
# the tables a term describes itself with
# --------------------------------------------------------------------------------------------


@dataclass
class Column:
    """One column: ``name``, ``unit`` (None for indices and flags; ``"1"`` for dimensionless
    numbers), ``values`` (1D int or float array) and a description."""

    name: str
    unit: str | None
    values: np.ndarray
    description: str = ""

    @property
    def header(self) -> str:
        return self.name if self.unit is None else f"{self.name} [{self.unit}]"


@dataclass
class Table:
    """A named table of :class:`Column` s of equal length."""

    name: str
    description: str
    columns: list[Column] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        for c in self.columns:
            if c.name == name:
                return c.values
        raise KeyError(f"table {self.name!r} has no column {name!r}; it has {', '.join(self.names)}")

    @property
    def names(self) -> list[str]:
        return [c.name for c in self.columns]

    @property
    def n_rows(self) -> int:
        return len(self.columns[0].values) if self.columns else 0


def make_column(name, unit, values, description="", dtype=float) -> Column:
    return Column(name, unit, np.ascontiguousarray(values, dtype=dtype), description)


def cell_columns(conn, solid: str) -> list[Column]:
    """The columns that name each cell of a per-cell table: its index and its nodes ``conn`` (m, k),
    ``solid`` the kind of cell (``"tetrahedron"``, ``"hexahedron"``)."""
    return [make_column("cell", None, np.arange(len(conn)), "cell index", int),
            *[make_column(f"node_{a}", None, conn[:, a], f"node {a} of the {solid}", int) for a in range(conn.shape[1])]]


# --------------------------------------------------------------------------------------------
# base classes
# --------------------------------------------------------------------------------------------


class Term:
    """Base class; see the module docstring for the interface.

    A term also describes itself to the exporters and readers (:mod:`msslib.export`,
    :func:`msslib.spring_constants`, the scene runner), which never test its type:

    ``kind``
        ``"springs"`` (``pairs``, ``k``, ``rest_length``: the springs table), ``"volume"``,
        ``"angular"``, ``"correction"``, ``"external"`` (dead loads the scene states itself), or
        None: a term that cannot be exported (the exporter refuses it, naming it).
    ``export_name``, ``export_label``, ``export_energy``
        the name of its table, a phrase naming it (for notes), its energy as a formula (None:
        non-conservative).
    ``export_formats``
        the export formats that carry it whole (``c``: the generated headers, which hold the
        kernels of every term; a format may also take terms by its own rule,
        :attr:`msslib.export.formats.Format.takes`); :meth:`export_note` says what another format
        leaves out.
    ``cell_constants``
        ``(variable, attribute, CF unit, long name)`` of its per-cell constants for
        :func:`msslib.spring_constants`.
    :meth:`export_tables`, :meth:`export_entry`, :meth:`export_forces`
        its tables (constants as named columns with units), its entry in the JSON ``terms`` list,
        and the constant nodal forces at load factor 1 that the simulator formats can carry.
    """

    conservative = True
    scales_with_load = False
    symmetric = True
    dim: int = 3
    kind: str | None = None
    export_name: str = ""
    export_label: str = ""
    export_energy: str | None = None
    export_formats: tuple[str, ...] = ("csv", "json", "c")
    cell_constants: tuple = ()

    def export_tables(self, mesh) -> list[Table]:
        """The term's tables (``mesh``: the model's mesh, for terms that act on its cells)."""
        return []

    def export_entry(self) -> dict:
        """The term's entry in the JSON document's ``terms`` list."""
        return {"kind": self.export_name, "count": self.export_count(), "table": self.export_name,
                "energy": self.export_energy, "conservative": self.conservative,
                "scales_with_load": self.scales_with_load}

    def export_forces(self) -> list[tuple[str, np.ndarray, str]]:
        """``(label, nodal forces (n, dim) at load factor 1, description)`` that a format carrying
        the term writes as constant forces (none by default)."""
        return []

    def export_note(self, fmt: str) -> str:
        """What format ``fmt``, which does not carry the term whole, leaves out of it (a phrase)."""
        return f"{self.export_label} on {self.export_count()} cells (table {self.export_name})"

    def export_count(self) -> int:
        """How many elements (cells, springs) the term has."""
        return int(len(self))

    def energy(self, x) -> float | None:  # pragma: no cover - abstract
        raise NotImplementedError

    def gradient(self, x) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def max_node(self) -> int:
        """Largest node id the term refers to (-1 if none); used to check it fits a mesh."""
        return -1

    def held_nodes(self) -> np.ndarray:
        """Nodes the term ties to fixed points in space in every axis (a support: a tether, a
        penalty spring to the ground); the check of a static scene for free rigid-body modes counts
        them as held. None by default."""
        return np.zeros(0, dtype=np.int64)

    def hessian_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty

    def hessian_values(self, x) -> np.ndarray:
        return np.zeros(0)

    def hessian_coo(self, x):
        rows, cols = self.hessian_pattern()
        return rows, cols, self.hessian_values(x)

    def abs_row_sums(self, x, scale: float, isq: np.ndarray, out: np.ndarray) -> bool:
        """Add the row sums of ``|scale H|`` scaled by ``isq`` (``1/sqrt(m)``, 0 on fixed dofs) at
        ``x`` to ``out`` (see :mod:`msslib.terms.bounds`) and return True, or return False when
        the term cannot (the caller then bounds the assembled stiffness)."""
        return False


class ElementTerm(Term):
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
            self._pattern = block_pattern(self.conn, self.dim)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        out = np.empty((len(self.conn), self._n_local))
        if len(self.conn):
            self._loops[2](_as_flat(x), self.conn, self._p, self._q, out)
        return out.ravel()

"""Inverted and collapsed cells: is a deformed state physical?

A cell of a deformed state is judged by its *relative Jacobian*: the minimum over a few sample
points of the cell of ``det J(deformed) / det J(rest)`` at the same point, where ``J`` is the
Jacobian of the isoparametric map from the reference cell (the local volume ratio ``det F``).
It is scale-free: 1 everywhere at rest, 0.5 where the material is locally squeezed to half its
volume, negative where the cell is turned inside out.  Because it is relative to the rest state,
it does not depend on the orientation of the rest cell (a clockwise triangle at rest is fine).

Sample points (:data:`SAMPLE_POINTS`): triangles and tetrahedra have a constant Jacobian (one
point); quads the 4 corners (``det J`` of a bilinear quad is linear in each reference coordinate,
so its minimum lies at a corner); hexahedra the 8 corners and the centre (``det J`` of a trilinear
hexahedron is quadratic in each coordinate, so the corners alone do not bound it; a hexahedron with
one corner pushed through the opposite faces is inverted there while its volume stays positive);
wedges their 6 corners and the centre.  Each type's points are its cell module's
(:mod:`msslib.mesh.cells`).

Classification of a cell with relative Jacobian ``r`` (:func:`check_state`):

* ``r < 0``: **inverted** (a part of the cell is turned inside out);
* ``0 <= r < threshold``: **collapsed** (default :data:`COLLAPSE_THRESHOLD` = 1e-3: somewhere
  the cell keeps less than 0.1 % of its rest volume; no elastic model of msslib is meant to go
  there, while the large but legitimate compressions of the experiments stay far above: a 50 %
  compression keeps ratios of order 0.5);
* ``r`` NaN: **undefined** (non-finite positions, or a cell whose Jacobian vanishes at every
  sample point already at rest); sample points where the rest Jacobian is below ``1e-6`` times
  the cell's mean ``|det J|`` are skipped (a badly shaped rest cell, e.g. a quad with three
  collinear nodes, is the mesh's problem, not the state's);
* otherwise **ok**.

The per-cell flags are :data:`OK`, :data:`COLLAPSED`, :data:`INVERTED`, :data:`UNDEFINED`
(``int8``; :data:`FLAG_VALUES`, :data:`FLAG_MEANINGS` are the CF attributes of the variable
``cell_state`` of a result).  :func:`check_history` applies the same test to every saved state of a
run, chunk by chunk (memory bounded), and reports the first state with an inverted cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from msslib.mesh import Mesh
from msslib.mesh import cells as _cells
from msslib.mesh.cells import RegistryView as _RegistryView

__all__ = [
    "COLLAPSE_THRESHOLD",
    "OK",
    "COLLAPSED",
    "INVERTED",
    "UNDEFINED",
    "FLAG_VALUES",
    "FLAG_MEANINGS",
    "SAMPLE_POINTS",
    "StateQuality",
    "HistoryQuality",
    "relative_jacobians",
    "check_state",
    "check_history",
    "guard",
]

#: a cell whose relative Jacobian is below this (and not negative) is collapsed
COLLAPSE_THRESHOLD = 1e-3
OK, COLLAPSED, INVERTED, UNDEFINED = 0, 1, 2, 3
FLAG_VALUES = np.array([OK, COLLAPSED, INVERTED, UNDEFINED], dtype=np.int8)
FLAG_MEANINGS = "ok collapsed inverted undefined"
#: sample points below this fraction of the cell's mean |det J| at rest are skipped
_REST_RTOL = 1e-6
#: about this many float64 values per temporary array when checking a history
_CHUNK_VALUES = 4_000_000

#: reference coordinates of the sample points of each cell type (its cell module's, :mod:`msslib.mesh.cells`)
SAMPLE_POINTS = _RegistryView(lambda c: c.sample_points.copy(), "cell type -> sample points")


def _gradients(cell_type: str) -> np.ndarray:
    """Shape-function gradients at the sample points, shape (points, nodes, dim)."""
    cell = _cells.get(cell_type)
    return cell.gradients(cell.sample_points)


def _det(j: np.ndarray) -> np.ndarray:
    """Determinant of the trailing (2, 2) or (3, 3) matrices."""
    if j.shape[-1] == 2:
        return j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
    return (j[..., 0, 0] * (j[..., 1, 1] * j[..., 2, 2] - j[..., 1, 2] * j[..., 2, 1])
            - j[..., 0, 1] * (j[..., 1, 0] * j[..., 2, 2] - j[..., 1, 2] * j[..., 2, 0])
            + j[..., 0, 2] * (j[..., 1, 0] * j[..., 2, 1] - j[..., 1, 1] * j[..., 2, 0]))


def _jacobians(cell_type: str, x: np.ndarray) -> np.ndarray:
    """det J at the sample points; ``x`` (..., cells, nodes, dim) -> (..., cells, points)."""
    grad = _gradients(cell_type)  # (points, nodes, dim)
    n_pts, nv, dim = grad.shape
    g = grad.transpose(1, 0, 2).reshape(nv, n_pts * dim)
    j = np.swapaxes(x, -1, -2) @ g  # (..., cells, dim_x, points * dim_xi): one matrix product
    j = j.reshape(*x.shape[:-2], dim, n_pts, dim)
    return _det(np.moveaxis(j, -2, -3))  # (..., cells, points, dim_x, dim_xi)


def _rest_denominator(mesh: Mesh) -> np.ndarray:
    """det J of the rest cells at the sample points, NaN where skipped (see the module docstring)."""
    rest = _jacobians(mesh.cell_type, mesh.points[mesh.cells])  # (cells, points)
    scale = np.abs(rest).mean(axis=1, keepdims=True)
    keep = np.abs(rest) > _REST_RTOL * scale
    return np.where(keep, rest, np.nan)


def _check_positions(mesh: Mesh, positions, leading: tuple) -> np.ndarray:
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh must be a msslib.mesh.Mesh, got {type(mesh).__name__}")
    x = np.asarray(positions, dtype=float)
    shape = (*leading, mesh.n_nodes, mesh.dim)
    if x.shape != shape:
        raise ValueError(f"positions must have shape {shape}, got {x.shape}")
    return x


def _min_ratio(det: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """Minimum over the sample points of det / rest, NaN for a cell without any valid point
    (or with a non-finite deformed Jacobian)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = det / rest
    valid = ~np.isnan(rest)
    broken = (~np.isfinite(ratio) & valid).any(axis=-1)
    out = np.where(valid, ratio, np.inf).min(axis=-1)
    out[broken | ~valid.any(axis=-1) | ~np.isfinite(out)] = np.nan
    return out


def relative_jacobians(mesh: Mesh, positions) -> np.ndarray:
    """Per cell the minimum over its sample points of ``det J(positions) / det J(rest)``.

    ``positions`` are the deformed node positions ``(n_nodes, dim)`` (rest positions plus
    displacement).  Returns ``(n_cells,)``: 1 at rest, below 0 for inverted cells, NaN where
    undefined (see the module docstring).
    """
    x = _check_positions(mesh, positions, ())
    rest = _rest_denominator(mesh)
    return _min_ratio(_jacobians(mesh.cell_type, x[mesh.cells]), rest)


def _classify(ratio: np.ndarray, threshold: float) -> np.ndarray:
    state = np.full(ratio.shape, OK, dtype=np.int8)
    state[np.isnan(ratio)] = UNDEFINED
    state[ratio < threshold] = COLLAPSED  # NaN compares False
    state[ratio < 0.0] = INVERTED
    return state


def _fmt_point(p) -> str:
    return "(" + ", ".join(f"{v:.4g}" for v in p) + ")"


@dataclass(frozen=True)
class _Verdict:
    """What the verdicts on one state and on a run share: the counts ``n_inverted`` and
    ``n_collapsed`` (numbers for one state, int64 arrays per state for a run) and what makes them ok."""

    n_inverted: int | np.ndarray
    n_collapsed: int | np.ndarray

    @property
    def _unphysical(self):
        """True where an inverted or a collapsed cell is present (per state for a run)."""
        return (np.asarray(self.n_inverted) > 0) | (np.asarray(self.n_collapsed) > 0)

    @property
    def ok(self) -> bool:
        """No inverted and no collapsed cell (in any state)."""
        return not np.any(self._unphysical)


@dataclass(frozen=True)
class StateQuality(_Verdict):
    """The verdict on one state (see :func:`check_state`).

    ``ratio`` and ``state`` are per cell (relative Jacobian, flag); ``worst_cell`` is the cell with
    the smallest ratio (-1 if no ratio is defined), ``worst_value`` that ratio (NaN likewise),
    ``worst_rest_centroid`` / ``worst_centroid`` its centroid at rest / deformed (m; None likewise);
    ``cells`` are up to ``max_report`` flagged cells (inverted or collapsed), worst first, with
    their centroids at rest (``rest_centroids``) and in the deformed state (``centroids``), in m.
    """

    cell_type: str
    threshold: float
    ratio: np.ndarray
    state: np.ndarray
    n_undefined: int
    worst_cell: int
    worst_value: float
    worst_rest_centroid: np.ndarray | None
    worst_centroid: np.ndarray | None
    cells: np.ndarray
    rest_centroids: np.ndarray
    centroids: np.ndarray

    @property
    def n_cells(self) -> int:
        return len(self.ratio)

    def summary(self) -> str:
        """One line: the counts, the worst cell and where it lies at rest."""
        text = (f"{self.n_inverted} inverted (relative Jacobian < 0) and {self.n_collapsed} collapsed "
                f"(< {self.threshold:g}) of {self.n_cells} {self.cell_type} cells")
        if self.worst_cell >= 0:
            text += (f"; worst cell {self.worst_cell} (relative Jacobian {self.worst_value:.3g}, centroid "
                     f"{_fmt_point(self.worst_rest_centroid)} m at rest, {_fmt_point(self.worst_centroid)} m deformed)")
        if self.n_undefined:
            text += f"; {self.n_undefined} cell(s) undefined (non-finite or degenerate at rest)"
        return text


def check_state(mesh: Mesh, positions, *, threshold: float = COLLAPSE_THRESHOLD, max_report: int = 5) -> StateQuality:
    """Count, flag and locate the inverted and collapsed cells of one deformed state.

    ``positions`` ``(n_nodes, dim)`` are the deformed node positions (m).  See the module
    docstring for the measure and the classes; ``threshold`` is the collapse threshold.
    """
    if not 0.0 < threshold < 1.0:
        raise ValueError(f"threshold must lie in (0, 1), got {threshold!r}")
    x = _check_positions(mesh, positions, ())
    ratio = relative_jacobians(mesh, x)
    state = _classify(ratio, threshold)
    flagged = np.flatnonzero((state == INVERTED) | (state == COLLAPSED))
    shown = flagged[np.argsort(ratio[flagged], kind="stable")][:max_report]
    defined = np.flatnonzero(~np.isnan(ratio))
    worst = int(defined[np.argmin(ratio[defined])]) if len(defined) else -1
    rest_c = mesh.points[mesh.cells].mean(axis=1)
    return StateQuality(
        cell_type=mesh.cell_type, threshold=float(threshold), ratio=ratio, state=state,
        n_inverted=int(np.count_nonzero(state == INVERTED)), n_collapsed=int(np.count_nonzero(state == COLLAPSED)),
        n_undefined=int(np.count_nonzero(state == UNDEFINED)), worst_cell=worst,
        worst_value=float(ratio[worst]) if worst >= 0 else float("nan"),
        worst_rest_centroid=rest_c[worst] if worst >= 0 else None,
        worst_centroid=x[mesh.cells[worst]].mean(axis=0) if worst >= 0 else None,
        cells=shown, rest_centroids=rest_c[shown], centroids=x[mesh.cells[shown]].mean(axis=1),
    )


@dataclass(frozen=True)
class HistoryQuality(_Verdict):
    """The verdict on every saved state of a run (see :func:`check_history`).

    Per state: ``n_inverted``, ``n_collapsed`` (int64) and ``min_ratio`` (the smallest relative
    Jacobian, NaN if none is defined).  ``first_inverted`` / ``first_unphysical`` are the index of
    the first state with an inverted cell / with an inverted or collapsed cell (-1 if none), and
    ``first_inverted_time`` / ``first_unphysical_time`` its time (NaN if none or no times given).
    """

    times: np.ndarray | None
    min_ratio: np.ndarray

    @property
    def n_states(self) -> int:
        return len(self.n_inverted)

    @staticmethod
    def _first(hit: np.ndarray) -> int:
        """Index of the first True state of ``hit``, -1 if none."""
        where = np.flatnonzero(hit)
        return int(where[0]) if len(where) else -1

    @property
    def first_inverted(self) -> int:
        return self._first(self.n_inverted > 0)

    @property
    def first_unphysical(self) -> int:
        return self._first(self._unphysical)

    def _time(self, index: int) -> float:
        return float(self.times[index]) if index >= 0 and self.times is not None else float("nan")

    @property
    def first_inverted_time(self) -> float:
        return self._time(self.first_inverted)

    @property
    def first_unphysical_time(self) -> float:
        return self._time(self.first_unphysical)

    @property
    def n_unphysical_states(self) -> int:
        return int(np.count_nonzero(self._unphysical))


def check_history(mesh: Mesh, positions, times=None, *, threshold: float = COLLAPSE_THRESHOLD) -> HistoryQuality:
    """Count the inverted and collapsed cells of every state of ``positions``
    ``(n_states, n_nodes, dim)`` (deformed node positions, m); ``times`` ``(n_states,)`` (s) is
    optional.  Vectorised over states in chunks of bounded memory."""
    if not 0.0 < threshold < 1.0:
        raise ValueError(f"threshold must lie in (0, 1), got {threshold!r}")
    x = np.asarray(positions, dtype=float)
    if x.ndim != 3:
        raise ValueError(f"positions must have shape (n_states, {mesh.n_nodes}, {mesh.dim}), got {x.shape}")
    x = _check_positions(mesh, x, (len(x),))
    n_t = len(x)
    if times is not None:
        times = np.asarray(times, dtype=float)
        if times.shape != (n_t,):
            raise ValueError(f"times must have shape ({n_t},), got {times.shape}")
    rest = _rest_denominator(mesh)
    n_pts, nv = rest.shape[1], mesh.nodes_per_cell
    per_state = max(1, mesh.n_cells * n_pts * max(nv, mesh.dim * mesh.dim) * mesh.dim)
    chunk = max(1, _CHUNK_VALUES // per_state)
    n_inv = np.zeros(n_t, dtype=np.int64)
    n_col = np.zeros(n_t, dtype=np.int64)
    worst = np.full(n_t, np.nan)
    for start in range(0, n_t, chunk):
        sl = slice(start, min(start + chunk, n_t))
        ratio = _min_ratio(_jacobians(mesh.cell_type, x[sl][:, mesh.cells]), rest)  # (states, cells)
        state = _classify(ratio, threshold)
        n_inv[sl] = np.count_nonzero(state == INVERTED, axis=1)
        n_col[sl] = np.count_nonzero(state == COLLAPSED, axis=1)
        if ratio.shape[1]:
            with np.errstate(invalid="ignore"):
                finite = np.where(np.isnan(ratio), np.inf, ratio).min(axis=1)
            worst[sl] = np.where(np.isfinite(finite), finite, np.nan)
    return HistoryQuality(times=times, n_inverted=n_inv, n_collapsed=n_col, min_ratio=worst)


# --------------------------------------------------------------------------------------------
# the guard of msslib.scene.run_scene
# --------------------------------------------------------------------------------------------

POLICIES = ("warn", "error")


def _history_text(h: HistoryQuality) -> str:
    def at(index):
        t = h._time(index)
        return f"t = {t:.6g} s" if np.isfinite(t) else f"state {index}"

    text = f"{h.n_unphysical_states} of {h.n_states} saved states have inverted or collapsed cells, first at " \
           f"{at(h.first_unphysical)}"
    if h.first_inverted >= 0 and h.first_inverted != h.first_unphysical:
        text += f" (first inverted at {at(h.first_inverted)})"
    return text


def guard(mesh: Mesh, displacement, *, history_displacement=None, history_time=None, policy: str = "warn",
          label: str = "", threshold: float = COLLAPSE_THRESHOLD) -> tuple[dict, dict]:
    """Check the final state (and the saved states, if given) of a run for inverted and collapsed
    cells; return ``(attrs, variables)`` to record in its result.

    ``displacement`` ``(n_nodes, dim)`` is the final displacement, ``history_displacement``
    ``(n_states, n_nodes, dim)`` those of the saved states at ``history_time`` (s).  With a flagged
    cell in any checked state, ``policy="warn"`` issues one
    :class:`~msslib.errors.MsslibWarning` line (counts, worst cell, its rest centroid) and
    ``policy="error"`` raises :class:`~msslib.errors.UnphysicalStateError` with that line.

    ``attrs``: ``inverted_cells``, ``collapsed_cells``, ``undefined_cells`` (counts in the final
    state, 0 for a clean run), ``min_relative_jacobian`` (smallest relative Jacobian of the final
    state, NaN if none is defined), ``collapse_threshold``; with a history also
    ``checked_states``, ``unphysical_states`` (saved states with an inverted or collapsed cell),
    ``first_inverted_time`` and ``first_unphysical_time`` (s; NaN when no saved state has one).
    ``variables`` (``(dims, data, attrs)`` tuples for :func:`msslib.results.netcdf.make_dataset`):
    ``relative_jacobian(cell)``, ``cell_state(cell)`` (int8 flags, CF ``flag_values`` /
    ``flag_meanings``) and with a history ``inverted_cells_history(time)``,
    ``collapsed_cells_history(time)``, ``min_relative_jacobian_history(time)``.
    """
    from msslib.errors import MsslibWarning, UnphysicalStateError

    if policy not in POLICIES:
        raise ValueError(f"policy must be one of {POLICIES}, got {policy!r}")
    u = _check_positions(mesh, displacement, ())
    final = check_state(mesh, mesh.points + u, threshold=threshold)
    attrs = {"inverted_cells": final.n_inverted, "collapsed_cells": final.n_collapsed,
             "undefined_cells": final.n_undefined, "min_relative_jacobian": final.worst_value,
             "collapse_threshold": float(threshold)}
    variables = {
        "relative_jacobian": (("cell",), final.ratio, {
            "units": "1", "long_name": "smallest det J / det J_rest over the cell's sample points, final state"}),
        "cell_state": (("cell",), final.state, {
            "long_name": "cell state in the final state", "flag_values": FLAG_VALUES,  # flags: no units
            "flag_meanings": FLAG_MEANINGS, "collapse_threshold": float(threshold)}),
    }
    hist = None
    if history_displacement is not None:
        uh = np.asarray(history_displacement, dtype=float)
        hist = check_history(mesh, mesh.points[None] + uh, history_time, threshold=threshold)
        attrs.update(checked_states=hist.n_states, unphysical_states=hist.n_unphysical_states,
                     first_inverted_time=hist.first_inverted_time, first_unphysical_time=hist.first_unphysical_time)
        if history_time is not None:
            variables.update(
                inverted_cells_history=(("time",), hist.n_inverted, {
                    "units": "1", "long_name": "number of inverted cells of the saved state"}),
                collapsed_cells_history=(("time",), hist.n_collapsed, {
                    "units": "1", "long_name": "number of collapsed cells of the saved state"}),
                min_relative_jacobian_history=(("time",), hist.min_ratio, {
                    "units": "1", "long_name": "smallest relative Jacobian of the saved state"}),
            )
    if final.ok and (hist is None or hist.ok):
        return attrs, variables

    prefix = f"{label}: " if label else ""
    if not final.ok:
        text = f"{prefix}unphysical final state: {final.summary()}"
        if hist is not None and not hist.ok:
            text += f"; {_history_text(hist)}"
    else:
        first = hist.first_unphysical
        state = check_state(mesh, mesh.points + np.asarray(history_displacement, dtype=float)[first],
                            threshold=threshold)
        text = f"{prefix}unphysical saved state: the final state is physical, but {_history_text(hist)}: {state.summary()}"
    if policy == "error":
        raise UnphysicalStateError(f"{text}; set checks.inverted: warn to keep the result")
    import warnings

    warnings.warn(f"{text}; result kept, see its attributes inverted_cells, collapsed_cells and variable cell_state",
                  MsslibWarning, stacklevel=3)
    return attrs, variables

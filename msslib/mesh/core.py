"""The mesh type and what every other module of :mod:`msslib.mesh` builds on.

:class:`Mesh` (node positions, cells of one type, a material index per cell, named groups; the
conventions are those of the docstring of :mod:`msslib.mesh`), the cell types
(:data:`CELL_TYPES`), the local numbering tables of the edges and facets of each cell type
(VTK/meshio node order), the tolerance and policies of coincident nodes, and small helpers
(argument checks, dropping unused nodes, formatting a point).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import cells as _cells
from .cells import RegistryView as _RegistryView

#: cell type -> (dimension, nodes per cell), of every type of the registry (:mod:`msslib.mesh.cells`)
CELL_TYPES = _RegistryView(lambda c: (c.dim, c.nodes), "cell type -> (dimension, nodes per cell)")

#: default tolerance of :func:`coincident_nodes`, relative to the diagonal of the bounding box
COINCIDENT_RTOL = 1e-10

#: what :func:`read` and :func:`resolve_coincident_nodes` may do with coincident nodes
COINCIDENT_POLICIES = ("merge", "error", "keep")


@dataclass(frozen=True)
class Mesh:
    """Node positions, cells of one type, a material index per cell, and named groups.

    Groups (empty for generated meshes; :func:`read` fills them from the file) are known by name,
    a group without a name (a gmsh physical group without a name) by its number as a string
    (``"3"``); the three dicts are separate, so one name may be a group of each kind:

    * ``cell_groups[name]``: sorted unique cell indices, ``(k,)`` int64;
    * ``facet_groups[name]``: ``(k, nodes_per_facet)`` node indices of lower-dimensional elements
      of the facet type of the cells (lines of a 2D mesh, triangles of a tetra mesh, quads of a
      hexahedron mesh; triangles or quads of a wedge mesh, one type per group), in the order and
      orientation of the file;
    * ``node_groups[name]``: sorted unique node indices, ``(k,)`` int64.

    Every group has at least one member.  Group arrays are read-only; functions that renumber
    nodes (:func:`resolve_coincident_nodes`) or reorder cell nodes (:func:`orient`) carry the
    groups along.  Use :func:`dataclasses.replace` to change a field and keep the others.
    """

    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    material: np.ndarray = field(default=None)
    cell_groups: dict = field(default=None)
    facet_groups: dict = field(default=None)
    node_groups: dict = field(default=None)

    def __post_init__(self):
        if not isinstance(self.cell_type, str) or self.cell_type not in CELL_TYPES:
            raise ValueError(f"unknown cell_type {self.cell_type!r}; expected one of {sorted(CELL_TYPES)}")
        ct = _cells.get(self.cell_type)
        dim, nv = ct.dim, ct.nodes
        points = np.ascontiguousarray(self.points, dtype=float)
        cells = np.ascontiguousarray(self.cells, dtype=np.int64)
        if points.ndim != 2 or points.shape[1] != dim:
            raise ValueError(f"points must have shape (n, {dim}) for {self.cell_type}, got {points.shape}")
        if cells.ndim != 2 or cells.shape[1] != nv:
            raise ValueError(f"cells must have shape (m, {nv}) for {self.cell_type}, got {cells.shape}")
        if cells.size and (cells.min() < 0 or cells.max() >= len(points)):
            raise ValueError("cells refer to nodes that do not exist")
        material = np.zeros(len(cells), dtype=np.int64) if self.material is None else np.asarray(self.material, dtype=np.int64)
        if material.shape != (len(cells),):
            raise ValueError(f"material must have shape ({len(cells)},), got {material.shape}")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "material", material)
        nf = sorted({len(f) for f in ct.faces})
        nf = nf[0] if len(nf) == 1 else tuple(nf)
        for kind, size, shape in (("cell_groups", len(cells), None), ("facet_groups", len(points), nf),
                                  ("node_groups", len(points), None)):
            object.__setattr__(self, kind, _checked_groups(kind, getattr(self, kind), size, shape))

    @property
    def dim(self) -> int:
        return self.points.shape[1]

    @property
    def n_nodes(self) -> int:
        return len(self.points)

    @property
    def n_cells(self) -> int:
        return len(self.cells)

    @property
    def nodes_per_cell(self) -> int:
        return self.cells.shape[1]


def _checked_groups(kind: str, groups, size: int, facet_nodes) -> dict:
    """``groups`` as a dict of read-only int64 arrays: indices below ``size``, sorted and unique
    (cell and node groups) or rows of ``facet_nodes`` node indices (facet groups; a tuple of the
    allowed counts for a cell type with facets of several types, a group holding facets of one)."""
    if groups is None:
        return {}
    if not isinstance(groups, dict):
        raise ValueError(f"{kind} must be a dict of name -> indices, got {type(groups).__name__}")
    what = "node" if facet_nodes is not None or kind == "node_groups" else "cell"
    out = {}
    for name, members in groups.items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"{kind}: group names must be non-empty strings, got {name!r}")
        a = np.asarray(members)
        if a.size and a.dtype.kind not in "iu":
            raise ValueError(f"{kind}[{name!r}]: expected integer {what} indices, got {a.dtype}")
        a = a.astype(np.int64)
        if facet_nodes is None:
            a = np.unique(a.ravel())
        elif a.ndim != 2 or a.shape[1] not in np.atleast_1d(facet_nodes):
            shape = " or ".join(f"(k, {n})" for n in np.atleast_1d(facet_nodes))
            raise ValueError(f"{kind}[{name!r}]: expected shape {shape}, got {a.shape}")
        if a.size == 0:
            raise ValueError(f"{kind}[{name!r}] is empty; allowed: groups with at least one member")
        if a.min() < 0 or a.max() >= size:
            raise ValueError(f"{kind}[{name!r}] refers to {what} {int(a.max() if a.max() >= size else a.min())}, "
                             f"which does not exist; allowed: {what}s 0 to {size - 1}")
        a = np.ascontiguousarray(a)
        a.flags.writeable = False
        out[name] = a
    return out


# --------------------------------------------------------------------------------------------
# local numbering tables (VTK/meshio node order, see the docstring of msslib.mesh)
# --------------------------------------------------------------------------------------------

#: cell type -> ``(edges, 2)`` local node pairs of its edges
LOCAL_EDGES = _RegistryView(lambda c: c.edges, "cell type -> local edges")

# Facets with outward orientation for a positively oriented cell, of the cell types whose facets
# are of one type.  In 2D an edge (a, b) is outward oriented when the cell lies on its left, i.e.
# the outward normal is (dy, -dx).  In 3D the right-hand-rule normal of the facet points out of the
# cell.  (A type with facets of several types, the wedge, has them per type: ``CellType.facets``.)
_LOCAL_FACETS = _RegistryView(lambda c: c.facets(), "cell type -> local facets",
                              only=lambda c: c.single_facet_type is not None)

_HEX_REF = _cells.get("hexahedron").reference

# Corners of the unit cube in hexahedron order: corner c sits at _HEX_REF01[c].
_HEX_REF01 = (_HEX_REF + 1.0) / 2.0


# --------------------------------------------------------------------------------------------
# small internal helpers
# --------------------------------------------------------------------------------------------


def _positive_int(name: str, value, minimum: int = 1) -> int:
    if int(value) != value or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _positive_length(name: str, value) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive length in metres, got {value!r}")
    return value


def _compact(points: np.ndarray, cells: np.ndarray, return_map: bool = False):
    """Drop the nodes no cell uses; keeps the relative order of the remaining nodes.

    Returns ``(points, cells)``, with ``return_map`` also the new number of every old node
    (-1 for a dropped node)."""
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    new_id = np.where(used, np.cumsum(used) - 1, -1)
    if return_map:
        return points[used], new_id[cells], new_id
    return points[used], new_id[cells]


def _fmt_point(x) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in x) + ")"

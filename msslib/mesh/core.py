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

CELL_TYPES = {"triangle": (2, 3), "quad": (2, 4), "tetra": (3, 4), "hexahedron": (3, 8)}

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
      hexahedron mesh), in the order and orientation of the file;
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
        if self.cell_type not in CELL_TYPES:
            raise ValueError(f"unknown cell_type {self.cell_type!r}; expected one of {sorted(CELL_TYPES)}")
        dim, nv = CELL_TYPES[self.cell_type]
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
        nf = _LOCAL_FACETS[self.cell_type].shape[1]
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


def _checked_groups(kind: str, groups, size: int, facet_nodes: int | None) -> dict:
    """``groups`` as a dict of read-only int64 arrays: indices below ``size``, sorted and unique
    (cell and node groups) or rows of ``facet_nodes`` node indices (facet groups)."""
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
        elif a.ndim != 2 or a.shape[1] != facet_nodes:
            raise ValueError(f"{kind}[{name!r}]: expected shape (k, {facet_nodes}), got {a.shape}")
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

LOCAL_EDGES = {
    "triangle": np.array([[0, 1], [1, 2], [2, 0]]),
    "quad": np.array([[0, 1], [1, 2], [2, 3], [3, 0]]),
    "tetra": np.array([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]]),
    "hexahedron": np.array(
        [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4], [0, 4], [1, 5], [2, 6], [3, 7]]
    ),
}

# Facets with outward orientation for a positively oriented cell.  In 2D an edge (a, b) is outward
# oriented when the cell lies on its left, i.e. the outward normal is (dy, -dx).  In 3D the
# right-hand-rule normal of the facet points out of the cell.
_LOCAL_FACETS = {
    "triangle": LOCAL_EDGES["triangle"],
    "quad": LOCAL_EDGES["quad"],
    "tetra": np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]),
    "hexahedron": np.array(
        [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    ),
}

_HEX_REF = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
    dtype=float,
)

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

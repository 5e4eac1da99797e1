"""Meshes: node positions, cells of one type, a material index per cell, named groups.

Conventions (shared by every module of msslib):

* ``points`` has shape ``(n_nodes, dim)`` in metres, ``dim`` is 2 or 3.
* ``cells`` has shape ``(n_cells, nodes_per_cell)``; node order is meshio's/VTK's:
  ``triangle`` and ``quad`` counter-clockwise; ``tetra`` positively oriented
  (``det[p1-p0, p2-p0, p3-p0] > 0``); ``hexahedron`` nodes 0-3 the bottom face counter-clockwise
  seen from above, 4-7 the top face, node ``i + 4`` above node ``i``.
* ``material`` has shape ``(n_cells,)``: an index into the list of materials of a model.
* ``cell_groups``, ``facet_groups``, ``node_groups``: named groups of cells, boundary facets and
  nodes from a mesh file (see :class:`Mesh` and :func:`read`).

Contents of this module (all lengths in metres, areas in m^2, volumes in m^3):

* structured generators: :func:`quad_grid`, :func:`triangle_grid_right`,
  :func:`triangle_grid_equilateral` (with :func:`equilateral_rows`), :func:`hexagon_equilateral`,
  :func:`hex_grid`, :func:`tet_grid`, :func:`l_block_hex`;
* unstructured meshes generated with gmsh: :func:`polygon_mesh`, :func:`cylinder_mesh`,
  :func:`cylinder_with_hole_mesh`, :func:`cone_mesh`, :func:`l_block_tet`.  Element sizes are at
  most ``h``, refined to about 12 elements per full circle on curved boundaries but not below
  ``h / 8``; gmsh runs single-threaded with a fixed random ``seed``, so a call is reproducible;
  the mesh keeps only the nodes its cells use and its simplices are positively oriented;
* input/output: :func:`read` (every failure one ValueError naming the file; keeps the file's
  physical groups, cell sets and node sets), :func:`write_vtu`, :func:`readable_suffixes`,
  :func:`check_mesh_suffix`;
* groups: :func:`materials_from_groups` (a material index per cell from cell groups),
  :func:`facet_cell_counts` (is a facet a face of the mesh);
* topology and geometry: :func:`unique_edges`, :func:`face_diagonals`, :func:`inner_diagonals`,
  :func:`boundary_facets`, :func:`facet_areas`, :func:`cell_measures`, :func:`check_cells`,
  :func:`orient`, :func:`select_nodes`, :func:`lumped_masses`;
* hygiene: :func:`coincident_nodes` and :func:`resolve_coincident_nodes` (nodes at the same place
  but with different numbers, which cut a body in two: merged or refused), :func:`connected_parts`
  and :func:`loose_parts` (parts whose fixed dofs leave a rigid-body mode free: floating, or free
  to slide or turn).

The L-shaped block (:func:`l_block_hex`, :func:`l_block_tet`) of edge ``size`` ``s`` is the cube
``[0, s]^3`` from which the quadrant ``x > s/2, z > s/2`` is removed: its cross-section in the
x-z plane is an "L" (three squares of side ``s/2``), extruded over ``0 <= y <= s``.
Its volume is ``3 s^3 / 4``.
"""

from __future__ import annotations

import os
import threading
import uuid
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

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


__all__ = [
    "CELL_TYPES",
    "Mesh",
    "NodePairs",
    "quad_grid",
    "triangle_grid_right",
    "equilateral_rows",
    "triangle_grid_equilateral",
    "hexagon_equilateral",
    "hex_grid",
    "tet_grid",
    "l_block_hex",
    "polygon_mesh",
    "cylinder_mesh",
    "cylinder_with_hole_mesh",
    "cone_mesh",
    "l_block_tet",
    "read",
    "materials_from_groups",
    "facet_cell_counts",
    "readable_suffixes",
    "check_mesh_suffix",
    "write_vtu",
    "unique_edges",
    "face_diagonals",
    "inner_diagonals",
    "boundary_facets",
    "facet_areas",
    "cell_measures",
    "check_cells",
    "orient",
    "select_nodes",
    "lumped_masses",
    "COINCIDENT_RTOL",
    "COINCIDENT_POLICIES",
    "coincident_nodes",
    "resolve_coincident_nodes",
    "connected_parts",
    "LoosePart",
    "loose_parts",
]

# --------------------------------------------------------------------------------------------
# local numbering tables (VTK/meshio node order, see the module docstring)
# --------------------------------------------------------------------------------------------

_LOCAL_EDGES = {
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
    "triangle": _LOCAL_EDGES["triangle"],
    "quad": _LOCAL_EDGES["quad"],
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

_AXES = {"x": 0, "y": 1, "z": 2}


class NodePairs(NamedTuple):
    """Unique node pairs (edges or diagonals) and the cells that share each of them.

    ``pairs`` has shape ``(n_pairs, 2)`` with ``pairs[:, 0] < pairs[:, 1]``, rows sorted
    lexicographically.  The cells sharing pair ``k`` are ``cells[indptr[k]:indptr[k + 1]]``
    (compressed sparse rows, cell ids ascending).  ``counts`` is the number of such cells: spring
    constants contributed per cell are summed over them.  Unpacks as ``pairs, indptr, cells``.
    """

    pairs: np.ndarray
    indptr: np.ndarray
    cells: np.ndarray

    @property
    def counts(self) -> np.ndarray:
        return np.diff(self.indptr)

    def cells_of(self, k: int) -> np.ndarray:
        """Ids of the cells sharing pair ``k``."""
        return self.cells[self.indptr[k] : self.indptr[k + 1]]


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


def _renumbered_groups(mesh: Mesh, node_map: np.ndarray, source: str) -> dict:
    """The facet and node groups of ``mesh`` with node ``i`` renumbered ``node_map[i]`` (-1: the
    node is dropped), as keyword arguments of :class:`Mesh`; the cell groups are unchanged.

    Nodes that are dropped leave their node groups; a facet that loses a node, or whose corners
    become one node, and a node group left empty, are a ValueError naming the group."""
    facet_groups, node_groups = {}, {}
    for name, facets in mesh.facet_groups.items():
        new = node_map[facets]
        ordered = np.sort(new, axis=1)
        bad = np.flatnonzero((new < 0).any(axis=1) | (ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
        if len(bad):
            f = facets[bad[0]]
            raise ValueError(f"{source}: facet group {name!r}: {len(bad)} facet(s) lose a node or collapse when "
                             f"nodes are merged or dropped, e.g. the facet of nodes {f.tolist()}; allowed: facets on "
                             f"nodes of the cells with distinct corners")
        facet_groups[name] = new
    for name, nodes in mesh.node_groups.items():
        new = node_map[nodes]
        new = new[new >= 0]
        if len(new) == 0:
            raise ValueError(f"{source}: node group {name!r}: none of its {len(nodes)} node(s) is used by a cell; "
                             f"allowed: groups of nodes of the cells")
        node_groups[name] = new
    return {"facet_groups": facet_groups, "node_groups": node_groups}


def _group_pairs(pairs: np.ndarray, cell_ids: np.ndarray, n_nodes: int) -> NodePairs:
    """Sort every pair, merge duplicates, and build the pair -> cells CSR table."""
    pairs = np.sort(pairs, axis=1).astype(np.int64)
    keys = pairs[:, 0] * np.int64(max(n_nodes, 1)) + pairs[:, 1]
    unique_keys, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    indptr = np.zeros(len(unique_keys) + 1, dtype=np.int64)
    np.cumsum(np.bincount(inverse, minlength=len(unique_keys)), out=indptr[1:])
    return NodePairs(pairs[first], indptr, cell_ids[order].astype(np.int64))


def _local_pairs(mesh: Mesh, local: np.ndarray) -> NodePairs:
    pairs = mesh.cells[:, local].reshape(-1, 2)
    cell_ids = np.repeat(np.arange(mesh.n_cells, dtype=np.int64), len(local))
    return _group_pairs(pairs, cell_ids, mesh.n_nodes)


def _lattice_triangles(q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Triangles of a triangular lattice given in axial coordinates.

    Node ``k`` sits at ``a * (q + r / 2, r * sqrt(3) / 2)``.  Every lattice triangle whose three
    corners are all present is returned, counter-clockwise.
    """
    qmin, rmin = q.min(), r.min()
    span = np.int64(r.max() - rmin + 2)
    keys = (q - qmin).astype(np.int64) * span + (r - rmin)
    order = np.argsort(keys)
    sorted_keys = keys[order]

    def lookup(dq, dr):
        k = (q + dq - qmin).astype(np.int64) * span + (r + dr - rmin)
        pos = np.clip(np.searchsorted(sorted_keys, k), 0, len(keys) - 1)
        found = sorted_keys[pos] == k
        return np.where(found, order[pos], -1)

    here = np.arange(len(q))
    # every triangle is anchored at its lowest vertex (the lower-left one for upward triangles)
    right, up, up_left = lookup(1, 0), lookup(0, 1), lookup(-1, 1)
    tri_up = np.stack([here, right, up], axis=1)
    tri_down = np.stack([here, up, up_left], axis=1)
    tris = np.concatenate([tri_up, tri_down])
    return tris[(tris >= 0).all(axis=1)]


# --------------------------------------------------------------------------------------------
# structured generators
# --------------------------------------------------------------------------------------------


def quad_grid(lx: float, ly: float, nx: int, ny: int, origin=(0.0, 0.0)) -> Mesh:
    """Rectangle ``[x0, x0 + lx] x [y0, y0 + ly]`` (metres) meshed with ``nx * ny`` quads.

    Node ``i + (nx + 1) * j`` sits at ``(x0 + i lx / nx, y0 + j ly / ny)``; quads are
    counter-clockwise, numbered x fastest.  Squares when ``lx / nx == ly / ny``.
    """
    lx, ly = _positive_length("lx", lx), _positive_length("ly", ly)
    nx, ny = _positive_int("nx", nx), _positive_int("ny", ny)
    x = origin[0] + np.linspace(0.0, lx, nx + 1)
    y = origin[1] + np.linspace(0.0, ly, ny + 1)
    xx, yy = np.meshgrid(x, y, indexing="xy")
    points = np.column_stack([xx.ravel(), yy.ravel()])
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    n0 = (i + (nx + 1) * j).ravel()
    cells = np.column_stack([n0, n0 + 1, n0 + nx + 2, n0 + nx + 1])
    return Mesh(points, cells, "quad")


def triangle_grid_right(lx: float, ly: float, nx: int, ny: int, origin=(0.0, 0.0)) -> Mesh:
    """Rectangle of :func:`quad_grid` with each ``lx/nx`` by ``ly/ny`` rectangle split in two
    right triangles along its diagonal from the lower-left to the upper-right corner.

    Same nodes as :func:`quad_grid`; ``2 * nx * ny`` counter-clockwise triangles, the two halves of
    rectangle ``c`` being cells ``2c`` (lower-right) and ``2c + 1`` (upper-left).
    """
    quads = quad_grid(lx, ly, nx, ny, origin)
    q = quads.cells
    lower = q[:, [0, 1, 2]]
    upper = q[:, [0, 2, 3]]
    cells = np.stack([lower, upper], axis=1).reshape(-1, 3)
    return Mesh(quads.points, cells, "triangle")


def equilateral_rows(width: float, height: float, n: int) -> tuple[int, float]:
    """Rows of triangles of :func:`triangle_grid_equilateral`: ``(n_rows, used_height)``.

    The edge is ``a = width / n`` and a row of triangles is ``a * sqrt(3) / 2`` high, so
    ``n_rows = floor(height / (a sqrt(3) / 2))`` (at least 1 is required) and the mesh spans
    ``used_height = n_rows * a * sqrt(3) / 2 <= height`` metres.
    """
    width, height = _positive_length("width", width), _positive_length("height", height)
    n = _positive_int("n", n)
    row_height = width / n * np.sqrt(3.0) / 2.0
    n_rows = int(np.floor(height / row_height * (1.0 + 1e-12)))
    return n_rows, n_rows * row_height


def triangle_grid_equilateral(width: float, height: float, n: int, origin=(0.0, 0.0)) -> Mesh:
    """Membrane meshed with equilateral triangles of edge ``a = width / n`` (metres).

    Node rows are ``a sqrt(3) / 2`` apart; even rows hold ``n + 1`` nodes at ``x = 0, a, ..., width``,
    odd rows ``n`` nodes offset by half an edge (``x = a/2, ..., width - a/2``), so every edge of the
    mesh has length ``a`` and the left and right sides are zig-zags.  As many rows of triangles as
    fit in ``height`` are used: that number and the height actually covered are reported by
    :func:`equilateral_rows` (also ``mesh.points[:, 1].max() - origin[1]``).  Each row of
    triangles holds ``2 n - 1`` counter-clockwise triangles.
    """
    n_rows, _ = equilateral_rows(width, height, n)
    if n_rows < 1:
        raise ValueError(
            f"height {height} m is smaller than one row of equilateral triangles "
            f"({width / n * np.sqrt(3) / 2} m for width {width} m and n = {n})"
        )
    a = width / n
    rows = np.arange(n_rows + 1)
    counts = np.where(rows % 2 == 0, n + 1, n)
    r = np.repeat(rows, counts)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    i = np.arange(counts.sum()) - np.repeat(start, counts)
    q = i - r // 2
    points = np.column_stack([a * (q + r / 2.0), a * r * np.sqrt(3.0) / 2.0]) + np.asarray(origin, float)
    return Mesh(points, _lattice_triangles(q, r), "triangle")


def hexagon_equilateral(height: float, n_rings: int, center=(0.0, 0.0)) -> Mesh:
    """Regular hexagon of ``height`` (distance between its flat top and bottom sides, metres)
    meshed with equilateral triangles, centred on ``center``.

    The circumradius is ``R = height / sqrt(3)`` (corners at ``(+-R, 0)``); the edge of the
    triangles is ``R / n_rings``.  Node count ``3 n^2 + 3 n + 1`` and ``6 n^2`` counter-clockwise
    triangles for ``n = n_rings``.
    """
    height = _positive_length("height", height)
    n = _positive_int("n_rings", n_rings)
    a = height / np.sqrt(3.0) / n
    q, r = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    q, r = q.ravel(), r.ravel()
    keep = np.abs(q + r) <= n
    q, r = q[keep], r[keep]
    points = np.column_stack([a * (q + r / 2.0), a * r * np.sqrt(3.0) / 2.0]) + np.asarray(center, float)
    return Mesh(points, _lattice_triangles(q, r), "triangle")


def _grid3_points(lx, ly, lz, nx, ny, nz, origin):
    x = origin[0] + np.linspace(0.0, lx, nx + 1)
    y = origin[1] + np.linspace(0.0, ly, ny + 1)
    z = origin[2] + np.linspace(0.0, lz, nz + 1)
    zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()])


def _grid3_cube_corners(nx, ny, nz):
    """Node ids of the 8 corners (hexahedron order) of every cube, x fastest; and (i, j, k)."""
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    off = _HEX_REF01.astype(np.int64)
    corners = (i[:, None] + off[:, 0]) + (nx + 1) * ((j[:, None] + off[:, 1]) + (ny + 1) * (k[:, None] + off[:, 2]))
    return corners, (i, j, k)


def hex_grid(lx: float, ly: float, lz: float, nx: int, ny: int, nz: int, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """Box ``origin + [0, lx] x [0, ly] x [0, lz]`` (metres) meshed with ``nx * ny * nz`` hexahedra.

    Node ``i + (nx + 1) * (j + (ny + 1) * k)`` sits at ``origin + (i lx/nx, j ly/ny, k lz/nz)``;
    cells numbered x fastest, then y, then z.
    """
    lx, ly, lz = (_positive_length(s, v) for s, v in (("lx", lx), ("ly", ly), ("lz", lz)))
    nx, ny, nz = (_positive_int(s, v) for s, v in (("nx", nx), ("ny", ny), ("nz", nz)))
    points = _grid3_points(lx, ly, lz, nx, ny, nz, origin)
    corners, _ = _grid3_cube_corners(nx, ny, nz)
    return Mesh(points, corners, "hexahedron")


# Five tetrahedra of a cube whose corner 0 has even parity: the central tetrahedron joins the even
# corners 0, 2, 5, 7 and one corner tetrahedron cuts off each odd corner 1, 3, 4, 6.
_CUBE5_EVEN = np.array([[0, 2, 5, 7], [1, 0, 2, 5], [3, 0, 2, 7], [4, 0, 5, 7], [6, 2, 5, 7]])
# Mirror image for cubes whose corner 0 has odd parity: central tetrahedron on 1, 3, 4, 6.
_CUBE5_ODD = np.array([[1, 3, 4, 6], [0, 1, 3, 4], [2, 1, 3, 6], [5, 1, 4, 6], [7, 3, 4, 6]])
# Kuhn/Freudenthal: the six paths 0 -> 6 along the cube edges, one per ordering of the axes.
_CUBE6 = np.array([[0, 1, 2, 6], [0, 1, 5, 6], [0, 3, 2, 6], [0, 3, 7, 6], [0, 4, 5, 6], [0, 4, 7, 6]])


def tet_grid(lx: float, ly: float, lz: float, nx: int, ny: int, nz: int, scheme: int = 6,
             origin=(0.0, 0.0, 0.0)) -> Mesh:
    """Box of :func:`hex_grid` with each cube split into tetrahedra, positively oriented.

    ``scheme=5``: five tetrahedra per cube (one central tetrahedron of a third of the cube's
    volume and four corner ones); the split alternates with the parity of ``i + j + k`` so that
    every face diagonal joins two nodes of even global parity and neighbouring faces conform.
    ``scheme=6``: Kuhn/Freudenthal split, six tetrahedra of equal volume sharing the cube
    diagonal from its lowest to its highest corner (conforming, translation invariant).
    Tetrahedra of cube ``c`` are cells ``scheme * c ... scheme * c + scheme - 1``.
    """
    if scheme not in (5, 6):
        raise ValueError(f"scheme must be 5 or 6, got {scheme!r}")
    hexes = hex_grid(lx, ly, lz, nx, ny, nz, origin)
    corners = hexes.cells
    if scheme == 6:
        tets = corners[:, _CUBE6]
    else:
        _, (i, j, k) = _grid3_cube_corners(nx, ny, nz)
        odd = ((i + j + k) % 2 == 1)[:, None, None]
        tets = np.where(odd, corners[:, _CUBE5_ODD], corners[:, _CUBE5_EVEN])
    return orient(Mesh(hexes.points, tets.reshape(-1, 4), "tetra"))


def l_block_hex(size: float, n: int, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """L-shaped block of edge ``size`` (metres) made of cubes of edge ``size / n`` (``n`` even).

    Shape (see the module docstring): the cube ``[0, size]^3`` minus the quadrant
    ``x > size/2, z > size/2``; an "L" in the x-z plane extruded along y.  ``3 n^3 / 4`` hexahedra.
    Nodes are those of ``hex_grid(size, size, size, n, n, n)`` that the remaining cubes use, in
    the same relative order.
    """
    size = _positive_length("size", size)
    n = _positive_int("n", n, minimum=2)
    if n % 2:
        raise ValueError(f"n must be even so that the removed quadrant is made of whole cubes, got {n}")
    full = hex_grid(size, size, size, n, n, n, origin)
    _, (i, _j, k) = _grid3_cube_corners(n, n, n)
    keep = ~((i >= n // 2) & (k >= n // 2))
    points, cells = _compact(full.points, full.cells[keep])
    return Mesh(points, cells, "hexahedron")


# --------------------------------------------------------------------------------------------
# unstructured meshes with gmsh
# --------------------------------------------------------------------------------------------

# gmsh keeps global state: one session at a time in this process.
_GMSH_LOCK = threading.Lock()


@contextmanager
def _gmsh_session(h: float, seed: int, name: str, min_size: float | None = None):
    """Initialise gmsh with deterministic, quiet options; always finalise it.

    Element sizes: at most ``h``; about 12 elements per full circle of a curved boundary, but
    not smaller than ``min_size`` (default ``h / 8``, which keeps a cone's apex from being
    over-refined).
    """
    try:
        import gmsh
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("the gmsh Python API is needed for unstructured meshes: pip install gmsh") from exc
    h = _positive_length("h", h)
    with _GMSH_LOCK:
        if gmsh.isInitialized():
            raise RuntimeError("gmsh is already initialised by other code; finalise it before calling msslib.mesh")
        # no signal handler (works outside the main thread), no user configuration files
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        try:
            opt = gmsh.option.setNumber
            opt("General.Terminal", 0)
            opt("General.Verbosity", 0)
            opt("General.NumThreads", 1)
            for d in ("1D", "2D", "3D"):
                opt(f"Mesh.MaxNumThreads{d}", 1)
            opt("Mesh.RandomSeed", int(seed))
            opt("Mesh.Algorithm", 6)  # Frontal-Delaunay
            opt("Mesh.Algorithm3D", 1)  # Delaunay
            opt("Mesh.ElementOrder", 1)
            opt("Mesh.MeshSizeMax", h)
            opt("Mesh.MeshSizeMin", h / 8 if min_size is None else min(float(min_size), h))
            opt("Mesh.MeshSizeFromPoints", 0)
            opt("Mesh.MeshSizeFromCurvature", 12)  # at least ~12 elements per full circle
            opt("Mesh.MeshSizeExtendFromBoundary", 1)
            gmsh.model.add(name)
            yield gmsh
        finally:
            gmsh.finalize()


def _gmsh_extract(gmsh, dim: int) -> Mesh:
    """Mesh the synchronised model in ``dim`` dimensions and return it as a positive Mesh."""
    gmsh.model.mesh.generate(dim)
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = np.asarray(coords, dtype=float).reshape(-1, 3)
    node_tags = np.asarray(node_tags, dtype=np.int64)
    etype, cell_type = (2, "triangle") if dim == 2 else (4, "tetra")
    _, elem_nodes = gmsh.model.mesh.getElementsByType(etype)
    elem_nodes = np.asarray(elem_nodes, dtype=np.int64).reshape(-1, CELL_TYPES[cell_type][1])
    if len(elem_nodes) == 0:
        raise RuntimeError("gmsh produced no elements; is h much larger than the geometry?")
    index = np.full(node_tags.max() + 1, -1, dtype=np.int64)
    index[node_tags] = np.arange(len(node_tags))
    cells = index[elem_nodes]
    points, cells = _compact(coords[:, :dim], cells)
    return orient(Mesh(points, cells, cell_type))


def polygon_mesh(vertices, h: float, seed: int = 0) -> Mesh:
    """Simple polygon (vertices ``(n, 2)`` in metres, either orientation, not repeated at the end)
    meshed with counter-clockwise triangles of size about ``h`` by gmsh.

    ``seed`` fixes gmsh's random generator; gmsh runs single-threaded, so the same call gives the
    same mesh.
    """
    vertices = np.asarray(vertices, dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 2 or len(vertices) < 3:
        raise ValueError(f"vertices must have shape (n >= 3, 2), got {vertices.shape}")
    with _gmsh_session(h, seed, "polygon") as gmsh:
        geo = gmsh.model.geo
        pts = [geo.addPoint(x, y, 0.0) for x, y in vertices]
        lines = [geo.addLine(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts))]
        loop = geo.addCurveLoop(lines)
        geo.addPlaneSurface([loop])
        geo.synchronize()
        return _gmsh_extract(gmsh, 2)


def _check_cylinder(radius, height):
    return _positive_length("radius", radius), _positive_length("height", height)


def cylinder_mesh(radius: float, height: float, h: float, seed: int = 0) -> Mesh:
    """Solid cylinder of ``radius`` and ``height`` (metres), axis z, base disc at ``z = 0``,
    meshed with positively oriented tetrahedra of size about ``h`` (gmsh, deterministic)."""
    radius, height = _check_cylinder(radius, height)
    with _gmsh_session(h, seed, "cylinder") as gmsh:
        gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, height, radius)
        gmsh.model.occ.synchronize()
        return _gmsh_extract(gmsh, 3)


def cylinder_with_hole_mesh(radius: float, height: float, hole_radius: float, h: float, seed: int = 0) -> Mesh:
    """Cylinder of :func:`cylinder_mesh` with a spherical cavity of ``hole_radius`` (metres) at its
    centre ``(0, 0, height / 2)``.  Volume ``pi r^2 height - 4/3 pi hole_radius^3``."""
    radius, height = _check_cylinder(radius, height)
    hole_radius = _positive_length("hole_radius", hole_radius)
    if hole_radius >= min(radius, height / 2):
        raise ValueError(f"hole_radius {hole_radius} must be smaller than the radius and half the height")
    with _gmsh_session(h, seed, "cylinder_with_hole", min_size=min(h / 8, np.pi * hole_radius / 6)) as gmsh:
        occ = gmsh.model.occ
        cyl = occ.addCylinder(0, 0, 0, 0, 0, height, radius)
        ball = occ.addSphere(0, 0, height / 2, hole_radius)
        occ.cut([(3, cyl)], [(3, ball)])
        occ.synchronize()
        return _gmsh_extract(gmsh, 3)


def cone_mesh(r_bottom: float, r_top: float, height: float, h: float, seed: int = 0) -> Mesh:
    """Truncated cone, axis z, base disc of radius ``r_bottom`` at ``z = 0``, top disc of radius
    ``r_top`` (may be 0: a full cone) at ``z = height`` (metres); tetrahedra of size about ``h``.
    Volume ``pi height (r_b^2 + r_b r_t + r_t^2) / 3``."""
    r_bottom = _positive_length("r_bottom", r_bottom)
    height = _positive_length("height", height)
    r_top = float(r_top)
    if r_top < 0:
        raise ValueError(f"r_top must be >= 0, got {r_top}")
    with _gmsh_session(h, seed, "cone") as gmsh:
        gmsh.model.occ.addCone(0, 0, 0, 0, 0, height, r_bottom, r_top)
        gmsh.model.occ.synchronize()
        return _gmsh_extract(gmsh, 3)


def l_block_tet(size: float, h: float, seed: int = 0) -> Mesh:
    """L-shaped block of :func:`l_block_hex` (cube ``[0, size]^3`` minus ``x > size/2, z > size/2``)
    meshed with positively oriented tetrahedra of size about ``h`` by gmsh."""
    size = _positive_length("size", size)
    with _gmsh_session(h, seed, "l_block") as gmsh:
        occ = gmsh.model.occ
        block = occ.addBox(0, 0, 0, size, size, size)
        notch = occ.addBox(size / 2, 0, size / 2, size / 2, size, size / 2)
        occ.cut([(3, block)], [(3, notch)])
        occ.synchronize()
        return _gmsh_extract(gmsh, 3)


# --------------------------------------------------------------------------------------------
# input / output
# --------------------------------------------------------------------------------------------


def readable_suffixes() -> list[str]:
    """The file suffixes meshio knows (``.msh``, ``.vtu``, ...), sorted; compound ones such as
    ``.vol.gz`` included."""
    import meshio

    return sorted(meshio.extension_to_filetypes)


def check_mesh_suffix(path) -> None:
    """Raise ValueError naming ``path`` and the suffixes meshio knows when its suffix is not one
    of them (meshio would otherwise give up on the file with :class:`SystemExit` or an error)."""
    path = Path(path)
    known = set(readable_suffixes())
    suffixes = [s.lower() for s in path.suffixes]
    if not any("".join(suffixes[i:]) in known for i in range(len(suffixes))):
        shown = repr(path.suffix) if path.suffix else "(none)"
        raise ValueError(f"{path}: unknown mesh file suffix {shown}; allowed: the suffixes meshio reads, "
                         f"{' '.join(sorted(known))}")


def _meshio_read(path: Path):
    """``meshio.read`` that never exits the interpreter: any failure (meshio calls ``sys.exit``
    for some files and raises anything from ``struct.error`` to ``UnicodeDecodeError`` for others)
    becomes one ValueError naming the file.  What meshio prints is captured: part of the message on
    failure; on success returned with the mesh and the warnings it raised, ``(mesh, printed,
    warnings)``, for :func:`read` to pass on once the mesh has passed its own checks."""
    import io
    import warnings
    from contextlib import redirect_stderr, redirect_stdout

    import meshio

    printed = io.StringIO()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with redirect_stdout(printed), redirect_stderr(printed):
                m = meshio.read(path)
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - every failure of a reader is bad input
            said = " ".join(printed.getvalue().replace("Error:", " ").split())
            if isinstance(exc, UnicodeDecodeError):
                detail = (f"not UTF-8 text where the {path.suffix or 'chosen'} reader expects text "
                          f"({exc.reason} at byte {exc.start})")
            elif isinstance(exc, SystemExit):
                detail = said or "meshio gave up on it"
            else:
                text = " ".join(str(exc).split())
                detail = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
                if said and said not in detail:
                    detail += f" ({said})"
            if "Incompatible cell data 'gmsh:physical'" in str(exc):
                detail += (" (meshio reads gmsh physical groups only when every element is in one: save without "
                           "Mesh.SaveAll, or put every entity in a physical group)")
            if len(detail) > 300:
                detail = detail[:297] + "..."
            raise ValueError(f"{path}: cannot read mesh: {detail}; allowed: a valid mesh file in a format meshio "
                             f"reads, chosen by its suffix") from None
    return m, " ".join(printed.getvalue().split()), caught


def read(path, material_key: str = "material", coincident_nodes: str = "merge",
         coincident_rtol: float = COINCIDENT_RTOL) -> Mesh:
    """Read any mesh file meshio can read.

    The cells are the blocks of the highest-dimensional supported type (``tetra`` or
    ``hexahedron`` before ``triangle`` or ``quad``; between two types of the same dimension the
    one with more cells); blocks of that type are concatenated.  Nodes no chosen cell uses are
    dropped (the others keep their order).  For 2D cells the z coordinate must be constant and is
    dropped.  ``cell_data[material_key]`` (one integer per cell), when present, becomes
    ``material``; otherwise every cell has material 0, also when the file has groups (the scenes
    assign materials by group, :func:`materials_from_groups`).  Two cells on the same nodes are
    an error (a gmsh 2 file repeats an element for every physical group it belongs to).

    Groups (:class:`Mesh`): the gmsh physical groups (``cell_data["gmsh:physical"]``, named by
    ``field_data`` ``{name: [tag, dim]}``; a group without a name is known by its tag, ``"3"``;
    meshio keeps one physical tag per element, the first) and meshio's ``cell_sets`` (gmsh 4
    named groups, Abaqus ELSET, ...; sets named ``gmsh:...`` are meshio's bookkeeping and are
    skipped) become ``cell_groups`` for elements of the chosen cell type, ``facet_groups`` for
    elements of its facet type (lines in 2D, triangles for tetra, quads for hexahedron cells) and
    ``node_groups`` (the nodes of the elements) for other lower-dimensional elements (gmsh
    physical points and curves of a 3D mesh, triangles of a hexahedron mesh); meshio's
    ``point_sets`` (Abaqus NSET, Exodus node sets) become ``node_groups``.  A group of the same
    name from both sources is their union.  Elements of other types of the cells' dimension and
    of higher dimensions are ignored, with their groups.  A facet or node group on a node no chosen
    cell uses is dropped with a :class:`msslib.errors.MsslibWarning` naming it (it could not carry
    its load or support).  VTU files hold no sets (meshio writes them as cell data it cannot split
    back reliably): their groups come from a ``gmsh:physical`` cell data array, by number.

    Coincident nodes (closer than ``coincident_rtol`` times the bounding-box diagonal, see
    :func:`resolve_coincident_nodes`) are merged with a :class:`msslib.errors.MsslibWarning`
    (``coincident_nodes="merge"``, the default), refused (``"error"``) or kept (``"keep"``); the
    messages give node numbers of the file.

    Raises FileNotFoundError for a missing file, and a one-line ValueError naming the file for
    everything else: a directory, an unknown suffix (listing the suffixes meshio knows), an empty
    or unreadable file (whatever meshio raises, :class:`SystemExit` included), no cells or no
    supported cell type (naming the types found), cells referring to nodes that do not exist,
    non-finite coordinates, material values that are not integers, duplicate cells, a cell
    collapsed by merging.
    """
    if coincident_nodes not in COINCIDENT_POLICIES:
        raise ValueError(f"coincident_nodes must be one of {', '.join(COINCIDENT_POLICIES)}, got {coincident_nodes!r}")
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path}: is a directory; allowed: a mesh file")
    if not path.exists():
        raise FileNotFoundError(f"mesh file not found: {path}")
    if not path.is_file():
        raise ValueError(f"{path}: not a regular file; allowed: a mesh file")
    check_mesh_suffix(path)
    if path.stat().st_size == 0:
        raise ValueError(f"{path}: cannot read mesh: the file is empty; allowed: a mesh file with cells")
    m, said, caught = _meshio_read(path)
    try:
        mesh, used, notes = _mesh_from_meshio(path, m, material_key)
    except (ValueError, TypeError, IndexError, KeyError) as exc:  # one line naming the file, whatever it is
        text = " ".join(str(exc).split()) or type(exc).__name__
        if not text.startswith(str(path)):
            text = f"{path}: cannot read mesh: {type(exc).__name__}: {text}"
        if said:  # what meshio printed while reading explains the problem
            text += f"; meshio said: {said[:200]}"
        raise ValueError(text) from None
    import warnings

    for w in caught:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if said:
        from msslib.errors import MsslibWarning

        warnings.warn(f"{path}: meshio says: {said}", MsslibWarning, stacklevel=2)
    if notes:
        from msslib.errors import MsslibWarning

        for note in notes:
            warnings.warn(f"{path}: {note}", MsslibWarning, stacklevel=2)
    hint = " (coincident_nodes: merge merges them)" if coincident_nodes == "error" else ""
    return resolve_coincident_nodes(mesh, coincident_nodes, coincident_rtol, source=str(path), node_ids=used,
                                    hint=hint)


def _mesh_from_meshio(path: Path, m, material_key: str):
    """The :class:`Mesh` of :func:`read` from a meshio mesh, the file numbers of its nodes, and the
    notes on dropped groups to warn about."""
    allowed = f"allowed: {', '.join(CELL_TYPES)} cells"
    blocks_all = [b for b in m.cells if len(b.data)]
    if not blocks_all:
        raise ValueError(f"{path}: the mesh has no cells ({len(m.points)} points); {allowed}")
    found = [block.type for block in blocks_all]
    supported = [t for t in CELL_TYPES if t in found]
    if not supported:
        raise ValueError(f"{path}: no supported cell type; found {sorted(set(found))}, supported {sorted(CELL_TYPES)}")

    def rank(t):
        return CELL_TYPES[t][0], sum(len(b.data) for b in m.cells if b.type == t)

    cell_type = max(supported, key=rank)
    dim = CELL_TYPES[cell_type][0]
    blocks = [k for k, b in enumerate(m.cells) if b.type == cell_type and len(b.data)]
    cells = np.concatenate([np.asarray(m.cells[k].data).reshape(len(m.cells[k].data), -1) for k in blocks])
    points = np.asarray(m.points, dtype=float)
    if points.ndim != 2 or not 2 <= points.shape[1] <= 3:
        raise ValueError(f"{path}: points have shape {points.shape}; allowed: 2 or 3 coordinates per point")
    n_file = len(points)
    outside = (cells < 0) | (cells >= n_file)
    if outside.any():
        c = int(np.flatnonzero(outside.any(axis=1))[0])
        node = int(cells[c][outside[c]][0])
        raise ValueError(f"{path}: {cell_type} cell {c} refers to node {node}, which does not exist; "
                         f"allowed: nodes 0 to {n_file - 1}")
    cells = cells.astype(np.int64)
    material = None
    if material_key in m.cell_data:
        values = np.concatenate([np.asarray(m.cell_data[material_key][k]).reshape(len(m.cells[k].data), -1)
                                 for k in blocks])
        if values.shape[1] != 1:
            raise ValueError(f"{path}: cell data {material_key!r} has {values.shape[1]} values per cell; "
                             f"allowed: one integer material index per cell")
        values = values[:, 0]
        if not np.issubdtype(values.dtype, np.number) or np.issubdtype(values.dtype, np.complexfloating):
            raise ValueError(f"{path}: cell data {material_key!r} has type {values.dtype}; allowed: integers")
        bad = np.flatnonzero(~np.isfinite(values) | (values != np.rint(values)))
        if len(bad):
            raise ValueError(f"{path}: cell data {material_key!r} of cell {int(bad[0])} is {values[bad[0]].item()!r}; "
                             f"allowed: integer material indices")
        material = np.rint(values).astype(np.int64)
    _check_duplicate_cells(path, cells, cell_type)
    used = np.unique(cells)  # file numbers of the nodes the cells use, ascending
    groups, notes = _file_groups(m, cell_type, blocks, used)
    points = points[used]
    cells = np.searchsorted(used, cells)
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if len(bad):
        raise ValueError(f"{path}: node {int(used[bad[0]])} has coordinates {_fmt_point(points[bad[0]])} "
                         f"({len(bad)} node(s) with NaN or infinite coordinates); allowed: finite coordinates")
    if points.shape[1] < dim:
        points = np.pad(points, ((0, 0), (0, dim - points.shape[1])))
    if dim == 2 and points.shape[1] == 3:
        z = points[:, 2]
        scale = max(np.ptp(points[:, :2], axis=0).max(initial=0.0), 1e-300)
        if len(z) and np.ptp(z) > 1e-9 * scale:
            raise ValueError(f"{path}: {cell_type} cells are not in a plane z = const; cannot make a 2D mesh")
        points = points[:, :2]
    return Mesh(points, cells, cell_type, material, **groups), used, notes


def _check_duplicate_cells(path: Path, cells: np.ndarray, cell_type: str) -> None:
    """Two cells on the same nodes (in any order) are a ValueError naming both."""
    if len(cells) < 2:
        return
    keys = np.sort(cells, axis=1)
    _, first, inverse, counts = np.unique(keys, axis=0, return_index=True, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    dup = np.flatnonzero(counts[inverse] > 1)
    dup = dup[dup != first[inverse[dup]]]
    if len(dup):
        c = int(dup[0])
        raise ValueError(f"{path}: {cell_type} cells {int(first[inverse[c]])} and {c} have the same nodes ({len(dup)} "
                         f"duplicate cell(s)); allowed: each cell once (a gmsh 2 file repeats an element for every "
                         f"physical group it belongs to: save it in gmsh format 4 or put each element in one group)")


#: topological dimension of meshio cell types that may carry groups (others are looked up in meshio)
_TOPOLOGICAL_DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "triangle6": 2, "quad": 2, "quad8": 2,
                    "quad9": 2, "polygon": 2, "tetra": 3, "tetra10": 3, "hexahedron": 3, "hexahedron20": 3,
                    "hexahedron27": 3, "wedge": 3, "pyramid": 3}

#: the element type of the facets of each cell type
_FACET_TYPE = {"triangle": "line", "quad": "line", "tetra": "triangle", "hexahedron": "quad"}


def _block_dim(cell_type: str) -> int | None:
    if cell_type in _TOPOLOGICAL_DIM:
        return _TOPOLOGICAL_DIM[cell_type]
    try:
        from meshio._mesh import topological_dimension
    except ImportError:  # pragma: no cover - depends on meshio's internals
        return None
    return topological_dimension.get(cell_type)


def _file_groups(m, cell_type: str, blocks: list, used: np.ndarray) -> tuple[dict, list]:
    """The groups of a meshio mesh (see :func:`read`) as keyword arguments of :class:`Mesh` (cell
    indices into the concatenated ``blocks``, node indices into ``used``), and the notes on the
    groups dropped because they touch nodes no chosen cell uses."""
    dim = CELL_TYPES[cell_type][0]
    offsets = {}
    start = 0
    for k in blocks:
        offsets[k] = start
        start += len(m.cells[k].data)
    names = {}  # (dim, tag) -> name, from gmsh's $PhysicalNames
    for name, value in (m.field_data or {}).items():
        value = np.asarray(value).ravel()
        if value.size == 2 and value.dtype.kind in "iu":
            names[(int(value[1]), int(value[0]))] = str(name)
    physical = (m.cell_data or {}).get("gmsh:physical")
    cell_sets = {str(k): v for k, v in (m.cell_sets or {}).items() if not str(k).startswith("gmsh:")}
    cells_acc, facets_acc, nodes_acc = {}, {}, {}
    for k, block in enumerate(m.cells):
        n = len(block.data)
        if n == 0:
            continue
        bdim = _block_dim(block.type)
        if block.type == cell_type:
            if k not in offsets:
                continue
            target = cells_acc
        elif bdim is None or bdim >= dim:
            continue  # another cell type of the same or a higher dimension: not in the mesh
        else:
            target = facets_acc if (bdim == dim - 1 and block.type == _FACET_TYPE[cell_type]) else nodes_acc
        members = []  # (group name, element indices in the block)
        if physical is not None and k < len(physical):
            tags = np.asarray(physical[k]).reshape(n, -1)[:, 0]
            if tags.dtype.kind in "iuf":
                for tag in np.unique(tags):
                    if tag != int(tag):
                        continue
                    members.append((names.get((bdim, int(tag)), str(int(tag))), np.flatnonzero(tags == tag)))
        for name, per_block in cell_sets.items():
            if k < len(per_block) and per_block[k] is not None and len(per_block[k]):
                members.append((name, np.asarray(per_block[k], dtype=np.int64).ravel()))
        data = np.asarray(block.data)
        for name, idx in members:
            if target is cells_acc:
                cells_acc.setdefault(name, []).append(offsets[k] + idx)
            elif target is facets_acc:
                facets_acc.setdefault(name, []).append(data[idx].reshape(len(idx), -1))
            else:
                nodes_acc.setdefault(name, []).append(data[idx].ravel())
    for name, nodes in (m.point_sets or {}).items():
        if not str(name).startswith("gmsh:") and len(nodes):
            nodes_acc.setdefault(str(name), []).append(np.asarray(nodes, dtype=np.int64).ravel())

    notes = []

    def to_mesh_nodes(kind, name, file_nodes):
        """File node numbers -> mesh node indices; None (and a note) if one is not a mesh node."""
        file_nodes = np.asarray(file_nodes, dtype=np.int64)
        pos = np.clip(np.searchsorted(used, file_nodes), 0, len(used) - 1)
        missing = used[pos] != file_nodes
        if missing.any():
            notes.append(f"{kind} group {name!r} dropped: {int(missing.sum())} of its node entries (e.g. node "
                         f"{int(file_nodes[missing].ravel()[0])}) belong to no {cell_type} cell, so it could not "
                         f"carry its loads or supports")
            return None
        return pos

    facet_groups, node_groups = {}, {}
    for name, parts in facets_acc.items():
        facets = to_mesh_nodes("facet", name, np.concatenate(parts))
        if facets is not None:
            _, first = np.unique(np.sort(facets, axis=1), axis=0, return_index=True)
            facet_groups[name] = facets[np.sort(first)]  # a facet in the group twice (two sources) once
    for name, parts in nodes_acc.items():
        nodes = to_mesh_nodes("node", name, np.unique(np.concatenate(parts)))
        if nodes is not None:
            node_groups[name] = nodes
    cell_groups = {name: np.unique(np.concatenate(parts)) for name, parts in cells_acc.items()}
    return {"cell_groups": cell_groups, "facet_groups": facet_groups, "node_groups": node_groups}, notes


def _pad_columns(a: np.ndarray, dim: int) -> np.ndarray:
    if dim == 2 and a.ndim == 2 and a.shape[1] == 2:
        return np.pad(a, ((0, 0), (0, 1)))
    return a


def write_vtu(path, mesh: Mesh, point_data: dict | None = None, cell_data: dict | None = None) -> Path:
    """Write ``mesh`` as a VTK unstructured grid (.vtu) that ParaView opens.

    2D points get ``z = 0``; on a 2D mesh, data arrays of shape ``(n, 2)`` (vectors) are padded
    to 3 components as well.  ``point_data`` arrays have ``n_nodes`` rows, ``cell_data`` arrays
    ``n_cells`` rows; ``material`` is always written as cell data.  The file is written to a
    temporary file in the same directory and moved into place with :func:`os.replace`, so a
    reader never sees a partial file.  Returns the path.
    """
    import meshio

    path = Path(path)
    point_data = {} if point_data is None else dict(point_data)
    cell_data = {} if cell_data is None else dict(cell_data)
    pdata, cdata = {}, {"material": [mesh.material]}
    for name, values in point_data.items():
        values = np.asarray(values)
        if len(values) != mesh.n_nodes:
            raise ValueError(f"point_data[{name!r}] has {len(values)} rows, the mesh {mesh.n_nodes} nodes")
        pdata[name] = _pad_columns(values, mesh.dim)
    for name, values in cell_data.items():
        values = np.asarray(values)
        if len(values) != mesh.n_cells:
            raise ValueError(f"cell_data[{name!r}] has {len(values)} rows, the mesh {mesh.n_cells} cells")
        cdata[name] = [_pad_columns(values, mesh.dim)]
    points = _pad_columns(mesh.points, mesh.dim)
    out = meshio.Mesh(points, [(mesh.cell_type, mesh.cells)], point_data=pdata, cell_data=cdata)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        meshio.write(tmp, out, file_format="vtu")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


# --------------------------------------------------------------------------------------------
# topology
# --------------------------------------------------------------------------------------------


def unique_edges(mesh: Mesh) -> NodePairs:
    """Edges of the mesh: ``(pairs, indptr, cells)``, see :class:`NodePairs`.

    ``pairs`` is ``(n_edges, 2)`` sorted node pairs; ``NodePairs.counts`` is the number of cells
    sharing each edge (1 or 2 for a quad/hexahedron boundary/interior edge in 2D, up to 4 around
    an interior edge of a hexahedron grid, any number for tetrahedra).
    """
    return _local_pairs(mesh, _LOCAL_EDGES[mesh.cell_type])


_FACE_DIAGONALS = {
    "quad": np.array([[0, 2], [1, 3]]),
    "hexahedron": _LOCAL_FACETS["hexahedron"][:, [[0, 2], [1, 3]]].reshape(-1, 2),
}
_INNER_DIAGONALS = np.array([[0, 6], [1, 7], [2, 4], [3, 5]])


def face_diagonals(mesh: Mesh) -> NodePairs:
    """Diagonals of the faces of hexahedra (12 per cell; of the cell itself for quads, 2 per cell).

    A diagonal of a face shared by two hexahedra appears once with ``counts == 2``.
    """
    if mesh.cell_type not in _FACE_DIAGONALS:
        raise ValueError(f"face diagonals need hexahedron or quad cells, got {mesh.cell_type}")
    return _local_pairs(mesh, _FACE_DIAGONALS[mesh.cell_type])


def inner_diagonals(mesh: Mesh) -> NodePairs:
    """The four space diagonals (0-6, 1-7, 2-4, 3-5) of each hexahedron; counts are 1."""
    if mesh.cell_type != "hexahedron":
        raise ValueError(f"inner diagonals need hexahedron cells, got {mesh.cell_type}")
    return _local_pairs(mesh, _INNER_DIAGONALS)


def _facet_table(mesh: Mesh):
    local = _LOCAL_FACETS[mesh.cell_type]
    facets = mesh.cells[:, local].reshape(-1, local.shape[1])
    keys = np.sort(facets, axis=1)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    return facets, counts[inverse.ravel()]


def boundary_facets(mesh: Mesh, return_cells: bool = False):
    """Facets belonging to exactly one cell, outward oriented.

    2D: ``(n, 2)`` edges with the mesh on their left (counter-clockwise around the outer boundary;
    outward normal ``(dy, -dx)``).  3D: ``(n, 3)`` triangles (tetra) or ``(n, 4)`` quads
    (hexahedron) whose right-hand-rule normal points out of the mesh.  Assumes positively oriented
    cells (see :func:`orient`).  Facets are listed cell by cell in local facet order.  With
    ``return_cells``, also the cell of each facet: ``(facets, cells)``.
    """
    facets, counts = _facet_table(mesh)
    on = counts == 1
    if return_cells:
        n_local = len(_LOCAL_FACETS[mesh.cell_type])
        return facets[on], np.flatnonzero(on) // n_local
    return facets[on]


def facet_cell_counts(mesh: Mesh, facets) -> np.ndarray:
    """For each facet of ``facets`` (``(k, nodes_per_facet)`` node indices, any order and
    orientation), the number of cells of ``mesh`` it is a face of: 0 (not a face: on no cell, or
    across one), 1 (a boundary facet) or 2 (an interior facet)."""
    facets = np.asarray(facets, dtype=np.int64)
    local = _LOCAL_FACETS[mesh.cell_type]
    if facets.ndim != 2 or facets.shape[1] != local.shape[1]:
        raise ValueError(f"facets of {mesh.cell_type} cells must have shape (k, {local.shape[1]}), got {facets.shape}")
    own = np.sort(mesh.cells[:, local].reshape(-1, local.shape[1]), axis=1)
    keys = np.concatenate([own, np.sort(facets, axis=1)])
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    counts = np.bincount(inverse[:len(own)], minlength=int(inverse.max(initial=-1)) + 1)
    return counts[inverse[len(own):]]


def _fmt_names(names) -> str:
    return ", ".join(sorted(names)) if names else "none"


def materials_from_groups(mesh: Mesh, keys, source: str = "materials") -> np.ndarray:
    """Material index of every cell from cell groups: ``material[c] = i`` for the cells of
    ``mesh.cell_groups[keys[i]]``.

    Every cell must be in exactly one of the groups: a group the mesh lacks (naming the cell
    groups it has), cells in none of them or in two of them (counted, with an example cell and
    its centroid) are a ValueError starting with ``source``.
    """
    keys = [str(k) for k in keys]
    groups = mesh.cell_groups
    for key in keys:
        if key not in groups:
            import difflib

            hint = difflib.get_close_matches(key, list(groups), n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise ValueError(f"{source}: the mesh has no cell group {key!r}{did}; its cell groups: "
                             f"{_fmt_names(groups)}")
    count = np.zeros(mesh.n_cells, dtype=np.int64)
    material = np.zeros(mesh.n_cells, dtype=np.int64)
    for i, key in enumerate(keys):
        count[groups[key]] += 1
        material[groups[key]] = i

    def contains(cells, c):  # cells sorted
        return bool(len(cells)) and cells[min(np.searchsorted(cells, c), len(cells) - 1)] == c

    def example(c):
        others = [name for name, cells in groups.items() if name not in keys and contains(cells, c)]
        where = f" (in the group(s) {_fmt_names(others)})" if others else ""
        centroid = mesh.points[mesh.cells[c]].mean(axis=0)
        return f"cell {c} at {_fmt_point(centroid)}{where}"

    many = np.flatnonzero(count > 1)
    if len(many):
        c = int(many[0])
        which = [key for key in keys if contains(groups[key], c)]
        raise ValueError(f"{source}: {len(many)} of {mesh.n_cells} cell(s) are in two or more of the groups "
                         f"{', '.join(keys)}, e.g. {example(c)} in {', '.join(which)}; allowed: every cell in "
                         f"exactly one of them")
    none = np.flatnonzero(count == 0)
    if len(none):
        raise ValueError(f"{source}: {len(none)} of {mesh.n_cells} cell(s) are in none of the groups "
                         f"{', '.join(keys)}, e.g. {example(int(none[0]))}; allowed: every cell in exactly one of "
                         f"them (the mesh's cell groups: {_fmt_names(groups)})")
    return material


def facet_areas(mesh: Mesh, facets: np.ndarray) -> np.ndarray:
    """Length (2D, metres) or area (3D, m^2) of each facet of ``facets`` (node ids).

    Quads use the area of the bilinear surface they span (2 x 2 Gauss quadrature; exact for
    planar quads).
    """
    facets = np.asarray(facets, dtype=np.int64)
    x = mesh.points[facets]
    if facets.shape[1] == 2:
        return np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
    if facets.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if facets.shape[1] == 4:
        g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
        area = np.zeros(len(facets))
        for u in g:
            for v in g:
                # bilinear map on [-1, 1]^2, corners counter-clockwise
                du = 0.25 * ((x[:, 1] - x[:, 0]) * (1 - v) + (x[:, 2] - x[:, 3]) * (1 + v))
                dv = 0.25 * ((x[:, 3] - x[:, 0]) * (1 - u) + (x[:, 2] - x[:, 1]) * (1 + u))
                area += np.linalg.norm(np.cross(du, dv), axis=1)
        return area
    raise ValueError(f"facets must have 2, 3 or 4 nodes, got {facets.shape[1]}")


# --------------------------------------------------------------------------------------------
# geometry and checks
# --------------------------------------------------------------------------------------------


def _hex_volumes(x: np.ndarray) -> np.ndarray:
    """Exact volume of trilinear hexahedra (det J is of degree <= 2 per variable: 2^3 Gauss)."""
    g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    gp = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T  # (8, 3)
    s = _HEX_REF  # (8 nodes, 3)
    # dN[g, a, d] = d N_a / d xi_d at Gauss point g
    f = 1.0 + gp[:, None, :] * s[None, :, :]  # (8 gp, 8 nodes, 3)
    dn = np.empty((len(gp), 8, 3))
    dn[..., 0] = s[:, 0] * f[..., 1] * f[..., 2]
    dn[..., 1] = s[:, 1] * f[..., 0] * f[..., 2]
    dn[..., 2] = s[:, 2] * f[..., 0] * f[..., 1]
    dn /= 8.0
    jac = np.einsum("cai,gad->cgid", x, dn)  # (cells, gp, 3, 3)
    return np.linalg.det(jac).sum(axis=1)


def cell_measures(mesh: Mesh) -> np.ndarray:
    """Signed area (2D, m^2) or volume (3D, m^3) of each cell; positive for the conventional
    orientation.

    Triangles and tetrahedra: exact.  Quads: exact area of the bilinear quad (shoelace formula).
    Hexahedra: exact volume of the trilinear hexahedron (2 x 2 x 2 Gauss quadrature of det J).
    """
    x = mesh.points[mesh.cells]
    t = mesh.cell_type
    if t == "triangle":
        a, b = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
        return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    if t == "quad":
        d1, d2 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
        return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    if t == "tetra":
        return np.linalg.det(x[:, 1:] - x[:, :1]) / 6.0
    return _hex_volumes(x)


def check_cells(mesh: Mesh, rtol: float = 1e-12, max_report: int = 5) -> np.ndarray:
    """Raise ValueError if a cell is inverted (negative measure) or degenerate
    (``|measure| <= rtol * mean |measure|``); otherwise return the measures.

    The message names the first ``max_report`` offending cell indices with their measure.
    """
    measures = cell_measures(mesh)
    if measures.size == 0:
        return measures
    mean = np.abs(measures).mean()
    degenerate = np.abs(measures) <= rtol * mean
    inverted = (measures < 0) & ~degenerate
    problems = []
    for label, mask in (("inverted", inverted), ("degenerate", degenerate)):
        bad = np.flatnonzero(mask)
        if len(bad):
            shown = ", ".join(f"cell {i} (measure {measures[i]:.3e})" for i in bad[:max_report])
            more = f" and {len(bad) - max_report} more" if len(bad) > max_report else ""
            problems.append(f"{len(bad)} {label} {mesh.cell_type} cell(s): {shown}{more}")
    if problems:
        raise ValueError("; ".join(problems) + f" (mean |measure| {mean:.3e})")
    return measures


_FLIP = {
    "triangle": np.array([0, 2, 1]),
    "quad": np.array([0, 3, 2, 1]),
    "tetra": np.array([0, 2, 1, 3]),
    "hexahedron": np.array([4, 5, 6, 7, 0, 1, 2, 3]),
}


def orient(mesh: Mesh) -> Mesh:
    """Return a mesh whose cells with negative measure are flipped: triangles and tetrahedra swap
    nodes 1 and 2, quads reverse their order, hexahedra swap their bottom and top faces."""
    flip = cell_measures(mesh) < 0
    if not flip.any():
        return mesh
    cells = mesh.cells.copy()
    cells[flip] = cells[flip][:, _FLIP[mesh.cell_type]]
    return replace(mesh, cells=cells)  # material and groups unchanged (cell and node numbers are kept)


def select_nodes(mesh: Mesh, box=None, plane=None, tol: float = 1e-9) -> np.ndarray:
    """Sorted ids of the nodes inside ``box`` and on ``plane`` (both optional; both -> intersection).

    ``box = ((xmin, ymin[, zmin]), (xmax, ymax[, zmax]))`` in metres, any bound may be None
    (unbounded), and either corner may be None.  ``plane = (axis, value)`` with axis "x", "y",
    "z" or 0, 1, 2, e.g. ``("z", 0.0)``.  Bounds are widened by ``tol`` metres.  With neither,
    every node is selected.  Raises ValueError if nothing is selected.
    """
    x = mesh.points
    keep = np.ones(len(x), dtype=bool)
    if box is not None:
        lower, upper = box
        for bounds, sign in ((lower, 1.0), (upper, -1.0)):
            if bounds is None:
                continue
            if len(bounds) != mesh.dim:
                raise ValueError(f"box corners need {mesh.dim} coordinates, got {bounds!r}")
            for d, b in enumerate(bounds):
                if b is not None:
                    keep &= sign * (x[:, d] - b) >= -tol
    if plane is not None:
        axis, value = plane
        d = _AXES.get(axis, axis) if isinstance(axis, str) else int(axis)
        if not isinstance(d, int) or not 0 <= d < mesh.dim:
            raise ValueError(f"plane axis {axis!r} is not an axis of a {mesh.dim}D mesh")
        keep &= np.abs(x[:, d] - value) <= tol
    ids = np.flatnonzero(keep)
    if len(ids) == 0:
        raise ValueError(f"no node selected by box={box!r}, plane={plane!r} (tol={tol})")
    return ids


def lumped_masses(mesh: Mesh, density, thickness: float = 1.0) -> np.ndarray:
    """Lumped nodal masses (kg): each cell's mass split equally among its nodes.

    ``density`` in kg/m^3, a scalar or one value per cell.  For 2D meshes the cell mass is
    ``density * area * thickness`` (thickness in metres); for 3D meshes ``density * volume``
    and ``thickness`` must be left at 1.
    """
    density = np.broadcast_to(np.asarray(density, dtype=float), (mesh.n_cells,))
    if mesh.dim == 3 and thickness != 1.0:
        raise ValueError("thickness applies to 2D meshes only")
    cell_mass = density * np.abs(cell_measures(mesh)) * (thickness if mesh.dim == 2 else 1.0)
    per_node = np.repeat(cell_mass / mesh.nodes_per_cell, mesh.nodes_per_cell)
    return np.bincount(mesh.cells.ravel(), weights=per_node, minlength=mesh.n_nodes)


# --------------------------------------------------------------------------------------------
# mesh hygiene: coincident nodes, connected parts, rigid-body modes left free by the fixed dofs
# --------------------------------------------------------------------------------------------


def _fmt_point(x) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in x) + ")"


def _bbox_diagonal(points: np.ndarray) -> float:
    if len(points) == 0:
        return 0.0
    return float(np.linalg.norm(np.ptp(points, axis=0)))


def coincident_nodes(points, rtol: float = COINCIDENT_RTOL) -> np.ndarray:
    """The lowest-numbered twin of every node: ``rep[i]`` is the smallest index of the nodes closer
    than ``rtol`` times the diagonal of the bounding box of ``points`` to node ``i`` (transitively),
    so ``rep[i] <= i`` and ``rep[i] == i`` for a node without twin.

    Two cells that share a face geometrically but not by node index are not connected; such nodes
    are what this finds.  Uses a k-d tree (:class:`scipy.spatial.cKDTree`): O(n log n).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=float)
    n = len(points)
    rep = np.arange(n, dtype=np.int64)
    if n < 2:
        return rep
    tol = float(rtol) * _bbox_diagonal(points)
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray")
    if len(pairs) == 0:
        return rep
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    n_groups, label = connected_components(graph, directed=False)
    lowest = np.full(n_groups, n, dtype=np.int64)
    np.minimum.at(lowest, label, rep)
    return lowest[label]


def _node_name(i: int, node_ids) -> str:
    return f"node {int(i) if node_ids is None else int(node_ids[i])}"


def _twins_text(points, rep, dup, node_ids, max_report) -> str:
    shown = ", ".join(f"{_node_name(i, node_ids)} = {_node_name(rep[i], node_ids)} at {_fmt_point(points[i])}"
                      for i in dup[:max_report])
    more = f" and {len(dup) - max_report} more" if len(dup) > max_report else ""
    return shown + more


def resolve_coincident_nodes(mesh: Mesh, policy: str = "merge", rtol: float = COINCIDENT_RTOL, *,
                             source: str = "mesh", node_ids=None, hint: str = "",
                             max_report: int = 3) -> Mesh:
    """Find the coincident nodes of ``mesh`` (:func:`coincident_nodes`) and apply ``policy``.

    ``"merge"``: every node is replaced by its lowest-numbered twin in the cells, the nodes no cell
    uses any more are dropped (the others keep their order, so indices above a dropped node shift
    down), the material and cell groups of each cell are kept, the facet and node groups follow
    their nodes (:class:`Mesh`), and one :class:`msslib.errors.MsslibWarning` names
    how many nodes were merged and the first ``max_report`` of them with their coordinates.
    ``"error"``: a ValueError naming them.  ``"keep"``: nothing is checked.  The mesh is returned
    unchanged when no node has a twin.

    A cell two of whose own nodes coincide would collapse when merged: a ValueError names it (under
    either policy).  ``source`` starts every message (a file name, a scene key); ``node_ids``
    optionally maps node indices to the numbers shown (e.g. the node numbers of a file); ``hint``
    is appended to the error message (what the caller allows instead).
    """
    if policy not in COINCIDENT_POLICIES:
        raise ValueError(f"coincident node policy must be one of {', '.join(COINCIDENT_POLICIES)}, got {policy!r}")
    if policy == "keep":
        return mesh
    rep = coincident_nodes(mesh.points, rtol)
    dup = np.flatnonzero(rep != np.arange(mesh.n_nodes))
    if len(dup) == 0:
        return mesh
    tol = float(rtol) * _bbox_diagonal(mesh.points)
    merged = rep[mesh.cells]
    ordered = np.sort(merged, axis=1)
    collapsed = np.flatnonzero((ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
    if len(collapsed):
        c = int(collapsed[0])
        local = mesh.cells[c]
        a, b = next((i, j) for i in range(len(local)) for j in range(i + 1, len(local))
                    if rep[local[i]] == rep[local[j]])
        more = f" (and {len(collapsed) - 1} more cell(s))" if len(collapsed) > 1 else ""
        raise ValueError(
            f"{source}: {mesh.cell_type} cell {c} has two coincident corners, {_node_name(local[a], node_ids)} and "
            f"{_node_name(local[b], node_ids)} at {_fmt_point(mesh.points[local[a]])} (closer than {tol:.3g} m){more}; "
            f"allowed: cells whose corners are distinct points")
    what = (f"{len(dup)} coincident node(s) (closer than {tol:.3g} m to a lower-numbered node): "
            f"{_twins_text(mesh.points, rep, dup, node_ids, max_report)}")
    if policy == "error":
        raise ValueError(f"{source}: {what}; allowed: distinct nodes{hint}")
    import warnings

    from msslib.errors import MsslibWarning

    points, cells, new_id = _compact(mesh.points, merged, return_map=True)
    groups = _renumbered_groups(mesh, new_id[rep], source)
    warnings.warn(f"{source}: merged {what}; cells renumbered to the lower-numbered node, {len(points)} nodes left",
                  MsslibWarning, stacklevel=2)
    return Mesh(points, cells, mesh.cell_type, mesh.material, cell_groups=mesh.cell_groups, **groups)


def connected_parts(mesh: Mesh) -> tuple[int, np.ndarray]:
    """Connected parts of a mesh: two cells belong to the same part when they share a node
    (by index: see :func:`coincident_nodes` for nodes that only share a position).

    Returns ``(n_parts, part)`` with ``part`` the part of each node, ``0 .. n_parts - 1``, numbered
    in the order of their lowest node (node 0 is in part 0); a node no cell uses is a part of its
    own.  The part of cell ``c`` is ``part[mesh.cells[c, 0]]``.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = mesh.n_nodes
    rows = mesh.cells.ravel()
    cols = np.repeat(mesh.cells[:, 0], mesh.nodes_per_cell)
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    n_parts, label = connected_components(graph, directed=False)
    # relabel in the order of the lowest node of each part (scipy's order is not documented)
    first = np.full(n_parts, n, dtype=np.int64)
    np.minimum.at(first, label, np.arange(n))
    order = np.empty(n_parts, dtype=np.int64)
    order[np.argsort(first, kind="stable")] = np.arange(n_parts)
    return int(n_parts), order[label]


class LoosePart(NamedTuple):
    """A connected part of a mesh that its fixed dofs do not hold (see :func:`loose_parts`).

    ``part`` is its number in :func:`connected_parts` (``n_parts`` parts in all), ``n_cells`` its
    cell count, ``node`` its lowest node.  ``floating``: no dof of the part is fixed.  ``n_free`` is
    the number of independent rigid-body modes left free (3 in 2D, 6 in 3D when floating) and
    ``modes`` their names when each is a translation along an axis or a rotation about a line
    parallel to an axis (e.g. ``"translation along x"``, ``"rotation about the z axis"``,
    ``"rotation about the line x = 0.1, y = 0 (parallel to z)"``, in 2D ``"rotation about the
    point (0, 0)"``; ``"rotation about an axis parallel to z"`` when a free translation lets the
    axis slide); otherwise the names found and ``"N other rigid-body mode(s) (...)"``.
    """

    part: int
    n_parts: int
    n_cells: int
    node: int
    floating: bool
    n_free: int
    modes: tuple

    def describe(self, mesh: Mesh) -> str:
        """One phrase: which part, and what is loose (for error messages)."""
        at = f"node {self.node} at {_fmt_point(mesh.points[self.node])}"
        if self.n_cells == 0:
            return f"{at} belongs to no cell and is not fixed in every axis"
        what = (f"part {self.part + 1} of {self.n_parts} ({self.n_cells} {mesh.cell_type} cells, {at})"
                if self.n_parts > 1 else f"the mesh ({self.n_cells} {mesh.cell_type} cells, {at})")
        if self.floating:
            return f"{what} is floating: none of its dofs is fixed"
        return f"{what} has {self.n_free} free rigid-body mode(s): {', '.join(self.modes)}"


def _rigid_modes(x: np.ndarray, center: np.ndarray, scale: float) -> np.ndarray:
    """Rigid-body velocity fields at the points ``x`` (m, dim): shape (m, dim, n_modes), the
    translations along each axis, then the rotations about the axes (z only in 2D) through
    ``center`` divided by ``scale`` (so that every mode has entries of order one)."""
    m, dim = x.shape
    r = (x - center) / scale
    if dim == 2:
        modes = np.zeros((m, 2, 3))
        modes[:, 0, 0] = modes[:, 1, 1] = 1.0
        modes[:, 0, 2], modes[:, 1, 2] = -r[:, 1], r[:, 0]
        return modes
    modes = np.zeros((m, 3, 6))
    for a in range(3):
        modes[:, a, a] = 1.0
        axis = np.zeros(3)
        axis[a] = 1.0
        modes[:, :, 3 + a] = np.cross(axis, r)
    return modes


def _name_free_modes(null: np.ndarray, dim: int, center: np.ndarray, scale: float) -> tuple:
    """Names of the rigid-body modes spanned by the orthonormal columns of ``null`` (mode
    coordinates of :func:`_rigid_modes`)."""
    k = null.shape[1]
    eye = np.eye(null.shape[0])
    in_span = [np.linalg.norm(eye[:, a] - null @ (null.T @ eye[:, a])) < 1e-6 for a in range(dim)]
    names = [f"translation along {'xyz'[a]}" for a in range(dim) if in_span[a]]
    rot_rows = [2] if dim == 2 else [3, 4, 5]
    rot_axes = [2] if dim == 2 else [0, 1, 2]
    w = null[rot_rows, :]
    scale_len = max(scale, 1e-300)
    for row, a in enumerate(rot_axes):
        target = np.zeros(len(rot_rows))
        target[row] = 1.0
        coef, *_ = np.linalg.lstsq(w, target, rcond=None)
        if np.linalg.norm(w @ coef - target) > 1e-6:
            continue
        t = np.zeros(3)
        t[:dim] = (null @ coef)[:dim]
        if abs(t[a]) > 1e-6 and not (a < dim and in_span[a]):
            continue  # a screw motion: counted, not named
        t[a] = 0.0
        axis = np.zeros(3)
        axis[a] = 1.0
        others = [b for b in range(3) if b != a and b < dim]
        if any(in_span[b] for b in others):  # the line can slide: only its direction is defined
            names.append("rotation" if dim == 2 else f"rotation about an axis parallel to {'xyz'[a]}")
            continue
        c3 = np.zeros(3)
        c3[:dim] = center
        p = c3 - scale_len * np.cross(t, axis)
        p[np.abs(p) < 1e-9 * scale_len] = 0.0
        if dim == 2:
            names.append(f"rotation about the point {_fmt_point(p[:2])}")
        elif not p[others].any():
            names.append(f"rotation about the {'xyz'[a]} axis")
        else:
            line = ", ".join(f"{'xyz'[b]} = {p[b]:.6g}" for b in others)
            names.append(f"rotation about the line {line} (parallel to {'xyz'[a]})")
    if len(names) < k:
        # fixed dofs are per axis, so every free translation is named: the rest turn about skew lines
        names.append(f"{k - len(names)} other rigid-body mode(s) (rotation about a line not parallel to an axis)")
    return tuple(names)


def loose_parts(mesh: Mesh, fixed, rtol: float = 1e-8) -> list[LoosePart]:
    """The parts of ``mesh`` (:func:`connected_parts`) whose fixed dofs leave a rigid-body mode
    free: a static solve of such a part has a singular stiffness.

    ``fixed`` is ``(n_nodes, dim)`` bool (prescribed displacements count as fixed).  For each part,
    the rigid-body modes (translations and infinitesimal rotations; 3 in 2D, 6 in 3D) restricted to
    its fixed dofs form a matrix whose null space (singular values below ``rtol`` times the
    largest) holds the free modes.  A part no dof of which is fixed is ``floating``.  A node that
    no cell uses is a part of its own, loose unless all its dofs are fixed.  Returns the loose parts
    in part order (empty: every part is held).
    """
    fixed = np.asarray(fixed, dtype=bool)
    dim = mesh.dim
    if fixed.shape != (mesh.n_nodes, dim):
        raise ValueError(f"fixed must have shape ({mesh.n_nodes}, {dim}), got {fixed.shape}")
    n_modes = 3 if dim == 2 else 6
    n_parts, part = connected_parts(mesh)
    cell_part = part[mesh.cells[:, 0]] if mesh.n_cells else np.zeros(0, dtype=np.int64)
    n_cells = np.bincount(cell_part, minlength=n_parts)
    held_parts = np.unique(part[fixed.any(axis=1)])
    order = np.argsort(part, kind="stable")
    starts = np.searchsorted(part[order], np.arange(n_parts + 1))
    out = []
    for p in range(n_parts):
        nodes = order[starts[p]:starts[p + 1]]
        node = int(nodes.min())
        if n_cells[p] == 0:
            if not fixed[nodes].all():
                out.append(LoosePart(p, n_parts, 0, node, True, dim, ()))
            continue
        if p not in held_parts:
            out.append(LoosePart(p, n_parts, int(n_cells[p]), node, True, n_modes, ()))
            continue
        x = mesh.points[nodes]
        center = x.mean(axis=0)
        scale = _bbox_diagonal(x) or 1.0
        modes = _rigid_modes(x, center, scale)[fixed[nodes]]  # (n fixed dofs, n_modes)
        _, s, vt = np.linalg.svd(np.linalg.qr(modes, mode="r"), full_matrices=True)  # QR first: O(n_fixed)
        rank = int(np.sum(s > rtol * s.max())) if s.size and s.max() > 0 else 0
        if rank == n_modes:
            continue
        null = vt[rank:].T
        out.append(LoosePart(p, n_parts, int(n_cells[p]), node, False, n_modes - rank,
                             _name_free_modes(null, dim, center, scale)))
    return out

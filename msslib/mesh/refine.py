"""Uniform (nested) refinement of a :class:`~msslib.mesh.Mesh`.

:func:`uniform` splits every cell into children of half its size: a triangle into 4 (edge
midpoints), a quad into 4 (edge midpoints and centre), a tetrahedron into 8 (four corner
tetrahedra and the inner octahedron cut along its shortest diagonal, the "red" refinement) and a
hexahedron into 8 (edge midpoints, face centres and centre). The new nodes sit at the average of
the corners that define them, which for quads and hexahedra is the point of the parent's
(bi-/tri-)linear map at the midpoint of the parameter range, so a refined mesh covers exactly the
same domain as its parent, with the same (flat or bilinear) boundary faces.

Nested numbering: the parent's nodes keep their indices (``fine.points[:n] == coarse.points``),
the new nodes follow (edge midpoints, then face centres, then cell centres). Child ``j`` of cell
``c`` is cell ``c * n_children + j``; children inherit the material and the cell groups of their
parent and have its orientation. Facet groups are refined with their facets (orientation kept);
a node group gains the new nodes whose defining corners all belong to it.
"""

from __future__ import annotations

import itertools

import numpy as np

from msslib.mesh import Mesh

__all__ = ["CHILDREN", "uniform"]

#: number of children of a cell (and of a facet) under one uniform refinement
CHILDREN = {"triangle": 4, "quad": 4, "tetra": 8, "hexahedron": 8, "line": 2}

_QUAD01 = np.array([[0, 0], [1, 0], [1, 1], [0, 1]])  # VTK quad corners in the unit square
_HEX01 = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])


def _lattice_tables(corners01: np.ndarray):
    """Virtual nodes (tuples of parent corners) and children of a tensor-product cell: the
    points of the 3^d lattice of half steps; a child's corners are lattice points in the parent's
    local corner order."""
    d = corners01.shape[1]
    index = {tuple(c): i for i, c in enumerate(corners01.tolist())}
    virtual, where = [], {}
    for p in itertools.product(range(3), repeat=d):
        choices = [(0,) if c == 0 else (1,) if c == 2 else (0, 1) for c in p]
        virtual.append(tuple(sorted(index[q] for q in itertools.product(*choices))))
        where[p] = len(virtual) - 1
    children = [[where[tuple(int(a + b) for a, b in zip(child, o))] for o in corners01.tolist()]
                for child in itertools.product(range(2), repeat=d)]
    return virtual, np.array(children)


def _simplex_tables():
    tri_virtual = [(0,), (1,), (2,), (0, 1), (1, 2), (0, 2)]
    tri_children = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])
    tet_virtual = [(0,), (1,), (2,), (3,), (0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    corner = [[0, 4, 5, 6], [4, 1, 7, 8], [5, 7, 2, 9], [6, 8, 9, 3]]
    # the inner octahedron, cut along one of its three diagonals (a, b); the other two pairs of
    # opposite vertices (c, c2), (e, e2) form the ring c, e, c2, e2 around it
    variants = []
    for (a, b), (c, c2), (e, e2) in (((4, 9), (5, 8), (6, 7)), ((5, 8), (4, 9), (6, 7)), ((6, 7), (4, 9), (5, 8))):
        variants.append(np.array(corner + [[a, b, c, e], [a, b, e, c2], [a, b, c2, e2], [a, b, e2, c]]))
    return (tri_virtual, tri_children), (tet_virtual, variants)


_TRI, _TET = _simplex_tables()
_QUAD = _lattice_tables(_QUAD01)
_HEX = _lattice_tables(_HEX01)
_LINE = ([(0,), (1,), (0, 1)], np.array([[0, 2], [2, 1]]))
_TABLES = {"triangle": _TRI, "quad": _QUAD, "hexahedron": _HEX, "line": _LINE}
_DIAGONALS = np.array([[4, 9], [5, 8], [6, 7]])  # the octahedron diagonals, in _TET's variant order
_FACET_KIND = {"triangle": "line", "quad": "line", "tetra": "triangle", "hexahedron": "quad"}


def _signed_measure(x: np.ndarray) -> np.ndarray:
    """Signed area (2D triangles) or volume (tetrahedra) of simplices ``x`` of shape (m, d+1, d)."""
    return np.linalg.det(x[:, 1:] - x[:, :1])


def _once(mesh: Mesh) -> Mesh:
    ct, cells, pts = mesh.cell_type, mesh.cells, mesh.points
    n, m = mesh.n_nodes, mesh.n_cells
    virtual = (_TET[0] if ct == "tetra" else _TABLES[ct][0])
    # global id of every virtual node of every cell: corners keep theirs, the others are numbered
    # after the parent's nodes by the sorted set of corners that defines them (shared across cells)
    vid = np.empty((m, len(virtual)), dtype=np.int64)
    new_points, key_tables, next_id = [pts], {}, n
    for k in sorted({len(v) for v in virtual}):
        cols = [i for i, v in enumerate(virtual) if len(v) == k]
        if k == 1:
            vid[:, cols] = cells[:, [virtual[i][0] for i in cols]]
            continue
        keys = np.sort(cells[:, np.array([virtual[i] for i in cols])], axis=2).reshape(-1, k)
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        vid[:, cols] = next_id + inverse.reshape(m, len(cols))
        new_points.append(pts[uniq].mean(axis=1))
        key_tables[k] = (uniq, next_id)
        next_id += len(uniq)
    points = np.concatenate(new_points)
    if ct == "tetra":
        x = points[vid]
        lengths = np.linalg.norm(x[:, _DIAGONALS[:, 0]] - x[:, _DIAGONALS[:, 1]], axis=2)
        choice = np.argmin(lengths, axis=1)
        tables = np.stack(_TET[1])  # (3, 8, 4)
        children = np.take_along_axis(vid, tables[choice].reshape(m, -1), axis=1).reshape(m, 8, 4)
    else:
        table = _TABLES[ct][1]
        children = vid[:, table]
    children = children.reshape(-1, cells.shape[1])
    if ct in ("triangle", "tetra"):  # orientation of the parent (every child of a flat cell keeps it)
        parent_sign = np.sign(_signed_measure(pts[cells]))
        flip = np.sign(_signed_measure(points[children])) != np.repeat(parent_sign, CHILDREN[ct])
        children[flip] = children[flip][:, [0, 2, 1] if ct == "triangle" else [0, 1, 3, 2]]
    nc = CHILDREN[ct]
    cell_groups = {name: (ids[:, None] * nc + np.arange(nc)).ravel() for name, ids in mesh.cell_groups.items()}
    node_groups = {}
    for name, ids in mesh.node_groups.items():
        member = np.zeros(n, dtype=bool)
        member[ids] = True
        extra = [start + np.flatnonzero(member[uniq].all(axis=1)) for uniq, start in key_tables.values()]
        node_groups[name] = np.concatenate([ids, *extra])
    facet_groups = {name: _refine_facets(f, _FACET_KIND[ct], key_tables) for name, f in mesh.facet_groups.items()}
    return Mesh(points, children, ct, material=np.repeat(mesh.material, nc), cell_groups=cell_groups,
                facet_groups=facet_groups, node_groups=node_groups)


def _lookup(key_tables, keys: np.ndarray) -> np.ndarray:
    """Global ids of the new nodes defined by the (unsorted) corner sets ``keys`` (r, k)."""
    k = keys.shape[1]
    uniq, start = key_tables[k]
    keys = np.sort(keys, axis=1)
    table = {tuple(row): start + i for i, row in enumerate(uniq.tolist())}
    try:
        return np.array([table[tuple(row)] for row in keys.tolist()], dtype=np.int64)
    except KeyError as exc:
        raise ValueError(f"a facet group holds a facet that is no face of a cell (corners {list(exc.args[0])})") from None


def _refine_facets(facets: np.ndarray, kind: str, key_tables) -> np.ndarray:
    virtual, table = _TABLES[kind]
    vid = np.empty((len(facets), len(virtual)), dtype=np.int64)
    for i, v in enumerate(virtual):
        vid[:, i] = facets[:, v[0]] if len(v) == 1 else _lookup(key_tables, facets[:, list(v)])
    return vid[:, table].reshape(-1, facets.shape[1])


def uniform(mesh: Mesh, times: int = 1) -> Mesh:
    """``mesh`` refined uniformly ``times`` times (see the module docstring); ``times = 0`` returns it."""
    if isinstance(times, bool) or not isinstance(times, (int, np.integer)) or times < 0:
        raise ValueError(f"times must be an integer >= 0, got {times!r}")
    if not isinstance(mesh, Mesh):
        raise ValueError(f"mesh must be a msslib.mesh.Mesh, got {type(mesh).__name__}")
    for _ in range(int(times)):
        mesh = _once(mesh)
    return mesh

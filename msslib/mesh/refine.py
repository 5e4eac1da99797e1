"""Uniform (nested) refinement of a :class:`~msslib.mesh.Mesh`.

:func:`uniform` splits every cell into children of half its size: a triangle into 4 (edge
midpoints), a quad into 4 (edge midpoints and centre), a tetrahedron into 8 (four corner
tetrahedra and the inner octahedron cut along its shortest diagonal, the "red" refinement) and a
hexahedron into 8 (edge midpoints, face centres and centre), a wedge into 8 (its triangles split
into 4, its height into 2: edge midpoints and quadrilateral face centres); the rule of each type
is its cell module's (:mod:`msslib.mesh.cells`). The new nodes sit at the average of
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

import numpy as np

from msslib.mesh import Mesh
from msslib.mesh import cells as _cells
from msslib.mesh.cells import RegistryView as _RegistryView

__all__ = ["CHILDREN", "uniform"]

#: number of children of a cell (and of a facet) under one uniform refinement
CHILDREN = _RegistryView(lambda c: c.refinement.n_children, "cell type -> children under one refinement",
                         extra={"line": _cells.LINE.n_children})


def _signed_measure(x: np.ndarray) -> np.ndarray:
    """Signed area (2D triangles) or volume (tetrahedra) of simplices ``x`` of shape (m, d+1, d)."""
    return np.linalg.det(x[:, 1:] - x[:, :1])


def _once(mesh: Mesh) -> Mesh:
    ct, cells, pts = mesh.cell_type, mesh.cells, mesh.points
    n, m = mesh.n_nodes, mesh.n_cells
    cell = _cells.get(ct)
    rule = cell.refinement
    virtual = rule.virtual
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
    nc = rule.n_children
    if rule.diagonals is not None:  # variants: each cell takes the one of its shortest diagonal
        x = points[vid]
        diagonals = rule.diagonals
        lengths = np.linalg.norm(x[:, diagonals[:, 0]] - x[:, diagonals[:, 1]], axis=2)
        choice = np.argmin(lengths, axis=1)
        tables = np.stack(rule.children)  # (variants, children, nodes)
        children = np.take_along_axis(vid, tables[choice].reshape(m, -1), axis=1).reshape(m, nc, -1)
    else:
        children = vid[:, rule.children]
    children = children.reshape(-1, cells.shape[1])
    if rule.reorient is not None:  # orientation of the parent (every child of a flat cell keeps it)
        parent_sign = np.sign(_signed_measure(pts[cells]))
        flip = np.sign(_signed_measure(points[children])) != np.repeat(parent_sign, nc)
        children[flip] = children[flip][:, list(rule.reorient)]
    cell_groups = {name: (ids[:, None] * nc + np.arange(nc)).ravel() for name, ids in mesh.cell_groups.items()}
    node_groups = {}
    for name, ids in mesh.node_groups.items():
        member = np.zeros(n, dtype=bool)
        member[ids] = True
        extra = [start + np.flatnonzero(member[uniq].all(axis=1)) for uniq, start in key_tables.values()]
        node_groups[name] = np.concatenate([ids, *extra])
    facet_groups = {name: _refine_facets(f, _cells.facet_type(f.shape[1], cell.dim), key_tables)
                    for name, f in mesh.facet_groups.items()}
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
    rule = _cells.refinement_of(kind)
    virtual, table = rule.virtual, rule.children
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

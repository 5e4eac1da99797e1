"""Topology of a mesh: its edges and diagonals as unique node pairs with the cells sharing each
(:class:`NodePairs`, :func:`unique_edges`, :func:`face_diagonals`, :func:`inner_diagonals`), its
boundary facets (:func:`boundary_facets`), whether given facets are faces of its cells
(:func:`facet_cell_counts`), and its pieces of cells joined through whole facets
(:func:`facet_connected_cells`: two pieces that share only a vertex, or an edge in 3D, meet at a
hinge).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import cells as _cells
from .core import LOCAL_EDGES, Mesh


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


def unique_edges(mesh: Mesh) -> NodePairs:
    """Edges of the mesh: ``(pairs, indptr, cells)``, see :class:`NodePairs`.

    ``pairs`` is ``(n_edges, 2)`` sorted node pairs; ``NodePairs.counts`` is the number of cells
    sharing each edge (1 or 2 for a quad/hexahedron boundary/interior edge in 2D, up to 4 around
    an interior edge of a hexahedron grid, any number for tetrahedra).
    """
    return _local_pairs(mesh, LOCAL_EDGES[mesh.cell_type])


#: the four space diagonals of a hexahedron (local node pairs)
INNER_DIAGONALS = _cells.get("hexahedron").inner_diagonals


def _with(attr: str) -> list[str]:
    return [n for n, c in _cells.registry().items() if getattr(c, attr) is not None]


def face_diagonals(mesh: Mesh) -> NodePairs:
    """Diagonals of the quadrilateral faces of the cells (12 per hexahedron, 6 per wedge; of the
    cell itself for quads, 2 per cell).

    A diagonal of a face shared by two cells appears once with ``counts == 2``.
    """
    local = _cells.get(mesh.cell_type).face_diagonals
    if local is None:
        raise ValueError(f"face diagonals need {' or '.join(reversed(_with('face_diagonals')))} cells, "
                         f"got {mesh.cell_type}")
    return _local_pairs(mesh, local)


def inner_diagonals(mesh: Mesh) -> NodePairs:
    """The four space diagonals (0-6, 1-7, 2-4, 3-5) of each hexahedron; counts are 1."""
    local = _cells.get(mesh.cell_type).inner_diagonals
    if local is None:
        raise ValueError(f"inner diagonals need {' or '.join(_with('inner_diagonals'))} cells, got {mesh.cell_type}")
    return _local_pairs(mesh, local)


def _single_facets(mesh: Mesh) -> np.ndarray:
    """The local facets of the cells of ``mesh``, of one type; ValueError for a cell type with
    facets of several types (see :func:`boundary_facets_by_type`)."""
    ct = _cells.get(mesh.cell_type)
    if ct.single_facet_type is None:
        raise ValueError(f"mesh: {mesh.cell_type} cells have facets of several types "
                         f"({', '.join(ct.facets_by_type())}), which one array of facets cannot hold (so no "
                         f"tractions or pressures on them); allowed: cells with facets of one type, or "
                         f"msslib.mesh.boundary_facets_by_type")
    return ct.facets()


def _facet_table(mesh: Mesh, local: np.ndarray):
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
    local = _single_facets(mesh)
    facets, counts = _facet_table(mesh, local)
    on = counts == 1
    if return_cells:
        return facets[on], np.flatnonzero(on) // len(local)
    return facets[on]


def boundary_facets_by_type(mesh: Mesh) -> dict:
    """Facet type -> ``(facets, cells)``: the boundary facets of each type of the cells' facets
    (as :func:`boundary_facets` with ``return_cells``), for every cell type; a wedge mesh has
    triangles and quads."""
    out = {}
    for kind, local in _cells.get(mesh.cell_type).facets_by_type().items():
        facets, counts = _facet_table(mesh, local)
        on = counts == 1
        out[kind] = (facets[on], np.flatnonzero(on) // len(local))
    return out


def facet_cell_counts(mesh: Mesh, facets) -> np.ndarray:
    """For each facet of ``facets`` (``(k, nodes_per_facet)`` node indices, any order and
    orientation), the number of cells of ``mesh`` it is a face of: 0 (not a face: on no cell, or
    across one), 1 (a boundary facet) or 2 (an interior facet)."""
    facets = np.asarray(facets, dtype=np.int64)
    by_width = {f.shape[1]: f for f in _cells.get(mesh.cell_type).facets_by_type().values()}
    if facets.ndim != 2 or facets.shape[1] not in by_width:
        shape = " or ".join(f"(k, {n})" for n in by_width)
        raise ValueError(f"facets of {mesh.cell_type} cells must have shape {shape}, got {facets.shape}")
    local = by_width[facets.shape[1]]
    own = np.sort(mesh.cells[:, local].reshape(-1, local.shape[1]), axis=1)
    keys = np.concatenate([own, np.sort(facets, axis=1)])
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    counts = np.bincount(inverse[:len(own)], minlength=int(inverse.max(initial=-1)) + 1)
    return counts[inverse[len(own):]]


def facet_connected_cells(mesh: Mesh) -> tuple[int, np.ndarray]:
    """Pieces of a mesh whose cells are joined through shared facets (faces in 3D, edges in 2D).

    Returns ``(n_pieces, piece)`` with ``piece`` the piece of each cell, ``0 .. n_pieces - 1``,
    numbered in the order of their lowest cell.  Cells sharing nodes but no whole facet (a single
    vertex, or a single edge of a 3D mesh) are in different pieces: where such pieces meet is a
    hinge, about which one can turn against the other.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = mesh.n_cells
    if m == 0:
        return 0, np.zeros(0, dtype=np.int64)
    n = np.int64(max(mesh.n_nodes, 1))
    inverses, cell_ofs, n_facets = [], [], 0
    for local in _cells.get(mesh.cell_type).facets_by_type().values():  # facets of each type apart
        facets = np.sort(mesh.cells[:, local].reshape(-1, local.shape[1]), axis=1).astype(np.int64)
        # pairs of node indices as one int64 key each (n^2 < 2^63): a lexsort of 2 keys, not np.unique(axis=0)
        keys = [facets[:, j] * n + facets[:, j + 1] if j + 1 < facets.shape[1] else facets[:, j]
                for j in range(0, facets.shape[1], 2)]
        order = np.lexsort(keys[::-1])
        new = np.ones(len(order), dtype=bool)
        for k in keys:
            new[1:] &= k[order][1:] == k[order][:-1]
        new[1:] = ~new[1:]
        inverse = np.empty(len(order), dtype=np.int64)
        inverse[order] = np.cumsum(new) - 1
        inverses.append(n_facets + inverse)
        n_facets += int(inverse.max()) + 1
        cell_ofs.append(np.repeat(np.arange(m, dtype=np.int64), len(local)))
    inverse, cell_of = np.concatenate(inverses), np.concatenate(cell_ofs)
    graph = coo_matrix((np.ones(len(cell_of)), (cell_of, m + inverse)), shape=(m + n_facets, m + n_facets))
    n_pieces, label = connected_components(graph, directed=False)
    label = label[:m]
    first = np.full(n_pieces, m, dtype=np.int64)
    np.minimum.at(first, label, np.arange(m))
    order = np.empty(n_pieces, dtype=np.int64)
    order[np.argsort(first, kind="stable")] = np.arange(n_pieces)
    return int(n_pieces), order[label]

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

from .core import LOCAL_EDGES, _LOCAL_FACETS, Mesh


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


_FACE_DIAGONALS = {
    "quad": np.array([[0, 2], [1, 3]]),
    "hexahedron": _LOCAL_FACETS["hexahedron"][:, [[0, 2], [1, 3]]].reshape(-1, 2),
}
INNER_DIAGONALS = np.array([[0, 6], [1, 7], [2, 4], [3, 5]])


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
    return _local_pairs(mesh, INNER_DIAGONALS)


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
    local = _LOCAL_FACETS[mesh.cell_type]
    facets = np.sort(mesh.cells[:, local].reshape(-1, local.shape[1]), axis=1).astype(np.int64)
    n = np.int64(max(mesh.n_nodes, 1))
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
    n_facets = int(inverse.max()) + 1
    cell_of = np.repeat(np.arange(m, dtype=np.int64), len(local))
    graph = coo_matrix((np.ones(len(cell_of)), (cell_of, m + inverse)), shape=(m + n_facets, m + n_facets))
    n_pieces, label = connected_components(graph, directed=False)
    label = label[:m]
    first = np.full(n_pieces, m, dtype=np.int64)
    np.minimum.at(first, label, np.arange(m))
    order = np.empty(n_pieces, dtype=np.int64)
    order[np.argsort(first, kind="stable")] = np.arange(n_pieces)
    return int(n_pieces), order[label]

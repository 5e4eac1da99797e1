"""Mesh hygiene: nodes at the same place with different numbers, which cut a body in two
(:func:`coincident_nodes`, :func:`resolve_coincident_nodes`: merged or refused), connected parts
(:func:`connected_parts`) and the parts whose fixed dofs leave a rigid-body mode free
(:func:`loose_parts`, :class:`LoosePart`: floating, free to slide or turn, or a mechanism: pieces
joined only at a vertex, or an edge in 3D, that turn about it), and the shape of each cell
(:func:`cell_shapes`: aspect ratio and smallest angle, which name a sliver).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import cells as _cells
from .core import (
    COINCIDENT_POLICIES,
    COINCIDENT_RTOL,
    LOCAL_EDGES,
    Mesh,
    _compact,
    _fmt_point,
)
from .geometry import cell_measures
from .groups import _renumbered_groups
from .topology import facet_connected_cells


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
    axis slide); otherwise the names found and ``"N other rigid-body mode(s) (...)"``.  A part held
    as a whole but made of pieces joined only at a vertex (or an edge in 3D) that turn about it
    is a mechanism: ``hinges`` holds the nodes where the moving pieces meet the rest (ascending),
    ``hanging_cells`` the cell count of the moving pieces, ``n_free`` the number of motions and
    ``modes`` is empty.
    """

    part: int
    n_parts: int
    n_cells: int
    node: int
    floating: bool
    n_free: int
    modes: tuple
    hinges: tuple = ()
    hanging_cells: int = 0

    def describe(self, mesh: Mesh) -> str:
        """One phrase: which part, and what is loose (for error messages)."""
        at = f"node {self.node} at {_fmt_point(mesh.points[self.node])}"
        if self.n_cells == 0:
            return f"{at} belongs to no cell and is not fixed in every axis"
        what = (f"part {self.part + 1} of {self.n_parts} ({self.n_cells} {mesh.cell_type} cells, {at})"
                if self.n_parts > 1 else f"the mesh ({self.n_cells} {mesh.cell_type} cells, {at})")
        if self.floating:
            return f"{what} is floating: none of its dofs is fixed"
        if self.hinges:
            facet = "face" if mesh.dim == 3 else "edge"
            return (f"{what} is a mechanism: {self.hanging_cells} {mesh.cell_type} cell(s) hang on the rest only at "
                    f"{_hinge_text(mesh, self.hinges)}, a hinge (the cells there share no {facet}), and can turn "
                    f"about it ({self.n_free} free mode(s)); join them through a shared {facet} or hold the "
                    f"hanging cells too")
        return f"{what} has {self.n_free} free rigid-body mode(s): {', '.join(self.modes)}"


def _hinge_text(mesh: Mesh, nodes) -> str:
    shown = [f"{int(i)} at {_fmt_point(mesh.points[i])}" for i in nodes[:3]]
    if len(nodes) == 1:
        return f"node {shown[0]}"
    if len(nodes) == 2:
        return f"the edge from node {shown[0]} to node {shown[1]}"
    more = f" and {len(nodes) - 3} more" if len(nodes) > 3 else ""
    return f"nodes {', '.join(shown)}{more}"


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
    no cell uses is a part of its own, loose unless all its dofs are fixed.  A part that its fixed
    dofs hold as a whole is also checked for hinges (:func:`_mechanism`): its pieces of cells joined
    through whole facets (:func:`msslib.mesh.topology.facet_connected_cells`), each taken as a rigid body
    moving with its shared nodes and held by its own fixed dofs, must not be able to move; two
    cubes sharing one corner, one clamped, turn about the corner.  Returns the loose parts in part
    order (empty: every part is held).
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
            hinge = _mechanism(mesh, fixed, cell_part == p, rtol)
            if hinge is not None:
                out.append(LoosePart(p, n_parts, int(n_cells[p]), node, False, hinge[0], (), hinge[1], hinge[2]))
            continue
        null = vt[rank:].T
        out.append(LoosePart(p, n_parts, int(n_cells[p]), node, False, n_modes - rank,
                             _name_free_modes(null, dim, center, scale)))
    return out


#: above this many pieces joined at hinges in one part, :func:`_mechanism` does not look (a dense
#: analysis of 6 rigid-body modes per piece)
MAX_HINGED_PIECES = 400


def _orthonormal_rows(a: np.ndarray, rtol: float) -> np.ndarray:
    """An orthonormal basis (rows) of the row space of ``a``."""
    if a.size == 0:
        return np.zeros((0, a.shape[1]))
    _, s, vt = np.linalg.svd(np.linalg.qr(a, mode="r"), full_matrices=False)
    rank = int(np.sum(s > rtol * s.max())) if s.size and s.max() > 0 else 0
    return vt[:rank]


def _mechanism(mesh: Mesh, fixed: np.ndarray, in_part: np.ndarray, rtol: float):
    """Whether the cells ``in_part`` (one connected part, held as one rigid body by its fixed dofs)
    are a mechanism: pieces joined through whole facets (:func:`facet_connected_cells`) taken as
    rigid bodies, joined to each other at their shared nodes (same velocity there) and held by
    their own fixed dofs; a motion of the pieces that meets these conditions is a mechanism.

    Returns None, or ``(n_free, hinge_nodes, hanging_cells)``: the number of independent motions,
    the shared nodes of the pieces that move (ascending) and the number of cells of those pieces.
    """
    cells = np.flatnonzero(in_part)
    sub = Mesh(mesh.points, mesh.cells[cells], mesh.cell_type)
    n_pieces, piece = facet_connected_cells(sub)
    if n_pieces < 2 or n_pieces > MAX_HINGED_PIECES:
        return None
    dim = mesh.dim
    n_modes = 3 if dim == 2 else 6
    node_piece = np.unique(np.stack([sub.cells.ravel(), np.repeat(piece, sub.nodes_per_cell)], axis=1), axis=0)
    by_piece = node_piece[np.lexsort((node_piece[:, 0], node_piece[:, 1]))]
    nodes_of = np.split(by_piece[:, 0], np.searchsorted(by_piece[:, 1], np.arange(1, n_pieces)))
    frames = []
    rows = []
    for k, nodes in enumerate(nodes_of):
        x = mesh.points[nodes]
        frames.append((x.mean(axis=0), _bbox_diagonal(x) or 1.0))
        held = _orthonormal_rows(_rigid_modes(x, *frames[k])[fixed[nodes]], rtol)
        block = np.zeros((len(held), n_pieces * n_modes))
        block[:, k * n_modes:(k + 1) * n_modes] = held
        rows.append(block)
    shared_nodes, first, counts = np.unique(node_piece[:, 0], return_index=True, return_counts=True)
    for node, start, count in zip(shared_nodes[counts > 1], first[counts > 1], counts[counts > 1]):
        pieces = node_piece[start:start + count, 1]
        x = mesh.points[node][None, :]
        ref = _rigid_modes(x, *frames[pieces[0]])[0]  # (dim, n_modes)
        for k in pieces[1:]:
            block = np.zeros((dim, n_pieces * n_modes))
            block[:, pieces[0] * n_modes:(pieces[0] + 1) * n_modes] = ref
            block[:, k * n_modes:(k + 1) * n_modes] = -_rigid_modes(x, *frames[k])[0]
            rows.append(block)
    a = np.vstack(rows)
    _, s, vt = np.linalg.svd(a, full_matrices=True)
    rank = int(np.sum(s > rtol * s.max())) if s.size and s.max() > 0 else 0
    if rank == a.shape[1]:
        return None
    null = vt[rank:].reshape(-1, n_pieces, n_modes)
    moving = np.flatnonzero(np.abs(null).max(axis=(0, 2)) > 1e-6)
    on_moving = np.isin(node_piece[:, 1], moving)
    hinge_nodes = np.intersect1d(shared_nodes[counts > 1], node_piece[on_moving, 0])
    return a.shape[1] - rank, tuple(int(i) for i in hinge_nodes), int(np.isin(piece, moving).sum())


def cell_shapes(mesh: Mesh) -> tuple[np.ndarray, np.ndarray | None]:
    """The shape of each cell: ``(aspect, angle)``.

    ``aspect`` is the longest edge over the smallest height, the height over a facet being the
    cell's measure over the facet's (simplices: ``dim`` times it): 1 for a square or a cube, 1.15
    for an equilateral triangle, 1.22 for a regular tetrahedron, ``1 / sin(a)`` for a needle of
    apex angle ``a`` and about ``2 / a`` for a flat triangle of base angles ``a``; infinite for a
    cell of zero measure.  ``angle`` is the smallest angle of each triangle in degrees (None for
    other cells).  A sliver has a large aspect ratio: its stiffness across the short side dwarfs
    that of its neighbours.
    """
    x = mesh.points[mesh.cells]
    edges = x[:, LOCAL_EDGES[mesh.cell_type][:, 1]] - x[:, LOCAL_EDGES[mesh.cell_type][:, 0]]
    longest = np.linalg.norm(edges, axis=2).max(axis=1, initial=0.0)
    largest = np.zeros(len(x))
    for local in _cells.get(mesh.cell_type).facets_by_type().values():
        facets = x[:, local]  # (m, n_facets, nodes per facet, dim)
        if mesh.dim == 2:
            facet = np.linalg.norm(facets[:, :, 1] - facets[:, :, 0], axis=2)
        elif facets.shape[2] == 3:
            facet = 0.5 * np.linalg.norm(np.cross(facets[:, :, 1] - facets[:, :, 0],
                                                  facets[:, :, 2] - facets[:, :, 0]), axis=2)
        else:
            facet = 0.5 * np.linalg.norm(np.cross(facets[:, :, 2] - facets[:, :, 0],
                                                  facets[:, :, 3] - facets[:, :, 1]), axis=2)
        largest = np.maximum(largest, facet.max(axis=1, initial=0.0))
    simplex = _cells.get(mesh.cell_type).simplex
    measure = np.abs(cell_measures(mesh)) * (mesh.dim if simplex else 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        aspect = np.where(measure > 0, longest * largest / measure, np.inf)
    if mesh.cell_type != "triangle":
        return aspect, None
    angles = []
    for k in range(3):
        a, b = x[:, (k + 1) % 3] - x[:, k], x[:, (k + 2) % 3] - x[:, k]
        cross = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        angles.append(np.degrees(np.arctan2(cross, np.einsum("ij,ij->i", a, b))))
    return aspect, np.min(angles, axis=0)

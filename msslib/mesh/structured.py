"""Structured meshes generated without gmsh: :func:`quad_grid`, :func:`triangle_grid_right`,
:func:`triangle_grid_equilateral` (with :func:`equilateral_rows`), :func:`hexagon_equilateral`,
:func:`wedge_grid`,
:func:`hex_grid`, :func:`tet_grid` and :func:`l_block_hex`.  All lengths in metres.

The L-shaped block (:func:`l_block_hex`, and :func:`msslib.mesh.l_block_tet` meshed by gmsh) of
edge ``size`` ``s`` is the cube ``[0, s]^3`` from which the quadrant ``x > s/2, z > s/2`` is
removed: its cross-section in the x-z plane is an "L" (three squares of side ``s/2``), extruded
over ``0 <= y <= s``.  Its volume is ``3 s^3 / 4``.
"""

from __future__ import annotations

import numpy as np

from .core import _HEX_REF01, Mesh, _compact, _positive_int, _positive_length
from .geometry import orient


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


def wedge_grid(lx: float, ly: float, lz: float, nx: int, ny: int, nz: int, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """Box of :func:`hex_grid` with each cube split into two wedges (triangular prisms) along the
    diagonal of its bottom face from corner 0 to corner 2, their triangles in planes z = const.

    Same nodes as :func:`hex_grid`; ``2 * nx * ny * nz`` positively oriented wedges (VTK order:
    the triangle of nodes 0-2 below, its normal pointing down, out of the cell), the two halves of
    a cube numbered consecutively.
    """
    hexes = hex_grid(lx, ly, lz, nx, ny, nz, origin)
    c = hexes.cells
    halves = np.stack([c[:, [0, 2, 1, 4, 6, 5]], c[:, [0, 3, 2, 4, 7, 6]]], axis=1)
    return Mesh(hexes.points, halves.reshape(-1, 6), "wedge")


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

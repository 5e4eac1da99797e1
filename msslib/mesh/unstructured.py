"""Unstructured meshes generated with gmsh: :func:`polygon_mesh`, :func:`cylinder_mesh`,
:func:`cylinder_with_hole_mesh`, :func:`cone_mesh` and :func:`l_block_tet`.

Element sizes are at most ``h``, refined to about 12 elements per full circle on curved
boundaries but not below ``h / 8``; gmsh runs single-threaded with a fixed random ``seed``, so a
call is reproducible; the mesh keeps only the nodes its cells use and its simplices are
positively oriented.  gmsh is imported when a mesh is generated, not with this module.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager

import numpy as np

from .core import CELL_TYPES, Mesh, _compact, _positive_length
from .geometry import orient

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

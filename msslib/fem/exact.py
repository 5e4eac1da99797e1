"""Closed-form linear-elastic solutions under pressure, their meshes and the error of a solution
against them: the verification problems of the pressure loads.

* :func:`cylinder_displacement`: the thick-walled cylinder (Lame) in plane strain, inner radius
  ``a``, outer ``b``, internal pressure ``p``:
  ``u_r = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r)``.
* :func:`sphere_displacement`: the thick-walled sphere under internal pressure:
  ``u_r = p a^3 / (E (b^3 - a^3)) ((1 - 2 nu) r + (1 + nu) b^3 / (2 r^2))``.

Both are modelled on a symmetric part: :func:`quarter_annulus` (a mapped structured grid of
triangles or quads, ``n`` cells through the wall and ``2 n`` around) and :func:`sphere_octant`
(gmsh tetrahedra of size ``h``), each with its normal displacements held on the symmetry planes
(:func:`symmetry_supports`) and the pressure on the inner wall (:func:`inner_wall`).  Their curved
walls are approximated by straight facets whose nodes lie on the circle or sphere, an ``O(h^2)``
approximation of the boundary which caps quadratic elements at order 2 in L2; with
``curved=curved_walls(mesh, a, b)`` (:func:`curved_walls`) the FEM solves place the quadratic
elements' mid-side nodes of both walls on the circles or spheres (isoparametric elements,
boundary to ``O(h^3)``) and the quadratic element converges at order 3.
"""

from __future__ import annotations

import numpy as np

from msslib.mesh import Mesh, boundary_facets, orient, quad_grid, triangle_grid_right


def cylinder_displacement(X, a: float, b: float, p: float, E: float, nu: float) -> np.ndarray:
    """Plane-strain displacement ``(..., 2)`` of the thick-walled cylinder at points ``X (..., 2)``."""
    X = np.asarray(X, dtype=float)
    r = np.linalg.norm(X, axis=-1)
    ur = (1 + nu) * p * a**2 / (E * (b**2 - a**2)) * ((1 - 2 * nu) * r + b**2 / r)
    return X * (ur / r)[..., None]


def sphere_displacement(X, a: float, b: float, p: float, E: float, nu: float) -> np.ndarray:
    """Displacement ``(..., 3)`` of the thick-walled sphere at points ``X (..., 3)``."""
    X = np.asarray(X, dtype=float)
    r = np.linalg.norm(X, axis=-1)
    ur = p * a**3 / (E * (b**3 - a**3)) * ((1 - 2 * nu) * r + (1 + nu) * b**3 / (2 * r**2))
    return X * (ur / r)[..., None]


def quarter_annulus(a: float, b: float, n: int, cell_type: str = "triangle") -> Mesh:
    """The quarter ``a <= r <= b``, ``x, y >= 0``: a structured grid of ``n`` cells through the wall
    and ``2 n`` around, mapped to polar coordinates (``"triangle"``: each quad halved)."""
    if cell_type not in ("triangle", "quad"):
        raise ValueError(f"cell_type must be 'triangle' or 'quad', got {cell_type!r}")
    base = (triangle_grid_right if cell_type == "triangle" else quad_grid)(1.0, 1.0, n, 2 * n)
    s, t = base.points.T
    r, theta = a + (b - a) * s, 0.5 * np.pi * t
    return orient(Mesh(np.column_stack([r * np.cos(theta), r * np.sin(theta)]), base.cells, base.cell_type))


def sphere_octant(a: float, b: float, h: float, seed: int = 0) -> Mesh:
    """The octant ``a <= |x| <= b``, ``x, y, z >= 0`` in tetrahedra of size ``h`` (gmsh, one
    thread, fixed ``seed``: reproducible)."""
    import gmsh

    if gmsh.isInitialized():
        raise RuntimeError("gmsh is already initialised by other code; finalise it before calling sphere_octant")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        for key, value in (("General.Terminal", 0), ("General.Verbosity", 0), ("General.NumThreads", 1),
                           ("Mesh.MaxNumThreads3D", 1), ("Mesh.RandomSeed", int(seed)), ("Mesh.MeshSizeMin", h),
                           ("Mesh.MeshSizeMax", h)):
            gmsh.option.setNumber(key, value)
        occ = gmsh.model.occ
        shell, _ = occ.cut([(3, occ.addSphere(0, 0, 0, b))], [(3, occ.addSphere(0, 0, 0, a))])
        occ.intersect(shell, [(3, occ.addBox(0, 0, 0, b, b, b))])
        occ.synchronize()
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, conn = gmsh.model.mesh.getElementsByType(4)
    finally:
        gmsh.finalize()
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[np.asarray(tags, dtype=np.int64)] = np.arange(len(tags))
    cells = index[np.asarray(conn, dtype=np.int64).reshape(-1, 4)]
    used, cells = np.unique(cells, return_inverse=True)
    points = np.asarray(xyz, dtype=float).reshape(-1, 3)[used]
    return orient(Mesh(points, cells.reshape(-1, 4), "tetra"))


def inner_wall(mesh: Mesh, a: float) -> np.ndarray:
    """The outward boundary facets of ``mesh`` whose nodes all lie at radius ``a``."""
    bf = boundary_facets(mesh)
    return bf[np.isclose(np.linalg.norm(mesh.points[bf], axis=-1), a, rtol=1e-9).all(axis=1)]


def onto_radius(radius: float):
    """The function ``X (k, dim) -> X radius / |X|``: the closest point of the circle or sphere of
    ``radius`` about the origin (a ``project`` of the FEM solves' ``curved``)."""
    def project(X):
        X = np.asarray(X, dtype=float)
        return X * (radius / np.linalg.norm(X, axis=-1))[..., None]
    return project


def curved_walls(mesh: Mesh, a: float, b: float) -> list:
    """``curved`` of the FEM solves for the walls at radii ``a`` and ``b``: their boundary facets
    (:func:`inner_wall`) with :func:`onto_radius` of each."""
    return [(inner_wall(mesh, r), onto_radius(r)) for r in (a, b)]


def symmetry_supports(mesh: Mesh) -> np.ndarray:
    """``fixed (n_nodes, dim)``: the displacement normal to each coordinate plane held on it."""
    return np.isclose(mesh.points, 0.0, rtol=0.0, atol=1e-12 * np.abs(mesh.points).max())


def l2_error(result, mesh: Mesh, order: int, exact, curved=()) -> float:
    """``||u_h - u|| / ||u||`` in L2 over the mesh of the FEM ``result`` (its every dof, element
    ``order``, the ``curved`` facets it was solved with) against ``exact(X)`` at the quadrature
    points of the stiffness."""
    from msslib.fem.space import _Geometry

    geo = _Geometry(mesh, order, curved=curved)
    uh = np.einsum("amq,ami->mqi", geo.phi, result.dof_displacement[geo.nodes])
    X = np.moveaxis(np.asarray(geo.basis.mapping.F(geo.basis.quadrature[0])), 0, -1)
    u = exact(X)
    return float(np.sqrt(np.sum(np.sum((uh - u) ** 2, axis=-1) * geo.dx) / np.sum(np.sum(u**2, axis=-1) * geo.dx)))


def max_nodal_error(result, mesh: Mesh, exact) -> float:
    """``max |u_h - u| / max |u|`` over the mesh's nodes (components)."""
    u = exact(mesh.points)
    return float(np.abs(result.displacement - u).max() / np.abs(u).max())

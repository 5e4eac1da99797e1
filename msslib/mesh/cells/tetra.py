"""The 4-node tetrahedron (P1): positively oriented (``det[p1-p0, p2-p0, p3-p0] > 0``), refined
into 8: four corner tetrahedra and the inner octahedron cut along its shortest diagonal (the
"red" refinement)."""

from __future__ import annotations

import numpy as np

from msslib.mesh.cells import CellType, FemElement, Refinement, simplex_gradients

RANK = 30


def _volume(x: np.ndarray) -> np.ndarray:
    return np.linalg.det(x[:, 1:] - x[:, :1]) / 6.0


def _refinement() -> Refinement:
    virtual = ((0,), (1,), (2,), (3,), (0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
    corner = [[0, 4, 5, 6], [4, 1, 7, 8], [5, 7, 2, 9], [6, 8, 9, 3]]
    # the inner octahedron, cut along one of its three diagonals (a, b); the other two pairs of
    # opposite vertices (c, c2), (e, e2) form the ring c, e, c2, e2 around it
    variants = []
    for (a, b), (c, c2), (e, e2) in (((4, 9), (5, 8), (6, 7)), ((5, 8), (4, 9), (6, 7)), ((6, 7), (4, 9), (5, 8))):
        variants.append(np.array(corner + [[a, b, c, e], [a, b, e, c2], [a, b, c2, e2], [a, b, e2, c]]))
    return Refinement(virtual, tuple(variants), diagonals=np.array([[4, 9], [5, 8], [6, 7]]), reorient=(0, 1, 3, 2))


CELL = CellType(
    name="tetra", dim=3, plural="tetrahedra", description="4-node tetrahedron",
    reference=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
    edges=[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
    faces=[[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]],  # right-hand-rule normals point out
    flip=(0, 2, 1, 3),
    measure=_volume,
    gradients=simplex_gradients(3),
    sample_points=[[0.25, 0.25, 0.25]],  # det J is constant
    refinement=_refinement(),
    linear=FemElement("MeshTet1", "ElementTetP1", "P1 tetrahedra", intorder=1),
    quadratic=FemElement("MeshTet1", "ElementTetP2", "P2 tetrahedra", intorder=2, reduced_intorder=1),
    vtk_id=10, meshio="tetra", sofa="tetrahedra", volume_shape="tetrahedron", simplex=True,
    example=("tet_grid", {"lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}),
    generators=("l_block_tet", "cylinder_mesh", "cylinder_with_hole_mesh", "cone_mesh"),
)

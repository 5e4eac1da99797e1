"""The 3-node triangle (P1): counter-clockwise nodes, refined into 4 by its edge midpoints."""

from __future__ import annotations

import numpy as np

from msslib.mesh.cells import CellType, FemElement, Refinement, simplex_gradients

RANK = 10


def _area(x: np.ndarray) -> np.ndarray:
    a, b = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


CELL = CellType(
    name="triangle", dim=2, plural="triangles", description="3-node triangle",
    reference=[[0, 0], [1, 0], [0, 1]],
    edges=[[0, 1], [1, 2], [2, 0]],
    faces=[[0, 1], [1, 2], [2, 0]],  # the cell on the left of each edge
    flip=(0, 2, 1),
    measure=_area,
    gradients=simplex_gradients(2),
    sample_points=[[1.0 / 3.0, 1.0 / 3.0]],  # det J is constant
    refinement=Refinement(((0,), (1,), (2,), (0, 1), (1, 2), (0, 2)),
                          np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]]), reorient=(0, 2, 1)),
    linear=FemElement("MeshTri1", "ElementTriP1", "P1 triangles", intorder=1),
    quadratic=FemElement("MeshTri1", "ElementTriP2", "P2 triangles", intorder=2, reduced_intorder=1),
    vtk_id=5, meshio="triangle", sofa="triangles", simplex=True,
    example=("triangle_grid_equilateral", {"width": 3.0, "height": 2.0, "n": 3}),
    generators=("triangle_grid_right", "hexagon_equilateral", "polygon_mesh"),
)

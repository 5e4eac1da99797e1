"""The 4-node quadrilateral (Q1): counter-clockwise nodes, refined into 4 by its edge midpoints and
centre."""

from __future__ import annotations

import numpy as np

from msslib.mesh.cells import CellType, FemElement, lattice_refinement, tensor_gradients

RANK = 20

_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)


def _area(x: np.ndarray) -> np.ndarray:
    """Exact area of the bilinear quad (shoelace formula)."""
    d1, d2 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


CELL = CellType(
    name="quad", dim=2, plural="quads", description="4-node quadrilateral",
    reference=_CORNERS,
    edges=[[0, 1], [1, 2], [2, 3], [3, 0]],
    faces=[[0, 1], [1, 2], [2, 3], [3, 0]],
    flip=(0, 3, 2, 1),
    measure=_area,
    gradients=tensor_gradients(_CORNERS),
    sample_points=_CORNERS,  # det J is linear in each coordinate: its minimum lies at a corner
    refinement=lattice_refinement((_CORNERS + 1) / 2),
    linear=FemElement("MeshQuad1", "ElementQuad1", "Q1 quadrilaterals with full 2x2 integration", intorder=2),
    quadratic=FemElement("MeshQuad1", "ElementQuad2", "Q2 quadrilaterals", intorder=4, reduced_intorder=3),
    vtk_id=9, meshio="quad", sofa="quads",
    face_diagonals=[[0, 2], [1, 3]],
    example=("quad_grid", {"lx": 3.0, "ly": 2.0, "nx": 3, "ny": 2}),
)

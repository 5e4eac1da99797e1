"""The 6-node wedge (triangular prism): nodes 0-2 a triangle whose right-hand-rule normal points
out of the cell (away from the other triangle, VTK's order), 3-5 the opposite triangle, node
``i + 3`` across from node ``i``; two triangular and three quadrilateral faces.

Reference cell: the triangle ``xi, eta >= 0, xi + eta <= 1`` times ``0 <= zeta <= 1`` (volume
1/2), node 0 at the origin, node 1 at ``eta = 1``, node 2 at ``xi = 1`` (so that the reference cell
itself is positively oriented in VTK's order); shape functions ``N_i = L_i (1 - zeta)``,
``N_{i+3} = L_i zeta`` with the triangle's barycentric coordinates ``L = (1 - xi - eta, eta, xi)``.

``det J`` is of degree 1 in ``(xi, eta)`` and 2 in ``zeta``: the measure integrates it exactly
with 1 x 2 points.  Linear FEM (scikit-fem's ``ElementWedge1``) uses a rule of its own, 3 points
on the triangle (degree 2) times 2 Gauss points across (degree 3), weights summing to the
reference volume 1/2: exact for the stiffness of a right prism (scikit-fem 12.0.2's own wedge rule
has weights summing to 1/4, half the volume).  scikit-fem has no quadratic wedge: no quadratic
reference on wedge meshes.

Refinement: each triangle into 4 (edge midpoints), the height into 2 (midpoints of the three
edges across, centres of the three quadrilateral faces): 8 children, orientation kept.
"""

from __future__ import annotations

import numpy as np

from msslib.mesh.cells import CellType, FemElement, Refinement, measure_by_quadrature

RANK = 50

_REFERENCE = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1], [0, 1, 1], [1, 0, 1]], dtype=float)


def _gradients(points) -> np.ndarray:
    points = np.asarray(points, dtype=float)
    xi, eta, zeta = points[:, 0], points[:, 1], points[:, 2]
    L = np.stack([1.0 - xi - eta, eta, xi], axis=1)  # (p, 3)
    dL = np.array([[-1.0, -1.0], [0.0, 1.0], [1.0, 0.0]])  # dL_i / d(xi, eta)
    grad = np.empty((len(points), 6, 3))
    for i in range(3):
        for k, (w, dw) in enumerate(((1.0 - zeta, -1.0), (zeta, 1.0))):
            grad[:, i + 3 * k, 0] = dL[i, 0] * w
            grad[:, i + 3 * k, 1] = dL[i, 1] * w
            grad[:, i + 3 * k, 2] = L[:, i] * dw
    return grad


_G = 0.5 / np.sqrt(3.0)  # Gauss points 1/2 -+ _G on [0, 1]
#: det J exactly: the centroid of the triangle (degree 1) times 2 Gauss points across (degree 3)
_MEASURE_POINTS = np.array([[1 / 3, 1 / 3, 0.5 - _G], [1 / 3, 1 / 3, 0.5 + _G]])
_MEASURE_WEIGHTS = np.array([0.25, 0.25])


def _rule():
    """3 points on the triangle (exact to degree 2, weights 1/6) times 2 Gauss points on [0, 1]
    (exact to degree 3, weights 1/2), in scikit-fem's reference wedge (the same triangle times
    ``[0, 1]``): ``(points (3, 6), weights (6,))``, weights summing to 1/2."""
    tri = np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]])
    across = np.array([0.5 - _G, 0.5 + _G])
    points = np.array([[x, y, z] for z in across for x, y in tri])
    return points.T, np.full(len(points), 1.0 / 12.0)


QUADRATURE = _rule()

def _refinement() -> Refinement:
    # corners, the midpoints of the edges of the two triangles and across, the centres of the sides
    virtual = ((0,), (1,), (2,), (3,), (4,), (5,), (0, 1), (1, 2), (0, 2), (3, 4), (4, 5), (3, 5), (0, 3), (1, 4),
               (2, 5), (0, 1, 3, 4), (1, 2, 4, 5), (0, 2, 3, 5))
    # three layers of 6 nodes: corners i = 0, 1, 2 and midpoints of the edges 01, 12, 02 of a triangle
    low, middle, high = (0, 1, 2, 6, 7, 8), (12, 13, 14, 15, 16, 17), (3, 4, 5, 9, 10, 11)
    triangle = ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))  # the children of a triangle, orientation kept
    children = [[below[i] for i in t] + [above[i] for i in t] for below, above in ((low, middle), (middle, high))
                for t in triangle]
    return Refinement(virtual, np.array(children))


_SIDES = [[0, 3, 4, 1], [1, 4, 5, 2], [2, 5, 3, 0]]  # the quadrilateral faces, normals out

CELL = CellType(
    name="wedge", dim=3, plural="wedges", description="6-node wedge (triangular prism)",
    reference=_REFERENCE,
    edges=[[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3], [0, 3], [1, 4], [2, 5]],
    faces=[[0, 1, 2], [3, 5, 4], *_SIDES],  # right-hand-rule normals point out
    flip=(0, 2, 1, 3, 5, 4),
    measure=measure_by_quadrature(_gradients, _MEASURE_POINTS, _MEASURE_WEIGHTS),
    gradients=_gradients,
    # det J is quadratic across: the corners alone do not bound it, the centre is added
    sample_points=np.vstack([_REFERENCE, [[1 / 3, 1 / 3, 0.5]]]),
    refinement=_refinement(),
    linear=FemElement("MeshWedge1", "ElementWedge1", "linear wedges (6-point rule of their own)",
                      intorder=None, rule=QUADRATURE, vtk_to_skfem=(0, 2, 1, 3, 5, 4)),
    quadratic=None,
    vtk_id=13, meshio="wedge", volume_shape="wedge",
    face_diagonals=np.array(_SIDES)[:, [[0, 2], [1, 3]]].reshape(-1, 2),
    example=("wedge_grid", {"lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}),
)

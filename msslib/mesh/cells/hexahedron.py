"""The 8-node hexahedron (Q1): nodes 0-3 the bottom face counter-clockwise seen from above, 4-7
the top face, node ``i + 4`` above node ``i``; refined into 8 by its edge midpoints, face centres
and centre."""

from __future__ import annotations

import numpy as np

from msslib.mesh.cells import CellType, FemElement, lattice_refinement, tensor_gradients

RANK = 40

_CORNERS = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
    dtype=float,
)
_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


def _volume(x: np.ndarray) -> np.ndarray:
    """Exact volume of trilinear hexahedra (det J is of degree <= 2 per variable: 2^3 Gauss)."""
    g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    gp = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T  # (8, 3)
    s = _CORNERS  # (8 nodes, 3)
    # dN[g, a, d] = d N_a / d xi_d at Gauss point g
    f = 1.0 + gp[:, None, :] * s[None, :, :]  # (8 gp, 8 nodes, 3)
    dn = np.empty((len(gp), 8, 3))
    dn[..., 0] = s[:, 0] * f[..., 1] * f[..., 2]
    dn[..., 1] = s[:, 1] * f[..., 0] * f[..., 2]
    dn[..., 2] = s[:, 2] * f[..., 0] * f[..., 1]
    dn /= 8.0
    jac = np.einsum("cai,gad->cgid", x, dn)  # (cells, gp, 3, 3)
    return np.linalg.det(jac).sum(axis=1)


CELL = CellType(
    name="hexahedron", dim=3, plural="hexahedra", description="8-node hexahedron",
    reference=_CORNERS,
    edges=[[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4], [0, 4], [1, 5], [2, 6], [3, 7]],
    faces=_FACES,  # right-hand-rule normals point out
    flip=(4, 5, 6, 7, 0, 1, 2, 3),
    measure=_volume,
    gradients=tensor_gradients(_CORNERS),
    # det J is quadratic in each coordinate: the corners alone do not bound it, the centre is added
    sample_points=np.vstack([_CORNERS, np.zeros((1, 3))]),
    refinement=lattice_refinement((_CORNERS + 1) / 2),
    linear=FemElement("MeshHex1", "ElementHex1", "Q1 hexahedra with full 2x2x2 integration", intorder=2,
                      vtk_to_skfem=(0, 4, 3, 1, 7, 5, 2, 6)),
    quadratic=FemElement("MeshHex1", "ElementHex2", "Q2 hexahedra", intorder=4, reduced_intorder=3,
                         vtk_to_skfem=(0, 4, 3, 1, 7, 5, 2, 6)),
    vtk_id=12, meshio="hexahedron", sofa="hexahedra", volume_shape="hexahedron",
    face_diagonals=np.array(_FACES)[:, [[0, 2], [1, 3]]].reshape(-1, 2),
    inner_diagonals=[[0, 6], [1, 7], [2, 4], [3, 5]],
    example=("hex_grid", {"lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}),
    generators=("l_block_hex",),
)

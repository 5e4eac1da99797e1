"""Write experiments/lloyd/meshes/cylinder91.msh, a tetrahedral cylinder with the 91 nodes of Lloyd et
al.'s Sec. 5.6 mesh (run by hand after a change; not part of the workflow).

The paper's cylinder has 91 nodes and 274 tetrahedra; gmsh does not mesh a cylinder of radius 1 cm
and height 2 cm that coarsely (its coarsest meshes have 87 and 106 nodes, whatever the element size
and the number of elements per circle). 91 nodes are 7 equally spaced layers of a regular 12-gon of
radius 1 cm with its centre, the 12-gons of successive layers turned by half a side (15 degrees), so
that the Delaunay tetrahedralisation of the points (scipy) is unique; it has 348 tetrahedra, not 274:
the paper's count is not reached by this construction either, and its mesh is not printed.

    python -m experiments.lloyd.meshes.make_cylinder91
"""

from pathlib import Path

import numpy as np

RADIUS, HEIGHT, LAYERS, SIDES = 0.01, 0.02, 7, 12
OUT = Path(__file__).resolve().parent / "cylinder91.msh"


def cylinder91():
    """Points (91, 3) and positively oriented tetrahedra (m, 4)."""
    from scipy.spatial import Delaunay

    pts = []
    for k in range(LAYERS):
        z = HEIGHT * k / (LAYERS - 1)
        pts.append([0.0, 0.0, z])
        a = 2 * np.pi * np.arange(SIDES) / SIDES + (np.pi / SIDES if k % 2 else 0.0)
        pts.extend(np.column_stack([RADIUS * np.cos(a), RADIUS * np.sin(a), np.full(SIDES, z)]).tolist())
    points = np.array(pts)
    cells = Delaunay(points).simplices.astype(np.int64)
    X = points[cells]
    vol = np.einsum("ij,ij->i", np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), X[:, 3] - X[:, 0])
    cells[vol < 0] = cells[vol < 0][:, [0, 2, 1, 3]]
    return points, cells


def main():
    import meshio

    points, cells = cylinder91()
    meshio.write(OUT, meshio.Mesh(points, [("tetra", cells)]), file_format="gmsh22", binary=False)
    print(f"{len(points)} nodes, {len(cells)} tetrahedra; written {OUT}")


if __name__ == "__main__":
    main()

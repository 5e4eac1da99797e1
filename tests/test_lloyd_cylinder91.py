"""The 91-node cylinder of Lloyd's Sec. 5.6 (experiments/lloyd/meshes/make_cylinder91.py): the
paper's node count, the cylinder's volume within the 12-gon's, every tetrahedron positive, the base
and top faces where the experiment's supports and tractions select them, and the mesh file written
from it is the one the study reads."""

import numpy as np
import pytest

from experiments.lloyd.meshes.make_cylinder91 import HEIGHT, OUT, RADIUS, SIDES, cylinder91
from msslib.mesh.files import read as read_mesh


def volumes(points, cells):
    X = points[cells]
    return np.einsum("ij,ij->i", np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]), X[:, 3] - X[:, 0]) / 6


def test_ninety_one_nodes_positive_cells_and_the_prism_volume():
    points, cells = cylinder91()
    assert len(points) == 91
    v = volumes(points, cells)
    assert v.min() > 0
    # the convex hull of staggered 12-gons: between the 12-gon prism and the circle's cylinder
    polygon = 0.5 * SIDES * RADIUS**2 * np.sin(2 * np.pi / SIDES)
    assert polygon * HEIGHT * 0.95 < v.sum() <= np.pi * RADIUS**2 * HEIGHT
    assert np.sum(np.isclose(points[:, 2], 0.0)) == 13 and np.sum(np.isclose(points[:, 2], HEIGHT)) == 13
    assert np.allclose(np.hypot(points[:, 0], points[:, 1])[np.hypot(points[:, 0], points[:, 1]) > 0], RADIUS)


def test_the_mesh_file_is_the_generated_mesh():
    points, cells = cylinder91()
    m = read_mesh(OUT)
    assert m.n_nodes == len(points) and m.n_cells == len(cells)
    np.testing.assert_allclose(m.points[:, :3], points, atol=1e-15)
    assert volumes(m.points, m.cells).sum() == pytest.approx(volumes(points, cells).sum(), rel=1e-12)

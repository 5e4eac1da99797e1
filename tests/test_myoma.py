"""The synthetic myoma of Lloyd Sec. 5.9 (experiments/lloyd/meshes): the stored mesh is what its
generator writes, and it has the shape the experiment describes (volume, loaded cap, fixed base)."""

import math
from pathlib import Path

import numpy as np
import pytest

from experiments.lloyd.meshes import make_myoma as G
from msslib import mesh as M

HERE = Path(__file__).resolve().parents[1] / "experiments" / "lloyd" / "meshes"

pytest.importorskip("gmsh")


@pytest.fixture(scope="module")
def stored():
    return M.read(HERE / "myoma.msh")


def test_stored_mesh_is_the_generated_one(stored):
    fresh = G.myoma_mesh(G.R, G.C, G.CAP, 0.0046)
    assert (fresh.n_nodes, fresh.n_cells) == (stored.n_nodes, stored.n_cells) == (122, 390)
    assert np.allclose(fresh.points, stored.points, atol=1e-15)
    assert np.array_equal(fresh.cells, stored.cells)
    assert np.all(M.cell_measures(stored) > 0)


def test_volume_is_the_spherical_segment(stored):
    # the part of a ball (radius R, centre C above the plane) above the plane: a segment of height
    # R + C, volume pi H^2 (3 R - H) / 3; the mesh is inscribed in it (flat facets), so it is smaller
    H = G.R + G.C
    exact = math.pi * H ** 2 * (3 * G.R - H) / 3
    vol = M.cell_measures(stored).sum()
    assert 0.93 * exact < vol < exact
    # every node lies in the ball and above the wall; the boundary nodes off the wall lie on the sphere
    r = np.linalg.norm(stored.points - [0.0, 0.0, G.C], axis=1)
    assert np.all(r <= G.R * (1 + 1e-9)) and np.all(stored.points[:, 2] >= -1e-12)
    facets = M.boundary_facets(stored)
    on_wall = np.all(np.abs(stored.points[facets, 2]) < 1e-12, axis=1)
    nodes = np.unique(facets[~on_wall])
    off_wall = nodes[stored.points[nodes, 2] > 1e-12]
    assert np.allclose(r[off_wall], G.R, rtol=1e-6)


def _area(mesh, facets):
    x = mesh.points[facets]
    return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1).sum()


def test_loaded_cap_and_fixed_base(stored):
    facets = M.boundary_facets(stored)
    z = stored.points[facets, 2]
    z_cap = G.C + G.CAP * G.R
    tol = 1e-9
    # the cap's edge is made of mesh edges: no boundary facet has nodes on both sides of z_cap
    assert not np.any((z.min(axis=1) < z_cap - tol) & (z.max(axis=1) > z_cap + tol))
    cap = facets[np.all(z >= z_cap - tol, axis=1)]
    # the cap's area: 2 pi R h for a cap of height h = R - CAP R (the facets are inscribed: smaller)
    exact_cap = 2 * math.pi * G.R * (G.R * (1 - G.CAP))
    assert 0.85 * exact_cap < _area(stored, cap) < exact_cap
    # the fixed base is the disc of radius sqrt(R^2 - C^2) on the wall
    base = facets[np.all(np.abs(z) < tol, axis=1)]
    disc = math.pi * (G.R ** 2 - G.C ** 2)
    assert 0.9 * disc < _area(stored, base) < disc

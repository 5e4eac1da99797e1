"""Smoke tests of msslib.plotting on tiny hand-made result datasets."""

import numpy as np
import pytest

from msslib import mesh as M
from msslib import plotting
from msslib.io import make_dataset


def _result(mesh, u, model="test"):
    return make_dataset(mesh, u, model=model, E=1.0, nu=0.3)


@pytest.fixture
def quad_pair():
    m = M.quad_grid(0.02, 0.02, 2, 2)
    u_ref = np.column_stack([0.1 * m.points[:, 1], 0.05 * m.points[:, 1]])
    u = u_ref.copy()
    u[-1] += [0.001, 0.0]  # one node off by 1 mm
    return _result(m, u, "mss"), _result(m, u_ref, "fem")


@pytest.fixture
def tet_result():
    m = M.tet_grid(0.01, 0.01, 0.02, 1, 1, 2)
    u = np.column_stack([np.zeros(m.n_nodes), 0.1 * m.points[:, 2], 0.05 * m.points[:, 2]])
    return _result(m, u)


def test_node_error_same_mesh(quad_pair):
    var, ref = quad_pair
    err = plotting.node_error(var, ref)
    assert err.shape == (9,)
    assert err[-1] == pytest.approx(0.001)
    assert np.count_nonzero(err) == 1


def test_node_error_interpolates_other_mesh():
    fine = M.quad_grid(0.02, 0.02, 4, 4)
    coarse = M.quad_grid(0.02, 0.02, 2, 2)

    def field(p):  # bilinear: reproduced exactly by the fine mesh's shape functions
        return np.column_stack([0.1 * p[:, 1], 0.02 * p[:, 0]])

    err = plotting.node_error(_result(coarse, field(coarse.points)), _result(fine, field(fine.points)))
    assert np.allclose(err, 0.0, atol=1e-12)


def test_deformed_mesh_2d(quad_pair):
    var, ref = quad_pair
    fig = plotting.figure()
    ax = fig.add_subplot()
    lines = plotting.deformed_mesh(ax, var, color="r")
    assert len(lines.get_segments()) == 12  # unique edges of a 2 x 2 quad grid
    im = plotting.deformed_mesh(ax, ref, color="k", colorby="displacement")
    assert im.get_array().max() == pytest.approx(np.linalg.norm(ref.displacement.values, axis=1).max() * 1e3)
    assert ax.get_xlabel() == "x (cm)" and ax.get_aspect() == 1.0
    with pytest.raises(ValueError):
        plotting.deformed_mesh(ax, var, colorby=np.zeros(3))
    with pytest.raises(ValueError):
        plotting.deformed_mesh(ax, var, length_unit="inch")


def test_deformed_mesh_3d_front_faces(tet_result):
    fig = plotting.figure()
    ax = fig.add_subplot()
    im = plotting.deformed_mesh(ax, tet_result, colorby="displacement", plane="yz", deformed=False)
    # a 1 x 1 x 2 box seen along x: its front face x = 0.01 is 2 squares of 2 triangles
    assert len(im.get_paths()) == 4
    assert ax.get_xlabel() == "y (cm)" and ax.get_ylabel() == "z (cm)"
    with pytest.raises(ValueError):
        plotting.deformed_mesh(ax, tet_result, plane="xx")


def test_error_map_and_save(tmp_path, quad_pair, tet_result):
    var, ref = quad_pair
    fig = plotting.comparison_figure({"a) shear": (var, ref), "b) same": (var, ref)}, plane="xy")
    png, pdf = plotting.save(fig, tmp_path / "sub" / "fig")
    assert png.stat().st_size > 1000 and pdf.stat().st_size > 1000
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == ["fig.pdf", "fig.png"]
    fig = plotting.figure()
    ax = fig.add_subplot()
    em = plotting.error_map(ax, tet_result, tet_result, plane="xz")
    assert em.get_array().max() == 0.0

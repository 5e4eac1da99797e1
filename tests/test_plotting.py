"""Smoke tests of experiments.plotting on tiny hand-made result datasets."""

import numpy as np
import pytest

from msslib import mesh as M
from experiments import plotting
from msslib.results import make_dataset


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


def test_shared_limits():
    a, b = np.array([0.5, 2.0, np.nan]), np.array([[1.0, 3.0]])
    assert plotting.shared_limits(a, b) == (0.5, 3.0)
    assert plotting.shared_limits(a, b, zero=True) == (0.0, 3.0)
    assert plotting.shared_limits(np.array([-1.0, 0.5]), symmetric=True) == (-1.0, 1.0)
    lo, hi = plotting.shared_limits(np.zeros(4), zero=True)  # constant values: still a usable scale
    assert lo == 0.0 and hi > 0.0
    lo, hi = plotting.shared_limits(np.array([np.inf]))
    assert hi > lo


def test_pareto_front_known_points():
    # time, error: (1, 10) (2, 5) (3, 7) (4, 1) (2, 5) (0.5, 20) (5, 1) (nan, 0)
    t = np.array([1.0, 2.0, 3.0, 4.0, 2.0, 0.5, 5.0, np.nan])
    e = np.array([10.0, 5.0, 7.0, 1.0, 5.0, 20.0, 1.0, 0.0])
    front = plotting.pareto_front(t, e)
    # (3, 7) is beaten by (2, 5); (5, 1) by (4, 1); the duplicate (2, 5) is kept once; nan ignored
    assert front.tolist() == [5, 0, 1, 3]
    assert np.all(np.diff(t[front]) > 0) and np.all(np.diff(e[front]) < 0)
    assert plotting.pareto_front([], []).size == 0
    with pytest.raises(ValueError):
        plotting.pareto_front([1.0, 2.0], [1.0])


@pytest.mark.parametrize("lims", [(1e-3, 10.0), (0.002, 0.03), (14.0, 18.0)])
def test_label_log_axis_labels_every_major_tick(lims):
    fig = plotting.figure()
    ax = fig.add_subplot()
    ax.set_yscale("log")
    ax.plot([1, 2], lims)
    ax.set_ylim(*lims)
    plotting.label_log_axis(ax, "y")
    fig.canvas.draw()
    locs = ax.yaxis.get_majorticklocs()
    labels = [t.get_text() for loc, t in zip(locs, ax.get_yticklabels()) if lims[0] <= loc <= lims[1]]
    assert len(labels) >= 2 and all(labels) and len(set(labels)) == len(labels)
    assert not any(t.get_text() for t in ax.get_yticklabels(minor=True))


def test_unique_legend_drops_duplicates_and_unlabelled():
    fig = plotting.figure()
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot([0, 1], color="r", label="MSS")
    ax2.plot([0, 1], color="r", label="MSS")
    ax2.plot([0, 1], color="k", label="FEM")
    ax2.plot([0, 1], color="b")  # no label: no entry
    leg = plotting.unique_legend(fig)
    assert [t.get_text() for t in leg.get_texts()] == ["MSS", "FEM"]
    leg = plotting.unique_legend(ax2)
    assert [t.get_text() for t in leg.get_texts()] == ["MSS", "FEM"]


def test_node_map_front_nodes_and_shared_error_scale(quad_pair, tet_result):
    fig = plotting.figure()
    ax = fig.add_subplot()
    values = np.arange(tet_result.sizes["node"], dtype=float)
    sc = plotting.node_map(ax, tet_result, values, plane="yz", deformed=False, value_scale=1.0)
    X = tet_result["rest_position"].values
    front = np.flatnonzero(np.isclose(X[:, 0], X[:, 0].max()))  # seen from +x: the x = 0.01 face
    assert sorted(sc.get_array().tolist()) == sorted(values[front].tolist())
    with pytest.raises(ValueError):
        plotting.node_map(ax, tet_result, np.zeros(3))
    var, ref = quad_pair
    bigger = var.copy()
    bigger["displacement"] = var["displacement"] + 0.002
    fig = plotting.comparison_figure({"a": (var, ref), "b": (bigger, ref)}, plane="xy", node_errors=True)
    from matplotlib.collections import PathCollection

    maps = [c for ax in fig.axes for c in ax.collections if isinstance(c, PathCollection)]
    assert len(maps) == 2
    assert len({m.norm.vmax for m in maps}) == 1  # one colour scale for the compared panels
    assert maps[0].norm.vmax == pytest.approx(max(m.get_array().max() for m in maps))

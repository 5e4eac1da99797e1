"""``msslib compare`` and msslib.compare: the error of one result against another, on the same mesh
and on other meshes of the same body, and experiments that belong to no paper."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

from msslib.compare import compare_results
from msslib.results import make_dataset, write_result
from msslib.mesh import hex_grid, quad_grid, tet_grid

ROOT = Path(__file__).resolve().parents[1]


def _affine(X):
    """A displacement field that every linear and trilinear element reproduces exactly [m]."""
    A = np.array([[1e-3, 2e-4, 0.0], [0.0, -3e-4, 5e-4], [1e-4, 0.0, 2e-3]])
    return X @ A.T + np.array([1e-5, 0.0, -2e-5])


def _quadratic(X):
    """The affine field plus a bump that vanishes at the box's corners: exactly known error [m]."""
    bump = 1e-3 * X[:, 0] * (0.1 - X[:, 0])
    return _affine(X) + np.column_stack([np.zeros(len(X)), np.zeros(len(X)), bump])


def _result(path, mesh, u, model="test"):
    write_result(path, make_dataset(mesh, u, model=model, E=1e6, nu=0.3))
    return path


def test_same_mesh_equals_the_per_node_distance(tmp_path):
    mesh = hex_grid(0.1, 0.05, 0.05, 4, 2, 2)
    u_ref = _affine(mesh.points)
    u = _quadratic(mesh.points)
    c = compare_results(_result(tmp_path / "a.nc", mesh, u), _result(tmp_path / "r.nc", mesh, u_ref))
    assert c.relation == "same mesh" and c.n_outside == 0
    err = 1e-3 * mesh.points[:, 0] * (0.1 - mesh.points[:, 0])  # |u - u_ref| = the bump, by construction
    scale = np.linalg.norm(u_ref, axis=1).max()
    assert c.error.mean == pytest.approx(err.mean(), rel=1e-12)
    assert c.error.max == pytest.approx(err.max(), rel=1e-12)
    assert c.error.std == pytest.approx(err.std(), rel=1e-12)
    assert c.error.rel_max == pytest.approx(err.max() / scale, rel=1e-12)
    assert c.reference_max == pytest.approx(scale, rel=1e-14)
    # against itself: nothing
    same = compare_results(tmp_path / "r.nc", tmp_path / "r.nc")
    assert same.error.max == 0.0


@pytest.mark.parametrize("coarse, fine", [
    (hex_grid(0.1, 0.05, 0.05, 2, 1, 1), hex_grid(0.1, 0.05, 0.05, 8, 4, 4)),     # nested hexahedra
    (tet_grid(0.1, 0.05, 0.05, 2, 1, 1), hex_grid(0.1, 0.05, 0.05, 6, 3, 3)),     # tetrahedra against hexahedra
    (hex_grid(0.1, 0.05, 0.05, 3, 2, 2), tet_grid(0.1, 0.05, 0.05, 4, 2, 2)),     # not nested
])
def test_other_mesh_uses_the_references_shape_functions(tmp_path, coarse, fine):
    """The reference's field is affine, so its shape functions reproduce it exactly at any point:
    the error at the coarse nodes is exactly the bump of the coarse field."""
    c = compare_results(_result(tmp_path / "coarse.nc", coarse, _quadratic(coarse.points)),
                        _result(tmp_path / "fine.nc", fine, _affine(fine.points)))
    assert c.relation == "interpolated" and c.n_outside == 0
    np.testing.assert_allclose(c.u_ref, _affine(coarse.points), rtol=0, atol=1e-15)
    X = coarse.points
    assert c.error.max == pytest.approx((1e-3 * X[:, 0] * (0.1 - X[:, 0])).max(), rel=1e-9)


def test_points_on_reference_nodes_and_points_located_in_blocks(monkeypatch):
    """Points on reference nodes take the node's value; the others are located a block at a time,
    some inside and some outside the reference, across block boundaries: the affine field is
    reproduced exactly inside and the outside points are flagged."""
    import msslib.compare as cmp

    fine = hex_grid(0.1, 0.05, 0.05, 6, 3, 3)
    u = _affine(fine.points)
    rng = np.random.default_rng(3)
    inner = rng.uniform([0, 0, 0], [0.1, 0.05, 0.05], size=(40, 3))
    outer = np.array([[0.1 + 2e-3, 0.02, 0.02], [0.05, -1e-3, 0.01]])
    points = np.vstack([fine.points[::3], inner[:20], outer[:1], inner[20:], outer[1:]])
    monkeypatch.setattr(cmp, "PROBE_BLOCK", 7)
    values, inside, distance = cmp._interpolate(fine, u, points)
    flagged = np.zeros(len(points), dtype=bool)
    n_nodes = len(fine.points[::3])
    flagged[[n_nodes + 20, len(points) - 1]] = True
    np.testing.assert_array_equal(~inside, flagged)
    np.testing.assert_allclose(values[inside], _affine(points[inside]), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(values[:n_nodes], u[::3])  # on the nodes: the nodes' own values
    nearest = np.linalg.norm(points[flagged][:, None, :] - fine.points[None, :, :], axis=2).min(axis=1)
    assert distance[flagged] == pytest.approx(nearest, rel=1e-12)  # outside: to the nearest reference node


def test_a_curved_boundary_is_counted_and_different_bodies_refused(tmp_path):
    fine = hex_grid(0.1, 0.05, 0.05, 4, 2, 2)
    ref = _result(tmp_path / "fine.nc", fine, _affine(fine.points))
    bulged = hex_grid(0.1, 0.05, 0.05, 2, 1, 1)
    bulged.points[bulged.points[:, 2] > 0.049, 2] += 1e-3  # the top lies 1 mm outside the reference
    c = compare_results(_result(tmp_path / "bulged.nc", bulged, _affine(bulged.points)), ref)
    assert c.n_outside == int((bulged.points[:, 2] > 0.05).sum()) and c.outside_distance == pytest.approx(1e-3)
    assert "outside the reference mesh" in c.table()
    elsewhere = hex_grid(0.1, 0.05, 0.05, 2, 1, 1, origin=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="not meshes of the same body"):
        compare_results(_result(tmp_path / "elsewhere.nc", elsewhere, _affine(elsewhere.points)), ref)
    plate = quad_grid(0.1, 0.05, 2, 1)
    with pytest.raises(ValueError, match="2D .* 3D"):
        compare_results(_result(tmp_path / "plate.nc", plate, np.zeros((plate.n_nodes, 2))), ref)


def _cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "msslib", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=600)


def test_command_line_writes_the_table_and_the_error_field(tmp_path):
    coarse, fine = hex_grid(0.1, 0.05, 0.05, 2, 1, 1), hex_grid(0.1, 0.05, 0.05, 4, 2, 2)
    _result(tmp_path / "coarse.nc", coarse, _quadratic(coarse.points))
    _result(tmp_path / "fine.nc", fine, _affine(fine.points))
    run = _cli("compare", "coarse.nc", "fine.nc", "--out", "error.md", "--vtu", "error.vtu", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    table = (tmp_path / "error.md").read_text()
    assert table == run.stdout and "| max |" in table and "shape functions" in table
    vtu = meshio.read(tmp_path / "error.vtu")
    bump = 1e-3 * coarse.points[:, 0] * (0.1 - coarse.points[:, 0])
    np.testing.assert_allclose(vtu.point_data["error_magnitude"], bump, rtol=1e-9, atol=1e-18)
    np.testing.assert_allclose(vtu.point_data["reference_displacement"], _affine(coarse.points), atol=1e-15)
    # an output that is an input is refused, and nothing is written
    bad = _cli("compare", "coarse.nc", "fine.nc", "--vtu", "fine.nc", cwd=tmp_path)
    assert bad.returncode == 1 and bad.stderr.startswith("msslib: error:") and len(bad.stderr.splitlines()) == 1
    other = _cli("compare", "coarse.nc", "missing.nc", cwd=tmp_path)
    assert other.returncode == 1 and "missing.nc" in other.stderr


def test_an_experiment_of_ones_own_runs_and_compares(tmp_path):
    """No ``paper:``: a user's own experiment runs and compares like the papers'; a reaction check
    makes the numbers independent (the clamped face carries the applied load)."""
    exp = {
        "title": "my own cube",
        "scene": {"geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1,
                                                                  "nx": 2, "ny": 2, "nz": 2}},
                  "materials": [{"E": 1.0e6, "nu": 0.3}],
                  "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
                  "loads": [{"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, -100.0]}]},
        "models": {"mss": {"model": "golec_cube"}, "fem": {"model": "fem_linear"}},
        "reference": "fem",
    }
    (tmp_path / "mine.yaml").write_text(yaml.safe_dump(exp))
    run = _cli("experiment", "run-all", "mine.yaml", "--out-dir", "runs", "--quiet", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    cmp = _cli("experiment", "compare", "mine.yaml", "--results", "runs", "--out", "cmp.nc", "--table", "cmp.md",
               cwd=tmp_path)
    assert cmp.returncode == 0, cmp.stderr
    import xarray as xr

    ds = xr.load_dataset(tmp_path / "cmp.nc")
    assert ds.attrs["paper"] == "" and np.isfinite(float(ds.relative_error_max.sel(case="default", variant="mss")))
    assert "my own cube" in (tmp_path / "cmp.md").read_text()
    fem = xr.load_dataset(tmp_path / "runs" / "default__fem.nc")
    reaction = fem["reaction_force"].transpose("node", "axis").values
    assert reaction[:, 2].sum() == pytest.approx(100.0 * 0.1 * 0.1, rel=1e-9)  # 100 Pa on 0.01 m^2
    # the command-line compare gives the same maximum as the experiment's comparison
    one = _cli("compare", "runs/default__mss.nc", "runs/default__fem.nc", cwd=tmp_path)
    assert one.returncode == 0, one.stderr
    c = compare_results(tmp_path / "runs" / "default__mss.nc", tmp_path / "runs" / "default__fem.nc")
    assert c.error.max == pytest.approx(float(ds.error_max.sel(case="default", variant="mss")), rel=1e-12)
    # a typo in paper: is still caught
    (tmp_path / "typo.yaml").write_text(yaml.safe_dump({**exp, "paper": "loyd"}))
    bad = _cli("experiment", "list", "typo.yaml", cwd=tmp_path)
    assert bad.returncode == 1 and "leave it out" in bad.stderr

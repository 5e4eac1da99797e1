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
    assert distance[flagged] == pytest.approx([2e-3, 1e-3], rel=1e-9)  # outside: to the reference's boundary
    assert (distance[~flagged] == 0).all()


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


def _bars(tmp_path):
    """A 10 cm bar's result and a 20 cm bar's result that contains it: one field, two bodies."""
    short, long = hex_grid(0.1, 0.02, 0.02, 10, 2, 2), hex_grid(0.2, 0.02, 0.02, 20, 2, 2)
    return (_result(tmp_path / "short.nc", short, _affine(short.points), model="mss"),
            _result(tmp_path / "long.nc", long, _affine(long.points), model="fem"))


def test_a_reference_that_extends_beyond_the_result_is_refused_both_ways(tmp_path):
    """The short bar lies inside the long one, so every short-bar node is on the reference: only the
    reference's side shows the other body (10 cm beyond, the element size 0.017 m)."""
    short, long = _bars(tmp_path)
    with pytest.raises(ValueError, match=r"not meshes of the same body: the reference extends beyond the result: "
                                         r"node \d+ of .*long.nc at \(0.2, [0-9.]+, [0-9.]+\) lies 0.1 m outside"):
        compare_results(short, long)
    with pytest.raises(ValueError, match=r"not meshes of the same body: node \d+ of .*long.nc at \(0.2, "
                                         r"[0-9.]+, [0-9.]+\) lies 0.1 m outside the reference mesh"):
        compare_results(long, short)
    # a coarser mesh of the same bar (not nested) is still the same body
    coarse = hex_grid(0.1, 0.02, 0.02, 3, 1, 1)
    c = compare_results(_result(tmp_path / "coarse.nc", coarse, _affine(coarse.points)), short)
    assert c.relation == "interpolated" and c.error.max < 1e-15


def test_a_curved_boundary_at_two_resolutions_is_the_same_body(tmp_path):
    """A disc as polygons of 8 and 64 sides (the chords of the coarse one lie 0.08 R inside the
    fine one's): within the tolerance, and each side's out-of-mesh distance is the exact gap."""
    from msslib.mesh import Mesh

    def disc(n):
        t = 2 * np.pi * np.arange(n) / n
        points = np.vstack([[0.0, 0.0], 0.05 * np.column_stack([np.cos(t), np.sin(t)])])
        return Mesh(points, np.column_stack([np.zeros(n, int), 1 + np.arange(n), 1 + (1 + np.arange(n)) % n]),
                    "triangle")

    coarse, fine = disc(8), disc(64)
    u = lambda X: X @ np.array([[1e-3, 2e-4], [0.0, -3e-4]]).T  # noqa: E731
    a = _result(tmp_path / "coarse.nc", coarse, u(coarse.points))
    b = _result(tmp_path / "fine.nc", fine, u(fine.points))
    c = compare_results(a, b)
    assert c.n_outside == 0  # the coarse polygon's corners are corners of the fine one
    back = compare_results(b, a)
    gap = 0.05 * (1 - np.cos(np.pi / 8))  # the fine nodes halfway between coarse corners: the sagitta
    assert back.n_outside == 56 and back.outside_distance == pytest.approx(gap, rel=1e-9)


@pytest.mark.parametrize("factor, unit", [(1000.0, "millimetres"), (100.0, "centimetres")])
def test_rest_positions_in_another_unit_are_named(tmp_path, factor, unit):
    mesh = hex_grid(0.1, 0.02, 0.02, 5, 1, 1)
    scaled = hex_grid(0.1 * factor, 0.02 * factor, 0.02 * factor, 5, 1, 1)
    a = _result(tmp_path / "a.nc", scaled, _affine(mesh.points))
    b = _result(tmp_path / "b.nc", mesh, _affine(mesh.points))
    with pytest.raises(ValueError, match=f"a.nc span {factor:g} times those of .*b.nc: they look like {unit}"):
        compare_results(a, b)
    with pytest.raises(ValueError, match=f"a.nc span {factor:g} times those of .*b.nc: they look like {unit}"):
        compare_results(b, a)


def test_messages_print_plain_numbers(tmp_path):
    ref = hex_grid(0.1, 0.05, 0.05, 2, 1, 1)
    elsewhere = hex_grid(0.1, 0.05, 0.05, 2, 1, 1, origin=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError) as info:
        compare_results(_result(tmp_path / "e.nc", elsewhere, _affine(elsewhere.points)),
                        _result(tmp_path / "r.nc", ref, _affine(ref.points)))
    assert "np.float" not in str(info.value) and "at (1.1, 0, 0) lies 1 m outside" in str(info.value)


def test_experiment_compare_refuses_what_compare_refuses(tmp_path):
    """`msslib experiment compare` takes the same road as `msslib compare`: the short bar against
    the long one is refused by both, in one line, and no output is written."""
    short, long = _bars(tmp_path)
    (tmp_path / "runs").mkdir()
    short.rename(tmp_path / "runs" / "default__mss.nc")
    long.rename(tmp_path / "runs" / "default__fem.nc")
    exp = {"title": "bars", "scene": {"geometry": {"generator": "hex_grid", "args": {
        "lx": 0.1, "ly": 0.02, "lz": 0.02, "nx": 1, "ny": 1, "nz": 1}}, "materials": [{"E": 1.0e6, "nu": 0.3}]},
        "models": {"mss": {"model": "golec_cube"}, "fem": {"model": "fem_linear"}}, "reference": "fem"}
    (tmp_path / "mine.yaml").write_text(yaml.safe_dump(exp))
    one = _cli("compare", "runs/default__mss.nc", "runs/default__fem.nc", cwd=tmp_path)
    both = _cli("experiment", "compare", "mine.yaml", "--results", "runs", "--out", "cmp.nc", cwd=tmp_path)
    for run in (one, both):
        assert run.returncode == 1 and run.stderr.startswith("msslib: error:") and len(run.stderr.splitlines()) == 1
        assert "not meshes of the same body: the reference extends beyond the result" in run.stderr, run.stderr
        assert "default__fem.nc" in run.stderr
    assert not (tmp_path / "cmp.nc").exists()


def test_a_boundary_clash_prints_plain_numbers():
    """Two boundary conditions that prescribe different displacements on one node: the message
    names both values as numbers (not NumPy reprs)."""
    from msslib.scene import load_scene, prepare

    scene = load_scene({"model": {"type": "golec_cube"}, "geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1,
                                                                        "nx": 1, "ny": 1, "nz": 1}},
                        "materials": [{"E": 1.0e6, "nu": 0.3}],
                        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"},
                                     {"select": {"plane": ["x", 0.0]}, "fix": "x", "displacement": [0.001, 0, 0]}]})
    with pytest.raises(ValueError, match=r"scene.boundary\[1\].displacement.*already fixed by scene.boundary\[0\] "
                                         r"with displacement 0, here 0.001$"):
        prepare(scene)

"""Inverted and collapsed cells in solved states are detected, reported and recorded
(msslib.mesh.quality and its guard in msslib.scene.run_scene)."""

from __future__ import annotations

import math
import warnings
from contextlib import contextmanager

import numpy as np
import pytest
import yaml

from msslib import experiment
from msslib import mesh as M
from msslib.mesh import quality as Q
from msslib.cli import main
from msslib.errors import MsslibWarning, UnphysicalStateError
from msslib.results import read_result
from msslib.scene import run_scene

# one reference cell of each type, positively oriented (node order of msslib.mesh)
CELLS = {
    "triangle": np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
    "quad": np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
    "tetra": np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
    "hexahedron": np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
                           dtype=float),
}


def _cell(cell_type, points=None):
    p = CELLS[cell_type] if points is None else points
    return M.Mesh(p, np.arange(len(p))[None, :], cell_type)


@contextmanager
def _no_msslib_warning():
    """Any MsslibWarning inside is an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", MsslibWarning)
        yield


# --------------------------------------------------------------------------------------------
# the measure on hand-built cells
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cell_type", sorted(CELLS))
def test_rest_state_is_one_and_measure_is_scale_free(cell_type):
    m = _cell(cell_type)
    assert Q.relative_jacobians(m, m.points) == pytest.approx([1.0])
    # a uniform stretch by 2 doubles every length: the local volume ratio is 2^dim
    assert Q.relative_jacobians(m, 2.0 * m.points) == pytest.approx([2.0 ** m.dim])
    # the same cell ten times smaller at rest gives the same ratio (relative to rest)
    small = _cell(cell_type, 0.1 * CELLS[cell_type])
    assert Q.relative_jacobians(small, 0.2 * CELLS[cell_type]) == pytest.approx([2.0 ** m.dim])
    # a rigid rotation keeps it at 1
    c, s = math.cos(0.7), math.sin(0.7)
    R = np.array([[c, -s], [s, c]]) if m.dim == 2 else np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    assert Q.relative_jacobians(m, m.points @ R.T + 3.0) == pytest.approx([1.0])
    q = Q.check_state(m, m.points)
    assert q.ok and q.n_inverted == q.n_collapsed == q.n_undefined == 0 and q.state.tolist() == [Q.OK]


@pytest.mark.parametrize("cell_type", sorted(CELLS))
def test_mirrored_cell_is_inverted(cell_type):
    m = _cell(cell_type)
    mirrored = m.points * np.r_[-1.0, np.ones(m.dim - 1)]
    assert Q.relative_jacobians(m, mirrored) == pytest.approx([-1.0])
    q = Q.check_state(m, mirrored)
    assert (q.n_inverted, q.n_collapsed) == (1, 0) and q.state.tolist() == [Q.INVERTED] and not q.ok
    assert q.worst_cell == 0 and q.worst_value == pytest.approx(-1.0)
    assert q.cells.tolist() == [0]
    np.testing.assert_allclose(q.rest_centroids[0], CELLS[cell_type].mean(axis=0))
    np.testing.assert_allclose(q.centroids[0], mirrored.mean(axis=0))


@pytest.mark.parametrize("cell_type", sorted(CELLS))
def test_flattened_cell_is_collapsed(cell_type):
    m = _cell(cell_type)
    nearly = m.points * np.r_[np.ones(m.dim - 1), 1e-5]
    assert Q.relative_jacobians(m, nearly) == pytest.approx([1e-5])
    q = Q.check_state(m, nearly)
    assert (q.n_inverted, q.n_collapsed) == (0, 1) and q.state.tolist() == [Q.COLLAPSED]
    flat = m.points * np.r_[np.ones(m.dim - 1), 0.0]
    assert Q.relative_jacobians(m, flat) == pytest.approx([0.0], abs=1e-15)
    assert Q.check_state(m, flat).n_collapsed + Q.check_state(m, flat).n_inverted == 1
    # just above the threshold is fine, just below is collapsed
    assert Q.check_state(m, m.points * np.r_[np.ones(m.dim - 1), 2e-3]).ok
    assert Q.check_state(m, m.points * np.r_[np.ones(m.dim - 1), 5e-4]).n_collapsed == 1


def test_hex_with_a_corner_pushed_through_is_inverted_though_its_volume_is_positive():
    m = _cell("hexahedron")
    x = m.points.copy()
    x[6] = [0.2, 0.2, 0.2]  # the corner (1, 1, 1) pushed towards the opposite corner, past the faces 0-3-7-4 ...
    assert M.cell_measures(M.Mesh(x, m.cells, "hexahedron"))[0] > 0.0  # the trilinear volume is still positive
    r = Q.relative_jacobians(m, x)[0]
    assert r < 0.0
    assert Q.check_state(m, x).state.tolist() == [Q.INVERTED]


def test_hex_centre_is_sampled():
    # top face twisted by 180 degrees about the vertical axis: every corner keeps det J = det J_rest,
    # the whole cell collapses through its centre
    m = _cell("hexahedron")
    x = m.points.copy()
    x[4:] = x[[6, 7, 4, 5]]
    assert np.allclose(Q.SAMPLE_POINTS["hexahedron"][-1], 0.0)
    per_point = Q._jacobians("hexahedron", x[m.cells]) / Q._jacobians("hexahedron", m.points[m.cells])
    assert np.allclose(per_point[0, :8], 1.0)  # the corners alone would call this cell perfect
    assert Q.relative_jacobians(m, x)[0] == pytest.approx(0.0, abs=1e-12)
    assert not Q.check_state(m, x).ok


def test_non_convex_quad_is_inverted_though_its_area_is_positive():
    m = _cell("quad")
    x = m.points.copy()
    x[2] = [0.3, 0.3]  # corner 2 pushed past the diagonal 1-3
    assert M.cell_measures(M.Mesh(x, m.cells, "quad"))[0] > 0.0
    assert Q.relative_jacobians(m, x)[0] == pytest.approx((0.3 * 0.3 - 0.7 * 0.7) / 1.0)
    assert Q.check_state(m, x).n_inverted == 1


def test_clockwise_rest_cell_is_judged_relative_to_rest():
    cw = CELLS["triangle"][[0, 2, 1]]
    m = _cell("triangle", cw)
    assert Q.relative_jacobians(m, cw) == pytest.approx([1.0])
    assert Q.relative_jacobians(m, cw * [-1.0, 1.0]) == pytest.approx([-1.0])


def test_non_finite_positions_are_undefined_not_ok():
    m = _cell("tetra")
    x = m.points.copy()
    x[1, 0] = np.nan
    q = Q.check_state(m, x)
    assert q.n_undefined == 1 and q.state.tolist() == [Q.UNDEFINED] and math.isnan(q.worst_value)
    assert "undefined" in q.summary()


def test_summary_counts_orders_and_locates_on_a_grid():
    m = M.quad_grid(2.0, 1.0, 2, 1)  # cells 0 (x < 1) and 1 (x > 1)
    x = m.points.copy()
    right = x[:, 0] > 1.5
    x[right, 0] = 1.0 - 0.5 * (x[right, 0] - 1.0) / 1.0 * 3.0  # cell 1 folded back over cell 0: inverted
    q = Q.check_state(m, x)
    assert q.n_inverted == 1 and q.state.tolist() == [Q.OK, Q.INVERTED]
    assert q.worst_cell == 1 and q.cells.tolist() == [1]
    np.testing.assert_allclose(q.worst_rest_centroid, [1.5, 0.5])
    text = q.summary()
    assert "1 inverted" in text and "0 collapsed" in text and "of 2 quad cells" in text
    assert "worst cell 1" in text and "(1.5, 0.5) m at rest" in text and "\n" not in text


def test_shape_errors_are_named():
    m = _cell("triangle")
    with pytest.raises(ValueError, match=r"positions must have shape \(3, 2\)"):
        Q.check_state(m, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="threshold"):
        Q.check_state(m, m.points, threshold=0.0)


# --------------------------------------------------------------------------------------------
# histories
# --------------------------------------------------------------------------------------------


def _history_cube():
    m = M.hex_grid(1.0, 1.0, 1.0, 2, 1, 1)
    squash = m.points * [1.0, 1.0, 1e-4]  # all cells collapsed
    mirror = m.points.copy()
    mirror[m.points[:, 0] > 0.75, 0] = 0.2  # the far face x = 1 pushed back past x = 0.5: cell 1 inverted
    states = np.stack([m.points, squash, mirror, m.points])
    return m, states, np.array([0.0, 0.1, 0.2, 0.3])


def test_history_counts_per_state_and_first_times():
    m, states, t = _history_cube()
    h = Q.check_history(m, states, t)
    assert h.n_inverted.tolist() == [0, 0, 1, 0]
    assert h.n_collapsed.tolist() == [0, 2, 0, 0]
    assert h.first_inverted == 2 and h.first_inverted_time == pytest.approx(0.2)
    assert h.first_unphysical == 1 and h.first_unphysical_time == pytest.approx(0.1)
    assert h.n_unphysical_states == 2 and not h.ok
    assert h.min_ratio[0] == pytest.approx(1.0) and h.min_ratio[2] < 0
    # chunking does not change anything
    small = Q._CHUNK_VALUES
    try:
        Q._CHUNK_VALUES = 1
        h1 = Q.check_history(m, states, t)
    finally:
        Q._CHUNK_VALUES = small
    assert h1.n_inverted.tolist() == h.n_inverted.tolist() and np.allclose(h1.min_ratio, h.min_ratio)
    clean = Q.check_history(m, states[[0, 3]], t[[0, 3]])
    assert clean.ok and clean.first_inverted == -1 and math.isnan(clean.first_inverted_time)


def test_guard_reports_a_saved_state_when_the_final_state_is_fine():
    m, states, t = _history_cube()
    u_hist = states - m.points
    with pytest.warns(MsslibWarning) as rec:
        attrs, variables = Q.guard(m, u_hist[-1], history_displacement=u_hist, history_time=t, label="demo")
    msg = str(rec[0].message)
    assert "\n" not in msg and msg.startswith("demo: unphysical saved state")
    assert "2 of 4 saved states" in msg and "first at t = 0.1 s" in msg and "first inverted at t = 0.2 s" in msg
    assert attrs["inverted_cells"] == 0 and attrs["collapsed_cells"] == 0
    assert attrs["first_inverted_time"] == pytest.approx(0.2) and attrs["first_unphysical_time"] == pytest.approx(0.1)
    assert attrs["unphysical_states"] == 2 and attrs["checked_states"] == 4
    assert variables["inverted_cells_history"][1].tolist() == [0, 0, 1, 0]
    with pytest.raises(UnphysicalStateError, match=r"first at t = 0\.1 s.*set checks\.inverted: warn"):
        Q.guard(m, u_hist[-1], history_displacement=u_hist, history_time=t, policy="error")


# --------------------------------------------------------------------------------------------
# through run_scene and the command line
# --------------------------------------------------------------------------------------------


def _compression(model="golec_cube", strain=1.5, cells="hex", **extra):
    if cells == "hex":
        geometry = {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 2, "nz": 2}}
    elif cells == "tet":
        geometry = {"generator": "tet_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 1, "ny": 1, "nz": 1}}
    elif cells == "quad":
        geometry = {"generator": "quad_grid", "args": {"lx": 0.1, "ly": 0.1, "nx": 2, "ny": 2}}
    else:
        geometry = {"generator": "triangle_grid_right", "args": {"lx": 0.1, "ly": 0.1, "nx": 2, "ny": 2}}
    axis = "z" if cells in ("hex", "tet") else "y"
    disp = [0.0, 0.0, -0.1 * strain] if axis == "z" else [0.0, -0.1 * strain]
    scene = {
        "name": "squeeze",
        "geometry": geometry,
        "materials": [{"E": 1.0e6, "nu": 0.3, "density": 1000.0}],
        "model": model,
        "boundary": [{"select": {"plane": [axis, 0.0]}, "fix": "all"},
                     {"select": {"plane": [axis, 0.1]}, "fix": "all", "displacement": disp}],
        "solver": {"type": "static", "load_steps": 10},
    }
    scene.update(extra)
    return scene


def _run_warned(scene):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        ds = run_scene(scene, progress=False)
    ours = [w for w in rec if issubclass(w.category, MsslibWarning)]
    return ds, ours


def test_150_percent_compression_warns_and_records():
    ds, ws = _run_warned(_compression())
    assert len(ws) == 1
    msg = str(ws[0].message)
    assert "\n" not in msg and msg.startswith("squeeze (golec_cube): unphysical final state: 8 inverted")
    assert "of 8 hexahedron cells" in msg and "worst cell" in msg and "m at rest" in msg
    assert ds.attrs["inverted_cells"] == 8 and ds.attrs["collapsed_cells"] == 0
    assert ds.attrs["min_relative_jacobian"] < 0
    assert ds["cell_state"].dims == ("cell",) and ds["cell_state"].dtype == np.int8
    assert ds["cell_state"].values.tolist() == [Q.INVERTED] * 8
    assert ds["cell_state"].attrs["flag_meanings"] == "ok collapsed inverted undefined"
    assert ds["relative_jacobian"].values.min() == pytest.approx(ds.attrs["min_relative_jacobian"])
    # the recorded numbers agree with the measure applied to the stored final state
    m = M.Mesh(ds["rest_position"].values, ds["cells"].values, "hexahedron")
    r = Q.relative_jacobians(m, m.points + ds["displacement"].values)
    np.testing.assert_allclose(ds["relative_jacobian"].values, r)


def test_150_percent_compression_is_an_error_when_asked(tmp_path, capsys):
    scene = _compression(checks={"inverted": "error"})
    with pytest.raises(UnphysicalStateError) as info:
        run_scene(scene, progress=False)
    msg = str(info.value)
    assert "\n" not in msg and "8 inverted" in msg and "worst cell" in msg and "m at rest" in msg
    assert msg.endswith("set checks.inverted: warn to keep the result")

    path = tmp_path / "squeeze.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    out = tmp_path / "out.nc"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("msslib: error: squeeze (golec_cube): unphysical final state")
    assert not out.exists() and list(tmp_path.iterdir()) == [path]


def test_warning_through_the_cli_keeps_the_result(tmp_path, capsys):
    path = tmp_path / "squeeze.yaml"
    path.write_text(yaml.safe_dump(_compression(), sort_keys=False))
    out = tmp_path / "out.nc"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert [line for line in err if line.startswith("msslib: warning:")] == [
        line for line in err if "unphysical" in line]
    assert len([line for line in err if "unphysical" in line]) == 1
    ds = read_result(out)
    assert ds.attrs["inverted_cells"] == 8 and ds["cell_state"].values.tolist() == [Q.INVERTED] * 8
    # the VTU export carries the cell check, for ParaView
    vtu = tmp_path / "out.vtu"
    assert main(["vtu", str(out), "--out", str(vtu)]) == 0
    import meshio

    cell_data = meshio.read(vtu).cell_data
    assert np.concatenate(cell_data["cell_state"]).tolist() == [Q.INVERTED] * 8
    np.testing.assert_allclose(np.concatenate(cell_data["relative_jacobian"]), ds["relative_jacobian"].values)


@pytest.mark.parametrize("strain", [0.1, 0.5])
def test_clean_and_large_legitimate_compression_record_zero(strain):
    with _no_msslib_warning():
        ds = run_scene(_compression(strain=strain), progress=False)
    assert ds.attrs["inverted_cells"] == 0 and ds.attrs["collapsed_cells"] == 0 and ds.attrs["undefined_cells"] == 0
    assert (ds["cell_state"].values == Q.OK).all()
    assert 0.2 < ds.attrs["min_relative_jacobian"] < 1.0 - strain / 2


def test_fem_svk_stops_at_an_inverted_equilibrium_before_the_scene_check():
    """The finite-strain FEM solve checks every converged load step itself (msslib.fem.solve_nonlinear):
    St Venant-Kirchhoff's equilibrium under this compression inverts elements, and the run stops
    in one line naming the load factor, where the scene's check would have warned about the result."""
    from msslib.errors import ConvergenceError

    with pytest.raises(ConvergenceError, match=r"^fem_svk: msslib\.fem\.solve_nonlinear: the equilibrium found at load "
                                                r"factor \S+ inverts element \d+ \(det F = -"):
        run_scene(_compression(model="fem_svk", cells="tet"), progress=False)


@pytest.mark.parametrize("model, cells", [
    ("fem_linear", "hex"), ("lloyd_tetrahedron", "tet"), ("fem_linear", "quad"),
    ("lloyd_square", "quad"), ("lloyd_triangle", "tri"),
])
def test_every_model_and_cell_type_is_checked(model, cells):
    ds, ws = _run_warned(_compression(model=model, cells=cells))
    assert ds.attrs["inverted_cells"] > 0, model
    assert len(ws) == 1 and f"({model}): unphysical final state" in str(ws[0].message)
    assert int((ds["cell_state"].values == Q.INVERTED).sum()) == ds.attrs["inverted_cells"]
    with pytest.raises(UnphysicalStateError):
        run_scene(_compression(model=model, cells=cells, checks={"inverted": "error"}), progress=False)


def _dynamic(strain, **extra):
    solver = {"type": "dynamic", "method": "symplectic_euler", "dt": 1e-5, "t_end": 2e-4, "save_every": 5}
    return _compression(strain=strain, solver=solver, **extra)


def test_dynamic_run_reports_the_first_inverted_saved_state():
    ds, ws = _run_warned(_dynamic(1.5))
    # prescribed displacements apply at t = 0: the first saved state is already inverted
    assert ds.attrs["first_inverted_time"] == 0.0 and ds.attrs["first_unphysical_time"] == 0.0
    n_t = ds.sizes["time"]
    assert ds.attrs["checked_states"] == n_t and ds.attrs["unphysical_states"] >= 1
    assert ds["inverted_cells_history"].dims == ("time",) and ds["inverted_cells_history"].values[0] > 0
    assert len(ws) == 1 and "saved states have inverted or collapsed cells, first at t = 0 s" in str(ws[0].message)


def test_clean_dynamic_run_records_zero():
    with _no_msslib_warning():
        ds = run_scene(_dynamic(0.01), progress=False)
    assert ds.attrs["inverted_cells"] == 0 and ds.attrs["unphysical_states"] == 0
    assert math.isnan(ds.attrs["first_inverted_time"]) and math.isnan(ds.attrs["first_unphysical_time"])
    assert (ds["inverted_cells_history"].values == 0).all() and ds["min_relative_jacobian_history"].values.min() > 0.9


def test_experiment_runs_carry_the_attributes(tmp_path):
    exp_file = tmp_path / "squeeze.yaml"
    base = _compression()
    base.pop("name")
    base.pop("model")
    exp_file.write_text(yaml.safe_dump({
        "paper": "golec", "scene": base,
        "cases": {"mild": {"boundary": _compression(strain=0.1)["boundary"]}, "crushed": {}},
        "models": {"golec": {"model": "golec_cube"}},
    }, sort_keys=False))
    exp = experiment.load_experiment(exp_file)
    with _no_msslib_warning():
        mild = experiment.run(exp, "mild", "golec")
    assert mild.attrs["inverted_cells"] == 0 and mild.attrs["case"] == "mild"
    with pytest.warns(MsslibWarning, match="unphysical final state"):
        crushed = experiment.run(exp, "crushed", "golec")
    assert crushed.attrs["inverted_cells"] == 8

"""ParaView export (msslib.results.paraview, ``run --vtu OUT.pvd``, ``vtu RESULT.nc --out OUT.pvd``): every
saved state of a dynamic run as a .pvd collection of VTU files, springs as line cells, all files
written together or none, outputs that are inputs refused."""

from __future__ import annotations

import hashlib
import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import yaml

from msslib import cli
from msslib.results import paraview
from msslib import mesh as M
from msslib.results import read_result, write_result
from msslib.scene import run_scene
from scene_helpers import pulled_sheet, swinging_bar

DYNAMIC = swinging_bar(save_every=5)
STATIC_2D = pulled_sheet()


@pytest.fixture(scope="module")
def dynamic():
    return run_scene(DYNAMIC, progress=False)


@pytest.fixture(scope="module")
def static_2d():
    return run_scene(STATIC_2D, progress=False)


def _collection(pvd):
    """(timesteps, files) of a .pvd collection."""
    root = ET.parse(pvd).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "Collection"
    sets = root.find("Collection").findall("DataSet")
    return [float(d.get("timestep")) for d in sets], [d.get("file") for d in sets]


def assert_series(pvd, ds):
    """The series at ``pvd`` holds every saved state of the result ``ds``."""
    times, files = _collection(pvd)
    np.testing.assert_array_equal(times, ds["time"].values)
    assert files == [f"{pvd.stem}_{i:04d}.vtu" for i in range(ds.sizes["time"])]
    u_hist = ds["displacement_history"].transpose("time", "node", "axis").values
    v_hist = ds["velocity_history"].transpose("time", "node", "axis").values
    r_hist = ds["reaction_force_history"].transpose("time", "node", "axis").values
    np.testing.assert_array_equal(r_hist[-1], ds["reaction_force"].transpose("node", "axis").values)
    for i, name in enumerate(files):
        state = meshio.read(pvd.parent / name)
        np.testing.assert_array_equal(state.points, ds["rest_position"].values)
        np.testing.assert_array_equal(state.point_data["displacement"], u_hist[i])
        np.testing.assert_array_equal(state.point_data["velocity"], v_hist[i])
        np.testing.assert_array_equal(state.point_data["reaction_force"], r_hist[i])  # the reaction of that state
        assert "reaction_force_final" not in state.point_data
        assert state.cells[0].type == "hexahedron" and len(state.cells[0].data) == ds.sizes["cell"]
    last = meshio.read(pvd.parent / files[-1])
    np.testing.assert_array_equal(last.cell_data["cell_state"][0], ds["cell_state"].values)
    np.testing.assert_allclose(last.cell_data["relative_jacobian"][0], ds["relative_jacobian"].values, rtol=1e-12)


def assert_springs(path, ds):
    springs = meshio.read(path)
    assert [block.type for block in springs.cells] == ["line"]  # VTK_LINE
    np.testing.assert_array_equal(springs.cells[0].data, ds["springs"].values)
    np.testing.assert_array_equal(springs.cell_data["spring_constant"][0], ds["spring_constant"].values)
    np.testing.assert_array_equal(springs.cell_data["rest_length"][0], ds["rest_length"].values)


def test_dynamic_series_holds_every_saved_state(tmp_path, dynamic):
    assert dynamic.sizes["time"] == 5  # t = 0, 0.5, 1, 1.5, 2 ms
    files = paraview.write(tmp_path / "swing.pvd", dynamic)
    assert [f.name for f in files] == ["swing.pvd", *(f"swing_{i:04d}.vtu" for i in range(5)), "swing_springs.vtu"]
    assert sorted(os.listdir(tmp_path)) == sorted(f.name for f in files)
    assert_series(tmp_path / "swing.pvd", dynamic)
    assert_springs(tmp_path / "swing_springs.vtu", dynamic)
    # the springs are not part of the time series: one DataSet per state
    assert "swing_springs.vtu" not in _collection(tmp_path / "swing.pvd")[1]


def test_static_result_is_a_one_state_series(tmp_path, static_2d):
    paraview.write(tmp_path / "sheet.pvd", static_2d)
    times, files = _collection(tmp_path / "sheet.pvd")
    assert times == [0.0] and files == ["sheet_0000.vtu"]
    state = meshio.read(tmp_path / "sheet_0000.vtu")
    u = static_2d["displacement"].values
    assert state.point_data["displacement"].shape == (static_2d.sizes["node"], 3)  # 2D padded with z = 0
    np.testing.assert_array_equal(state.point_data["displacement"][:, :2], u)
    np.testing.assert_array_equal(state.point_data["displacement"][:, 2], 0.0)
    assert "velocity" not in state.point_data
    assert_springs(tmp_path / "sheet_springs.vtu", static_2d)


def test_width_of_state_numbers_grows_with_the_states():
    files = paraview.series_files("out/a.pvd", 12345, springs=False)
    assert [p.name for _, p in files[:2]] == ["a.pvd", "a_00000.vtu"] and files[-1][1].name == "a_12344.vtu"


# ---- command line --------------------------------------------------------------------------------

def _snapshot(directory):
    return {name: hashlib.sha256((directory / name).read_bytes()).hexdigest() for name in sorted(os.listdir(directory))
            if (directory / name).is_file()}


def _cli(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    return code, capsys.readouterr().err


def test_cli_run_and_vtu_write_the_series(tmp_path, capsys, dynamic):
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump(DYNAMIC))
    code, err = _cli(capsys, "run", tmp_path / "swing.yaml", "--out", tmp_path / "swing.nc",
                     "--vtu", tmp_path / "swing.pvd", "--quiet")
    assert code == 0, err
    ds = read_result(tmp_path / "swing.nc")
    assert_series(tmp_path / "swing.pvd", ds)
    assert_springs(tmp_path / "swing_springs.vtu", ds)

    code, err = _cli(capsys, "vtu", tmp_path / "swing.nc", "--out", tmp_path / "again.pvd")
    assert code == 0, err
    assert_series(tmp_path / "again.pvd", ds)
    for i in range(ds.sizes["time"]):  # the same states, whichever command wrote them
        a, b = (meshio.read(tmp_path / f"{stem}_{i:04d}.vtu") for stem in ("swing", "again"))
        np.testing.assert_array_equal(a.point_data["displacement"], b.point_data["displacement"])
    assert not [n for n in os.listdir(tmp_path) if "msslib-tmp" in n]


def test_scene_output_pvd_writes_a_series(tmp_path, capsys):
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump({**DYNAMIC, "output": {"vtu": "states.pvd"}}))
    code, err = _cli(capsys, "run", tmp_path / "swing.yaml", "--out", tmp_path / "swing.nc", "--quiet")
    assert code == 0, err
    assert_series(tmp_path / "states.pvd", read_result(tmp_path / "swing.nc"))


def _refused(capsys, directory, argv, *names):
    before = _snapshot(directory)
    code, err = _cli(capsys, *argv)
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1 and lines[0].startswith("msslib: error:"), err
    for name in names:
        assert str(name) in lines[0], (name, err)
    assert _snapshot(directory) == before


def test_series_that_would_overwrite_an_input_is_refused(tmp_path, capsys, monkeypatch, dynamic):
    monkeypatch.setattr("msslib.scene.run_scene", lambda *a, **k: pytest.fail("ran before refusing"))
    M.write_vtu(tmp_path / "part_0000.vtu", M.hex_grid(0.08, 0.02, 0.02, 4, 1, 1))
    (tmp_path / "part.yaml").write_text(yaml.safe_dump({**DYNAMIC, "geometry": {"file": "part_0000.vtu"}}))
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump(DYNAMIC))
    os.symlink(tmp_path / "swing.yaml", tmp_path / "link.pvd")
    write_result(tmp_path / "res_springs.vtu", dynamic)  # a result file named like a springs file
    d = tmp_path
    # the series' first state file is the scene's mesh file
    _refused(capsys, d, ["run", d / "part.yaml", "--out", d / "o.nc", "--vtu", d / "part.pvd"],
             "part_0000.vtu", "mesh file", "part.pvd")
    # the .pvd is (a link to) the scene file
    _refused(capsys, d, ["run", d / "swing.yaml", "--out", d / "o.nc", "--vtu", d / "link.pvd"], "link.pvd", "scene file")
    # the springs file of the series is the result read
    _refused(capsys, d, ["vtu", d / "res_springs.vtu", "--out", d / "res.pvd"], "res_springs.vtu", "result file")
    # the .pvd is the result read
    _refused(capsys, d, ["vtu", d / "res_springs.vtu", "--out", d / "res_springs.vtu"], "res_springs.vtu")
    # neither .vtu nor .pvd
    _refused(capsys, d, ["vtu", d / "res_springs.vtu", "--out", d / "res.vtk"], "res.vtk", ".vtu", ".pvd")
    _refused(capsys, d, ["run", d / "swing.yaml", "--out", d / "o.nc", "--vtu", d / "o.xdmf"], "o.xdmf", ".pvd")


def test_series_is_written_whole_or_not_at_all(tmp_path, capsys, monkeypatch, dynamic):
    write_result(tmp_path / "swing.nc", dynamic)
    (tmp_path / "old.pvd").write_text("old collection\n")
    (tmp_path / "old_0001.vtu").write_text("old state\n")
    real = M.write_vtu
    calls = []

    def third_fails(path, *args, **kwargs):
        calls.append(path)
        if len(calls) == 3:
            raise OSError(28, "No space left on device", str(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(M, "write_vtu", third_fails)
    _refused(capsys, tmp_path, ["vtu", tmp_path / "swing.nc", "--out", tmp_path / "old.pvd"],
             "old_0002.vtu", "No space left on device")
    assert len(calls) == 3
    assert (tmp_path / "old.pvd").read_text() == "old collection\n"
    assert sorted(os.listdir(tmp_path)) == ["old.pvd", "old_0001.vtu", "swing.nc"]  # no temporary file left


def test_first_saved_reaction_carries_the_weight_of_the_clamped_nodes(dynamic):
    """At rest (t = 0) the springs are unstretched: a support carries exactly its node's weight."""
    from msslib.scene import load_scene, prepare

    setup = prepare(load_scene(DYNAMIC))
    r0 = dynamic["reaction_force_history"].isel(time=0).transpose("node", "axis").values
    clamped = setup.fixed.all(axis=1)
    expected = -setup.masses[:, None] * setup.gravity[None, :]
    np.testing.assert_allclose(r0[clamped], expected[clamped], rtol=1e-12, atol=1e-15)
    assert np.all(r0[~setup.fixed] == 0.0)
    # later states differ: the body moves and the supports feel it
    assert np.abs(dynamic["reaction_force_history"].isel(time=-1).values - r0).max() > 1e-3 * np.abs(r0).max()

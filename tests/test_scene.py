"""Tests of msslib.scene and the command line (msslib.cli): example scenes, validation, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.cli import main
from msslib.results import read_result
from msslib.scene import Scene, load_scene, prepare, run_scene

SCENES = Path(__file__).resolve().parents[1] / "experiments" / "scenes"
EXAMPLES = sorted(SCENES.glob("*.yaml"))


def _write(tmp_path: Path, data: dict, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _example(name: str) -> dict:
    return yaml.safe_load((SCENES / f"{name}.yaml").read_text())


def _error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert err, "expected an error message on stderr"
    assert not any("Traceback" in line for line in err)
    return err[-1]


def _refused_run(tmp_path: Path, capsys, data: dict, *options: str) -> tuple[Path, str]:
    """Write ``data`` as a scene and ``msslib run`` it: exit code 1 and no output file. Returns the
    scene's path and the error line."""
    scene = _write(tmp_path, data)
    out = tmp_path / "out.nc"
    assert main(["run", str(scene), "--out", str(out), *options]) == 1
    line = _error_line(capsys)
    assert not out.exists()
    return scene, line


def _small_cube(**overrides) -> dict:
    scene = {
        "name": "cube",
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 2, "nz": 2}},
        "materials": [{"E": 1.0e6, "nu": 0.3, "density": 1000.0}],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, 1.0e3]}],
        "solver": {"type": "static"},
    }
    scene.update(overrides)
    return scene


# --------------------------------------------------------------------------------------------
# example scenes through the command line
# --------------------------------------------------------------------------------------------


def test_examples_exist():
    names = {p.stem for p in EXAMPLES}
    assert {"membrane_lloyd_stretch", "membrane_fem_stretch", "baudet_beam_tension", "golec_compression",
            "cylinder_tet_shear", "cantilever_gravity_dynamic"} <= names


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_scene_runs(path, tmp_path, capsys):
    assert main(["validate", str(path)]) == 0
    assert "ok" in capsys.readouterr().out
    out = tmp_path / f"{path.stem}.nc"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    ds = read_result(out)
    scene = load_scene(path)
    assert ds.attrs["model"] == scene.model
    assert ds.attrs["scene_name"] == scene.name
    assert ds.attrs["scene"] == path.read_text()
    u = ds["displacement"].values
    assert np.isfinite(u).all() and np.abs(u).max() > 0
    assert ds["fixed"].dtype == bool and ds["fixed"].values.any()
    assert "reaction_force" in ds and np.isfinite(ds.attrs["wall_time_s"])
    if scene.is_fem:
        assert "springs" not in ds
    else:
        assert (ds["spring_constant"].values > 0).all()
    if scene.is_dynamic:
        assert ds["displacement_history"].shape[0] == ds.sizes["time"] >= 2
        assert ds.attrs["solver_method"] == scene.solver["method"]
    if scene.output["vtu"]:
        assert out.with_suffix(".vtu").is_file()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # no temporary files


@pytest.mark.parametrize("name, model", [
    ("baudet_beam_tension", "fem_linear"),
    ("golec_compression", "fem_svk"),
    ("cylinder_tet_shear", "fem_neohookean"),
])
def test_fem_twins_run(name, model, tmp_path):
    data = _example(name)
    data["model"] = model
    data.pop("output", None)
    scene = _write(tmp_path, data)
    out = tmp_path / "fem.nc"
    vtu = tmp_path / "fem.vtu"
    assert main(["run", str(scene), "--out", str(out), "--vtu", str(vtu), "--quiet"]) == 0
    ds = read_result(out)
    assert ds.attrs["model"] == model and vtu.is_file()
    assert np.isfinite(ds["displacement"].values).all()


def test_mss_membrane_agrees_with_fem_linear():
    mss = run_scene(SCENES / "membrane_lloyd_stretch.yaml", progress=False)
    fem = run_scene(SCENES / "membrane_fem_stretch.yaml", progress=False)
    assert mss["material_nu"].values == pytest.approx([1 / 3])
    np.testing.assert_array_equal(mss["rest_position"].values, fem["rest_position"].values)
    u_mss, u_fem = mss["displacement"].values, fem["displacement"].values
    assert np.abs(u_mss - u_fem).max() <= 0.03 * np.abs(u_fem).max()
    # the Poisson contraction itself (not only the imposed stretch) agrees
    assert np.abs(u_mss[:, 1] - u_fem[:, 1]).max() <= 0.05 * np.abs(u_fem[:, 1]).max()


# --------------------------------------------------------------------------------------------
# model options and loads
# --------------------------------------------------------------------------------------------


def test_baudet_correction_uses_residual_line_search():
    data = _example("baudet_beam_tension")
    ds = run_scene(data, progress=False)
    assert ds.attrs["solver_line_search_merit"] == "residual"
    no_corr = run_scene({**data, "model": {"type": "baudet_cube", "terms": ["springs"]}}, progress=False)
    assert no_corr.attrs["solver_line_search_merit"] == "energy"
    # the correction changes the lateral contraction only
    assert not np.allclose(ds["displacement"].values[:, 1], no_corr["displacement"].values[:, 1])


def test_golec_terms_and_published():
    full = prepare(load_scene(_small_cube()))
    classical = prepare(load_scene(_small_cube(model={"type": "golec_cube", "terms": ["springs"]})))
    assert [type(t).__name__ for t in full.model.terms] == ["Springs", "HexVolume", "NodalForces"]
    assert [type(t).__name__ for t in classical.model.terms] == ["Springs", "NodalForces"]
    printed = prepare(load_scene(_small_cube(model={"type": "golec_cube", "published": True, "A": 0.5})))
    assert not np.allclose(printed.model.terms[0].k, full.model.terms[0].k)


def test_nodal_force_gravity_and_reactions():
    scene = _small_cube(loads=[
        {"type": "nodal_force", "select": {"plane": ["z", 0.1]}, "total": [0.0, 0.0, 2.0]},
        {"type": "gravity", "g": [0.0, 0.0, -9.81]},
    ], model="fem_linear")
    setup = prepare(load_scene(scene))
    top = M.select_nodes(setup.mesh, plane=("z", 0.1))
    np.testing.assert_allclose(setup.surface_forces[top, 2], 2.0 / len(top))
    assert setup.masses.sum() == pytest.approx(1000.0 * 0.1**3)
    ds = run_scene(scene, progress=False)
    weight = 1000.0 * 0.1**3 * 9.81
    # reactions balance the applied loads
    assert ds["reaction_force"].values[:, 2].sum() == pytest.approx(weight - 2.0, rel=1e-8)


def test_mesh_file_and_regions(tmp_path):
    (tmp_path / "meshes").mkdir()
    M.write_vtu(tmp_path / "meshes" / "strip.vtu", M.triangle_grid_right(0.1, 0.02, 10, 2))
    data = {
        "geometry": {"file": "meshes/strip.vtu"},
        "materials": [{"E": 1.0e6, "nu": 0.3}, {"E": 2.0e6, "nu": 0.3}],
        "regions": [{"box": [[0.05, None], None], "material": 1}],
        "thickness": 0.001,
        "model": "fem_linear",
        "boundary": [{"select": {"plane": ["x", 0.0]}}],
        "loads": [{"type": "traction", "select": {"plane": ["x", 0.1]}, "traction": [1.0e4, 0.0]}],
    }
    scene_path = _write(tmp_path, data)
    setup = prepare(load_scene(scene_path))
    centroid_x = setup.mesh.points[setup.mesh.cells].mean(axis=1)[:, 0]
    np.testing.assert_array_equal(setup.mesh.material, (centroid_x >= 0.05).astype(int))
    # traction 1e4 Pa on an edge 0.02 m long and 0.001 m thick
    assert setup.surface_forces[:, 0].sum() == pytest.approx(0.2)
    out = tmp_path / "strip.nc"
    assert main(["run", str(scene_path), "--out", str(out), "--quiet"]) == 0
    np.testing.assert_allclose(read_result(out)["material_E"].values, [1.0e6, 2.0e6])


# --------------------------------------------------------------------------------------------
# validation errors
# --------------------------------------------------------------------------------------------


def test_unknown_key_names_the_path(tmp_path, capsys):
    data = _example("baudet_beam_tension")
    data["loads"].insert(0, {"type": "gravity", "g": [0.0, 0.0, -9.81]})
    data["loads"][1]["tractoin"] = data["loads"][1].pop("traction")
    _, line = _refused_run(tmp_path, capsys, data)
    assert "scene.loads[1].tractoin: unknown key" in line and "traction" in line


@pytest.mark.parametrize("key_path, bad, expected", [
    (("materials", 0, "E"), -1.0e6, "scene.materials[0].E"),
    (("materials", 0, "E"), "-1e6", "-1e6"),
    (("materials", 0, "nu"), 0.5, "scene.materials[0].nu"),
    (("materials", 0, "nu"), -1.2, "-1.2"),
    (("solver", "dt"), -1.0e-4, "scene.solver.dt"),
    (("solver", "method"), "leapfrog", "'leapfrog'"),
    (("model", "type"), "golec_cubes", "'golec_cubes'"),
    (("geometry", "generator"), "hex_grids", "'hex_grids'"),
    (("geometry", "args", "nxx"), 3, "scene.geometry.args.nxx: unknown argument"),
    (("boundary", 0, "fix"), "w", "scene.boundary[0].fix[0]: unknown axis 'w'"),
])
def test_bad_values_exit_1(key_path, bad, expected, tmp_path, capsys):
    data = _example("cantilever_gravity_dynamic")
    target = data
    for key in key_path[:-1]:
        target = target[key]
    target[key_path[-1]] = bad
    scene, line = _refused_run(tmp_path, capsys, data, "--quiet")
    assert line.startswith("msslib: error: ") and expected in line
    if "unknown" not in expected:
        assert str(bad) in line  # the message names the value
    assert main(["validate", str(scene)]) == 1


def test_missing_mesh_file(tmp_path, capsys):
    data = _example("membrane_fem_stretch")
    data["geometry"] = {"file": "meshes/absent.msh"}
    scene, line = _refused_run(tmp_path, capsys, data)
    assert "scene.geometry.file" in line and "meshes/absent.msh" in line
    with pytest.raises(FileNotFoundError, match="absent.msh"):
        load_scene(scene)


@pytest.mark.parametrize("where", ["missing_dir", "file_as_dir"])
def test_unwritable_output(where, tmp_path, capsys):
    if where == "missing_dir":
        out = tmp_path / "no_such_dir" / "out.nc"
    else:
        (tmp_path / "a_file").write_text("x")
        out = tmp_path / "a_file" / "out.nc"
    assert main(["run", str(SCENES / "membrane_fem_stretch.yaml"), "--out", str(out), "--quiet"]) == 1
    line = _error_line(capsys)
    assert str(out) in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if where == "missing_dir" else ["a_file"])


def test_divergence_is_one_line_and_leaves_no_file(tmp_path, capsys):
    data = _example("cantilever_gravity_dynamic")
    data["solver"].update(dt=1.0e-2, t_end=0.2, allow_unstable=True)  # else refused before the run
    scene, line = _refused_run(tmp_path, capsys, data, "--quiet")
    assert "diverged" in line
    assert list(tmp_path.iterdir()) == [scene]


def test_scene_level_checks():
    with pytest.raises(ValueError, match=r"scene\.solver\.type: dynamic runs need an MSS model"):
        load_scene(_small_cube(model="fem_linear", solver={"type": "dynamic", "dt": 1e-4, "t_end": 1e-3}))
    with pytest.raises(ValueError, match=r"scene\.materials\[0\]\.density: required for gravity"):
        load_scene(_small_cube(materials=[{"E": 1e6, "nu": 0.3}], loads=[{"type": "gravity", "g": [0, 0, -9.81]}]))
    with pytest.raises(ValueError, match=r"scene\.model: lloyd_triangle needs triangle cells"):
        load_scene(_small_cube(model="lloyd_triangle"))
    with pytest.raises(ValueError, match=r"scene\.model\.A: only golec_cube"):
        load_scene(_small_cube(model={"type": "baudet_cube", "A": 1.0}))
    with pytest.raises(ValueError, match=r"scene\.thickness: applies to 2D meshes only"):
        load_scene(_small_cube(thickness=0.01))
    with pytest.raises(ValueError, match=r"scene\.boundary\[0\]\.select: selects no node"):
        prepare(load_scene(_small_cube(boundary=[{"select": {"plane": ["z", 0.5]}}])))
    with pytest.raises(ValueError, match=r"scene\.loads\[0\]\.traction: expected 3 values"):
        prepare(load_scene(_small_cube(loads=[{"type": "traction", "select": "all", "traction": [1.0, 0.0]}])))
    with pytest.raises(ValueError, match=r"scene\.geometry\.args: hex_grid needs the argument\(s\) nz"):
        load_scene(_small_cube(geometry={"generator": "hex_grid",
                                         "args": {"lx": 1, "ly": 1, "lz": 1, "nx": 1, "ny": 1}}))
    assert isinstance(load_scene(_small_cube()), Scene)


def test_duplicate_yaml_key(tmp_path, capsys):
    scene = tmp_path / "dup.yaml"
    scene.write_text((SCENES / "golec_compression.yaml").read_text() + "model: baudet_cube\n")
    assert main(["validate", str(scene)]) == 1
    assert "duplicate key 'model'" in _error_line(capsys)


def test_any_result_exports_to_vtu(tmp_path):
    import meshio

    from msslib.cli import main

    scene = Path(__file__).resolve().parent.parent / "experiments" / "scenes" / "membrane_fem_stretch.yaml"
    nc, vtu = tmp_path / "r.nc", tmp_path / "r.vtu"
    assert main(["run", str(scene), "--out", str(nc), "--quiet"]) == 0
    assert main(["vtu", str(nc), "--out", str(vtu)]) == 0
    m = meshio.read(vtu)
    assert "displacement" in m.point_data and m.point_data["displacement"].shape[1] == 3
    assert main(["vtu", str(tmp_path / "missing.nc"), "--out", str(vtu)]) == 1

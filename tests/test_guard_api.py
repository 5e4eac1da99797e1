"""The API validates types too: msslib.parameters, the scene loader, planning and the plan /
experiment / vtu commands refuse wrong kinds of values with one message naming the argument."""

from __future__ import annotations

import hashlib
import os
import warnings

import numpy as np
import pytest
import xarray as xr
import yaml

from cli_helpers import assert_refused
from cli_helpers import run_cli as _cli
from msslib import planning
from msslib import parameters as P
from msslib.results import write_result
from msslib.scene import load_scene, run_scene
from scene_helpers import pressed_cube

# ---- parameters: types -------------------------------------------------------------------

#: function -> (valid keyword arguments, the names its messages use for them)
CALLS = {
    "lloyd_triangle": (P.lloyd_triangle, {"E": 1e6, "t": 0.01}, {"E": "E", "t": "thickness t"}),
    "van_gelder_triangle": (P.van_gelder_triangle, {"E": 1e6, "t": 0.01, "area": 0.5, "length": 1.0},
                            {"E": "E", "t": "thickness t", "area": "area", "length": "length"}),
    "lloyd_square": (P.lloyd_square, {"E": 1e6, "t": 0.01}, {"E": "E", "t": "thickness t"}),
    "equivalent_edge_length": (P.equivalent_edge_length, {"volume": 1.0}, {"volume": "volume"}),
    "lloyd_tetrahedron": (P.lloyd_tetrahedron, {"E": 1e6, "l": 1.0, "nu": 0.25},
                          {"E": "E", "l": "edge length l", "nu": "nu"}),
    "lloyd_tetrahedron_volume": (P.lloyd_tetrahedron_volume, {"E": 1e6, "l": 1.0, "nu": 0.3},
                                 {"E": "E", "l": "edge length l", "nu": "nu"}),
    "baudet_cube": (P.baudet_cube, {"E": 1e6, "nu": 0.3, "a": 1.0}, {"E": "E", "nu": "nu", "a": "cube edge a"}),
    "golec_cube": (P.golec_cube, {"E": 1e6, "nu": 0.3, "a": 1.0, "A": 1.0},
                   {"E": "E", "nu": "nu", "a": "cube edge a", "A": "ratio A"}),
    "check_material": (P.check_material, {"E": 1e6, "nu": 0.3}, {"E": "E", "nu": "nu"}),
}
BAD_TYPES = {
    "string": ("1e6", "'1e6'"),
    "bool": (True, "True"),
    "None": (None, "None"),
    "list": ([1.0], "[1.0]"),
    "string array": (np.array(["1"]), "dtype <U1"),
    "object": (object(), "object"),
    "huge int": (10**400, "too large"),
}
TYPE_CASES = [(f, p, b) for f, (_, kw, _) in CALLS.items() for p in kw
              for b in BAD_TYPES if not (p == "nu" and b == "None" and f.startswith("lloyd_tetrahedron") and
                                         f != "lloyd_tetrahedron_volume")]


@pytest.mark.parametrize("function, param, bad", TYPE_CASES)
def test_parameters_reject_wrong_types(function, param, bad):
    fn, kwargs, shown = CALLS[function]
    value, text = BAD_TYPES[bad]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", P.FormulaValidityWarning)
        with pytest.raises(ValueError) as info:
            fn(**{**kwargs, param: value})
    message = str(info.value)
    assert shown[param] in message and text in message, message


def test_optional_nu_may_be_none():
    assert P.lloyd_tetrahedron(1e6, l=1.0, nu=None).k == P.lloyd_tetrahedron(1e6, l=1.0).k
    with pytest.warns(P.FormulaValidityWarning):
        P.lloyd_triangle(1e6, t=0.01, nu=0.3)


@pytest.mark.parametrize("value", ["yes", 1, None])
def test_published_must_be_a_bool(value):
    with pytest.raises(ValueError, match=rf"published must be True or False, got .*{value!r}"):
        P.golec_cube(1e6, nu=0.3, a=1.0, A=1.0, published=value)


def test_arrays_of_one_shape_are_elementwise():
    E = np.array([1e6, 2e6, 3e6])
    nu = np.array([0.2, 0.3, 0.35])
    out = P.golec_cube(E, nu=nu, a=0.1, A=1.0)
    for i in range(3):
        one = P.golec_cube(float(E[i]), nu=float(nu[i]), a=0.1, A=1.0)
        for field in ("k_edge", "k_face", "k_inner", "kappa"):
            assert getattr(out, field)[i] == pytest.approx(getattr(one, field), rel=1e-15)


@pytest.mark.parametrize("call", [
    lambda: P.golec_cube(np.ones(3) * 1e6, nu=np.full(2, 0.3), a=1.0, A=1.0),
    lambda: P.golec_cube(np.ones(3) * 1e6, nu=0.3, a=np.ones((3, 1)), A=1.0),  # would broadcast to (3, 3)
    lambda: P.baudet_cube(np.ones(2) * 1e6, nu=np.full(3, 0.3), a=1.0),
    lambda: P.check_material(np.ones(2) * 1e6, nu=np.full(3, 0.3)),
    lambda: P.lloyd_triangle(np.ones(2) * 1e6, t=np.full(3, 0.01)),
])
def test_arrays_of_different_shapes_are_refused(call):
    with pytest.raises(ValueError, match="same shape"):
        call()


@pytest.mark.parametrize("call, names", [
    (lambda: P.golec_cube(1e308, nu=0.3, a=10.0, A=1.0), ["golec_cube", "E=1e+308", "k_edge", "infinite"]),
    (lambda: P.baudet_cube(1e308, nu=0.3, a=100.0), ["baudet_cube", "E=1e+308", "a=100.0"]),
    (lambda: P.van_gelder_triangle(1e300, t=1e10, area=1.0, length=1e-10), ["van_gelder_triangle", "E=1e+300", "length=1e-10"]),
    (lambda: P.lloyd_tetrahedron_volume(1e6, l=1e120, nu=0.3), ["lloyd_tetrahedron_volume", "l=1e+120"]),
    (lambda: P.golec_cube(np.array([1e6, 1e308]), nu=0.3, a=10.0, A=1.0), ["golec_cube", "array of shape (2,)"]),
])
def test_results_out_of_double_range_are_refused(call, names):
    with pytest.raises(ValueError) as info:
        call()
    for name in names:
        assert name in str(info.value), str(info.value)


# ---- the scene loader --------------------------------------------------------------------

SCENE = pressed_cube("guard_api")


def _with(path, value):
    scene = yaml.safe_load(yaml.safe_dump(SCENE))
    *keys, last = path
    node = scene
    for k in keys:
        node = node[k]
    node[last] = value
    return scene


@pytest.mark.parametrize("path, key", [
    (("materials", 0, "E"), "scene.materials[0].E"),
    (("materials", 0, "nu"), "scene.materials[0].nu"),
    (("geometry", "args", "lx"), "scene.geometry.args.lx"),
    (("solver",), "scene.solver.load_steps"),
])
@pytest.mark.parametrize("value", ["abc", True, None, [1.0], {"a": 1}, 10**400, "nan"],
                         ids=["string", "bool", "None", "list", "mapping", "huge_int", "nan"])
def test_scene_loader_rejects_wrong_types(path, key, value):
    if path == ("solver",):
        path, value = ("solver",), {"type": "static", "load_steps": value}
    elif path[0] == "geometry" and isinstance(value, list):
        value = [1.0, "abc"]  # generator arguments may be lists (polygon vertices), of numbers only
        key += "[1]"
    with pytest.raises(ValueError) as info:
        load_scene(_with(path, value))
    assert str(info.value).startswith(key + ":"), str(info.value)


def test_scene_loader_accepts_numbers_written_as_strings():
    scene = load_scene(_with(("materials", 0, "E"), "1e6"))
    assert scene.materials[0].E == 1.0e6


# ---- plan: its arguments are checked before anything is measured --------------------------

def _files(directory):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in directory.iterdir() if p.is_file()}


@pytest.fixture
def no_measuring(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a run started before the arguments were checked")

    monkeypatch.setattr(planning, "_run", refuse)
    monkeypatch.setattr("msslib.scene.run_scene", refuse)


@pytest.mark.parametrize("args, names", [
    (["--repeats", "0"], ["--repeats", "got 0"]),
    (["--repeats", "-2"], ["--repeats", "got -2"]),
    (["--levels", "a,b"], ["--levels", "'a'", "integer >= 1"]),
    (["--levels=-1,2"], ["--levels", "'-1'"]),
    (["--levels", "1.5"], ["--levels", "'1.5'"]),
    (["--levels", "0"], ["--levels", "'0'"]),
    (["--levels", ""], ["--levels", "empty"]),
    (["--levels", " , "], ["--levels"]),
    (["--levels", "1,2,1"], ["--levels", "level 1 is given twice"]),
    (["--budget", "0"], ["--budget", "got 0.0"]),
    (["--budget", "-3"], ["--budget", "got -3.0"]),
    (["--budget", "inf"], ["--budget", "finite"]),
    (["--max-error", "inf"], ["--max-error", "finite", "got inf"]),
    (["--max-error", "nan"], ["--max-error", "got nan"]),
    (["--max-error", "0"], ["--max-error", "> 0"]),
])
def test_plan_rejects_bad_arguments(tmp_path, capsys, no_measuring, args, names):
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    argv = ["plan", scene, "--max-error", "0.1"]
    if "--max-error" in args:
        argv = ["plan", scene]
    before = _files(tmp_path)
    code, err = _cli(capsys, *argv, *args, "--save", tmp_path / "front.nc")
    assert_refused(code, err, *names)
    assert _files(tmp_path) == before  # nothing written
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]


@pytest.mark.parametrize("content, names", [
    ("", ["scene.yaml", "is empty"]),
    ("  \n# only a comment\n", ["scene.yaml", "is empty"]),
    ("- a list\n", ["scene.yaml", "expected a mapping"]),
    ("geometry: [unclosed\n", ["scene.yaml", "invalid YAML"]),
    (yaml.safe_dump({**SCENE, "geometry": {"file": "missing.vtu"}}), ["scene.geometry.file", "missing.vtu"]),
    (yaml.safe_dump({**SCENE, "materials": [{"E": "abc", "nu": 0.3}]}), ["scene.materials[0].E", "'abc'"]),
    (yaml.safe_dump({**SCENE, "geometry": {"generator": "hex_grid", "args": {
        "lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2.5, "ny": 2, "nz": 2}}}), ["scene.geometry", "nx", "2.5"]),
    (yaml.safe_dump({**SCENE, "solver": {"type": "dynamic", "dt": 1e-4, "t_end": 1e-3}, "materials": [
        {"E": 1e6, "nu": 0.3, "density": 1000.0}]}), ["scene.solver", "dynamic"]),
], ids=["empty", "comment only", "a list", "invalid YAML", "mesh file", "bad E", "fractional nx", "dynamic"])
def test_plan_rejects_scenes_it_cannot_plan(tmp_path, capsys, no_measuring, content, names):
    from msslib import mesh as M

    M.write_vtu(tmp_path / "mesh.vtu", M.hex_grid(0.1, 0.1, 0.1, 1, 1, 1))
    scene = tmp_path / "scene.yaml"
    scene.write_text(content)
    before = _files(tmp_path)
    code, err = _cli(capsys, "plan", scene, "--max-error", "0.1")
    assert_refused(code, err, *names)
    assert _files(tmp_path) == before


def test_plan_front_options_and_mismatched_scene(tmp_path, capsys, no_measuring):
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    front = xr.Dataset(
        {name: (("model", "level"), np.array([[0.1]]), {"units": "1", "long_name": name})
         for name in ("wall_time", "error_max", "error_mean")},
        coords={"model": ["golec_cube"], "level": [1]},
        attrs={"reference_model": "fem_neohookean", "reference_level": 2, "scene": yaml.safe_dump(SCENE)})
    front["n_dofs"] = (("model", "level"), np.array([[81]]), {"units": "1", "long_name": "dofs"})
    front["status"] = (("model", "level"), np.array([["ok"]]), {"units": "1", "long_name": "status"})
    write_result(tmp_path / "front.nc", front)
    code, err = _cli(capsys, "plan", scene, "--max-error", "0.2", "--front", tmp_path / "front.nc")
    assert code == 0, err
    code, err = _cli(capsys, "plan", scene, "--max-error", "0.2", "--front", tmp_path / "front.nc", "--levels", "1")
    assert_refused(code, err, "--levels", "--front")
    other = tmp_path / "other.yaml"
    other.write_text(yaml.safe_dump({**SCENE, "name": "another"}))
    code, err = _cli(capsys, "plan", other, "--max-error", "0.2", "--front", tmp_path / "front.nc")
    assert_refused(code, err, "front.nc", "other.yaml", "not measured for")
    code, err = _cli(capsys, "plan", scene, "--max-error", "0.2", "--front", scene)
    assert_refused(code, err, "scene.yaml", "not a NetCDF file")


@pytest.mark.parametrize("kwargs, name", [
    ({"levels": []}, "levels"),
    ({"levels": "1,2"}, "levels"),
    ({"levels": (1, 1)}, "levels must be distinct"),
    ({"levels": (1, 2.5)}, "levels[1]"),
    ({"levels": (True,)}, "levels[0]"),
    ({"levels": (0, 1)}, "levels[0]"),
    ({"repeats": 0}, "repeats"),
    ({"repeats": 2.0}, "repeats"),
    ({"repeats": "3"}, "repeats"),
    ({"budget": 0}, "budget"),
    ({"budget": float("nan")}, "budget"),
    ({"budget": "30"}, "budget"),
    ({"models": ["golec"]}, "unknown model 'golec'"),
    ({"models": "golec_cube"}, "models"),
    ({"models": ["lloyd_triangle"]}, "cannot run on hexahedron cells"),
])
def test_measure_front_checks_its_arguments_first(no_measuring, kwargs, name):
    with pytest.raises(ValueError) as info:
        planning.measure_front(SCENE, **kwargs, progress=None)
    assert name in str(info.value), str(info.value)


@pytest.mark.parametrize("value", [0, -0.1, float("inf"), float("nan"), "0.1", True, None])
def test_choose_checks_max_error(value):
    front = xr.Dataset({name: (("model", "level"), np.array([[0.1]])) for name in
                        ("wall_time", "error_max", "error_mean", "n_dofs", "status")},
                       coords={"model": ["m"], "level": [1]}, attrs={"reference_model": "r", "reference_level": 2})
    assert planning.choose(front, 0.2) == ("m", 1, 0.1, 0.1)
    with pytest.raises(ValueError, match="max_error must be a finite number > 0"):
        planning.choose(front, value)


def test_refine_checks_level_and_counts():
    with pytest.raises(ValueError, match="level must be an integer >= 1, got 0"):
        planning.refine(SCENE, 0)
    bad = yaml.safe_load(yaml.safe_dump(SCENE))
    bad["geometry"]["args"]["nx"] = "two"
    with pytest.raises(ValueError, match=r"scene\.geometry\.args\.nx: expected a number, got 'two'"):
        planning.refine(bad, 2)
    assert planning.refine(SCENE, 3)["geometry"]["args"]["nx"] == 6


# ---- experiment and vtu: missing files, bad choices, files that are not results -------------

EXPERIMENT = {"paper": "golec", "scene": SCENE, "cases": {"press": {}, "pull": {}},
              "models": {"mss": {"model": "golec_cube"}, "fem": {"model": "fem_linear"}}, "reference": "fem"}


@pytest.fixture
def exp_dir(tmp_path):
    (tmp_path / "exp.yaml").write_text(yaml.safe_dump(EXPERIMENT))
    return tmp_path


@pytest.mark.parametrize("argv, names", [
    (["experiment", "run", "{d}/missing.yaml", "--case", "press", "--model", "mss", "--out", "{d}/o.nc"],
     ["experiment file not found", "missing.yaml"]),
    (["experiment", "run", "{d}/exp.yaml", "--case", "push", "--model", "mss", "--out", "{d}/o.nc"],
     ["--case 'push'", "expected one of press, pull"]),
    (["experiment", "run", "{d}/exp.yaml", "--case", "press", "--model", "fe", "--out", "{d}/o.nc"],
     ["--model 'fe'", "expected one of fem, mss"]),
    (["experiment", "list", "{d}/missing.yaml"], ["experiment file not found", "missing.yaml"]),
    (["experiment", "list", "{d}/binary.yaml"], ["binary.yaml", "not UTF-8"]),
    (["experiment", "list", "{d}/bad.yaml"], ["bad.yaml", "invalid YAML"]),
    (["experiment", "list", "{d}/text.txt"], ["text.txt", "must be a mapping"]),
    (["experiment", "compare", "{d}/exp.yaml", "--results", "{d}/nowhere", "--out", "{d}/c.nc"],
     ["--results", "nowhere", "not a directory"]),
    (["experiment", "compare", "{d}/exp.yaml", "--results", "{d}", "--out", "{d}/c.nc"],
     ["missing run", "press__fem.nc"]),
    (["experiment", "run-all", "{d}/exp.yaml", "--out-dir", "{d}/text.txt"], ["--out-dir", "text.txt"]),
    (["vtu", "{d}/missing.nc", "--out", "{d}/o.vtu"], ["result file not found", "missing.nc"]),
    (["vtu", "{d}/text.txt", "--out", "{d}/o.vtu"], ["text.txt", "not a NetCDF file"]),
    (["vtu", "{d}/other.nc", "--out", "{d}/o.vtu"], ["other.nc", "no variable 'rest_position'"]),
    (["vtu", "{d}", "--out", "{d}/o.vtu"], ["is not a file"]),
    (["run", "{d}/binary.yaml", "--out", "{d}/o.nc"], ["binary.yaml", "not UTF-8"]),
    (["validate", "{d}/missing.yaml"], ["scene file not found", "missing.yaml"]),
])
def test_commands_refuse_bad_files_and_choices(exp_dir, capsys, no_measuring, argv, names):
    d = exp_dir
    (d / "binary.yaml").write_bytes(b"\x89PNG\r\n\x1a\n\x00")
    (d / "bad.yaml").write_text("paper: [golec\n")
    (d / "text.txt").write_text("hello\n")
    xr.Dataset({"a": ("x", [1.0])}).to_netcdf(d / "other.nc")
    before = _files(d)
    names_before = sorted(os.listdir(d))
    code, err = _cli(capsys, *[a.format(d=d) for a in argv])
    assert_refused(code, err, *names)
    assert _files(d) == before
    assert sorted(os.listdir(d)) == names_before


def test_run_all_validates_every_scene_before_running(exp_dir, capsys, no_measuring):
    exp = yaml.safe_load((exp_dir / "exp.yaml").read_text())
    exp["models"]["fem"] = {"model": "fem_linear", "materials": [{"E": -1.0, "nu": 0.3}]}
    (exp_dir / "exp.yaml").write_text(yaml.safe_dump(exp))
    code, err = _cli(capsys, "experiment", "run-all", exp_dir / "exp.yaml", "--out-dir", exp_dir / "out", "--quiet")
    assert_refused(code, err, "scene.materials[0].E")
    assert not (exp_dir / "out").exists()


def test_scene_with_huge_values_stops_with_one_line(tmp_path, capsys):
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({**SCENE, "materials": [{"E": 10**400, "nu": 0.3}]}))
    code, err = _cli(capsys, "run", scene, "--out", tmp_path / "o.nc")
    assert_refused(code, err, "scene.materials[0].E", "finite")
    assert sorted(os.listdir(tmp_path)) == ["scene.yaml"]


def test_valid_scene_still_runs():
    ds = run_scene(SCENE, progress=False)
    assert float(abs(ds["displacement"]).max()) == pytest.approx(0.001)


def test_dict_scene_with_numpy_values_is_read_and_checked():
    import numpy as np

    from msslib.scene import load_scene

    d = {"geometry": {"generator": "hex_grid", "args": {"lx": 1, "ly": 1, "lz": 1, "nx": np.int64(2), "ny": 2, "nz": 2}},
         "materials": [{"E": np.float64(1e6), "nu": 0.3, "density": 1.0}], "model": "golec_cube",
         "loads": [{"type": "gravity", "g": np.array([0.0, 0.0, -9.81])}]}
    assert load_scene(d).loads[0]["g"] == [0.0, 0.0, -9.81]
    d["loads"][0]["g"] = np.zeros((2, 2))
    with pytest.raises(ValueError, match=r"scene\.loads\[0\]\.g\[0\]: expected a number"):
        load_scene(d)
    d["loads"][0]["g"] = object()
    with pytest.raises(ValueError, match=r"scene\.loads\[0\]\.g: expected numbers, strings, lists or mappings"):
        load_scene(d)

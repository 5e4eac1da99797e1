"""The Python API of ``import msslib``: the documented example runs as written, imports are lazy,
models and results are those of the scene machinery, bad arguments are one-line errors; the
version; the text progress bar's rate and time left."""

from __future__ import annotations

import io
import re
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import msslib
from msslib import cli, parameters
from msslib import scene as S

ROOT = Path(__file__).resolve().parents[1]
CUBE = {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 2, "nz": 2}}
STEEL = msslib.Material(E=1.0e6, nu=0.3, density=1000.0)
PRESS = {"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, -1.0e3]}


def _example(doc: str) -> str:
    """The code block of the package docstring."""
    match = re.search(r"\.\. code-block:: python\n\n((?:    .*\n|\n)+)", doc)
    assert match, "no code block in the docstring"
    return textwrap.dedent(match.group(1))


def test_docstring_example_runs_as_written(tmp_path, monkeypatch):
    code = _example(msslib.__doc__)
    assert len([line for line in code.splitlines() if line and not line.startswith(" ")]) == 5  # five statements
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code, "msslib.__doc__", "exec"), namespace)  # noqa: S102 - our own docstring
    written = msslib.read_result(tmp_path / "cube.nc")
    # the same result as the scene the example describes, run by the scene machinery
    scene = {"geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 4, "ny": 4, "nz": 4}},
             "materials": [{"E": 1e6, "nu": 0.3, "density": 1000.0}], "model": "golec_cube",
             "boundary": [{"select": {"plane": ["z", 0.0]}}], "loads": [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]}
    expected = S.run_scene(scene, progress=False)
    np.testing.assert_array_equal(written["displacement"].values, expected["displacement"].values)
    np.testing.assert_array_equal(written["spring_constant"].values, expected["spring_constant"].values)
    assert written["displacement"].isel(axis=2).min() < 0  # it sags under its weight
    assert "in-memory msslib.mesh.Mesh: 125 nodes, 64 hexahedron cells" in written.attrs["scene"]
    assert str(tmp_path) not in written.attrs["scene"] and "msslib-api-" not in written.attrs["scene"]


def test_import_is_lazy():
    code = ("import sys, msslib; heavy = [m for m in ('numba', 'scipy', 'xarray', 'msslib.scene', 'msslib.system') "
            "if m in sys.modules]; print(heavy); msslib.build_model; print('msslib.api' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split("\n")[:2] == ["[]", "True"]


def test_names_and_submodules():
    assert set(msslib.__all__) <= set(dir(msslib))
    for name in msslib.__all__:
        assert getattr(msslib, name) is not None
    assert msslib.Material is S.Material and msslib.run_scene is S.run_scene
    assert msslib.parameters is parameters and msslib.mesh.hex_grid  # submodules as attributes
    with pytest.raises(AttributeError, match="has no attribute 'no_such_thing'"):
        msslib.no_such_thing


def test_version(capsys):
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert msslib.__version__ == project
    with pytest.raises(SystemExit) as exit_:
        cli.main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == f"msslib {project}\n"
    out = subprocess.run([sys.executable, "-m", "msslib", "--version"], capture_output=True, text=True, check=True)
    assert out.stdout == f"msslib {project}\n"


# ---- build, inspect, solve -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def cube():
    return msslib.build_model("golec_cube", msslib.mesh.hex_grid(0.1, 0.1, 0.1, 2, 2, 2), STEEL,
                              fixed={"plane": ["z", 0.0]}, loads=PRESS)


def test_model_is_the_scenes_model(cube, tmp_path, monkeypatch):
    assert isinstance(cube, msslib.ModelSetup) and isinstance(cube, S.Setup)
    assert [type(t).__name__ for t in cube.model.terms] == ["Springs", "HexVolume", "NodalForces"]
    assert int(cube.fixed.sum()) == 27 and cube.scene.model == "golec_cube"
    np.testing.assert_array_equal(cube.mesh.points, msslib.mesh.hex_grid(0.1, 0.1, 0.1, 2, 2, 2).points)  # exactly
    setup = S.prepare(S.load_scene({"geometry": CUBE, "materials": [{"E": 1e6, "nu": 0.3, "density": 1000.0}],
                                    "model": "golec_cube", "boundary": [{"select": {"plane": ["z", 0.0]}}],
                                    "loads": [PRESS]}))
    x = cube.model.x0 + 1e-4 * np.sin(np.arange(cube.model.n_dof))
    np.testing.assert_array_equal(cube.model.force(x), setup.model.force(x))
    # the same model from a mesh file (a relative one is found from where the model was built) and
    # from a scene geometry mapping
    path = msslib.mesh.write_vtu(tmp_path / "cube.vtu", msslib.mesh.hex_grid(0.1, 0.1, 0.1, 2, 2, 2))
    monkeypatch.chdir(tmp_path)
    built = {mesh if isinstance(mesh, str) else type(mesh).__name__:
             msslib.build_model("golec_cube", mesh, STEEL, fixed={"plane": ["z", 0.0]}, loads=PRESS)
             for mesh in (path, "cube.vtu", CUBE)}
    for other in built.values():
        np.testing.assert_array_equal(other.model.force(x), cube.model.force(x))
    monkeypatch.chdir(ROOT)
    moved = msslib.solve_static(built["cube.vtu"], progress=False)
    assert "cube.vtu" in moved.attrs["scene"] and str(tmp_path) not in moved.attrs["scene"]


def test_spring_constants(cube):
    table = msslib.spring_constants(cube)
    result = msslib.solve_static(cube, progress=False)
    # the springs of the result, in its order
    np.testing.assert_array_equal(np.column_stack([table.node_a, table.node_b]), result["springs"].values)
    np.testing.assert_array_equal(table.spring_constant, result["spring_constant"].values)
    np.testing.assert_array_equal(table.rest_length, result["rest_length"].values)
    np.testing.assert_allclose(table.rest_distance, table.rest_length, rtol=1e-12)  # no prestrain in Golec's cube
    # 2 x 2 x 2 cubes: 54 edges, 72 face diagonals (36 faces), 32 inner diagonals
    assert dict(table.sizes) == {"spring": 54 + 72 + 32, "cell": 8}
    golec = parameters.golec_cube(1.0e6, nu=0.3, a=0.05, A=1.0)
    np.testing.assert_allclose(table.kappa, golec.kappa, rtol=1e-12)
    np.testing.assert_allclose(table.rest_volume, 0.05**3, rtol=1e-12)
    assert table.spring_constant.attrs["units"] == "N m-1" and table.kappa.attrs["units"] == "Pa"
    frame = table[["node_a", "node_b", "spring_constant", "rest_length"]].to_dataframe()
    assert len(frame) == table.sizes["spring"]
    # an edge inside the cube (4 cells) is 4 times as stiff as a corner edge (1 cell)
    assert np.isclose(table.spring_constant.max() / golec.k_edge, 4.0)
    # Lloyd's squares are prestrained: rest lengths differ from the mesh distances
    sheet = msslib.build_model("lloyd_square", msslib.mesh.quad_grid(0.1, 0.1, 2, 2), msslib.Material(1e6, 1 / 3),
                               thickness=0.01, fixed="all")
    squares = msslib.spring_constants(sheet)
    assert not np.allclose(squares.rest_length, squares.rest_distance) and "cell" not in squares.sizes


def test_solve_static_is_run_scene(cube):
    result = msslib.solve_static(cube, load_steps=2, progress=False)
    expected = S.run_scene({"geometry": CUBE, "materials": [{"E": 1e6, "nu": 0.3, "density": 1000.0}],
                            "model": "golec_cube", "boundary": [{"select": {"plane": ["z", 0.0]}}], "loads": [PRESS],
                            "solver": {"type": "static", "load_steps": 2}}, progress=False)
    np.testing.assert_array_equal(result["displacement"].values, expected["displacement"].values)
    assert result.attrs["solver_n_load_steps"] == 2
    top = np.isclose(result["rest_position"].isel(axis=2), 0.1)
    assert float(result["displacement"].isel(axis=2)[top].max()) < 0  # pressed down


def test_solve_dynamic(tmp_path):
    beam = msslib.build_model("golec_cube", msslib.mesh.hex_grid(0.08, 0.02, 0.02, 4, 1, 1),
                              msslib.Material(1.0e5, 0.3, 1000.0), fixed={"plane": ["x", 0.0]},
                              loads={"type": "gravity", "g": [0.0, 0.0, -9.81]})
    result = msslib.solve_dynamic(beam, dt=1e-4, t_end=2e-3, save_every=5, progress=False)
    np.testing.assert_allclose(result["time"].values, [0.0, 5e-4, 1e-3, 1.5e-3, 2e-3], rtol=1e-12)
    assert result["displacement_history"].shape == (5, 20, 3) and "velocity_history" in result
    np.testing.assert_array_equal(result["displacement_history"][-1].values, result["displacement"].values)
    assert result.attrs["solver_type"] == "dynamic" and result.attrs["solver_method"] == "symplectic_euler"
    files = msslib.write_paraview(tmp_path / "beam.pvd", result)
    assert len(files) == 1 + 5 + 1
    # a free body can only be built for a dynamic run; its dt and t_end are the defaults of solve_dynamic
    with pytest.raises(ValueError, match=r"scene\.boundary: .*dynamic"):
        msslib.build_model("golec_cube", msslib.mesh.hex_grid(0.02, 0.02, 0.02, 1, 1, 1), STEEL)
    free = msslib.build_model("golec_cube", msslib.mesh.hex_grid(0.02, 0.02, 0.02, 1, 1, 1), STEEL,
                              loads={"type": "gravity", "g": [0.0, 0.0, -9.81]},
                              solver={"type": "dynamic", "dt": 1e-4, "t_end": 1e-3})
    fall = msslib.solve_dynamic(free, save_every=10, history=True, progress=False)
    assert fall.sizes["time"] == 2
    # free fall: u_z = -g t^2 / 2 at every node (symplectic Euler: -g t (t + dt) / 2)
    np.testing.assert_allclose(fall["displacement"].isel(axis=2), -9.81 * 1e-3 * 1.1e-3 / 2, rtol=1e-9)


def test_fem_reference_through_the_api(cube):
    fem = msslib.build_model("fem_linear", CUBE, {"E": 1e6, "nu": 0.3}, fixed={"plane": ["z", 0.0]}, loads=PRESS)
    assert fem.model is None
    result = msslib.solve_static(fem, progress=False)
    mss = msslib.solve_static(cube, progress=False)
    assert result.attrs["model"] == "fem_linear"
    uz = result["displacement"].isel(axis=2).values
    assert np.sign(uz.min()) == np.sign(mss["displacement"].isel(axis=2).values.min()) == -1
    with pytest.raises(ValueError, match="fem_linear is a FEM reference; it has no spring constants"):
        msslib.spring_constants(fem)


def test_write_result_either_order(tmp_path, cube):
    result = msslib.solve_static(cube, progress=False)
    msslib.write_result(tmp_path / "a.nc", result)
    msslib.write_result(result, tmp_path / "b.nc")
    for name in ("a.nc", "b.nc"):
        xr.testing.assert_equal(msslib.read_result(tmp_path / name)["displacement"], result["displacement"])


def _one_line(exc_info, *parts):
    text = str(exc_info.value)
    assert "\n" not in text, text
    for part in parts:
        assert part in text, (part, text)


@pytest.mark.parametrize("call, parts", [
    (lambda m: msslib.build_model("golec_cub", m, STEEL, fixed="all"), ["scene.model", "golec_cub", "golec_cube"]),
    (lambda m: msslib.build_model("golec_cube", m, msslib.Material(1e6, 0.6), fixed="all"),
     ["scene.materials[0].nu", "< 0.5", "0.6"]),
    (lambda m: msslib.build_model("golec_cube", m, msslib.Material("stiff", 0.3), fixed="all"),
     ["scene.materials[0].E", "'stiff'"]),
    (lambda m: msslib.build_model("golec_cube", m, [], fixed="all"), ["scene.materials", "non-empty list"]),
    (lambda m: msslib.build_model("golec_cube", 42, STEEL, fixed="all"), ["mesh must be a msslib.mesh.Mesh", "int"]),
    (lambda m: msslib.build_model("golec_cube", m, STEEL, fixed={"plane": ["z", 5.0]}),
     ["scene.boundary[0].select", "selects no node"]),
    (lambda m: msslib.build_model("golec_cube", m, STEEL, fixed="all", stiffness=2), ["scene.model.stiffness",
                                                                                        "unknown key"]),
    (lambda m: msslib.build_model("lloyd_tetrahedron", m, STEEL, fixed="all"), ["needs tetra cells", "hexahedron"]),
    (lambda m: msslib.build_model("golec_cube", m, STEEL, fixed="all", loads={"type": "wind"}),
     ["scene.loads[0].type", "wind"]),
    (lambda m: msslib.solve_static("model.yaml"), ["solve_static", "build_model", "str"]),
    (lambda m: msslib.solve_dynamic(msslib.build_model("golec_cube", m, STEEL, fixed="all")),
     ["scene.solver.dt", "required"]),
    (lambda m: msslib.spring_constants(m), ["spring_constants", "Mesh"]),
    (lambda m: msslib.build_model("golec_cube", msslib.mesh.Mesh(m.points, m.cells[:0], "hexahedron"), STEEL),
     ["scene.geometry.mesh: the mesh has no cells"]),
    (lambda m: msslib.build_model("golec_cube", msslib.mesh.Mesh(m.points * [1, 1, 2], m.cells, "hexahedron"), STEEL,
                                  fixed="all"), ["scene.model: golec_cube", "not cubes"]),
    (lambda m: msslib.write_result("a.nc", "b.nc"), ["write_result", "str and str"]),
    (lambda m: msslib.read_mesh("no_such_mesh.vtu"), ["no_such_mesh.vtu", "not found"]),
])
def test_bad_arguments_are_one_line_errors(call, parts):
    mesh = msslib.mesh.hex_grid(0.1, 0.1, 0.1, 1, 1, 1)
    with pytest.raises((ValueError, FileNotFoundError)) as exc_info:
        call(mesh)
    _one_line(exc_info, *parts)


# ---- progress: rate and time left, quiet for short runs, whole lines in logs ---------------------

class _Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


class _Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.fixture
def clock(monkeypatch):
    c = _Clock()
    monkeypatch.setattr(S.time, "perf_counter", c)
    return c


def test_progress_shows_rate_and_time_left_in_whole_lines(clock):
    log = io.StringIO()
    bar = S.TextProgress("swing", stream=log, total=2000)
    clock.now = 101.0
    bar(0.0, "t = 0 s")  # the first report: the rate is measured from here
    clock.now = 111.0
    bar(0.25, "t = 0.025 s")  # 500 steps in 10 s
    clock.now = 112.0
    bar(0.3)  # within 5 s of the last line: nothing in a log
    bar.close()
    lines = log.getvalue().split("\n")
    assert "\r" not in log.getvalue() and lines[-1] == ""
    assert lines[0].startswith("swing [") and "0.0% t = 0 s (1.0 s)" in lines[0]
    assert "25.0% t = 0.025 s (11.0 s, 50 steps/s, 0:30 left)" in lines[1]
    assert "30.0%" in lines[2] and "(12.0 s, 54.5 steps/s, 0:26 left)" in lines[2]  # close() draws the last state


def test_progress_without_total_and_on_a_terminal(clock):
    tty = _Terminal()
    bar = S.TextProgress("plan", stream=tty)
    clock.now = 100.6
    bar(0.1)
    clock.now = 3700.6
    bar(0.5)  # 40 % in 3600 s: 50 % more take 4500 s
    bar.close()
    out = tty.getvalue()
    assert out.count("\r") == 3 and out.endswith("\n")
    assert "(3600.6 s, 0.0111 %/s, 1:15:00 left)" in out


def test_short_runs_stay_quiet(clock):
    log = io.StringIO()
    bar = S.TextProgress("quick", stream=log)
    for i in range(1, 5):
        clock.now = 100.0 + 0.1 * i
        bar(i / 4)
    bar.close()
    assert log.getvalue() == ""

"""plan chooses its default levels within a time limit, from an estimate of the dofs, memory and
time of every level and of the reference made before anything runs, and prints its progress
with the time left."""

import pytest
import yaml

from msslib import mesh as M
from msslib import planning
from msslib.cli import main as cli
from msslib.mesh.refine import uniform
from msslib.planning import reference as ref
from msslib.planning.reference import solve_setup
from msslib.scene import load_scene, prepare

SCENE = {"name": "block", "geometry": {"generator": "tet_grid",
                                       "args": {"lx": 0.1, "ly": 0.02, "lz": 0.02, "nx": 5, "ny": 1, "nz": 1}},
         "materials": [{"E": 1.0e5, "nu": 0.3}], "model": "fem_linear",
         "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
         "loads": [{"type": "traction", "select": {"plane": ["x", 0.1]}, "traction": [0.0, 0.0, -10.0]}],
         "solver": {"type": "static", "load_steps": 1}}


def test_level_sizes_are_the_refined_meshes_and_the_quadratic_dofs():
    mesh = M.tet_grid(0.1, 0.02, 0.02, 5, 1, 1)
    sizes = ref.level_sizes(mesh, [1, 2])
    assert sizes == {1: mesh.n_nodes, 2: uniform(mesh, 1).n_nodes, 3: uniform(mesh, 2).n_nodes}
    # the quadratic reference of a level has the nodes of the level above as dofs
    setup = prepare(load_scene(SCENE))
    assert solve_setup(setup, order=2, law=None).stats["n_dofs"] == 3 * sizes[2]


def test_the_estimate_grows_with_the_levels_and_counts_the_reference_below_the_top():
    setup = prepare(load_scene(SCENE))
    one = ref.estimate(setup, [1], repeats=1)
    three = ref.estimate(setup, [1, 2, 3], repeats=1)
    assert sorted(three["levels"]) == [1, 2, 3] and sorted(one["levels"]) == [1]
    lv = three["levels"]
    assert lv[1]["reference_dofs"] < lv[2]["reference_dofs"] < lv[3]["reference_dofs"]
    assert lv[3]["memory_bytes"] > lv[2]["memory_bytes"]
    # the reference on levels 1, 2, 3, every model on every level twice (one repeat, one warm-up)
    expect = sum(lv[k]["reference_s"] for k in (1, 2, 3)) + 2 * sum(lv[k]["models_s"] for k in (1, 2, 3))
    assert three["total_s"] == pytest.approx(expect, rel=1e-12)
    # a faster machine never lowers the floor; a slower one raises the estimate
    slow = ref.estimate(setup, [1, 2, 3], repeats=1, calibration=10 * ref.TIME_RATE)
    assert slow["total_s"] == pytest.approx(10 * three["total_s"], rel=1e-12)
    assert ref.estimate(setup, [1, 2, 3], repeats=1, calibration=ref.TIME_RATE / 10)["total_s"] == three["total_s"]


def test_levels_are_dropped_from_the_top_until_the_estimate_fits(tmp_path):
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    levels, est, lines = planning.levels_within(str(scene), 1e6, repeats=1, calibrate=False)
    assert levels == (1, 2, 3) and lines[0].startswith("time limit 1e+06 s (--time-limit): measuring levels 1,2,3")
    full = est["total_s"]
    two = ref.estimate(prepare(load_scene(SCENE)), [1, 2], repeats=1, n_models=len(planning.MODELS["tetra"]))["total_s"]
    levels, est, lines = planning.levels_within(str(scene), (two + full) / 2, repeats=1, calibrate=False)
    assert levels == (1, 2) and est["total_s"] == pytest.approx(two) and "(level 3 would exceed it)" in lines[0]
    levels, _, lines = planning.levels_within(str(scene), 1e-9, repeats=1, calibrate=False)
    assert levels == (1,) and "(levels 2,3 would exceed it)" in lines[0]
    assert any("level 3: models" in ln and "GB" in ln for ln in planning.levels_within(
        str(scene), 1e6, repeats=1, calibrate=False)[2])
    with pytest.raises(ValueError, match="time_limit must be a finite number of seconds > 0, got 0"):
        planning.levels_within(str(scene), 0)


def test_progress_lines_carry_the_elapsed_time_and_the_time_left():
    lines, now = [], [100.0]
    say = planning.with_eta(lines.append, 60.0, clock=lambda: now[0])
    now[0] = 110.0
    say("level 1 done")
    now[0] = 175.0
    say("level 3 done")
    assert lines == ["level 1 done  [10 s elapsed, about 50 s left]", "level 3 done  [75 s elapsed, past the estimate]"]


@pytest.mark.parametrize("args, words", [
    (["--time-limit", "0"], ["--time-limit", "> 0", "got 0.0"]),
    (["--time-limit", "nan"], ["--time-limit", "got nan"]),
    (["--time-limit", "10", "--levels", "1,2"], ["--time-limit", "--levels"]),
])
def test_plan_refuses_a_bad_time_limit_in_one_line(tmp_path, capsys, monkeypatch, args, words):
    def refuse(*a, **k):
        raise AssertionError("measured before the arguments were checked")

    monkeypatch.setattr(planning, "levels_within", refuse)
    monkeypatch.setattr(planning, "measure_front", refuse)
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    code = cli(["plan", str(scene), "--max-error", "0.2", *args])
    err = capsys.readouterr().err
    assert code != 0 and err.count("\n") == 1 and err.startswith("msslib: error:"), err
    for w in words:
        assert w in err, err


def test_plan_with_the_default_levels_prints_the_limit_and_its_estimate(tmp_path, capsys):
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    code = cli(["plan", str(scene), "--max-error", "0.9", "--repeats", "1", "--time-limit", "1e-9"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert out.startswith("time limit 1e-09 s (--time-limit): measuring levels 1, estimated ")
    assert "(levels 2,3 would exceed it)" in out.splitlines()[0]
    assert "elapsed, " in err and "choice: " in out

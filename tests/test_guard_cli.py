"""Inputs are never destroyed and outputs are all-or-nothing (the command line and msslib.results.netcdf).

Every refused command must exit with 1 and print exactly one line ``msslib: error: ...`` naming the
paths involved; afterwards every file of the directory is byte-identical and no temporary file is
left.
"""

from __future__ import annotations

import errno
import hashlib
import os
import signal
import subprocess
import sys
import textwrap

import pytest
import yaml

from cli_helpers import assert_refused
from cli_helpers import run_cli as _cli
from msslib import cli
from msslib.results import paraview
from msslib import experiment as EXP
from msslib import mesh as M
from msslib.results import StagedOutputs, read_result, remove_stale_temporaries, write_result, write_text
from msslib.scene import run_scene
from scene_helpers import pressed_cube

SCENE = pressed_cube("guard")
EXPERIMENT = {"paper": "golec", "scene": SCENE, "cases": {"press": {}},
              "models": {"mss": {"model": "golec_cube"}, "fem": {"model": "fem_linear"}}, "reference": "fem"}


# ---- helpers -------------------------------------------------------------------------------------

def _snapshot(directory):
    """name -> sha256 of every file below ``directory`` (symbolic links: their target)."""
    out = {}
    for root, _, files in os.walk(directory):
        for name in files:
            path = os.path.join(root, name)
            key = os.path.relpath(path, directory)
            if os.path.islink(path):
                out[key] = "link:" + os.readlink(path)
            else:
                with open(path, "rb") as f:
                    out[key] = hashlib.sha256(f.read()).hexdigest()
    return out


def _temporaries(directory):
    return sorted(name for root, _, files in os.walk(directory) for name in files
                  if "msslib-tmp" in name or "msslib-bak" in name or name.endswith(".tmp"))


@pytest.fixture(scope="module")
def result_ds():
    return run_scene(SCENE, progress=False)


@pytest.fixture
def work(tmp_path, result_ds):
    """A directory with a scene, a mesh file, a scene reading it, an old result, a VTU file and an
    experiment with its runs."""
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(SCENE))
    M.write_vtu(tmp_path / "mesh.vtu", M.hex_grid(0.1, 0.1, 0.1, 2, 2, 2))
    (tmp_path / "mesh_scene.yaml").write_text(yaml.safe_dump({**SCENE, "geometry": {"file": "mesh.vtu"}}))
    write_result(tmp_path / "old.nc", result_ds)
    (tmp_path / "old.vtu").write_text("old vtu\n")
    (tmp_path / "exp.yaml").write_text(yaml.safe_dump(EXPERIMENT))
    (tmp_path / "runs").mkdir()
    for case, model in EXP.runs(EXP.load_experiment(tmp_path / "exp.yaml")):
        write_result(tmp_path / "runs" / f"{case}__{model}.nc", result_ds)
    (tmp_path / "paper.md").write_text("# Title\n\ntext\n")
    return tmp_path


# ---- an output is never an input, nor another output ---------------------------------------------

def _refusals(d):
    scene, mesh_scene, old, exp = d / "scene.yaml", d / "mesh_scene.yaml", d / "old.nc", d / "exp.yaml"
    (d / "sub").mkdir(exist_ok=True)
    os.symlink(scene, d / "scene_link.yaml")
    os.link(scene, d / "scene_hard.yaml")
    run = d / "runs" / "press__mss.nc"
    return {
        "run --out scene": (["run", scene, "--out", scene], [scene]),
        "run --out scene, other spelling": (["run", scene, "--out", d / "sub" / ".." / "scene.yaml"], [scene]),
        "run --out symlink to scene": (["run", scene, "--out", d / "scene_link.yaml"], ["scene_link.yaml", scene]),
        "run --out hard link of scene": (["run", scene, "--out", d / "scene_hard.yaml"], ["scene_hard.yaml", scene]),
        "run --vtu scene": (["run", scene, "--out", d / "new.nc", "--vtu", scene], [scene]),
        "run --vtu equals --out": (["run", scene, "--out", old, "--vtu", old], [old, "same file"]),
        "run --out mesh file": (["run", mesh_scene, "--out", d / "mesh.vtu"], ["mesh.vtu", "mesh file"]),
        "run --vtu mesh file": (["run", mesh_scene, "--out", d / "new.nc", "--vtu", d / "mesh.vtu"],
                                ["mesh.vtu", "mesh file"]),
        "vtu --out result": (["vtu", old, "--out", old], [old]),
        "experiment run --out experiment": (["experiment", "run", exp, "--case", "press", "--model", "mss",
                                             "--out", exp], [exp]),
        "experiment compare --table experiment": (["experiment", "compare", exp, "--results", d / "runs",
                                                   "--out", d / "cmp.nc", "--table", exp], [exp, "table"]),
        "experiment compare --out a run": (["experiment", "compare", exp, "--results", d / "runs", "--out", run],
                                           [run, "run"]),
        "experiment compare --table equals --out": (["experiment", "compare", exp, "--results", d / "runs",
                                                     "--out", d / "cmp.nc", "--table", d / "cmp.nc"],
                                                    ["cmp.nc", "same file"]),
        "plan --save scene": (["plan", scene, "--max-error", "0.1", "--save", scene], [scene, "--save"]),
        "plan --save equals --front": (["plan", scene, "--max-error", "0.1", "--front", old, "--save", old],
                                       [old, "--front"]),
        "run --out /dev/null": (["run", scene, "--out", os.devnull], [os.devnull, "not a regular file"]),
    }


REFUSAL_NAMES = [
    "run --out scene", "run --out scene, other spelling", "run --out symlink to scene",
    "run --out hard link of scene", "run --vtu scene", "run --vtu equals --out", "run --out mesh file",
    "run --vtu mesh file", "vtu --out result", "experiment run --out experiment",
    "experiment compare --table experiment", "experiment compare --out a run",
    "experiment compare --table equals --out", "plan --save scene", "plan --save equals --front",
    "run --out /dev/null",
]


@pytest.mark.parametrize("case", REFUSAL_NAMES)
def test_output_that_is_an_input_is_refused(work, capsys, monkeypatch, case):
    argv, names = _refusals(work)[case]
    monkeypatch.setattr("msslib.scene.run_scene", lambda *a, **k: pytest.fail("ran before refusing"))
    before = _snapshot(work)
    code, err = _cli(capsys, *argv)
    assert_refused(code, err, *names)
    assert _snapshot(work) == before
    assert _temporaries(work) == []


def test_refusal_cases_are_all_listed(work):
    assert sorted(_refusals(work)) == sorted(REFUSAL_NAMES)


# ---- several outputs: all or nothing -------------------------------------------------------------

@pytest.mark.parametrize("failure", [
    OSError(errno.ENOSPC, "No space left on device"),
    RuntimeError("NetCDF: HDF error"),
])
def test_run_failing_vtu_keeps_old_result(work, capsys, monkeypatch, failure):
    out, vtu = work / "old.nc", work / "old.vtu"
    seen = []

    def failing_vtu(tmp, ds):
        seen.append(tmp)
        assert any(n.startswith(".old.nc.msslib-tmp-") for n in os.listdir(work))  # the new result is staged
        assert _snapshot(work)["old.nc"] == before["old.nc"]  # the old one is still in place
        if isinstance(failure, OSError):
            raise OSError(failure.errno, failure.strerror, str(tmp))
        raise RuntimeError(f"{failure}: {tmp}")

    monkeypatch.setattr(paraview, "write_state", failing_vtu)
    before = _snapshot(work)
    code, err = _cli(capsys, "run", work / "scene.yaml", "--out", out, "--vtu", vtu, "--quiet")
    assert_refused(code, err, vtu, str(failure.strerror if isinstance(failure, OSError) else failure))
    assert len(seen) == 1 and "msslib-tmp" in seen[0].name  # the writer was given a temporary file
    assert _snapshot(work) == before
    assert _temporaries(work) == []


def test_run_writes_both_outputs(work, capsys):
    out, vtu = work / "new.nc", work / "new.vtu"
    code, err = _cli(capsys, "run", work / "scene.yaml", "--out", out, "--vtu", vtu, "--quiet")
    assert code == 0, err
    assert read_result(out).attrs["model"] == "golec_cube"
    assert M.read(vtu).n_nodes == 27
    assert _temporaries(work) == []


def test_run_all_failing_run_writes_no_result(work, capsys, monkeypatch):
    out_dir = work / "runs"
    real_run = EXP.run
    calls = []

    def second_fails(exp, case, model, **kwargs):
        calls.append(model)
        if len(calls) == 2:
            raise ValueError(f"boom in {model}")
        return real_run(exp, case, model, **kwargs)

    monkeypatch.setattr(EXP, "run", second_fails)
    before = _snapshot(work)
    code, err = _cli(capsys, "experiment", "run-all", work / "exp.yaml", "--out-dir", out_dir, "--quiet")
    assert_refused(code, err, "boom in")
    assert len(calls) == 2
    assert _snapshot(work) == before  # the first run's result was not put in place alone
    assert _temporaries(work) == []


def test_compare_failing_table_keeps_old_comparison(work, capsys, monkeypatch):
    exp, cmp, table = work / "exp.yaml", work / "cmp.nc", work / "table.md"
    code, err = _cli(capsys, "experiment", "compare", exp, "--results", work / "runs", "--out", cmp, "--table", table)
    assert code == 0, err
    before = _snapshot(work)
    monkeypatch.setattr(EXP, "markdown_table", lambda ds: 42)  # not text: writing the table fails
    code, err = _cli(capsys, "experiment", "compare", exp, "--results", work / "runs", "--out", cmp, "--table", table)
    assert_refused(code, err, table)
    assert _snapshot(work) == before
    assert _temporaries(work) == []


@pytest.mark.parametrize("before, error", [
    # a.txt is replaced first, then put back
    pytest.param({"a.txt": "old a\n", "b.txt": "old b\n"}, PermissionError(errno.EACCES, "Permission denied"),
                 id="replaced_files_put_back"),
    # a.txt did not exist before: the new one is removed
    pytest.param({"b.txt": "old b\n"}, OSError(errno.EIO, "I/O error"), id="new_file_removed"),
])
def test_commit_restores_the_directory_when_a_later_rename_fails(tmp_path, monkeypatch, before, error):
    for name, text in before.items():
        (tmp_path / name).write_text(text)
    real_replace = os.replace

    def replace(src, dst, *args, **kwargs):
        if os.path.basename(dst) == "b.txt":
            raise type(error)(error.errno, error.strerror, str(dst))
        return real_replace(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(type(error), match="b.txt") as info:
        with StagedOutputs() as out:
            out.write_text(tmp_path / "a.txt", "new a\n")
            out.write_text(tmp_path / "b.txt", "new b\n")
    assert "msslib-tmp" not in str(info.value)
    monkeypatch.undo()
    assert {p.name: p.read_text() for p in tmp_path.iterdir()} == before


def test_error_inside_the_block_touches_nothing(tmp_path):
    a = tmp_path / "a.txt"
    a.write_text("old\n")
    with pytest.raises(ZeroDivisionError):
        with StagedOutputs() as out:
            out.write_text(a, "new\n")
            out.write_text(tmp_path / "b.txt", "new\n")
            1 / 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    assert a.read_text() == "old\n"


def test_write_error_names_destination_not_temporary(tmp_path, result_ds, monkeypatch):
    import xarray as xr

    def fails(self, path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(xr.Dataset, "to_netcdf", fails)
    target = tmp_path / "run.nc"
    with pytest.raises(OSError) as info:
        write_result(target, result_ds)
    assert info.value.filename == str(target)
    assert "run.nc" in str(info.value) and "msslib-tmp" not in str(info.value)
    assert os.listdir(tmp_path) == []


# ---- SIGTERM and killed runs ---------------------------------------------------------------------

def _python(code, *args):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code), *map(str, args)],
                          capture_output=True, text=True, timeout=120)


def test_sigterm_during_a_staged_write_removes_temporaries(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old\n")
    proc = _python("""
        import os, signal, sys, time
        from pathlib import Path
        from msslib.results import StagedOutputs
        d = Path(sys.argv[1])
        with StagedOutputs() as out:
            out.write_text(d / "out.txt", "new\\n")
            out.write_text(d / "second.txt", "new\\n")
            assert len([p for p in os.listdir(d) if "msslib-tmp" in p]) == 2
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(30)
        print("not reached")
    """, tmp_path)
    assert proc.returncode == -signal.SIGTERM, proc.stderr  # still ends as killed by SIGTERM
    assert "not reached" not in proc.stdout
    assert sorted(os.listdir(tmp_path)) == ["out.txt"]
    assert target.read_text() == "old\n"


def test_sigterm_during_cli_run_keeps_old_outputs(work):
    out, vtu = work / "old.nc", work / "old.vtu"
    before = _snapshot(work)
    proc = _python("""
        import os, signal, sys, time
        from msslib import cli
        from msslib.results import paraview

        def killed(tmp, ds):  # SIGTERM arrives while both outputs are staged
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(30)

        paraview.write_state = killed
        sys.exit(cli.main(sys.argv[1:]))
    """, "run", work / "scene.yaml", "--out", out, "--vtu", vtu, "--quiet")
    assert proc.returncode == 143, proc.stderr
    assert proc.stderr.splitlines() == ["msslib: terminated"]
    assert _snapshot(work) == before
    assert _temporaries(work) == []


def _dead_pid():
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_temporaries_of_killed_runs_are_removed(tmp_path, result_ds):
    dead, alive = _dead_pid(), os.getppid()
    stale = tmp_path / f".run.nc.msslib-tmp-{dead}-0123abcd"
    stale_inner = tmp_path / f"..run.nc.msslib-tmp-{dead}-0123abcd.{'f' * 32}.tmp"
    live = tmp_path / f".run.nc.msslib-tmp-{alive}-89abcdef"
    other_target = tmp_path / f".other.nc.msslib-tmp-{dead}-0123abcd"
    user_file = tmp_path / ".run.nc.msslib-tmp-notes"
    for p in (stale, stale_inner, live, other_target, user_file):
        p.write_text("partial")
    write_result(tmp_path / "run.nc", result_ds)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted(["run.nc", live.name, other_target.name, user_file.name])
    assert remove_stale_temporaries(tmp_path / "other.nc") == [other_target]
    assert remove_stale_temporaries(tmp_path / "other.nc") == []


def test_temporary_name_carries_pid(tmp_path):
    out = StagedOutputs()
    tmp = out.stage(tmp_path / "x.txt")
    try:
        assert tmp.parent == tmp_path
        assert tmp.name.startswith(f".x.txt.msslib-tmp-{os.getpid()}-")
    finally:
        out.discard()
    assert os.listdir(tmp_path) == []
    write_text(tmp_path / "x.txt", "done\n")
    assert os.listdir(tmp_path) == ["x.txt"]


def test_every_warning_is_one_line_naming_its_origin(monkeypatch, capsys):
    import warnings as _warnings

    from msslib.errors import MsslibWarning

    def noisy(args):
        _warnings.warn("overflow encountered in dot\n  sqnorm = x.dot(x)", RuntimeWarning)
        _warnings.warn("3 nodes merged", MsslibWarning)
        for _ in range(3):  # a model built again says the same: shown once
            with _warnings.catch_warnings():
                _warnings.simplefilter("always")
                _warnings.warn("3 nodes merged", MsslibWarning)
        _warnings.warn("4 nodes merged", MsslibWarning)
        return 0

    parser = cli.build_parser()
    args = parser.parse_args(["validate", "x.yaml"])
    monkeypatch.setattr(cli, "build_parser", lambda: type("P", (), {"parse_args": lambda self, argv: args})())
    monkeypatch.setattr(args, "func", noisy)
    assert cli.main(["validate", "x.yaml"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == ["msslib: warning: overflow encountered in dot sqnorm = x.dot(x) (RuntimeWarning in test_guard_cli.py)",
                   "msslib: warning: 3 nodes merged", "msslib: warning: 4 nodes merged"]

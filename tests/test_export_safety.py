"""What users take away from ``msslib export`` is safe to use.

* The MuJoCo model of the README's quick start (a dynamic scene stepped by implicit Euler at 2 ms)
  steps at a time step MuJoCo integrates stably: MuJoCo run at the scene's 2 ms blows up within
  50 ms, at the written step it stays finite and bounded for the scene's whole t_end, and its final
  sag matches msslib's own dynamic result and the static equilibrium.
* An export into a folder that holds a previous export removes the files that export owned and the
  new one does not write (its manifest says which), and nothing else: a user's file stays, and one
  that would be overwritten stops the export.
* A failed export leaves nothing behind, not even the folder it was to create.
"""

from __future__ import annotations

import errno
import hashlib
import json
import math
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml
from test_readme import _quick_start_blocks

from msslib import cli
from msslib.export import simulators as export_simulators
from msslib.export import files as export_files
from msslib import export
from msslib.solvers import static_solve

_SCENES = yaml.safe_load((Path(__file__).parent / "data" / "export_scenes.yaml").read_text())
BAUDET, SQUARE = _SCENES["baudet"], _SCENES["square"]


def _scene_file(folder: Path, scene: dict) -> Path:
    path = folder / f"{scene['name']}.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    return path


def _cli(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    return code, capsys.readouterr().err


def _snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def _one_error_line(code, err, *names):
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1 and lines[0].startswith("msslib: error:"), err
    for name in names:
        assert str(name) in lines[0], (name, err)


# ---- the time step of the MuJoCo model ---------------------------------------------------------


def _positions(m, d, exp):
    x = exp.points + exp.prescribed
    for j in range(m.njnt):
        node, axis = re.fullmatch(r"node(\d+)_([xyz])", m.joint(j).name).groups()
        x[int(node), "xyz".index(axis)] += d.qpos[m.jnt_qposadr[j]]
    return x


def test_readme_quick_start_mujoco_model_runs_stably_for_the_whole_scene(tmp_path, monkeypatch):
    mujoco = pytest.importorskip("mujoco")
    (kind, body), _ = _quick_start_blocks()
    assert kind == "bash" and "msslib export bar.yaml --out bar_export/" in body
    proc = subprocess.run(["bash", "-ec", f'export PATH="{Path(sys.executable).parent}:$PATH"\n{body}'],
                          cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    # the export says which step it wrote, and why
    (warning,) = [line for line in proc.stderr.splitlines() if "mjcf output steps at" in line]
    assert warning.startswith("msslib: warning: bar:") and "dt = 0.002 s" in warning and "stable only below" in warning
    path = tmp_path / "bar_export" / "bar_mujoco.xml"
    assert re.search(r"<!-- Time step: timestep [0-9.e-]+ s = 0.5 x the stability limit, NOT the scene's dt = 0.002 s",
                     path.read_text())

    exp = export.build(tmp_path / "bar.yaml")
    dt, t_end = exp.scene.solver["dt"], exp.scene.solver["t_end"]
    assert (dt, t_end) == (2.0e-3, 0.5)
    tip = np.isclose(exp.points[:, 0], exp.points[:, 0].max())
    # msslib's own answers: the dynamic run of the quick start at t_end, and the static equilibrium
    from msslib.results import read_result

    ds = read_result(tmp_path / "bar.nc")
    assert float(ds["time"].values[-1]) == pytest.approx(t_end)
    sag_dynamic = float(ds["displacement"].values[tip, 2].mean())
    res = static_solve(exp.model, exp.model.x0, load_steps=4, tol=1e-10)
    sag_static = float((res.x.reshape(-1, 3) - exp.points)[tip, 2].mean())
    assert -0.06 < sag_static < -0.03  # about 5 cm under gravity

    m = mujoco.MjModel.from_xml_path(str(path))
    h = m.opt.timestep
    assert h < dt / 10
    bad = int(mujoco.mjtWarning.mjWARN_BADQACC)  # MuJoCo's "unstable" flag (it then resets the state)
    # at the scene's own step MuJoCo blows up at once (and says so in MUJOCO_LOG.TXT, in the working folder)
    monkeypatch.chdir(tmp_path)
    m.opt.timestep = dt
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d, 25)
    assert d.warning[bad].number > 0  # within 25 steps (50 ms); at t = 8 ms on this model
    # at the written step: finite and bounded for the whole simulated time
    m.opt.timestep = h
    d = mujoco.MjData(m)
    n = math.ceil(t_end / h - 1e-9)
    peak = 0.0
    for chunk in np.array_split(np.arange(n), 100):
        mujoco.mj_step(m, d, len(chunk))
        assert np.isfinite(d.qpos).all() and d.warning[bad].number == 0, d.time
        peak = max(peak, float(np.abs(d.qpos).max()))
    assert d.time == pytest.approx(t_end, abs=h)
    assert peak < 2.5 * abs(sag_static)  # a damped swing: overshoot below twice the static sag
    sag = float((_positions(m, d, exp) - exp.points)[tip, 2].mean())
    assert sag == pytest.approx(sag_dynamic, rel=0.05)  # 49.3 mm and 48.9 mm
    assert sag == pytest.approx(sag_static, rel=0.10)  # 47.9 mm: still swinging a little at t_end


def test_a_step_below_half_the_limit_is_kept(tmp_path):
    scene = {**SQUARE, "name": "slow", "solver": {"type": "dynamic", "method": "implicit_euler", "dt": 1.0e-6,
                                                  "t_end": 1.0e-5}}
    exp = export.build(scene)
    step = export_simulators.mjcf_time_step(exp)
    assert step.step == 1.0e-6 and not step.reduced and step.limit > 2.0e-6
    text = export_simulators.mjcf_text(exp)
    assert float(ET.fromstring(text).find("option").get("timestep")) == 1.0e-6
    assert "<!-- Time step: timestep 1e-06 s, the scene's dt, at most 0.5 x the stability limit" in text


# ---- a folder that holds a previous export -----------------------------------------------------


def _manifest(folder: Path, stem: str) -> dict:
    return json.loads((folder / f"{stem}{export_files.MANIFEST_SUFFIX}").read_text())


def test_a_new_export_removes_the_previous_exports_files_and_nothing_else(tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("my notes\n")
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json,sofa")
    assert code == 0, err
    first = sorted(p.name for p in out.iterdir())
    assert len(first) == 1 + 7 + 1 + 1 + 1  # notes, 7 tables, JSON, SOFA, manifest
    doc = _manifest(out, "baudet_bar")
    assert sorted(doc["files"]) == sorted(set(first) - {"notes.txt", "baudet_bar.export-manifest.json"})
    for name, digest in doc["files"].items():
        assert hashlib.sha256((out / name).read_bytes()).hexdigest() == digest
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "json")
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["baudet_bar.export-manifest.json", "baudet_bar.json",
                                                     "notes.txt"]
    assert (out / "notes.txt").read_text() == "my notes\n"
    assert list(_manifest(out, "baudet_bar")["files"]) == ["baudet_bar.json"]


def test_a_user_file_is_never_overwritten(tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    out = tmp_path / "out"
    out.mkdir()
    (out / "baudet_bar.json").write_text('{"mine": true}\n')
    before = _snapshot(out)
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json")
    _one_error_line(code, err, "baudet_bar.json", "not written by msslib export")
    assert _snapshot(out) == before  # nothing written, nothing removed
    # an exported file the user has edited since is theirs now
    (out / "baudet_bar.json").unlink()
    assert _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json")[0] == 0
    with open(out / "baudet_bar_springs.csv", "a") as f:
        f.write("# checked by hand\n")
    before = _snapshot(out)
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json")
    _one_error_line(code, err, "baudet_bar_springs.csv", "has changed since")
    assert _snapshot(out) == before
    # and is not removed when the next export no longer writes it (said in a warning)
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "json")
    assert code == 0, err
    assert "baudet_bar_springs.csv" in err and "left in place" in err
    assert (out / "baudet_bar_springs.csv").read_text().endswith("# checked by hand\n")
    assert not (out / "baudet_bar_nodes.csv").exists()
    # a file that is not a manifest in the manifest's place
    (out / "other.export-manifest.json").write_text("not json\n")
    code, err = _cli(capsys, "export", scene, "--out", out / "other", "--format", "json")
    _one_error_line(code, err, "other.export-manifest.json")


def test_a_manifest_cannot_remove_files_outside_its_own_listing(tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("keep\n")
    digest = hashlib.sha256(victim.read_bytes()).hexdigest()
    (out / "baudet_bar.export-manifest.json").write_text(json.dumps(
        {"schema": export_files.MANIFEST_SCHEMA, "files": {"../victim.txt": digest, str(victim): digest}}))
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "json")
    assert code == 0, err
    assert victim.read_text() == "keep\n"


def test_shared_c_headers_stay_while_another_export_lists_them(tmp_path, capsys):
    a, b = _scene_file(tmp_path, BAUDET), _scene_file(tmp_path, {**SQUARE, "name": "sq"})
    out = tmp_path / "out"
    out.mkdir()
    assert _cli(capsys, "export", a, "--out", f"{out}/", "--format", "json,c")[0] == 0
    assert _cli(capsys, "export", b, "--out", f"{out}/", "--format", "json,c")[0] == 0  # same headers, theirs
    headers = sorted(p.name for p in export.c_header_paths())
    assert _cli(capsys, "export", a, "--out", f"{out}/", "--format", "json")[0] == 0
    assert sorted(p.name for p in out.glob("*.h")) == headers  # the square's export still owns them
    assert _cli(capsys, "export", b, "--out", f"{out}/", "--format", "json")[0] == 0
    assert not list(out.glob("*.h"))


# ---- a failed export leaves nothing ------------------------------------------------------------


def test_a_failed_export_leaves_no_folder(tmp_path, capsys, monkeypatch):
    scene = _scene_file(tmp_path, BAUDET)

    def fail(_exp):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(export_simulators, "sofa_text", fail)
    code, err = _cli(capsys, "export", scene, "--out", f"{tmp_path / 'new'}/", "--format", "csv,json,sofa")
    _one_error_line(code, err, str(tmp_path / "new" / "baudet_bar.scn"), "No space left on device")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["baudet_bar.yaml"]  # no folder, no temporary one
    # interrupted too
    def interrupt(_exp):
        raise KeyboardInterrupt

    monkeypatch.setattr(export_simulators, "sofa_text", interrupt)
    with pytest.raises(KeyboardInterrupt):
        export_files.write_outputs(export.build(scene), tmp_path / "new" / "deep" / "b",
                                   export_files.output_paths(export.build(scene), tmp_path / "new" / "deep" / "b",
                                                             ("json", "sofa")))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["baudet_bar.yaml"]


def test_a_new_folder_appears_whole(tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    dead = tmp_path / ".new.msslib-tmp-999999999-0123abcd"  # left by an export killed outright
    (dead / "x").mkdir(parents=True)
    code, err = _cli(capsys, "export", scene, "--out", f"{tmp_path / 'new'}/", "--format", "json,mjcf")
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["baudet_bar.yaml", "new"]
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == [
        "baudet_bar.export-manifest.json", "baudet_bar.json", "baudet_bar_mujoco.xml"]
    doc = _manifest(tmp_path / "new", "baudet_bar")
    assert sorted(doc["files"]) == ["baudet_bar.json", "baudet_bar_mujoco.xml"] and doc["formats"] == ["json", "mjcf"]
    assert not os.path.lexists(dead)

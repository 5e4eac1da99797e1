"""Runs: the first run of a model family, which compiles its numba kernels (seconds to a minute),
says so in one line and keeps the compile out of the progress rate; a later run, which loads the
kernels from numba's cache, says nothing.  And ``plan --repeats`` has an upper bound."""

from __future__ import annotations

import io
import os
import subprocess
import sys

import pytest
import yaml

from msslib import cli, planning
from msslib.scene import progress as P
from scene_helpers import pulled_sheet

SHEET = pulled_sheet()
NOTICE = "msslib: compiling the lloyd kernels (first run only, cached afterwards) ..."


def _run(tmp_path, cache, *extra):
    """stderr of ``python -m msslib run`` in a fresh process with numba's cache in ``cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-m", "msslib", "run", str(tmp_path / "sheet.yaml"),
                          "--out", str(tmp_path / "sheet.nc"), *extra],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    return out.stderr


def test_first_run_says_it_compiles_and_a_cached_run_does_not(tmp_path):
    (tmp_path / "sheet.yaml").write_text(yaml.safe_dump(SHEET))
    cache = tmp_path / "numba-cache"  # empty: everything is compiled
    first = _run(tmp_path, cache)
    assert first.splitlines().count(NOTICE) == 1, first
    assert first.splitlines()[0] == NOTICE  # before anything else: the compile is what takes the time
    assert any(cache.rglob("*.nbi"))  # numba did cache the kernels
    second = _run(tmp_path, cache)  # loaded from the cache: nothing compiled, nothing said
    assert "compiling" not in second, second
    assert "sheet: lloyd_square, 9 nodes" in second
    quiet = _run(tmp_path, tmp_path / "another-cache", "--quiet")  # compiles, but --quiet says nothing
    assert quiet == "", quiet


class _Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_rate_starts_again_after_a_compile(monkeypatch):
    clock = _Clock()
    monkeypatch.setattr(P.time, "perf_counter", clock)
    stream = _Terminal()
    bar = P.TextProgress("run", stream=stream, total=100, unit="steps", delay=0.0, interval=0.0)
    bar(0.0)  # step 0 at t = 0
    clock.t += 30.0  # a 30 s compile during step 1
    bar.restart_rate()
    bar(0.01)
    clock.t += 1.0  # then 10 steps in 1 s
    bar(0.11)
    # 10 steps/s since the compile, 89 steps left: 0:09 (with the compile counted it would be
    # 11 steps in 31 s, 0.355 steps/s and 4:11 left)
    assert stream.getvalue().split("\r")[-1].rstrip().endswith("(31.0 s, 10 steps/s, 0:09 left)"), stream.getvalue()


def test_note_ends_a_drawn_bar_line_first():
    stream = _Terminal()
    bar = P.TextProgress("run", stream=stream, delay=0.0, interval=0.0)
    bar(0.5)
    bar.note("msslib: compiling the golec kernels (first run only, cached afterwards) ...")
    text = stream.getvalue()
    assert text.startswith("\r") and "\nmsslib: compiling the golec kernels" in text and text.endswith("...\n")


# ---- plan --repeats ----------------------------------------------------------------------------


def test_repeats_has_an_upper_bound(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(planning, "measure_front", lambda *a, **k: pytest.fail("measured before refusing"))
    scene = tmp_path / "sheet.yaml"
    scene.write_text(yaml.safe_dump(SHEET))
    assert planning.MAX_REPEATS == 100
    code = cli.main(["plan", str(scene), "--max-error", "0.05", "--repeats", "101"])
    err = capsys.readouterr().err
    assert code == 1 and err.splitlines() == ["msslib: error: --repeats must be an integer from 1 to 100, got 101"]
    with pytest.raises(ValueError, match="repeats must be an integer from 1 to 100"):
        planning.check_arguments(repeats=101)
    assert planning.check_arguments(repeats=100) == (1, 2, 3)  # the bound itself is allowed
    help_text = " ".join(cli.build_parser()._subparsers._group_actions[0].choices["plan"].format_help().split())
    assert "1 to 100" in help_text and "only lengthen the measurement" in help_text

"""Long ParaView series (``run --vtu OUT.pvd``): every output check, the files of the series
included, runs before the solve, and the checks take a time linear in the number of files (a
series of 10 001 states is checked in a fraction of a second, not in half an hour)."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import yaml

from msslib import cli
from msslib.cli.inputs import check_distinct
from msslib.results import read_result
from msslib.results.paraview import series_files
from msslib.results.staging import StagedOutputs
from scene_helpers import swinging_bar

SWING = swinging_bar(save_every=1)


def _cli(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    return code, capsys.readouterr().err


def _listing(directory):
    return sorted((name, (directory / name).is_dir()) for name in os.listdir(directory))


@pytest.fixture
def no_solve(monkeypatch):
    """The solve fails the test: every refusal here must come before it."""
    monkeypatch.setattr("msslib.scene.run_scene", lambda *a, **k: pytest.fail("the scene was solved before refusing"))


def _refused_before_solve(capsys, tmp_path, *names):
    before = _listing(tmp_path)
    code, err = _cli(capsys, "run", tmp_path / "swing.yaml", "--out", tmp_path / "r.nc", "--vtu", tmp_path / "r.pvd")
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1 and lines[0].startswith("msslib: error:"), err
    for name in names:
        assert name in lines[0], (name, err)
    assert _listing(tmp_path) == before  # nothing written, nothing removed


def test_directory_in_the_way_of_a_series_file_is_refused_before_the_solve(tmp_path, capsys, no_solve):
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump(SWING))
    (tmp_path / "r_0001.vtu").mkdir()
    _refused_before_solve(capsys, tmp_path, "r_0001.vtu", "is a directory", "r.pvd")
    (tmp_path / "r_0001.vtu").rmdir()
    (tmp_path / "r_springs.vtu").mkdir()
    _refused_before_solve(capsys, tmp_path, "r_springs.vtu", "is a directory")


def test_series_file_linked_to_an_input_is_refused_before_the_solve(tmp_path, capsys, no_solve):
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump(SWING))
    os.symlink(tmp_path / "swing.yaml", tmp_path / "r_0003.vtu")
    _refused_before_solve(capsys, tmp_path, "scene file", "swing.yaml", "r_0003.vtu")


class _CountingKey(tuple):
    """A file key that counts how often it is compared for equality: a dict lookup compares only
    keys whose hashes collide, a check of every name against every other compares them all."""
    comparisons = 0

    def __eq__(self, other):
        type(self).comparisons += 1
        return tuple.__eq__(self, other)

    __hash__ = tuple.__hash__


def _comparisons(n_states: int, monkeypatch) -> int:
    """Equality comparisons of file keys made to check the output file and the ``n_states + 2``
    files of a series against each other and the inputs."""
    from msslib.cli import inputs as inputs_module
    real = inputs_module._file_keys
    monkeypatch.setattr(inputs_module, "_file_keys", lambda path: [_CountingKey(k) for k in real(path)])
    directory = os.path.abspath("series-not-written")
    files = [("output file", os.path.join(directory, "r.nc")), *series_files(os.path.join(directory, "r.pvd"),
                                                                              n_states, springs=True)]
    inputs = [("scene file", os.path.join(directory, "scene.yaml")), ("mesh file", os.path.join(directory, "m.vtu"))]
    _CountingKey.comparisons = 0
    check_distinct(files, inputs)
    return _CountingKey.comparisons


def test_checking_a_long_series_takes_linear_time(monkeypatch):
    # counted, not timed (a busy machine made a timed version fail): a check of every name against
    # every other (about 36 min for 10 000 states before) makes about n^2 / 2 = 5e7 comparisons here
    small, large = _comparisons(1_000, monkeypatch), _comparisons(10_001, monkeypatch)
    assert large <= 10 * small + 100, (small, large)
    assert large < 3 * 10_001, large


def test_checking_a_series_still_finds_two_names_of_one_file(tmp_path):
    files = series_files(tmp_path / "r.pvd", 5000, springs=False)
    with pytest.raises(cli.CommandError, match="r_4999.vtu.*the same file"):
        check_distinct([*files, ("copy", tmp_path / "." / "r_4999.vtu")])
    (tmp_path / "m.vtu").write_text("mesh\n")
    os.link(tmp_path / "m.vtu", tmp_path / "r_2500.vtu")  # a hard link: the same file by another name
    with pytest.raises(cli.CommandError, match="r_2500.vtu.*is the mesh file"):
        check_distinct(files, [("mesh file", tmp_path / "m.vtu")])


def test_staging_a_long_series_lists_the_directory_once(tmp_path, monkeypatch):
    # counted, not timed (a timed ratio fails on a busy machine): staging a file looks for the
    # temporaries that dead runs left beside it; listing the directory for every file made staging
    # a series quadratic, so it is listed once per directory and looked up
    from msslib.results import staging

    listings = []
    real = staging._stale_index
    monkeypatch.setattr(staging, "_stale_index", lambda d: listings.append(d) or real(d))
    (tmp_path / "other").mkdir()
    staged = StagedOutputs()
    try:
        for i in range(3000):
            staged.stage(tmp_path / f"r_{i:05d}.vtu", what="VTU file of the series")
        staged.stage(tmp_path / "other" / "r.pvd", what="ParaView collection")
        assert len(listings) == 2, len(listings)  # one per directory
    finally:
        staged.discard()
    assert sorted(os.listdir(tmp_path)) == ["other"] and os.listdir(tmp_path / "other") == []  # all removed


def test_normal_series_is_written_complete(tmp_path, capsys):
    (tmp_path / "swing.yaml").write_text(yaml.safe_dump(SWING))
    (tmp_path / "r_0003.vtu").write_text("an older state\n")  # replaced
    (tmp_path / "r_0040.vtu").write_text("a state of an older, longer series\n")  # left alone
    code, err = _cli(capsys, "run", tmp_path / "swing.yaml", "--out", tmp_path / "r.nc", "--vtu", tmp_path / "r.pvd",
                     "--quiet")
    assert code == 0, err
    n_states = 21  # t_end / dt = 20 steps, every one saved, and the start
    collection = ET.parse(tmp_path / "r.pvd").getroot().find("Collection")
    entries = [(float(d.get("timestep")), d.get("file")) for d in collection]
    assert [name for _, name in entries] == [f"r_{i:04d}.vtu" for i in range(n_states)]
    np.testing.assert_allclose([t for t, _ in entries], np.arange(n_states) * 1.0e-4, rtol=1e-12, atol=1e-15)
    first = meshio.read(tmp_path / "r_0000.vtu")
    np.testing.assert_array_equal(first.point_data["displacement"], 0.0)  # the run starts at rest
    ds = read_result(tmp_path / "r.nc")
    last = meshio.read(tmp_path / f"r_{n_states - 1:04d}.vtu")
    np.testing.assert_array_equal(last.point_data["displacement"], ds["displacement"].transpose("node", "axis").values)
    # gravity pulls every free node down
    assert np.all(last.point_data["displacement"][ds["rest_position"].values[:, 0] > 0, 2] < 0)
    assert (tmp_path / "r_0040.vtu").read_text() == "a state of an older, longer series\n"
    assert "older" not in (tmp_path / "r_0003.vtu").read_text(errors="replace")
    assert (tmp_path / "r_springs.vtu").is_file()
    assert not [n for n in os.listdir(tmp_path) if "msslib-tmp" in n or "msslib-bak" in n]

"""A new export format is one module in :mod:`msslib.export.formats` (its writer and its entry) and
its test: nothing else in msslib learns its name.

The test writes such a module into a temporary folder, makes it part of the format package for its
duration, and runs it through the command line, beside the built-in formats. It declares two
formats: ``npz``, every table of the model as arrays in one NumPy archive (it takes every term by its
own rule), and ``edges``, the springs alone as text lines ``i j k L`` (springs only: written by
default only for models it carries whole, and naming what it leaves out otherwise). The archive is
checked against the CSV tables the same export writes, value for value; the edges against the
springs table.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
import yaml

from cli_helpers import run_cli
from msslib import export
from msslib.export import formats
from msslib.export.text import read_csv

MODULE = '''
import io

import numpy as np

from msslib.export.formats import Format, one_file, text_writer


def _npz(exp, table):
    def write(path):
        arrays = {f"{name}/{c.name}": np.asarray(c.values) for name, t in exp.tables().items() for c in t.columns}
        buffer = io.BytesIO()
        np.savez(buffer, **arrays)
        with open(path, "wb") as f:
            f.write(buffer.getvalue())
    return write


def _edges(exp, table):
    springs = exp.tables()["springs"]
    return text_writer(lambda: "".join(f"{i} {j} {float(k)!r} {float(L)!r}\\n" for i, j, k, L in zip(
        springs["node_i"], springs["node_j"], springs["stiffness"], springs["rest_length"])))


FORMATS = (
    Format("npz", 70, one_file("NumPy archive", ".npz"), _npz, "every table as arrays",
           "every table as arrays STEM.npz (TABLE/COLUMN)", takes=lambda term: True),
    Format("edges", 80, one_file("spring list", "_edges.txt"), _edges, "the springs",
           "the springs as lines 'i j k L' STEM_edges.txt", whole_only=True,
           takes=lambda term: term.kind in ("springs", "external")),
)
'''


def _scene(tmp_path, volume: bool):
    raw = {"name": "block",
           "geometry": {"generator": "hex_grid" if volume else "tet_grid",
                        "args": {"lx": 0.02, "ly": 0.02, "lz": 0.02, "nx": 2, "ny": 2, "nz": 2}},
           "materials": [{"E": 1.0e6, "nu": 0.25, "density": 1000.0}],
           "model": "golec_cube" if volume else "lloyd_tetrahedron",
           "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
           "loads": [{"type": "gravity", "g": [0.0, 0.0, -9.81]}],
           "solver": {"type": "static", "load_steps": 1, "tol": 1e-10}}
    path = tmp_path / ("volume.yaml" if volume else "springs.yaml")
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    return path


@pytest.fixture
def new_formats(tmp_path, monkeypatch):
    """The module, in a folder the format package scans for its duration."""
    folder = tmp_path / "formats"
    folder.mkdir()
    (folder / "arrays_and_edges.py").write_text(textwrap.dedent(MODULE), encoding="utf-8")
    monkeypatch.setattr(formats, "__path__", [*formats.__path__, str(folder)])
    formats.table.cache_clear()
    yield folder
    formats.table.cache_clear()


def test_the_table_and_the_help_take_the_new_formats(new_formats, capsys):
    from msslib import cli

    assert formats.names() == ("csv", "json", "vtu", "mjcf", "sofa", "c", "npz", "edges")
    assert formats.whole_only() == ("mjcf", "sofa", "edges")
    help_text = " ".join(cli.build_parser()._subparsers._group_actions[0].choices["export"].format_help().split())
    assert "npz: every table as arrays STEM.npz" in help_text and "edges: the springs as lines" in help_text


def test_the_new_formats_write_what_the_csv_tables_hold(new_formats, tmp_path, capsys):
    scene = _scene(tmp_path, volume=True)  # Golec's cubes: springs and a volume term
    code, err = run_cli(capsys, "export", scene, "--out", tmp_path / "m", "--format", "csv,npz,edges")
    assert code == 0, err
    # edges does not carry the volume term: the command says so, naming the model and the term
    (warn,) = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert "edges output of model golec_cube does not carry" in warn and "hex_volume" in warn
    exp = export.build(scene)
    assert export.not_carried(exp, "npz") == []
    with np.load(tmp_path / "m.npz") as archive:
        assert {k.split("/")[0] for k in archive.files} == set(exp.tables())
        for name in exp.tables():
            csv = read_csv(tmp_path / f"m_{name}.csv")
            for column in csv.names:
                np.testing.assert_array_equal(archive[f"{name}/{column}"], np.asarray(csv[column]))
    springs = read_csv(tmp_path / "m_springs.csv")
    lines = (tmp_path / "m_edges.txt").read_text(encoding="utf-8").splitlines()
    assert len(lines) == springs.n_rows > 0
    i, j, k, L = lines[7].split()
    assert (int(i), int(j), float(k), float(L)) == (springs["node_i"][7], springs["node_j"][7], springs["stiffness"][7],
                                                    springs["rest_length"][7])
    manifest = (tmp_path / "m.export-manifest.json").read_text(encoding="utf-8")
    assert "m.npz" in manifest and "m_edges.txt" in manifest


def test_a_springs_only_new_format_is_written_by_default_only_when_it_carries_the_model(new_formats, tmp_path,
                                                                                        capsys):
    code, err = run_cli(capsys, "export", _scene(tmp_path, volume=False), "--out", f"{tmp_path / 's'}/")
    assert code == 0, err  # Lloyd's tetrahedra under gravity: springs and loads only
    assert (tmp_path / "s" / "block_edges.txt").is_file() and (tmp_path / "s" / "block.npz").is_file()
    code, err = run_cli(capsys, "export", _scene(tmp_path, volume=True), "--out", f"{tmp_path / 'v'}/")
    assert code == 0, err
    (warn,) = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert "mjcf, sofa and edges not written" in warn and "hex_volume" in warn
    assert (tmp_path / "v" / "block.npz").is_file() and not (tmp_path / "v" / "block_edges.txt").exists()


def test_a_format_declared_twice_is_refused_naming_both_modules(new_formats):
    (new_formats / "again.py").write_text("from msslib.export.formats.builtin import FORMATS\n", encoding="utf-8")
    formats.table.cache_clear()
    with pytest.raises(ValueError, match=r"'csv' is declared twice: in msslib.export.formats.again and "
                                         r"msslib.export.formats.builtin"):
        formats.table()

"""The experiment file and curves file loaders check the type and range of every key and name it, in
one line, on the Python API, through ``msslib experiment`` and through ``python -m experiments.figures``;
the hint printed for missing runs is a command that works as printed."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from msslib.experiment import load_experiment

from test_experiment_figures import CURVES, TINY, _with_figure, _write

ROOT = Path(__file__).resolve().parents[1]


def _with(top: dict) -> str:
    raw = yaml.safe_load(TINY)
    raw.update(top)
    return yaml.safe_dump(raw, sort_keys=False)


BAD_FIGURES = [
    ({"kind": ["comparison"]}, "experiment.figures.column.kind", "['comparison'] is not one of ['comparison']"),
    ({"kind": {"a": 1}}, "experiment.figures.column.kind", "is not one of ['comparison']"),
    ({"columns": [{"title": "a", "case": ["pull"], "variant": "mss"}]},
     "experiment.figures.column.columns[0].case", "['pull'] is not one of ['pull', 'shear']"),
    ({"columns": [{"title": "a", "case": "pull", "variant": {"x": 1}}]},
     "experiment.figures.column.columns[0].variant", "{'x': 1} is not one of ['fem', 'mss']"),
    ({"columns": [{"title": "a", "case": "pull", "variant": "mss", "reference": ["fem"]}]},
     "experiment.figures.column.columns[0].reference", "['fem'] is not one of ['fem', 'mss']"),
    ({"columns": [{"title": 5, "case": "pull", "variant": "mss"}]},
     "experiment.figures.column.columns[0].title", "expected a string (the column's title), got 5"),
    ({"caption": 5}, "experiment.figures.column.caption", "expected a string"),
    ({"caption": " "}, "experiment.figures.column.caption", "empty"),
    ({"panel_width": -2}, "experiment.figures.column.panel_width", "-2.0 is out of range; expected a number above 0"),
    ({"panel_width": float("nan")}, "experiment.figures.column.panel_width", "nan is out of range"),
    ({"panel_height": float("inf")}, "experiment.figures.column.panel_height", "inf is out of range"),
    ({"panel_height": 0}, "experiment.figures.column.panel_height", "0.0 is out of range"),
    ({"panel_width": 1e4}, "experiment.figures.column.panel_width", "at most 20"),
    ({"magnify": 0.0}, "experiment.figures.column.magnify", "0.0 is out of range"),
    ({"plane": ["xz"]}, "experiment.figures.column.plane", "expected a str"),
    ({"title": 5}, "experiment.figures.column.title", "expected a str, got 5"),
    # a column drawn against itself would show zero error everywhere
    ({"columns": [{"title": "a", "case": "pull", "variant": "fem"}]}, "experiment.figures.column.columns[0].variant",
     "'fem' is the column's reference (its errors would all be 0); expected another model of ['mss']"),
    ({"columns": [{"title": "a", "case": "pull", "variant": "mss", "reference": "mss"}]},
     "experiment.figures.column.columns[0].variant", "'mss' is the column's reference"),
]

BAD_TOP = [
    ({"reference": ["fem"]}, "experiment.reference", "['fem'] is not one of ['fem', 'mss']"),
    ({"title": 5}, "experiment.title", "expected a string, got 5"),
    ({"description": ["x"]}, "experiment.description", "expected a string"),
    ({"quick": [1]}, "experiment.quick", "expected a mapping, got [1]"),
    ({"published": [1]}, "experiment.published", "expected a mapping, got [1]"),
    ({"published": {"pull": [1]}}, "experiment.published.pull", "expected a mapping of model to values"),
    ({"published": {"pull": {"mss": [1]}}}, "experiment.published.pull.mss", "expected a mapping of metric"),
    ({"published": {"pull": {"mss": {"max": [float("nan"), "mm"]}}}}, "experiment.published.pull.mss.max",
     "expected [value, unit]"),
    ({"published": {"pull": {"mss": {"max": [1.0, ["mm"]]}}}}, "experiment.published.pull.mss.max",
     "expected [value, unit]"),
    ({"models": {"mss": {"model": "baudet_cube"}, 3: {"model": "fem_linear"}}, "reference": "mss"},
     "experiment.models", "name 3: a case or model name is a non-empty string"),
    # an empty value of the wrong type is not "none": `cases: []` was read as one default case
    ({"cases": []}, "experiment.cases", "[]: expected a mapping (leave the key out for none)"),
    ({"figures": []}, "experiment.figures", "[]: expected a mapping"),
    ({"figures": ""}, "experiment.figures", "'': expected a mapping"),
    ({"cases": ""}, "experiment.cases", "'': expected a mapping"),
    ({"quick": 0}, "experiment.quick", "0: expected a mapping"),
    ({"published": False}, "experiment.published", "False: expected a mapping"),
    ({"paper": []}, "experiment.paper", "[]: expected a paper name"),
    ({"paper": 5}, "experiment.paper", "5 is not one of"),
]


@pytest.mark.parametrize("change, where, says", BAD_FIGURES)
def test_a_bad_figure_value_is_named_in_one_line(tmp_path, change, where, says):
    with pytest.raises(ValueError) as info:
        load_experiment(_write(tmp_path, _with_figure(change)))
    message = str(info.value)
    assert "\n" not in message and message.startswith(where + ":") and says in message, message


@pytest.mark.parametrize("change, where, says", BAD_TOP)
def test_a_bad_top_level_value_is_named_in_one_line(tmp_path, change, where, says):
    with pytest.raises(ValueError) as info:
        load_experiment(_write(tmp_path, _with(change)))
    message = str(info.value)
    assert "\n" not in message and message.startswith(where + ":") and says in message, message


@pytest.mark.parametrize("change", [{"kind": ["comparison"]}, {"panel_width": float("nan")},
                                    {"columns": [{"title": "a", "case": ["pull"], "variant": "mss"}]}])
def test_both_commands_name_the_key_in_one_line(tmp_path, change):
    path = _write(tmp_path, _with_figure(change))
    for cmd in ([sys.executable, "-m", "msslib", "experiment", "list", str(path)],
                [sys.executable, "-m", "experiments.figures", str(path), "column", "--out", str(tmp_path / "x")]):
        r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120)
        lines = r.stderr.strip().splitlines()
        assert r.returncode != 0 and len(lines) == 1, r.stderr
        assert re.match(r"(msslib|experiments\.figures): error: .*experiment\.figures\.column\.", lines[0]), lines[0]
        assert "TypeError" not in lines[0] and "Traceback" not in r.stderr
        assert not (tmp_path / "x.png").exists()


def test_the_missing_runs_hint_works_as_printed(tmp_path):
    """No runs yet: the one-line error names a run-all command; run exactly as printed, it writes the
    runs the figure reads, and the figure is then drawn."""
    exp = _write(tmp_path, TINY)
    runs = tmp_path / "my runs"
    draw = [sys.executable, "-m", "experiments.figures", str(exp), "column", "--results", str(runs),
            "--out", str(tmp_path / "fig")]
    r = subprocess.run(draw, cwd=ROOT, capture_output=True, text=True, timeout=300)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1, r.stderr
    hint = re.search(r"run `([^`]+)` first", lines[0])
    assert hint, lines[0]
    argv = shlex.split(hint.group(1))
    assert argv[:3] == ["python", "-m", "msslib"]
    done = subprocess.run([sys.executable, *argv[1:]], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    r = subprocess.run(draw, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fig.png").is_file()


def _curves_with(tmp_path, edit):
    raw = yaml.safe_load(CURVES)
    edit(raw["figures"]["errors"])
    path = tmp_path / "curves.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    return path


@pytest.mark.parametrize("edit, says", [
    (lambda f: f.update(result=["results/a.nc"]), "result ['results/a.nc'] is not a results/....nc file"),
    (lambda f: f.update(variable=["E_error"]), "variable ['E_error']: expected a non-empty string"),
    (lambda f: f.update(x=3), "x 3: expected a non-empty string"),
    (lambda f: f.update(description=None), "description None: expected a string (or leave it out)"),
    (lambda f: f.update(xlabel=""), "xlabel '': expected a non-empty string"),
    (lambda f: f.update(xscale=-1.0), "xscale -1.0: expected a number above 0"),
    (lambda f: f.update(yscale="100"), "yscale '100': expected a number above 0"),
    (lambda f: f.update(band=float("nan")), "band nan: expected a number above 0"),
    (lambda f: f.update(height=-2), "height -2: expected a height in inches above 0"),
    (lambda f: f.update(height=True), "height True: expected a height"),
    (lambda f: f.update(panels={"reading a": ["a"]}), "panels must map a title to a selection"),
    (lambda f: f.update(panels={"reading a": {"reading": ["a", "b"]}}),
     "panels 'reading a': reading: ['a', 'b'] is not one coordinate value"),
    (lambda f: f.update(marks={"reading b": [[10.0, "2.5", "0.3"]]}),
     "marks 'reading b': [10.0, '2.5', '0.3'] is not a list of published points"),
    (lambda f: f.update(marks={"reading b": {"x": 1}}), "marks must map a title to published points"),
])
def test_a_bad_curves_value_is_named_in_one_line(tmp_path, edit, says):
    from experiments import figures

    path = _curves_with(tmp_path, edit)
    with pytest.raises(ValueError) as err:
        figures.load_curves(path)
    assert "\n" not in str(err.value) and "'errors'" in str(err.value) and says in str(err.value), str(err.value)


def test_a_bad_curves_file_fails_in_one_line_on_the_command_line(tmp_path):
    path = _curves_with(tmp_path, lambda f: f.update(height=float("nan")))
    r = subprocess.run([sys.executable, "-m", "experiments.figures", str(path), "errors", "--out", str(tmp_path / "x")],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1 and "height nan" in lines[0], r.stderr
    (tmp_path / "curves.yaml").write_text("figures: {a: [\n", encoding="utf-8")
    r = subprocess.run([sys.executable, "-m", "experiments.figures", str(tmp_path / "curves.yaml"), "a", "--out",
                        str(tmp_path / "x")], cwd=ROOT, capture_output=True, text=True, timeout=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1 and "invalid YAML" in lines[0], r.stderr


def test_the_missing_study_hint_works_as_printed(tmp_path):
    """A curves figure whose study result is missing: the one-line error names the study's command;
    run as printed (in the same folder), it writes the result and the figure is then drawn."""
    import os

    curves = yaml.safe_load((ROOT / "experiments" / "baudet" / "figures" / "curves.yaml").read_text())
    (tmp_path / "curves.yaml").write_text(yaml.safe_dump({"figures": {"bulk_modulus": curves["figures"]["bulk_modulus"]}}))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    draw = [sys.executable, "-m", "experiments.figures", "curves.yaml", "bulk_modulus", "--out", "fig"]
    r = subprocess.run(draw, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1, r.stderr
    hint = re.search(r"run `([^`]+)`$", lines[0])
    assert hint, lines[0]
    argv = shlex.split(hint.group(1))
    assert argv[:2] == ["python", "-m"]
    done = subprocess.run([sys.executable, *argv[1:]], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "results" / "baudet" / "studies" / "bulk.nc").is_file()
    r = subprocess.run(draw, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fig.png").is_file()


def test_experiment_compare_missing_run_hint_works_as_printed(tmp_path):
    """compare before the runs: the one-line error names a run-all command; run exactly as printed
    (from another folder, with a space in the path), compare then succeeds."""
    exp = _write(tmp_path, TINY)
    runs = tmp_path / "my runs"
    runs.mkdir()
    compare = [sys.executable, "-m", "msslib", "experiment", "compare", str(exp), "--results", str(runs),
               "--out", str(tmp_path / "cmp.nc")]
    r = subprocess.run(compare, cwd=ROOT, capture_output=True, text=True, timeout=300)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1 and lines[0].startswith("msslib: error: missing run"), r.stderr
    hint = re.search(r"run `([^`]+)` first", lines[0])
    assert hint, lines[0]
    argv = shlex.split(hint.group(1))
    assert argv[:3] == ["python", "-m", "msslib"]
    done = subprocess.run([sys.executable, *argv[1:], "--quiet"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    r = subprocess.run(compare, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "cmp.nc").is_file()

"""Figures as data: the ``figures`` block of an experiment file (checked by msslib.experiment, drawn by
``python -m experiments.figures``), the curves files (a study result as error curves), the workflow's
figure and table targets and their declarations, and the one command line (--out, --quick) of every
study, figure and table."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml

from msslib.experiment import figure_runs, load_experiment

ROOT = Path(__file__).resolve().parents[1]
PAPERS = ("lloyd", "baudet", "golec", "performance", "summary")

TINY = """\
title: A column of two cubes, sheared and pulled
scene:
  geometry: {generator: hex_grid, args: {lx: 0.1, ly: 0.1, lz: 0.2, nx: 1, ny: 1, nz: 2}}
  materials: [{E: 1000.0, nu: 0.3}]
  boundary: [{select: {plane: [z, 0.0]}, fix: all}]
  loads: [{type: traction, select: {plane: [z, 0.2]}, traction: [5.0, 0.0, 0.0]}]
  solver: {type: static, load_steps: 1, tol: 1.0e-10}
cases:
  shear: {}
  pull: {loads: [{type: traction, select: {plane: [z, 0.2]}, traction: [0.0, 0.0, 5.0]}]}
models:
  mss: {model: baudet_cube}
  fem: {model: fem_linear}
reference: fem
figures:
  column:
    caption: "MSS over FEM, sheared and pulled"
    kind: comparison
    plane: xz
    length_unit: mm
    columns:
      - {title: "a) shear", case: shear, variant: mss}
      - {title: "b) pull", case: pull, variant: mss, reference: fem}
"""


def _write(tmp_path, text, name="tiny.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _with_figure(extra: dict) -> str:
    """TINY with the figure ``column`` updated by ``extra`` (a key set to None is removed)."""
    raw = yaml.safe_load(TINY)
    fig = raw["figures"]["column"]
    for k, v in extra.items():
        if v is None:
            fig.pop(k, None)
        else:
            fig[k] = v
    return yaml.safe_dump(raw, sort_keys=False)


# ---- the block, checked -------------------------------------------------------------------------

def test_figure_block_is_read_with_defaults(tmp_path):
    exp = load_experiment(_write(tmp_path, TINY))
    fig = exp.figures["column"]
    assert fig["kind"] == "comparison" and fig["options"] == {"plane": "xz", "length_unit": "mm"}
    # the first column takes the experiment's reference; runs are listed once, in column order
    assert fig["columns"][0] == {"title": "a) shear", "case": "shear", "variant": "mss", "reference": "fem"}
    assert figure_runs(exp, "column") == [("shear", "mss"), ("shear", "fem"), ("pull", "mss"), ("pull", "fem")]


def test_paper_figures_read_the_runs_their_scripts_read():
    """The declarations that replaced the Lloyd and Baudet comparison scripts: the cone compares one MSS
    run with two references, the cantilever three resolutions (not the fourth) with one FEM run."""
    cone = load_experiment(ROOT / "experiments/lloyd/cone.yaml")
    assert figure_runs(cone, "cone") == [("shear", "mss"), ("shear", "fem_linear"), ("shear", "fem_svk")]
    assert cone.figures["cone"]["options"] == {"plane": "yz", "panel_width": 3.6}
    cantilever = load_experiment(ROOT / "experiments/baudet/cantilever.yaml")
    assert figure_runs(cantilever, "cantilever") == [("gravity", "mss_4x1x1"), ("gravity", "fem"),
                                                     ("gravity", "mss_8x2x2"), ("gravity", "mss_16x4x4")]
    assert cantilever.figures["cantilever"]["options"]["magnify"] == 100.0
    myoma = load_experiment(ROOT / "experiments/lloyd/myoma.yaml")
    assert [c["case"] for c in myoma.figures["myoma"]["columns"]] == ["push_300", "pull_300", "push_1000", "pull_1000"]


@pytest.mark.parametrize("change, where, says", [
    ({"colour": "red"}, "experiment.figures.column.colour", "unknown key; expected one of"),
    ({"kind": "heatmap"}, "experiment.figures.column.kind", "'heatmap' is not one of ['comparison']"),
    ({"caption": None}, "experiment.figures.column.caption", "missing"),
    ({"plane": "xw"}, "experiment.figures.column.plane", "'xw' is not one of"),
    ({"magnify": "ten"}, "experiment.figures.column.magnify", "expected a float"),
    ({"node_errors": 1}, "experiment.figures.column.node_errors", "expected a bool"),
    ({"columns": []}, "experiment.figures.column.columns", "non-empty list"),
    ({"columns": [{"title": "a", "case": "twist", "variant": "mss"}]}, "experiment.figures.column.columns[0].case",
     "'twist' is not one of ['pull', 'shear']"),
    ({"columns": [{"title": "a", "case": "shear", "variant": "mss", "colour": 1}]},
     "experiment.figures.column.columns[0].colour", "unknown key"),
    ({"columns": [{"title": "a", "variant": "mss"}]}, "experiment.figures.column.columns[0].case", "missing"),
])
def test_a_bad_figure_is_refused_in_one_line(tmp_path, change, where, says):
    with pytest.raises(ValueError) as info:
        load_experiment(_write(tmp_path, _with_figure(change)))
    message = str(info.value)
    assert "\n" not in message and message.startswith(where + ":") and says in message


def test_the_cli_refuses_a_bad_figure_key_in_one_line(tmp_path):
    path = _write(tmp_path, _with_figure({"colour": "red"}))
    for cmd in ([sys.executable, "-m", "msslib", "experiment", "list", str(path)],
                [sys.executable, "-m", "experiments.figures", str(path), "column", "--out", str(tmp_path / "x")]):
        r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120)
        lines = r.stderr.strip().splitlines()
        assert r.returncode != 0 and len(lines) == 1, r.stderr
        assert re.match(r"(msslib|experiments\.figures): error: .*experiment\.figures\.column\.colour: unknown key", lines[0])
        assert not (tmp_path / "x.png").exists()


def test_figure_names_name_files_and_titles_are_unique(tmp_path):
    with pytest.raises(ValueError, match=r"experiment\.figures\.a b: a figure name is letters"):
        load_experiment(_write(tmp_path, TINY.replace("  column:", "  a b:")))
    twice = _with_figure({"columns": [{"title": "a", "case": "shear", "variant": "mss"},
                                      {"title": "a", "case": "pull", "variant": "mss"}]})
    with pytest.raises(ValueError, match=r"columns\[1\]\.title: 'a' names two columns"):
        load_experiment(_write(tmp_path, twice))


# ---- one figure drawn --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory):
    """The tiny experiment run by the CLI the workflow uses (python -m msslib experiment run-all)."""
    folder = tmp_path_factory.mktemp("tiny")
    exp = _write(folder, TINY)
    r = subprocess.run([sys.executable, "-m", "msslib", "experiment", "run-all", str(exp), "--out-dir",
                        str(folder / "runs"), "--quiet"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return exp, folder / "runs"


def test_one_figure_drawn_from_a_small_experiment(tiny_runs, tmp_path):
    exp_path, runs = tiny_runs
    stem = tmp_path / "out" / "tiny_column"
    r = subprocess.run([sys.executable, "-m", "experiments.figures", str(exp_path), "column", "--results", str(runs),
                        "--out", str(stem), "--quick"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    png, pdf = stem.with_suffix(".png"), stem.with_suffix(".pdf")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and pdf.read_bytes()[:5] == b"%PDF-"
    from matplotlib.image import imread

    image = imread(png)
    assert image.shape[0] > 300 and image.shape[1] > 300 and np.ptp(image[..., :3]) > 0.5  # drawn, not blank


def test_the_drawn_figure_shows_the_runs_it_declares(tiny_runs):
    """The columns' titles, and the colour scales against numbers taken from the run files here: the
    largest reference displacement and the largest node distance MSS - FEM (same mesh, node by node)."""
    import xarray as xr

    from experiments.figures import draw

    exp_path, runs = tiny_runs
    exp = load_experiment(exp_path)
    fig = draw(exp, "column", runs)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles == ["a) shear", "b) pull"]

    def disp(case, model):
        with xr.open_dataset(runs / f"{case}__{model}.nc") as ds:
            return ds["displacement"].transpose("node", "axis").values

    u_ref_max = max(np.linalg.norm(disp(c, "fem"), axis=1).max() for c in ("shear", "pull")) * 1e3
    err_max = max(np.linalg.norm(disp(c, "mss") - disp(c, "fem"), axis=1).max() for c in ("shear", "pull")) * 1e3
    assert err_max > 1e-3 * u_ref_max  # the two models differ: the error scale is a real number
    climits = {tuple(np.round(a.get_clim(), 9)) for ax in fig.axes for a in ax.collections
               if a.get_array() is not None}
    assert (0.0, round(u_ref_max, 9)) in climits and (0.0, round(err_max, 9)) in climits


def test_a_missing_run_stops_with_one_line(tiny_runs, tmp_path):
    exp_path, runs = tiny_runs
    partial = tmp_path / "runs"
    shutil.copytree(runs, partial)
    (partial / "pull__mss.nc").unlink()
    r = subprocess.run([sys.executable, "-m", "experiments.figures", str(exp_path), "column", "--results", str(partial),
                        "--out", str(tmp_path / "x")], cwd=ROOT, capture_output=True, text=True, timeout=300)
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0 and len(lines) == 1 and "pull__mss.nc" in lines[0] and "run-all" in lines[0], r.stderr
    assert not (tmp_path / "x.png").exists()


# ---- the workflow's targets and their declarations ---------------------------------------------

def _experiment_figures():
    out = {}
    for paper in PAPERS:
        for path in sorted((ROOT / "experiments" / paper).glob("*.yaml")):
            for name in load_experiment(path).figures:
                out[(paper, name)] = path
    return out


def _curves(paper):
    from experiments.figures import load_curves

    path = ROOT / "experiments" / paper / "figures" / "curves.yaml"
    return load_curves(path) if path.is_file() else {}


def _declared(paper, kind):
    path = ROOT / "experiments" / paper / kind / "inputs.yaml"
    return (yaml.safe_load(path.read_text()) or {}) if path.is_file() else {}


@pytest.fixture(scope="module")
def workflow_targets():
    """(file, rule) of every figure and table the workflow builds (``snakemake --summary``)."""
    pytest.importorskip("snakemake")
    r = subprocess.run([shutil.which("snakemake") or "snakemake", "--summary", "-j1"], cwd=ROOT, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    rows = [line.split("\t") for line in r.stdout.splitlines()[1:] if "\t" in line]
    return {row[0]: row[2] for row in rows if row[0].startswith(("paper/figures/", "paper/tables/"))}


def test_every_figure_and_table_target_has_a_declaration(workflow_targets):
    declared = _experiment_figures()
    pngs = {f: rule for f, rule in workflow_targets.items() if f.endswith(".png")}
    assert len(pngs) >= 29
    for target, rule in pngs.items():
        paper, name = Path(target).stem.split("_", 1)
        if rule == "experiment_figure":
            assert (paper, name) in declared, target
        elif rule == "curve_figure":
            assert name in _curves(paper), target
            assert not (ROOT / "experiments" / paper / "figures" / f"{name}.py").exists(), target
        else:
            assert rule == "figure", target
            assert (ROOT / "experiments" / paper / "figures" / f"{name}.py").is_file(), target
            assert name in _declared(paper, "figures"), f"{target}: not in experiments/{paper}/figures/inputs.yaml"
            assert (paper, name) not in declared, f"{target}: a script and an experiment file both declare it"
        assert target.replace(".png", ".pdf") in workflow_targets
    assert {f"paper/figures/{p}_{n}.png" for p, n in declared} <= set(pngs)
    for target, rule in workflow_targets.items():
        if rule == "table":
            paper, name = Path(target).stem.split("_", 1)
            assert name in _declared(paper, "tables"), f"{target}: not in experiments/{paper}/tables/inputs.yaml"


def test_every_figure_the_paper_shows_is_a_target(workflow_targets):
    sources = list((ROOT / "paper" / "sections").glob("*.md")) + list((ROOT / "paper").glob("*.md.in"))
    shown = {m for p in sources for m in re.findall(r"\{\{figure ([A-Za-z0-9_]+)", p.read_text())}
    assert shown and not {f"paper/figures/{n}.png" for n in shown} - set(workflow_targets)


def test_every_script_has_its_inputs_declared_and_no_stale_declaration():
    for paper in PAPERS:
        for kind in ("figures", "tables"):
            scripts = {p.stem for p in (ROOT / "experiments" / paper / kind).glob("*.py")}
            declared = _declared(paper, kind)
            assert scripts == set(declared), (paper, kind, scripts ^ set(declared))
            for name, files in declared.items():
                assert files and all(isinstance(f, str) for f in files), (paper, kind, name)


# ---- the declared inputs are what each script opens ---------------------------------------------

def _scripts():
    return [(paper, kind, p.stem) for paper in PAPERS for kind in ("figures", "tables")
            for p in sorted((ROOT / "experiments" / paper / kind).glob("*.py"))]


DRIVER = textwrap.dedent("""
    import json, os, runpy, sys
    import netCDF4
    root, module, out = sys.argv[1:4]
    opened = set()
    sys.addaudithook(lambda event, args: opened.add(os.path.abspath(str(args[0])))
                     if event == "open" and isinstance(args[0], (str, bytes, os.PathLike)) else None)
    original = netCDF4.Dataset
    class Recorded(original):
        def __init__(self, filename, *a, **k):
            opened.add(os.path.abspath(str(filename)))
            super().__init__(filename, *a, **k)
    netCDF4.Dataset = Recorded
    sys.argv = [module, "--out", out]
    runpy.run_module(module, run_name="__main__")
    imported = {os.path.abspath(m.__file__) for m in list(sys.modules.values()) if getattr(m, "__file__", None)}
    print(json.dumps(sorted(os.path.relpath(p, root) for p in opened | imported)))
""")


@pytest.mark.slow
@pytest.mark.parametrize("paper, kind, name", _scripts())
def test_a_script_opens_exactly_the_results_it_declares(paper, kind, name, tmp_path):
    """Run the script against the results in results/ (skipped where they are not built) with the file
    opens recorded (Python's open, netCDF4, imported modules): every declared file is opened, and every
    file of results/ it opens is declared."""
    import json

    declared = _declared(paper, kind)[name]
    missing = [f for f in declared if not (ROOT / f).is_file()]
    if missing:
        pytest.skip(f"not built: {missing[0]}")
    out = tmp_path / (f"{paper}_{name}" + (".md" if kind == "tables" else ""))
    r = subprocess.run([sys.executable, "-c", DRIVER, str(ROOT), f"experiments.{paper}.{kind}.{name}", str(out)],
                       cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    opened = set(json.loads(r.stdout.strip().splitlines()[-1]))
    assert set(declared) <= opened, sorted(set(declared) - opened)
    undeclared = {f for f in opened if f.startswith("results/")} - set(declared)
    assert not undeclared, sorted(undeclared)


# ---- one command line ----------------------------------------------------------------------------

def _entry_points():
    out = [f"experiments.{p}.{k}.{n}" for p, k, n in _scripts()]
    out += [f"experiments.{p.parent.parent.name}.studies.{p.stem}" for paper in PAPERS
            for p in sorted((ROOT / "experiments" / paper / "studies").glob("*.py"))]
    return out + ["experiments.figures"]


def test_every_study_figure_and_table_takes_out_and_quick():
    """Each entry point parses its command line through experiments.script (--out, --quick) or, for a
    study whose body is shared, calls a main that does; no script builds a parser of its own."""
    def calls(module):
        tree = ast.parse((ROOT / Path(*module.split(".")).with_suffix(".py")).read_text())
        found = {ast.unparse(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
        # a study whose body is shared calls the main it imports from another module of experiments/
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("experiments.") \
                    and any(a.name == "main" for a in node.names) and "main" in found:
                found |= calls(node.module)
        return found

    for module in _entry_points():
        found = calls(module)
        assert "argparse.ArgumentParser" not in found, f"{module} builds its own parser"
        assert found & {"script.args", "script.parse", "C.parse"}, f"{module}: not the shared command line"


@pytest.mark.parametrize("module", ["experiments.baudet.figures.cantilever_floor", "experiments.performance.tables.pareto",
                                    "experiments.lloyd.studies.sparsity", "experiments.figures"])
def test_help_names_out_and_quick(module):
    r = subprocess.run([sys.executable, "-m", module, "--help"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "--out" in r.stdout and "--quick" in r.stdout, r.stdout + r.stderr


# --------------------------------------------------------------------------------------------
# curves files: a study result drawn as error curves, one per nu, one panel per selection
# --------------------------------------------------------------------------------------------

CURVES = """\
shared:
  panels: &panels
    "reading a": {reading: a, geometry: cube}
    "reading b": {reading: b, geometry: cube}
figures:
  errors:
    result: results/demo/studies/errors.nc
    variable: E_error
    x: strain
    xlabel: axial strain (%)
    ylabel: E error (%)
    panels: *panels
    dashed: {"a beam": {geometry: beam}}
    marks: {"reading b": [[10.0, 2.5, "0.3"]]}
    band: 5.0
"""


def _errors_study(folder):
    """A study-like result: E_error(reading, geometry, nu, strain), each value distinct."""
    import xarray as xr

    strain = np.linspace(0.0, 0.1, 6)
    values = np.arange(2 * 2 * 2 * 6, dtype=float).reshape(2, 2, 2, 6) / 1000.0
    ds = xr.Dataset({"E_error": (("reading", "geometry", "nu", "strain"), values)},
                    coords={"reading": ["a", "b"], "geometry": ["cube", "beam"], "nu": [0.3, 0.4], "strain": strain})
    path = folder / "results" / "demo" / "studies" / "errors.nc"
    path.parent.mkdir(parents=True)
    ds.to_netcdf(path)
    return ds


def test_a_curves_figure_draws_the_study_values_it_declares(tmp_path, monkeypatch):
    from experiments import figures

    (tmp_path / "curves.yaml").write_text(CURVES, encoding="utf-8")
    ds = _errors_study(tmp_path)
    monkeypatch.chdir(tmp_path)
    spec = figures.load_curves(tmp_path / "curves.yaml")["errors"]
    fig = figures.draw_curves(spec)
    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["reading a", "reading b"]
    for ax, reading in zip(axes, ["a", "b"]):
        assert ax.get_yscale() == "symlog"  # the band: linear within +-5 %, logarithmic beyond
        lines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 6]
        drawn = sorted((ln.get_linestyle(), tuple(ln.get_ydata())) for ln in lines)
        expected = sorted((style, tuple(ds["E_error"].sel(reading=reading, geometry=geometry, nu=nu).values * 100.0))
                          for geometry, style in (("cube", "-"), ("beam", "--")) for nu in (0.3, 0.4))
        assert drawn == expected, reading
        np.testing.assert_allclose(lines[0].get_xdata(), ds["strain"].values * 100.0)
    marks = [ln for ln in axes[1].get_lines() if ln.get_marker() == "o"]
    assert len(marks) == 1 and (marks[0].get_xdata()[0], marks[0].get_ydata()[0]) == (10.0, 2.5)


@pytest.mark.parametrize("edit, says", [
    (lambda f: f.pop("variable"), "missing variable"),
    (lambda f: f.update(colour="red"), "unknown colour"),
    (lambda f: f.update(result="elsewhere/errors.nc"), "is not a results/....nc file"),
    (lambda f: f.update(marks={"reading c": [[1.0, 1.0, "0.3"]]}), "marks for panels it does not draw: reading c"),
    (lambda f: f.update(panels=["reading a"]), "panels must map a title to a selection"),
])
def test_a_bad_curves_figure_is_refused_in_one_line(tmp_path, edit, says):
    from experiments import figures

    raw = yaml.safe_load(CURVES)
    edit(raw["figures"]["errors"])
    path = tmp_path / "curves.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    with pytest.raises(ValueError, match=re.escape(says)) as err:
        figures.load_curves(path)
    assert "\n" not in str(err.value) and "'errors'" in str(err.value)


def test_the_paper_curves_files_load_and_read_study_results():
    for paper in PAPERS:
        for name, spec in _curves(paper).items():
            study = Path(spec["result"])
            assert study.parts[:3] == ("results", paper, "studies"), (paper, name)
            assert (ROOT / "experiments" / paper / "studies" / f"{study.stem}.py").is_file(), (paper, name, study)


def test_a_panel_that_leaves_a_dimension_open_is_refused(tmp_path, monkeypatch):
    from experiments import figures

    raw = yaml.safe_load(CURVES)
    raw["figures"]["errors"]["panels"] = {"reading a": {"reading": "a"}}
    raw["figures"]["errors"].pop("marks")
    (tmp_path / "curves.yaml").write_text(yaml.safe_dump(raw), encoding="utf-8")
    _errors_study(tmp_path)
    monkeypatch.chdir(tmp_path)
    spec = figures.load_curves(tmp_path / "curves.yaml")["errors"]
    with pytest.raises(ValueError, match="panel 'reading a' leaves geometry open"):
        figures.draw_curves(spec)

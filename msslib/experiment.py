"""Experiments: a base scene, named load cases and model variants, a reference, published numbers.

An experiment file (YAML, one per experiment of the papers, under ``experiments/<paper>/``) is

.. code-block:: yaml

    name: lloyd_membrane_equilateral       # optional; default: the file name
    paper: lloyd                           # lloyd | baudet | golec | performance; optional: a
                                           # user's own experiment belongs to no paper
    title: Equilateral membrane, stretch / compression / shear
    section: "Sec. 5.1, Fig. 9"
    scene: {...}                           # a scene (see msslib.scene), the common part
    cases:                                 # load cases: overrides merged into the scene
      stretch: {loads: [...]}
      shear: {loads: [...]}
    models:                                # model variants: overrides merged after the case
      mss: {model: lloyd_triangle}
      fem: {model: fem_linear}
    reference: fem                         # the variant the others are compared with (optional)
    quick: {geometry: {args: {n: 4}}}      # overrides for the reduced (CI) build
    published:                             # numbers printed in the paper, with their unit
      stretch: {mss: {max: [0.033, cm], mean: [0.008, cm]}}
    figures:                               # figures drawn from the runs (python -m experiments.figures)
      membrane_equilateral:                # the figure's name: paper/figures/<paper>_<name>.png and .pdf
        caption: "Lloyd et al. Fig. 9: MSS (red) over linear FEM"
        kind: comparison                   # the only kind: one column per (case, variant, reference)
        plane: xy                          # options of the kind (:data:`FIGURE_OPTIONS`)
        columns:
          - {title: "a) stretch", case: stretch, variant: mss}   # reference: the experiment's
          - {title: "b) shear", case: shear, variant: mss, reference: fem}

Overrides merge mappings key by key; any other value (lists included) replaces the base value. A
run is one (case, model) pair: :func:`scene_of` gives its scene, :func:`run` solves it. The
comparison (:func:`compare`) measures every non-reference variant against the reference of the
same case (per-node Euclidean distance: mean, standard deviation and maximum, absolute and relative
to the largest reference displacement) and puts the published values beside them. When the meshes
differ (a reference computed at another resolution), the reference displacement is interpolated at
the variant's nodes with the reference's own shape functions. It is ``msslib compare``'s
measurement (:func:`msslib.compare.compare_results`): results that are not of the reference's body
are refused the same way.

A figure (``figures``) is data: its kind, its columns and the kind's drawing options, checked here
(:func:`figure_runs` names the runs it reads); ``experiments.figures`` draws it.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

KEYS = {"name", "paper", "title", "section", "description", "scene", "cases", "models", "reference", "quick", "published",
        "figures"}
PAPERS = ("lloyd", "baudet", "golec", "performance")  # performance: experiments of this project beyond the papers
UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "%": 1e-2, "1": 1.0, "Pa": 1.0, "kPa": 1e3, "s": 1.0, "m^3": 1.0, "cm^3": 1e-6}
METRICS = ("mean", "std", "max")
#: The figure kinds and the options each accepts beside ``kind``, ``caption`` and ``columns``, with
#: their types (the drawing options of ``experiments.plotting.comparison_figure``).
FIGURE_OPTIONS = {"comparison": {"plane": str, "length_unit": str, "panel_width": float, "panel_height": float,
                                 "magnify": float, "node_errors": bool, "show_rest": bool, "variant_label": str,
                                 "reference_label": str, "title": str}}
#: the figure options that are sizes (inches) or a factor: finite, above 0, at most the bound
FIGURE_RANGES = {"panel_width": 20.0, "panel_height": 20.0, "magnify": 1e6}
FIGURE_PLANES = ("xy", "xz", "yz", "yx", "zx", "zy")
FIGURE_LENGTH_UNITS = ("m", "cm", "mm")
COLUMN_KEYS = ("title", "case", "variant", "reference")


@dataclass(frozen=True)
class Experiment:
    name: str
    paper: str
    title: str
    section: str
    scene: dict
    cases: dict
    models: dict
    reference: str | None
    quick: dict
    published: dict
    base_dir: Path
    description: str = ""
    path: Path | None = field(default=None)
    figures: dict = field(default_factory=dict)


def _fail(path, msg):
    raise ValueError(f"{path}: {msg}")


def _text(where, value, what, required=True):
    """``value`` as a string of text; a missing one (None) fails as missing when ``required``."""
    if value is None:
        if required:
            _fail(where, f"missing: {what}")
        return value
    if not isinstance(value, str):
        _fail(where, f"expected a string ({what}), got {value!r}")
    return value


def _one_of(where, value, names, what):
    """``value`` a name among ``names`` (a mapping or a list)."""
    if not isinstance(value, str) or value not in names:
        _fail(where, f"{value!r} is not one of {list(names)} ({what}, a string)")
    return value


def load_experiment(path) -> Experiment:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"experiment file not found: {str(path)!r}")
    raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    if not isinstance(raw, dict):
        _fail("experiment", "must be a mapping")
    unknown = sorted(map(str, set(raw) - KEYS))
    if unknown:
        _fail(f"experiment.{unknown[0]}", f"unknown key; expected one of {', '.join(sorted(KEYS))}")
    for key in ("scene", "models"):
        if key not in raw:
            _fail(f"experiment.{key}", "missing")
    for key in ("paper", "cases", "quick", "published", "figures"):  # `or` below must not swallow [], 0 or ''
        if (key in raw and raw[key] is not None and not raw[key]
                and not isinstance(raw[key], str if key == "paper" else dict)):
            _fail(f"experiment.{key}", f"{raw[key]!r}: expected " + ("a paper name" if key == "paper" else "a mapping")
                  + " (leave the key out for none)")
    paper = raw.get("paper") or ""
    if paper and (not isinstance(paper, str) or paper not in PAPERS):
        _fail("experiment.paper", f"{paper!r} is not one of {PAPERS} (leave it out for an experiment of your own)")
    cases = raw.get("cases") or {"default": {}}
    models = raw["models"]
    for key, val in (("cases", cases), ("models", models), ("scene", raw["scene"])):
        if not isinstance(val, dict) or not val:
            _fail(f"experiment.{key}", "must be a non-empty mapping")
    for key, names in (("cases", cases), ("models", models)):
        for name in names:
            if not isinstance(name, str) or not name or "__" in name or "/" in name:
                _fail(f"experiment.{key}", f"name {name!r}: a case or model name is a non-empty string without "
                                          "'__' or '/'")
    for key in ("name", "title", "section", "description"):
        if key in raw and not isinstance(raw[key], (str, int, float) if key == "section" else str):
            _fail(f"experiment.{key}", f"expected a string, got {raw[key]!r}")
    for key in ("quick", "published"):
        if not isinstance(raw.get(key) or {}, dict):
            _fail(f"experiment.{key}", f"expected a mapping, got {raw[key]!r}")
    ref = raw.get("reference")
    if ref is not None:
        _one_of("experiment.reference", ref, sorted(models), "a model of the experiment")
    published = raw.get("published") or {}
    for case, per_model in published.items():
        if not isinstance(case, str) or case not in cases:
            _fail(f"experiment.published.{case}", f"unknown case; expected one of {sorted(cases)}")
        if not isinstance(per_model, dict):
            _fail(f"experiment.published.{case}", f"expected a mapping of model to values, got {per_model!r}")
        for model, values in per_model.items():
            if not isinstance(model, str) or model not in models:
                _fail(f"experiment.published.{case}.{model}", f"unknown model; expected one of {sorted(models)}")
            if not isinstance(values, dict):
                _fail(f"experiment.published.{case}.{model}", f"expected a mapping of metric to [value, unit], "
                                                             f"got {values!r}")
            for metric, v in values.items():
                if not (isinstance(v, list) and len(v) == 2 and isinstance(v[1], str) and v[1] in UNITS
                        and isinstance(v[0], (int, float)) and not isinstance(v[0], bool) and math.isfinite(v[0])):
                    _fail(f"experiment.published.{case}.{model}.{metric}", f"expected [value, unit] with unit in {sorted(UNITS)}, got {v!r}")
    figures = _figures(raw.get("figures") or {}, cases, models, ref)
    return Experiment(name=raw.get("name", path.stem), paper=paper, title=raw.get("title", path.stem),
                      section=str(raw.get("section", "")), scene=raw["scene"], cases=cases, models=models,
                      reference=ref, quick=raw.get("quick") or {}, published=published, base_dir=path.parent,
                      description=raw.get("description", ""), path=path, figures=figures)


def _figures(raw, cases, models, reference):
    """The ``figures`` block checked and completed: every column names its case, variant and
    reference (a column may leave out the case of a one-case experiment and the experiment's
    reference); options are those of the kind, of the right type."""
    if not isinstance(raw, dict):
        _fail("experiment.figures", "must be a mapping of figure name to figure")
    out = {}
    for name, fig in raw.items():
        where = f"experiment.figures.{name}"
        if not isinstance(name, str) or not name.replace("_", "").replace("-", "").isalnum():
            _fail(where, "a figure name is letters, digits, '_' and '-' (it names the output file)")
        if not isinstance(fig, dict):
            _fail(where, "must be a mapping with kind, caption and columns")
        kind = _one_of(f"{where}.kind", fig.get("kind"), sorted(FIGURE_OPTIONS), "a figure kind")
        allowed = {"kind", "caption", "columns", *FIGURE_OPTIONS[kind]}
        unknown = sorted(set(fig) - allowed)
        if unknown:
            _fail(f"{where}.{unknown[0]}", f"unknown key; expected one of {', '.join(sorted(allowed))}")
        if not (_text(f"{where}.caption", fig.get("caption"), "one line saying what the figure shows") or "").strip():
            _fail(f"{where}.caption", "empty: one line saying what the figure shows")
        options = {}
        for key, typ in FIGURE_OPTIONS[kind].items():
            if key not in fig:
                continue
            v = fig[key]
            ok = isinstance(v, bool) if typ is bool else (isinstance(v, (int, float)) and not isinstance(v, bool)
                                                          if typ is float else isinstance(v, typ))
            if not ok:
                _fail(f"{where}.{key}", f"expected a {typ.__name__}, got {v!r}")
            if key in FIGURE_RANGES and not 0.0 < float(v) <= FIGURE_RANGES[key]:
                _fail(f"{where}.{key}", f"{float(v)} is out of range; expected a number above 0 and at most "
                                        f"{FIGURE_RANGES[key]:g}")
            options[key] = float(v) if typ is float else v
        if "plane" in options:
            _one_of(f"{where}.plane", options["plane"], FIGURE_PLANES, "a plane")
        if "length_unit" in options:
            _one_of(f"{where}.length_unit", options["length_unit"], FIGURE_LENGTH_UNITS, "a length unit")
        columns = fig.get("columns")
        if not isinstance(columns, list) or not columns:
            _fail(f"{where}.columns", "must be a non-empty list of {title, case, variant, reference}")
        checked = [_column(f"{where}.columns[{k}]", c, cases, models, reference) for k, c in enumerate(columns)]
        titles = [c["title"] for c in checked]
        for k, title in enumerate(titles):
            if title in titles[:k]:
                _fail(f"{where}.columns[{k}].title", f"{title!r} names two columns")
        out[name] = {"kind": kind, "caption": fig["caption"].strip(), "options": options, "columns": checked}
    return out


def _column(where, col, cases, models, reference):
    if not isinstance(col, dict):
        _fail(where, f"must be a mapping with keys {', '.join(COLUMN_KEYS)}")
    unknown = sorted(set(col) - set(COLUMN_KEYS))
    if unknown:
        _fail(f"{where}.{unknown[0]}", f"unknown key; expected one of {', '.join(COLUMN_KEYS)}")
    col = {"case": next(iter(cases)) if len(cases) == 1 else None, "reference": reference, **col}
    for key, names, what in (("case", cases, "a case"), ("variant", models, "a model"),
                             ("reference", models, "a model")):
        if col.get(key) is None:
            _fail(f"{where}.{key}", "missing" + (" (the experiment has no reference)" if key == "reference" else ""))
        _one_of(f"{where}.{key}", col[key], sorted(names), f"{what} of the experiment")
    if col["variant"] == col["reference"]:
        _fail(f"{where}.variant", f"{col['variant']!r} is the column's reference (its errors would all be 0); "
                                  f"expected another model of {sorted(set(models) - {col['reference']})}")
    _text(f"{where}.title", col.get("title"), "the column's title")
    return {k: col[k] for k in COLUMN_KEYS}


def figure_runs(exp: Experiment, name: str):
    """The (case, model) runs figure ``name`` of ``exp`` reads, each once, in the order of its
    columns (variant, then reference)."""
    if name not in exp.figures:
        raise ValueError(f"{exp.name}: no figure {name!r}; declared: {sorted(exp.figures) or 'none'}")
    out = []
    for col in exp.figures[name]["columns"]:
        for run in ((col["case"], col["variant"]), (col["case"], col["reference"])):
            if run not in out:
                out.append(run)
    return out


def merge(base, override):
    """Deep merge: mappings key by key, anything else replaced (a copy is returned)."""
    if isinstance(base, dict) and isinstance(override, dict):
        out = copy.deepcopy(base)
        for k, v in override.items():
            out[k] = merge(out[k], v) if k in out else copy.deepcopy(v)
        return out
    return copy.deepcopy(override)


def scene_of(exp: Experiment, case: str, model: str, quick: bool = False) -> dict:
    if case not in exp.cases:
        raise ValueError(f"{exp.name}: unknown case {case!r}; expected one of {sorted(exp.cases)}")
    if model not in exp.models:
        raise ValueError(f"{exp.name}: unknown model {model!r}; expected one of {sorted(exp.models)}")
    scene = merge(exp.scene, exp.cases[case] or {})
    scene = merge(scene, exp.models[model] or {})
    if quick:
        scene = merge(scene, exp.quick)
    scene["name"] = f"{exp.name}/{case}/{model}"
    return scene


def runs(exp: Experiment):
    return [(c, m) for c in exp.cases for m in exp.models]


def run(exp: Experiment, case: str, model: str, quick: bool = False, progress=False):
    from msslib.scene import load_scene, run_scene

    scene = load_scene(scene_of(exp, case, model, quick), base_dir=exp.base_dir)
    ds = run_scene(scene, progress=progress)
    ds.attrs.update(experiment=exp.name, paper=exp.paper, case=case, variant=model, quick=int(quick))
    return ds


# ---- comparison ------------------------------------------------------------------------------

def _published(exp, case, model):
    out = {}
    for metric, (value, unit) in (exp.published.get(case, {}).get(model, {}) or {}).items():
        out[metric] = (float(value) * UNITS[unit], unit)
    return out


def compare(exp: Experiment, results: dict):
    """``results[(case, model)]`` are the run datasets; returns an xarray Dataset with dims
    (case, variant) of error statistics against the reference and the published values."""
    import xarray as xr

    from msslib.compare import compare_results

    variants = [m for m in exp.models if m != exp.reference]
    cases = list(exp.cases)
    shape = (len(cases), len(variants))
    data = {f"error_{s}": np.full(shape, np.nan) for s in METRICS}
    data.update({f"relative_error_{s}": np.full(shape, np.nan) for s in METRICS})
    data["reference_max_displacement"] = np.full(len(cases), np.nan)
    data["max_displacement"] = np.full(shape, np.nan)
    data["wall_time"] = np.full(shape, np.nan)
    pub = {f"published_{s}": np.full(shape, np.nan) for s in ("mean", "std", "max", "relative_mean", "relative_std", "relative_max")}
    pub_text = np.full(shape, "", dtype=object)
    for i, case in enumerate(cases):
        ref = results.get((case, exp.reference)) if exp.reference else None
        if ref is not None:
            u_ref = ref["displacement"].transpose("node", "axis").values
            data["reference_max_displacement"][i] = np.linalg.norm(u_ref, axis=1).max()
        for j, model in enumerate(variants):
            ds = results[(case, model)]
            u = ds["displacement"].transpose("node", "axis").values
            data["max_displacement"][i, j] = np.linalg.norm(u, axis=1).max()
            data["wall_time"][i, j] = float(ds.attrs.get("wall_time_s", np.nan))
            if ref is not None:  # the one measurement of `msslib compare`
                err = compare_results(
                    ds, ref, result_name=str(ds.encoding.get("source") or f"the run ({case}, {model})"),
                    reference_name=str(ref.encoding.get("source") or f"the run ({case}, {exp.reference})")).error
                for s in METRICS:
                    data[f"error_{s}"][i, j] = getattr(err, s)
                    data[f"relative_error_{s}"][i, j] = getattr(err, f"rel_{s}")
            raw = (exp.published.get(case, {}).get(model, {}) or {})
            pub_text[i, j] = ", ".join(f"{k} {v[0]:g} {v[1]}" for k, v in raw.items())
            for metric, (value, unit) in _published(exp, case, model).items():
                key = f"published_{'relative_' if unit == '%' else ''}{metric}"
                if key in pub:
                    pub[key][i, j] = value
    coords = {"case": cases, "variant": variants}
    units = {"wall_time": "s"}
    ds = xr.Dataset(coords=coords)
    for name, arr in {**data, **pub}.items():
        dims = ("case",) if arr.ndim == 1 else ("case", "variant")
        unit = units.get(name, "1" if "relative" in name else "m")
        ds[name] = xr.DataArray(arr, dims=dims, attrs={"units": unit, "long_name": name.replace("_", " ")})
    ds["published_text"] = xr.DataArray(pub_text.astype(str), dims=("case", "variant"),
                                        attrs={"long_name": "published values as printed", "units": "1"})
    ds.attrs.update(experiment=exp.name, paper=exp.paper, title=exp.title, section=exp.section,
                    reference=exp.reference or "")
    return ds


def markdown_table(ds) -> str:
    """The comparison as a Markdown table: ours (absolute and relative to the largest reference
    displacement), the published values as printed, and the difference ours - published for the
    mean and maximum where the paper gives them (in mm, or in % for relative values)."""
    source = ", ".join(str(v) for v in (ds.attrs['paper'], ds.attrs['section']) if str(v))
    lines = [f"**{ds.attrs['title']}**{f' ({source})' if source else ''}; reference: {ds.attrs['reference'] or '-'}", "",
             "| case | model | mean (mm) | SD (mm) | max (mm) | mean (%) | SD (%) | max (%) | published | "
             "ours - published, mean | ours - published, max | wall time (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def mm(v):
        return "-" if not np.isfinite(v) else f"{v * 1e3:.3g}"

    def pc(v):
        return "-" if not np.isfinite(v) else f"{v * 100:.3g}"

    def diff(r, stat):
        ours, pub = float(r[f"error_{stat}"]), float(r[f"published_{stat}"])
        if np.isfinite(ours) and np.isfinite(pub):
            return f"{(ours - pub) * 1e3:+.2g} mm"
        ours, pub = float(r[f"relative_error_{stat}"]), float(r[f"published_relative_{stat}"])
        if np.isfinite(ours) and np.isfinite(pub):
            return f"{(ours - pub) * 100:+.2g} %"
        return "-"

    for case in ds.case.values:
        for var in ds.variant.values:
            r = ds.sel(case=case, variant=var)
            text = str(r.published_text.values) if "published_text" in ds else ""
            lines.append(
                f"| {case} | {var} | {mm(r.error_mean)} | {mm(r.error_std)} | {mm(r.error_max)} | "
                f"{pc(r.relative_error_mean)} | {pc(r.relative_error_std)} | {pc(r.relative_error_max)} | "
                f"{text or '-'} | {diff(r, 'mean')} | {diff(r, 'max')} | {float(r.wall_time):.3g} |")
    return "\n".join(lines) + "\n"

"""Draw a figure declared as data: in an experiment file (its ``figures`` block, checked by
:mod:`msslib.experiment`) from the experiment's runs, or in a curves file
(``experiments/<paper>/figures/curves.yaml``) from a study's result::

    python -m experiments.figures experiments/lloyd/cone.yaml cone --out paper/figures/lloyd_cone
    python -m experiments.figures experiments/baudet/figures/curves.yaml bulk_modulus --out paper/figures/baudet_bulk_modulus

writes ``STEM.png`` and ``STEM.pdf``. The runs are read from ``--results DIR`` (default
``results/<paper>/<experiment file name>``, where ``python -m msslib experiment run-all`` writes them);
``--quick`` is accepted like every figure, table and study of experiments/ (a figure draws whatever
runs it finds, reduced or not). Kind ``comparison``: one column per (case, variant, reference), the
variant's wireframe (red) over the reference coloured by its displacement magnitude, the rest shape
in grey, and the per-node distance between the two below
(:func:`experiments.plotting.comparison_figure`, which takes the figure's options). A curves figure:
one study variable as curves over one coordinate, one per Poisson's ratio, one panel per selection
(:func:`experiments.plotting.curves_figure`; the keys are listed at the top of the curves file and in
:data:`CURVES_KEYS`).
"""

from __future__ import annotations

import math
import shlex
from pathlib import Path

import yaml

from experiments import script
from msslib.experiment import figure_runs, load_experiment


def results_dir(exp) -> Path:
    """Where ``python -m msslib experiment run-all`` puts the runs of ``exp`` in the workflow."""
    return Path("results", *([exp.paper] if exp.paper else []), exp.path.stem)


def inputs(exp, name, results=None) -> list[Path]:
    """The run files figure ``name`` of ``exp`` reads, in the order of its columns."""
    folder = Path(results) if results is not None else results_dir(exp)
    return [folder / f"{case}__{model}.nc" for case, model in figure_runs(exp, name)]


def draw(exp, name, results=None):
    """The figure ``name`` of ``exp`` as a :class:`matplotlib.figure.Figure`; a missing run file raises
    FileNotFoundError naming it."""
    from experiments import plotting
    from msslib.results import read_result

    spec = exp.figures[name]
    files = inputs(exp, name, results)
    missing = [str(p) for p in files if not p.is_file()]
    if missing:
        folder = Path(results) if results is not None else results_dir(exp)
        raise FileNotFoundError(f"figure {name!r} of {exp.path} reads {len(missing)} missing run file(s), "
                                f"first {missing[0]}; run `python -m msslib experiment run-all "
                                f"{shlex.quote(str(exp.path))} --out-dir {shlex.quote(str(folder))}` first")
    data = dict(zip(figure_runs(exp, name), (read_result(p) for p in files)))
    pairs = {c["title"]: (data[(c["case"], c["variant"])], data[(c["case"], c["reference"])])
             for c in spec["columns"]}
    return plotting.comparison_figure(pairs, **spec["options"])


#: the keys of a figure in a curves file: required, and optional with their defaults
CURVES_KEYS = {"required": ("result", "variable", "x", "xlabel", "ylabel", "panels"),
               "optional": {"description": "", "dashed": None, "marks": None, "xscale": 100.0, "yscale": 100.0,
                            "band": None, "height": None}}


def load_curves(path) -> dict:
    """The figures of a curves file, ``{name: spec}`` with the optional keys filled in; a one-line
    ValueError naming the file, the figure and the key for anything else."""
    path = Path(path)
    raw = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    if not isinstance(raw, dict) or not isinstance(raw.get("figures"), dict) or set(raw) - {"figures", "shared"}:
        raise ValueError(f"{path}: a curves file holds 'figures' (name: figure) and optionally 'shared'")
    out = {}
    allowed = set(CURVES_KEYS["required"]) | set(CURVES_KEYS["optional"])
    for name, spec in raw["figures"].items():
        where = f"{path}: figure {name!r}"
        if not isinstance(spec, dict):
            raise ValueError(f"{where}: expected a mapping of {', '.join(sorted(allowed))}")
        missing = [k for k in CURVES_KEYS["required"] if k not in spec]
        unknown = sorted(set(spec) - allowed)
        if missing or unknown:
            raise ValueError(f"{where}: " + "; ".join(
                ([f"missing {', '.join(missing)}"] if missing else []) + ([f"unknown {', '.join(unknown)}"] if unknown else []))
                + f" (keys: {', '.join(sorted(allowed))})")
        spec = {**CURVES_KEYS["optional"], **spec}
        result = spec["result"]
        if not isinstance(result, str) or not result.startswith("results/") or not result.endswith(".nc"):
            raise ValueError(f"{where}: result {result!r} is not a results/....nc file")
        for key in ("variable", "x", "xlabel", "ylabel", "description"):
            if not isinstance(spec.get(key, ""), str) or (key != "description" and not spec[key].strip()):
                raise ValueError(f"{where}: {key} {spec[key]!r}: expected a "
                                 + ("string (or leave it out)" if key == "description" else "non-empty string"))
        for key, low, high, what in (("xscale", 0.0, None, "a number above 0"), ("yscale", 0.0, None, "a number above 0"),
                                     ("band", 0.0, None, "a number above 0 (%), or leave it out"),
                                     ("height", 0.0, 20.0, "a height in inches above 0 and at most 20, or leave it out")):
            value = spec.get(key)
            if value is None and key in ("band", "height"):
                continue
            if (not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value)
                    or not value > low or (high is not None and value > high)):
                raise ValueError(f"{where}: {key} {value!r}: expected {what}")
        for key in ("panels", "dashed", "marks"):
            value = spec.get(key)
            if value is not None and not (isinstance(value, dict) and value and all(
                    isinstance(t, str) and isinstance(v, list if key == "marks" else dict) for t, v in value.items())):
                raise ValueError(f"{where}: {key} must map a title to "
                                 + ("published points [[x, y, nu], ...]" if key == "marks" else "a selection"))
            for title, sel in (value or {}).items():
                if key == "marks":
                    bad = [m for m in sel if not (isinstance(m, list) and len(m) == 3 and all(
                        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in m[:2])
                        and isinstance(m[2], (str, int, float)) and not isinstance(m[2], bool))]
                    if bad or not sel:
                        raise ValueError(f"{where}: marks {title!r}: {bad[0] if bad else sel!r} is not a list of "
                                         "published points [x, y, nu] (x and y finite numbers)")
                    continue
                bad = {d: v for d, v in sel.items() if not isinstance(d, str) or isinstance(v, bool)
                       or not isinstance(v, (str, int, float))}
                if bad:
                    d, v = next(iter(bad.items()))
                    raise ValueError(f"{where}: {key} {title!r}: {d}: {v!r} is not one coordinate value "
                                     "(a string or a number)")
        unknown_marks = sorted(set(spec.get("marks") or {}) - set(spec["panels"]))
        if unknown_marks:
            raise ValueError(f"{where}: marks for panels it does not draw: {', '.join(unknown_marks)}")
        out[name] = spec
    return out


def draw_curves(spec):
    """A curves figure (a spec of :func:`load_curves`) from its study result."""
    import xarray as xr

    from experiments import plotting

    path = Path(spec["result"])
    if not path.is_file():
        # results/<paper>/studies/<name>.nc is written by experiments/<paper>/studies/<name>.py
        study = Path(__file__).resolve().parent.joinpath(*path.parts[1:-1], f"{path.stem}.py")
        build = (f"`python -m experiments.{'.'.join(path.parts[1:-1])}.{path.stem} --out {shlex.quote(str(path))}`"
                 if study.is_file() and path.parts[0] == "results" else "its study")
        raise FileNotFoundError(f"{path}: the study result the figure reads is missing; build it first: run {build}")
    with xr.open_dataset(path) as ds:
        ds = ds.load()
    for key in (spec["variable"], spec["x"]):
        if key not in ds.variables:
            raise ValueError(f"{path} has no {key!r}")
    da = ds[spec["variable"]]
    for title, sel in spec["panels"].items():
        for extra in [{}, *(spec["dashed"] or {}).values()]:
            unknown = sorted(set({**sel, **extra}) - set(da.dims))
            open_dims = sorted(set(da.dims) - {"nu", spec["x"]} - set({**sel, **extra}))
            if unknown or open_dims:
                raise ValueError(f"{path}: {spec['variable']}: panel {title!r} "
                                 + (f"selects {', '.join(unknown)}, not a dimension" if unknown else
                                    f"leaves {', '.join(open_dims)} open")
                                 + f" (dimensions: {', '.join(da.dims)})")
    marks = {title: [tuple(m) for m in points] for title, points in (spec["marks"] or {}).items()} or None
    return plotting.curves_figure(da, ds[spec["x"]].values, xlabel=spec["xlabel"],
                                  ylabel=spec["ylabel"], panels=spec["panels"], xscale=spec["xscale"],
                                  yscale=spec["yscale"], dashed=spec["dashed"], marks=marks, band=spec["band"],
                                  height=spec["height"])


def main(argv=None):
    from experiments import plotting

    def extra(ap):
        ap.add_argument("experiment", help="experiment file (YAML) with a figures block, or a curves file")
        ap.add_argument("name", help="the figure's name in that block")
        ap.add_argument("--results", help="folder of the runs (default: results/<paper>/<experiment>)")

    _, args = script.parse(__doc__, argv, extra=extra)
    try:
        if Path(args.experiment).name == "curves.yaml":
            figures = load_curves(args.experiment)
            if args.name not in figures:
                raise ValueError(f"{args.experiment}: no figure {args.name!r}; declared: {', '.join(sorted(figures))}")
            plotting.save(draw_curves(figures[args.name]), args.out)
            return
        exp = load_experiment(args.experiment)
        if args.name not in exp.figures:
            raise ValueError(f"{args.experiment}: no figure {args.name!r}; declared: "
                             f"{', '.join(sorted(exp.figures)) or 'none'}")
        fig = draw(exp, args.name, args.results)
    except yaml.YAMLError as exc:
        raise SystemExit(f"experiments.figures: error: {args.experiment}: invalid YAML: "
                         f"{' '.join(str(exc).split())}") from None
    except (OSError, ValueError) as exc:
        raise SystemExit(f"experiments.figures: error: {exc}") from None
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

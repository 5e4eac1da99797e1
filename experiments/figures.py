"""Draw a figure declared in an experiment file (its ``figures`` block, checked by
:mod:`msslib.experiment`) from the experiment's runs::

    python -m experiments.figures experiments/lloyd/cone.yaml cone --out paper/figures/lloyd_cone

writes ``STEM.png`` and ``STEM.pdf``. The runs are read from ``--results DIR`` (default
``results/<paper>/<experiment file name>``, where ``python -m msslib experiment run-all`` writes them);
``--quick`` is accepted like every figure, table and study of experiments/ (a figure draws whatever
runs it finds, reduced or not). Kind ``comparison``: one column per (case, variant, reference), the
variant's wireframe (red) over the reference coloured by its displacement magnitude, the rest shape
in grey, and the per-node distance between the two below
(:func:`experiments.plotting.comparison_figure`, which takes the figure's options).
"""

from __future__ import annotations

from pathlib import Path

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
        raise FileNotFoundError(f"figure {name!r} of {exp.path} reads {len(missing)} missing run file(s), "
                                f"first {missing[0]}; run `python -m msslib experiment run-all {exp.path}` first")
    data = dict(zip(figure_runs(exp, name), (read_result(p) for p in files)))
    pairs = {c["title"]: (data[(c["case"], c["variant"])], data[(c["case"], c["reference"])])
             for c in spec["columns"]}
    return plotting.comparison_figure(pairs, **spec["options"])


def main(argv=None):
    from experiments import plotting

    def extra(ap):
        ap.add_argument("experiment", help="experiment file (YAML) with a figures block")
        ap.add_argument("name", help="the figure's name in that block")
        ap.add_argument("--results", help="folder of the runs (default: results/<paper>/<experiment>)")

    _, args = script.parse(__doc__, argv, extra=extra)
    try:
        exp = load_experiment(args.experiment)
        if args.name not in exp.figures:
            raise ValueError(f"{args.experiment}: no figure {args.name!r}; declared: "
                             f"{', '.join(sorted(exp.figures)) or 'none'}")
        fig = draw(exp, args.name, args.results)
    except (OSError, ValueError) as exc:
        raise SystemExit(f"experiments.figures: error: {exc}") from None
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()

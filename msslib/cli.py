"""Command line of msslib: ``python -m msslib COMMAND ...`` (also the ``msslib`` console script).

Commands
--------
``run SCENE.yaml --out OUT.nc [--vtu OUT.vtu] [--quiet]``
    Validate, build and solve a scene (:mod:`msslib.scene`) and write the result atomically as
    NetCDF (:func:`msslib.io.write_result`); with ``--vtu`` (or ``output: {vtu: ...}`` in the scene)
    also a VTU file for ParaView.  Output directories are checked before the run; on any failure no
    output file is left behind.  A progress bar is drawn on stderr for runs longer than half a
    second unless ``--quiet``.
``validate SCENE.yaml``
    Check the scene and build its mesh, boundary conditions, loads and model without solving.
``experiment run|run-all|compare|list EXPERIMENT.yaml ...``
    Run the (case, model) pairs of an experiment and compare them with its reference
    (:mod:`msslib.experiment`).
``plan SCENE.yaml --max-error E``
    The cheapest measured (model, resolution) within an error budget (:mod:`msslib.planning`).
``vtu RESULT.nc --out OUT.vtu``
    Export any result to VTU for ParaView.
``paper SOURCE --out OUT.html``
    Build the paper (:mod:`msslib.paper`).

Exit codes: 0 success, 1 bad input or a failed solve (a one-line ``msslib: error: ...`` message on
stderr, no traceback), 2 bad command-line usage (argparse).

Adding a command: write ``_add_NAME(subparsers)`` that creates its subparser and sets
``func=_cmd_NAME`` with :meth:`argparse.ArgumentParser.set_defaults`, where ``_cmd_NAME(args) ->
int``, and append it to :data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

__all__ = ["main", "build_parser", "COMMANDS"]


class CommandError(Exception):
    """A user-facing error reported as one line with exit code 1."""


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _check_writable(path: Path, what: str) -> None:
    """Fail early (before a long run) when ``path`` cannot be written."""
    if path.is_dir():
        raise CommandError(f"{what} {str(path)!r} is a directory")
    directory = path.parent
    if not directory.exists():
        raise CommandError(f"cannot write {what} {str(path)!r}: directory {str(directory)!r} does not exist")
    if not directory.is_dir():
        raise CommandError(f"cannot write {what} {str(path)!r}: {str(directory)!r} is not a directory")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise CommandError(f"cannot write {what} {str(path)!r}: directory {str(directory)!r} is not writable")


def _vtu_path(scene, out: Path, cli_vtu: str | None) -> Path | None:
    if cli_vtu:
        return Path(cli_vtu)
    vtu = scene.output.get("vtu", False)
    if vtu is True:
        return out.with_suffix(".vtu")
    if isinstance(vtu, str):
        return out.parent / vtu
    return None


def _write_vtu(path: Path, ds) -> None:
    import numpy as np

    from msslib.io import mesh_from_result
    from msslib.mesh import write_vtu

    mesh = mesh_from_result(ds)
    point_data = {"displacement": ds["displacement"].transpose("node", "axis").values}
    if "reaction_force" in ds:
        point_data["reaction_force"] = ds["reaction_force"].transpose("node", "axis").values
    if "fixed" in ds:
        point_data["fixed"] = np.asarray(ds["fixed"].transpose("node", "axis").values, dtype=np.int8)
    write_vtu(path, mesh, point_data=point_data)


# --------------------------------------------------------------------------------------------
# commands
# --------------------------------------------------------------------------------------------


def _add_run(subparsers) -> None:
    p = subparsers.add_parser("run", help="run a scene and write its result (NetCDF, optionally VTU)",
                              description="Run a scene and write its result atomically.")
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--out", "-o", required=True, help="result file (NetCDF, .nc)")
    p.add_argument("--vtu", help="also write the final state as a VTU file (ParaView)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary line")
    p.set_defaults(func=_cmd_run)


def _cmd_run(args) -> int:
    from msslib.io import write_result
    from msslib.scene import load_scene, run_scene

    scene = load_scene(args.scene)
    out = Path(args.out)
    vtu = _vtu_path(scene, out, args.vtu)
    _check_writable(out, "output file")
    if vtu is not None:
        _check_writable(vtu, "VTU file")
        if vtu.resolve() == out.resolve():
            raise CommandError(f"the VTU file and the output file are the same: {str(out)!r}")
    ds = run_scene(scene, progress=not args.quiet)
    existed = out.exists()
    write_result(out, ds)
    if vtu is not None:
        try:
            _write_vtu(vtu, ds)
        except BaseException:
            if not existed:  # no half-finished set of outputs
                try:
                    out.unlink()
                except OSError:
                    pass
            raise
    if not args.quiet:
        extra = f" and {vtu}" if vtu is not None else ""
        umax = float(abs(ds["displacement"]).max())
        print(f"{scene.name}: {ds.attrs['model']}, {ds.sizes['node']} nodes, max |u_i| {umax:.4g} m, "
              f"{ds.attrs['wall_time_s']:.2f} s -> {out}{extra}", file=sys.stderr)
    return 0


def _add_validate(subparsers) -> None:
    p = subparsers.add_parser("validate", help="check a scene without solving it",
                              description="Check a scene: keys, values, mesh, selections, model.")
    p.add_argument("scene", help="scene file (YAML)")
    p.set_defaults(func=_cmd_validate)


def _cmd_validate(args) -> int:
    from msslib.scene import load_scene, prepare

    scene = load_scene(args.scene)
    setup = prepare(scene)
    mesh = setup.mesh
    kind = scene.solver["type"]
    print(f"{args.scene}: ok ({scene.name}: {scene.model}, {kind}; {mesh.n_nodes} nodes, {mesh.n_cells} "
          f"{mesh.cell_type} cells, {int(setup.fixed.sum())} fixed dofs)")
    return 0


def _add_experiment(subparsers) -> None:
    p = subparsers.add_parser("experiment", help="run one case of an experiment, or compare its runs",
                              description="Experiments (msslib.experiment): cases x model variants of a base scene.")
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    r = sub.add_parser("run", help="run one (case, model) of an experiment")
    r.add_argument("experiment", help="experiment file (YAML)")
    r.add_argument("--case", required=True)
    r.add_argument("--model", required=True)
    r.add_argument("--quick", action="store_true", help="apply the experiment's reduced (quick) overrides")
    r.add_argument("--out", "-o", required=True, help="result file (NetCDF)")
    r.add_argument("--quiet", "-q", action="store_true")
    r.set_defaults(func=_cmd_experiment_run)
    c = sub.add_parser("compare", help="compare every variant with the reference, beside the published numbers")
    c.add_argument("experiment", help="experiment file (YAML)")
    c.add_argument("--results", required=True, help="directory holding CASE__MODEL.nc")
    c.add_argument("--out", "-o", required=True, help="comparison file (NetCDF)")
    c.add_argument("--table", help="also write the comparison as a Markdown table")
    c.set_defaults(func=_cmd_experiment_compare)
    a = sub.add_parser("run-all", help="run every (case, model) of an experiment in one process")
    a.add_argument("experiment", help="experiment file (YAML)")
    a.add_argument("--out-dir", required=True, help="directory for CASE__MODEL.nc")
    a.add_argument("--quick", action="store_true", help="apply the experiment's reduced (quick) overrides")
    a.add_argument("--quiet", "-q", action="store_true")
    a.set_defaults(func=_cmd_experiment_run_all)
    ls = sub.add_parser("list", help="print the CASE__MODEL run names of an experiment")
    ls.add_argument("experiment")
    ls.set_defaults(func=_cmd_experiment_list)


def _cmd_experiment_run(args) -> int:
    from msslib import experiment
    from msslib.io import write_result

    exp = experiment.load_experiment(args.experiment)
    out = Path(args.out)
    _check_writable(out, "output file")
    ds = experiment.run(exp, args.case, args.model, quick=args.quick, progress=not args.quiet)
    write_result(out, ds)
    return 0


def _cmd_experiment_run_all(args) -> int:
    from msslib import experiment
    from msslib.io import write_result

    exp = experiment.load_experiment(args.experiment)
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    runs = experiment.runs(exp)
    for i, (case, model) in enumerate(runs, 1):
        out = out_dir / f"{case}__{model}.nc"
        if not args.quiet:
            print(f"[{i}/{len(runs)}] {exp.name}: {case} / {model}", file=sys.stderr, flush=True)
        write_result(out, experiment.run(exp, case, model, quick=args.quick, progress=not args.quiet))
    return 0


def _cmd_experiment_compare(args) -> int:
    from msslib import experiment
    from msslib.io import read_result, write_result, write_text

    exp = experiment.load_experiment(args.experiment)
    out = Path(args.out)
    _check_writable(out, "output file")
    results = {}
    for case, model in experiment.runs(exp):
        path = Path(args.results) / f"{case}__{model}.nc"
        if not path.is_file():
            raise CommandError(f"missing run {str(path)!r}")
        results[(case, model)] = read_result(path)
    ds = experiment.compare(exp, results)
    write_result(out, ds)
    if args.table:
        table = Path(args.table)
        _check_writable(table, "table")
        write_text(table, experiment.markdown_table(ds))
    return 0


def _cmd_experiment_list(args) -> int:
    from msslib import experiment

    exp = experiment.load_experiment(args.experiment)
    for case, model in experiment.runs(exp):
        print(f"{case}__{model}")
    return 0


def _add_vtu(subparsers) -> None:
    p = subparsers.add_parser("vtu", help="export a NetCDF result to VTU (ParaView)",
                              description="Write the final state of any msslib result file as a VTU file.")
    p.add_argument("result", help="result file (NetCDF) written by msslib")
    p.add_argument("--out", "-o", required=True, help="VTU file")
    p.set_defaults(func=_cmd_vtu)


def _cmd_vtu(args) -> int:
    from msslib.io import read_result

    src = Path(args.result)
    if not src.is_file():
        raise CommandError(f"result file not found: {str(src)!r}")
    out = Path(args.out)
    _check_writable(out, "VTU file")
    _write_vtu(out, read_result(src))
    return 0


def _add_paper(subparsers) -> None:
    p = subparsers.add_parser("paper", help="build the paper (Markdown with placeholders -> HTML)")
    p.add_argument("source", help="main source, e.g. paper/paper.md.in")
    p.add_argument("--out", "-o", required=True, help="HTML file (a .md twin is written beside it)")
    p.set_defaults(func=_cmd_paper)


def _cmd_paper(args) -> int:
    from msslib.paper import build

    build(args.source, args.out)
    return 0


def _add_plan(subparsers) -> None:
    p = subparsers.add_parser("plan", help="the cheapest model and resolution within an error budget",
                              description="Measure (or read) the speed/error front of a scene and pick the cheapest "
                                          "(model, resolution) whose error against converged non-linear FEM is within budget.")
    p.add_argument("scene", help="scene file (YAML) with a mesh generator")
    p.add_argument("--max-error", type=float, required=True, help="budget: max node error / max reference displacement")
    p.add_argument("--front", help="a front measured before (NetCDF from `plan --save` or the workflow)")
    p.add_argument("--save", help="write the measured front here (NetCDF)")
    p.add_argument("--levels", default="1,2,3", help="resolution levels to measure (default 1,2,3)")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--budget", type=float, default=30.0, help="wall-time budget per run (s); slower runs are recorded as failed")
    p.set_defaults(func=_cmd_plan)


def _cmd_plan(args) -> int:
    from msslib import planning
    from msslib.io import read_result, write_result

    if not args.max_error > 0:
        raise CommandError(f"--max-error must be > 0, got {args.max_error}")
    if args.front:
        front = read_result(args.front)
    else:
        levels = tuple(int(v) for v in args.levels.split(","))
        front = planning.measure_front(args.scene, levels=levels, repeats=args.repeats, budget=args.budget,
                                       progress=lambda s: print(s, file=sys.stderr))
        if args.save:
            _check_writable(Path(args.save), "front file")
            write_result(args.save, front)
    best = planning.choose(front, args.max_error)
    print(f"reference: {front.attrs['reference_model']} at level {front.attrs['reference_level']}")
    for m, lv, t, e in planning.pareto(front):
        print(f"  front: {m:26s} level {lv}: {t:.3g} s, max error {100 * e:.3g} %")
    if best is None:
        raise CommandError(f"no measured model/resolution reaches max error {args.max_error:g}; "
                           f"smallest measured: {100 * float(front.error_max.min()):.3g} %")
    m, lv, t, e = best
    print(f"choice: {m} at resolution level {lv}: max error {100 * e:.3g} % <= {100 * args.max_error:.3g} %, "
          f"median wall time {t:.3g} s")
    return 0


#: subparser builders, in the order of the help text
COMMANDS = [_add_run, _add_validate, _add_experiment, _add_paper, _add_plan, _add_vtu]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="msslib", description="Mass-spring systems and their FEM references.")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in COMMANDS:
        add(subparsers)
    return parser


def main(argv=None) -> int:
    """Entry point; returns the exit code (0 ok, 1 error, 2 usage)."""
    import warnings

    from msslib.errors import MsslibWarning, UnphysicalStateError
    from msslib.solvers import ConvergenceError, DivergenceError

    parser = build_parser()
    args = parser.parse_args(argv)
    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, MsslibWarning):
            print(f"msslib: warning: {_one_line(message)}", file=sys.stderr)
        else:
            previous(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        return int(args.func(args) or 0)
    except (CommandError, ValueError, OSError, ConvergenceError, DivergenceError, UnphysicalStateError) as exc:
        print(f"msslib: error: {_one_line(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("msslib: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.showwarning = previous

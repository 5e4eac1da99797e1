"""Command line of msslib: ``python -m msslib COMMAND ...`` (also the ``msslib`` console script).

Commands
--------
``run SCENE.yaml --out OUT.nc [--vtu OUT.vtu|OUT.pvd] [--quiet]``
    Validate, build and solve a scene (:mod:`msslib.scene`) and write the result atomically as
    NetCDF (:func:`msslib.results.netcdf.write_result`); with ``--vtu`` (or ``output: {vtu: ...}`` in the scene)
    also for ParaView (:mod:`msslib.results.paraview`; the suffix decides): ``.vtu`` the final state,
    ``.pvd`` every saved state as a time series (``OUT_0000.vtu``, ... and ``OUT_springs.vtu``
    beside it).  Output directories are checked before the run; on any failure no
    output file is left behind.  A progress bar is drawn on stderr for runs longer than half a
    second unless ``--quiet``.
``validate SCENE.yaml``
    Check the scene and build its mesh, boundary conditions, loads and model without solving.
``experiment run|run-all|compare|list EXPERIMENT.yaml ...``
    Run the (case, model) pairs of an experiment and compare them with its reference
    (:mod:`msslib.experiment`).
``plan SCENE.yaml --max-error E``
    The cheapest measured (model, resolution) within an error budget (:mod:`msslib.planning`).
``compare RESULT.nc REFERENCE.nc [--out TABLE.md] [--vtu ERROR.vtu]``
    The per-node error of a result against a reference on the same or another mesh of the same
    body (:mod:`msslib.compare`), as a table and optionally as a field for ParaView.
``vtu RESULT.nc --out OUT.vtu|OUT.pvd``
    Export any result for ParaView: ``.vtu`` the final state, ``.pvd`` every saved state.
``export SCENE.yaml --out DIR/|STEM [--format csv,json,vtu,mjcf,sofa,c]``
    The complete mass-spring system of a scene, without solving (:mod:`msslib.export`): springs,
    volume and correction terms, masses, fixed nodes and loads as CSV/JSON and VTU, a MuJoCo model,
    a SOFA scene and the C header of the derived formulas and kernels.

Inputs and outputs: an output that is one of the command's inputs (the scene, its mesh file, the
experiment, the result or front read) or another of its outputs is refused before anything runs
(same resolved path, or :func:`os.path.samefile`: hard and symbolic links too); a ParaView series
is refused before the run when a file it writes beside the ``.pvd`` would be an input.  A command that
writes several files writes them together (:class:`msslib.results.staging.StagedOutputs`): all are replaced,
or none is; temporary files are removed on any error, on SIGINT and on SIGTERM.

``--version`` prints ``msslib X.Y.Z``.

Exit codes: 0 success, 1 bad input or a failed solve (a one-line ``msslib: error: ...`` message on
stderr, no traceback), 2 bad command-line usage (argparse), 130 interrupted (SIGINT), 143
terminated (SIGTERM).

Adding a command: write ``_add_NAME(subparsers)`` that creates its subparser and sets
``func=_cmd_NAME`` with :meth:`argparse.ArgumentParser.set_defaults`, where ``_cmd_NAME(args) ->
int``, and append it to :data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

__all__ = ["main", "build_parser", "COMMANDS"]


from msslib.cli.stop import StopWhenAsked
from msslib.cli.inputs import (
    CommandError,
    one_line,
    check_distinct,
    check_writable,
    input_file,
    load_scene,
    mesh_input,
    load_experiment,
    choice,
    read_result_file,
    vtu_path,
    check_paraview,
)


# --------------------------------------------------------------------------------------------
# commands
# --------------------------------------------------------------------------------------------


def _add_run(subparsers) -> None:
    p = subparsers.add_parser("run", help="run a scene and write its result (NetCDF, optionally VTU)",
                              description="Run a scene and write its result atomically.")
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--out", "-o", required=True, help="result file (NetCDF, .nc)")
    p.add_argument("--vtu", help="also write for ParaView: OUT.vtu the final state, OUT.pvd every saved state "
                                 "(OUT_0000.vtu, ... and OUT_springs.vtu beside it)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary line")
    p.set_defaults(func=_cmd_run)


def _cmd_run(args) -> int:
    from msslib.results import StagedOutputs, stage_result
    from msslib.results.paraview import ParaViewOutput
    from msslib.scene import run_scene

    scene = load_scene(args.scene)
    out = Path(args.out)
    vtu = vtu_path(scene, out, args.vtu)
    view = ParaViewOutput(vtu) if vtu is not None else None
    inputs = [("scene file", Path(args.scene)), *mesh_input(scene)]
    outputs = [("output file", out), *([(view.what, view.path)] if view is not None else [])]
    check_distinct(outputs, inputs)
    if view is not None:
        check_paraview(view, [*inputs, ("output file", out)])
    for what, path in outputs:
        check_writable(path, what)
    ds = run_scene(scene, progress=not args.quiet)
    files = view.files(ds) if view is not None else []
    check_distinct([("output file", out), *files], inputs)  # every file of a series, links included
    with StagedOutputs() as staged:  # every file, or none
        stage_result(staged, out, ds)
        if view is not None:
            view.stage(staged, ds)
    if not args.quiet:
        extra = f" and {vtu}" if vtu is not None else ""
        if len(files) > 1:
            extra += f" (with {len(files) - 1} VTU files beside it)"
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
    from msslib.scene import prepare

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
    a = sub.add_parser("run-all", help="run every (case, model) of an experiment in one process",
                       description="Run every (case, model) of an experiment; the result files are written "
                                   "together at the end (all of them, or none).")
    a.add_argument("experiment", help="experiment file (YAML)")
    a.add_argument("--out-dir", required=True, help="directory for CASE__MODEL.nc")
    a.add_argument("--quick", action="store_true", help="apply the experiment's reduced (quick) overrides")
    a.add_argument("--quiet", "-q", action="store_true")
    a.set_defaults(func=_cmd_experiment_run_all)
    ls = sub.add_parser("list", help="print the CASE__MODEL run names of an experiment")
    ls.add_argument("experiment")
    ls.set_defaults(func=_cmd_experiment_list)


def _experiment_scenes(exp, pairs, quick):
    """Every run's scene, validated (before anything runs); their mesh files."""
    from msslib import experiment
    from msslib.scene import load_scene

    meshes = []
    for case, model in pairs:
        scene = load_scene(experiment.scene_of(exp, case, model, quick), base_dir=exp.base_dir)
        meshes += [m for m in mesh_input(scene) if m not in meshes]
    return meshes


def _cmd_experiment_run(args) -> int:
    from msslib import experiment
    from msslib.results import write_result

    exp = load_experiment(args.experiment)
    choice("--case", args.case, list(exp.cases), f"case of experiment {exp.name}")
    choice("--model", args.model, list(exp.models), f"model of experiment {exp.name}")
    meshes = _experiment_scenes(exp, [(args.case, args.model)], args.quick)
    out = Path(args.out)
    check_distinct([("output file", out)], [("experiment file", Path(args.experiment)), *meshes])
    check_writable(out, "output file")
    ds = experiment.run(exp, args.case, args.model, quick=args.quick, progress=not args.quiet)
    write_result(out, ds)
    return 0


def _cmd_experiment_run_all(args) -> int:
    from msslib import experiment
    from msslib.results import StagedOutputs, stage_result

    exp = load_experiment(args.experiment)
    out_dir = Path(args.out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise CommandError(f"--out-dir {str(out_dir)!r} is not a directory")
    runs = experiment.runs(exp)
    meshes = _experiment_scenes(exp, runs, args.quick)
    outputs = [("output file", out_dir / f"{case}__{model}.nc") for case, model in runs]
    check_distinct(outputs, [("experiment file", Path(args.experiment)), *meshes])
    out_dir.mkdir(parents=True, exist_ok=True)
    for what, path in outputs:
        check_writable(path, what)
    with StagedOutputs() as staged:  # every result, or none
        for i, ((case, model), (_, out)) in enumerate(zip(runs, outputs), 1):
            if not args.quiet:
                print(f"[{i}/{len(runs)}] {exp.name}: {case} / {model}", file=sys.stderr, flush=True)
            stage_result(staged, out, experiment.run(exp, case, model, quick=args.quick, progress=not args.quiet))
    return 0


def _cmd_experiment_compare(args) -> int:
    from msslib import experiment
    from msslib.results import StagedOutputs, stage_result

    exp = load_experiment(args.experiment)
    out = Path(args.out)
    table = Path(args.table) if args.table else None
    results_dir = Path(args.results)
    if not results_dir.is_dir():
        raise CommandError(f"--results {str(results_dir)!r} is not a directory")
    paths = {(case, model): results_dir / f"{case}__{model}.nc" for case, model in experiment.runs(exp)}
    outputs = [("output file", out), ("table", table)]
    check_distinct(outputs, [("experiment file", Path(args.experiment)), *(("run", p) for p in paths.values())])
    for what, path in outputs:
        if path is not None:
            check_writable(path, what)
    results = {}
    for key, path in paths.items():
        if not path.is_file():
            import shlex

            run_all = shlex.join(["python", "-m", "msslib", "experiment", "run-all", str(args.experiment),
                                  "--out-dir", str(results_dir)])
            raise CommandError(f"missing run {str(path)!r}; run `{run_all}` first")
        results[key] = read_result_file(path, "run")
    ds = experiment.compare(exp, results)
    with StagedOutputs() as staged:  # both files, or neither
        stage_result(staged, out, ds, what="comparison")
        if table is not None:
            staged.write_text(table, experiment.markdown_table(ds), what="table")
    return 0


def _cmd_experiment_list(args) -> int:
    from msslib import experiment

    exp = load_experiment(args.experiment)
    for case, model in experiment.runs(exp):
        print(f"{case}__{model}")
    return 0


def _add_vtu(subparsers) -> None:
    p = subparsers.add_parser("vtu", help="export a NetCDF result for ParaView (.vtu or .pvd)",
                              description="Write any msslib result file for ParaView: OUT.vtu the final state, "
                                          "OUT.pvd every saved state (a time series).")
    p.add_argument("result", help="result file (NetCDF) written by msslib")
    p.add_argument("--out", "-o", required=True,
                   help="OUT.vtu (the final state) or OUT.pvd (every saved state: OUT_0000.vtu, ... and "
                        "OUT_springs.vtu beside it)")
    p.set_defaults(func=_cmd_vtu)


def _cmd_vtu(args) -> int:
    from msslib.results.paraview import ParaViewOutput

    src, out = Path(args.result), Path(args.out)
    if not src.exists():
        raise CommandError(f"result file not found: {str(src)!r}")
    view = ParaViewOutput(out)
    check_distinct([(view.what, out)], [("result file", src)])
    check_paraview(view, [("result file", src)])
    check_writable(out, view.what)
    ds = read_result_file(src)
    check_distinct(view.files(ds), [("result file", src)])
    view.write(ds)  # every file of a series, or none
    return 0


def _add_compare(subparsers) -> None:
    p = subparsers.add_parser("compare", help="the per-node error of one result against another (msslib.compare)")
    p.add_argument("result", help="result file (NetCDF)")
    p.add_argument("reference", help="reference result file (NetCDF), same mesh or another mesh of the same body")
    p.add_argument("--out", "-o", help="also write the table (Markdown)")
    p.add_argument("--vtu", help="also write the error field on the result's mesh for ParaView (.vtu)")
    p.set_defaults(func=_cmd_compare)


def _cmd_compare(args) -> int:
    from msslib.compare import compare_results, write_error_field
    from msslib.results import StagedOutputs

    src, ref = Path(args.result), Path(args.reference)
    out, vtu = (Path(a) if a else None for a in (args.out, args.vtu))
    if vtu and vtu.suffix.lower() != ".vtu":
        raise CommandError(f"--vtu {str(vtu)!r}: the error field is one state; give a .vtu file")
    outputs = [("table", out), ("error field", vtu)]
    check_distinct(outputs, [("result file", src), ("reference file", ref)])
    for what, path in outputs:
        if path is not None:
            check_writable(path, what)
    comparison = compare_results(read_result_file(src, "result file"), read_result_file(ref, "reference file"),
                                 result_name=str(src), reference_name=str(ref))
    with StagedOutputs() as staged:  # both files, or neither
        if out is not None:
            staged.write_text(out, comparison.table(), what="table")
        if vtu is not None:
            staged.write(vtu, lambda tmp: write_error_field(tmp, comparison), what="error field")
    print(comparison.table(), end="")
    return 0


LEVELS_HELP = "distinct integers >= 1 separated by commas, e.g. 1,2,3"


def _add_plan(subparsers) -> None:
    p = subparsers.add_parser("plan", help="the cheapest model and resolution within an error budget",
                              description="Measure (or read) the speed/error front of a scene and pick the cheapest "
                                          "(model, resolution) whose error against converged non-linear FEM is within budget.")
    p.add_argument("scene", help="scene file (YAML), with a mesh generator or a mesh file")
    p.add_argument("--max-error", type=float, required=True,
                   help="budget: max node error / max reference displacement, a fraction (0.05 = 5 %%)")
    p.add_argument("--front", help="a front measured before (NetCDF from `plan --save`) for this scene")
    p.add_argument("--save", help="write the front here (NetCDF)")
    p.add_argument("--levels", help=f"resolution levels to measure: {LEVELS_HELP} (default 1,2,3)")
    p.add_argument("--repeats", type=int, help="runs per (model, level), 1 to 100; the median time counts (default 3; "
                                               "the median of 100 runs scatters an eighth as much as one run, more runs "
                                               "only lengthen the measurement)")
    p.add_argument("--budget", type=float,
                   help="wall-time budget per run (s); slower runs are recorded as failed (default 30)")
    p.add_argument("--time-limit", type=float,
                   help="without --levels: measure the levels of 1,2,3 whose estimated time in all (dofs, memory and "
                        "time of every level and of the reference, estimated before anything runs) is within this "
                        "many seconds (default 150)")
    p.set_defaults(func=_cmd_plan)


def _parse_levels(text: str) -> tuple[int, ...]:
    if not text.strip():
        raise CommandError(f"--levels is empty; give {LEVELS_HELP}")
    levels = []
    for item in text.split(","):
        item = item.strip()
        if not item.isdigit() or not item.isascii() or int(item) < 1:
            raise CommandError(f"--levels {text!r}: {item!r} is not an integer >= 1; give {LEVELS_HELP}")
        if int(item) in levels:
            raise CommandError(f"--levels {text!r}: level {int(item)} is given twice; give {LEVELS_HELP}")
        levels.append(int(item))
    return tuple(levels)


def _positive_number(option: str, value: float, what: str) -> float:
    if not (math.isfinite(value) and value > 0):
        raise CommandError(f"{option} must be a finite number > 0 ({what}), got {value!r}")
    return value


def _read_front(path: Path, scene: Path):
    import yaml

    from msslib import planning

    ds = read_result_file(path, "front file", required=())
    try:
        planning.check_front(ds, name=f"front file {str(path)!r}")
    except ValueError as exc:
        raise CommandError(one_line(exc)) from None
    raw, _ = planning._raw(scene)
    try:
        measured = yaml.safe_load(str(ds.attrs.get("scene", "")))
    except yaml.YAMLError:
        measured = None
    if measured != raw:
        raise CommandError(f"front file {str(path)!r} was not measured for the scene {str(scene)!r}; "
                           f"give the scene it was measured for, or measure again without --front")
    return ds


def _cmd_plan(args) -> int:
    from msslib import planning
    from msslib.results import write_result

    scene = Path(args.scene)
    max_error = _positive_number("--max-error", args.max_error, "a fraction of the largest reference displacement")
    planning.check_arguments(max_error=max_error)  # above 1: "did you mean 5 %?"
    if args.front is not None:
        given = [o for o, v in (("--levels", args.levels), ("--repeats", args.repeats), ("--budget", args.budget),
                                ("--time-limit", args.time_limit)) if v is not None]
        if given:
            raise CommandError(f"{given[0]} applies to a measurement; with --front nothing is measured")
    levels = _parse_levels("1,2,3" if args.levels is None else args.levels)
    repeats = 3 if args.repeats is None else args.repeats
    if not 1 <= repeats <= planning.MAX_REPEATS:
        raise CommandError(f"--repeats must be an integer from 1 to {planning.MAX_REPEATS}, got {repeats}")
    budget = 30.0 if args.budget is None else _positive_number("--budget", args.budget, "seconds per run")
    if args.time_limit is not None:
        _positive_number("--time-limit", args.time_limit, "seconds for the whole measurement")
        if args.levels is not None:
            raise CommandError("--time-limit chooses the levels; with --levels they are given")
    input_file(scene, "scene file")
    front_path = Path(args.front) if args.front is not None else None
    save = Path(args.save) if args.save is not None else None
    check_distinct([("--save file", save)], [("scene file", scene), ("--front file", front_path)])
    if save is not None:
        check_writable(save, "--save file")
    if front_path is not None:
        front = _read_front(front_path, scene)
    else:
        progress = lambda s: print(s, file=sys.stderr)  # noqa: E731
        if args.levels is None:  # the default levels within the time limit, estimated before anything runs
            limit = planning.DEFAULT_TIME_LIMIT if args.time_limit is None else args.time_limit
            levels, estimate, lines = planning.levels_within(args.scene, limit, levels=levels, repeats=repeats)
            for line in lines:
                print(line, flush=True)
            progress = planning.with_eta(progress, estimate["total_s"])
        front = planning.measure_front(args.scene, levels=levels, repeats=repeats, budget=budget, progress=progress)
    if save is not None:
        write_result(save, front)
    for line in planning.report(front, max_error):  # the reference's own error beside the choice
        print(line)
    return 0


def _add_export(subparsers) -> None:
    from msslib.export.files import format_help

    p = subparsers.add_parser(
        "export", help="write a scene's mass-spring system without solving it (CSV, JSON, VTU, MuJoCo, SOFA, C)",
        description="Build a scene's model without solving and write it (msslib.export): the springs (nodes, "
                    "stiffness N/m, rest length m), volume terms and Baudet's correction with their constants, node "
                    "masses and rest positions, fixed nodes, prescribed displacements, loads and gravity. csv: one "
                    "table per file, header row with units; json: one document with a schema version; vtu: springs as "
                    "line cells; mjcf: a MuJoCo model; sofa: a SOFA scene (.scn); c: the generated C header. MuJoCo "
                    "and SOFA cannot carry volume terms: by default they are written only for models without them.")
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--out", "-o", required=True,
                   help="a directory (existing, or ending in '/': the files are named after the scene) or a path "
                        "prefix STEM: STEM_TABLE.csv, STEM.json, STEM.vtu, STEM_mujoco.xml, STEM.scn, msslib_mss.h")
    p.add_argument("--format", "-f", dest="formats", metavar="LIST",
                   help=format_help())
    p.add_argument("--quiet", "-q", action="store_true", help="no summary line")
    p.set_defaults(func=_cmd_export)


def _cmd_export(args) -> int:
    import warnings

    from msslib.export import files as export_files
    from msslib.export import formats as export_formats
    from msslib import export
    from msslib.errors import MsslibWarning

    try:
        formats = export_files.parse_formats(args.formats)
    except ValueError as exc:
        raise CommandError(one_line(exc)) from None
    scene_path = Path(args.scene)
    scene = load_scene(scene_path)
    if scene.is_fem:
        raise CommandError(f"scene file {str(scene_path)!r}: model {scene.model} is a FEM reference; export writes "
                           f"the mass-spring models")
    out = Path(args.out)
    directory = out.is_dir() or str(args.out).endswith(("/", os.sep))
    if directory and out.exists() and not out.is_dir():
        raise CommandError(f"--out {str(args.out)!r} is not a directory")
    exp = export.build(scene)
    chosen = formats if formats is not None else export_files.default_formats(exp)
    stem = export_files.stem_for(out, scene.name, directory)
    planned = export_files.output_paths(exp, stem, chosen)
    inputs = [("scene file", scene_path), *mesh_input(scene)]
    if "c" in chosen:
        inputs.append(("generated C header", export.C_HEADER_PATH))
    check_distinct([(what, path) for _, what, path, _ in planned], inputs)
    if directory and not out.exists():
        check_writable(out, "output directory")
    else:
        for _, what, path, _ in planned:
            check_writable(path, what)
    skipped = [f for f in export_formats.whole_only() if formats is None and f not in chosen]
    if skipped:
        left_out = list(dict.fromkeys(n for f in skipped for n in export.not_carried(exp, f)))
        listed = " and ".join(skipped) if len(skipped) < 3 else f"{', '.join(skipped[:-1])} and {skipped[-1]}"
        warnings.warn(f"{scene.name}: {listed} not written: the model {scene.model} has "
                      f"{'; '.join(left_out)}, which {'they cannot' if len(skipped) > 1 else 'it cannot'} express; "
                      f"--format {','.join(skipped)} writes the rest of the model with a note", MsslibWarning,
                      stacklevel=2)
    for fmt in chosen:
        missing = export.not_carried(exp, fmt) if fmt in export_formats.whole_only() else []
        if missing:
            warnings.warn(f"{scene.name}: the {fmt} output of model {scene.model} does not carry {'; '.join(missing)} "
                          f"(said in the file; "
                          f"the csv and json outputs carry everything)", MsslibWarning, stacklevel=2)
    # every file or none, with a manifest; a new folder appears whole; never over a file not the export's
    export_files.write_outputs(exp, stem, planned)
    if not args.quiet:
        extra = f", {'; '.join(exp.volume_terms)}" if exp.volume_terms else ""
        print(f"{scene.name}: {scene.model}, {exp.n_nodes} nodes, {len(exp.pairs)} springs{extra} -> "
              f"{len(planned)} files ({', '.join(chosen)}) at {stem}", file=sys.stderr)
    return 0


#: subparser builders, in the order of the help text
COMMANDS = [_add_run, _add_validate, _add_experiment, _add_compare, _add_plan, _add_vtu, _add_export]


def build_parser() -> argparse.ArgumentParser:
    from msslib import __version__

    parser = argparse.ArgumentParser(prog="msslib", description="Mass-spring systems and their FEM references.")
    parser.add_argument("--version", action="version", version=f"msslib {__version__}",
                        help="print the version (msslib X.Y.Z) and exit")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in COMMANDS:
        add(subparsers)
    return parser


def main(argv=None) -> int:
    """Entry point; returns the exit code (0 ok, 1 error, 2 usage, 130 interrupted, 143 terminated)."""
    import warnings

    from msslib.errors import MsslibWarning, UnphysicalStateError
    from msslib.results import Terminated, terminate_raises
    from msslib.solvers import ConvergenceError, DivergenceError

    parser = build_parser()
    args = parser.parse_args(argv)
    previous = warnings.showwarning

    shown = set()

    def show(message, category, filename, lineno, file=None, line=None):
        # one line per distinct warning (a model built again, e.g. by plan's repeats, says the same
        # once): msslib's own as they are, others (numpy, scipy, ...) with their origin
        origin = "" if issubclass(category, MsslibWarning) else f" ({category.__name__} in {Path(filename).name})"
        text = f"msslib: warning: {one_line(message)}{origin}"
        if text not in shown:
            shown.add(text)
            print(text, file=sys.stderr)

    warnings.showwarning = show
    stop = StopWhenAsked()
    try:
        with terminate_raises(), stop:  # SIGTERM unwinds like SIGINT: temporary files are removed
            return int(args.func(args) or 0)
    except (CommandError, ValueError, OSError, ConvergenceError, DivergenceError, UnphysicalStateError) as exc:
        print(f"msslib: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except Terminated:
        print("msslib: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("msslib: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:
        if getattr(exc, "msslib_output", None) is None:  # a failed write of an output names it
            raise
        print(f"msslib: error: {one_line(exc)}", file=sys.stderr)
        return 1
    finally:
        warnings.showwarning = previous

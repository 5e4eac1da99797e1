"""Speed against error: measure the front of (model, resolution) for a scene, and choose from it.

:func:`measure_front` (:mod:`msslib.planning.front`, the engine of ``python -m msslib plan`` and
of the paper's speed-against-error study) runs a scene on nested levels (level ``k``: its mesh,
generated or read from a file, refined uniformly ``k - 1`` times) with every model that fits its
cells (mass-spring models, linear FEM, non-linear FEM), records the time and the displacement
error against a quadratic-element FEM reference (:mod:`msslib.planning.reference`: its own error
estimated from its coarser levels, locking-free near nu = 1/2), and returns an xarray Dataset.
:func:`choose` returns the cheapest measured (model, level) whose error is within a budget, and
refuses a budget below what the reference resolves; :func:`report` gives the lines ``plan``
prints, the reference's own error beside the choice.  Errors are relative to the largest
reference displacement (maximum over nodes of the Euclidean error); a budget is a fraction
(0.05 = 5 %), and one above 1 is refused as a likely percentage.

:func:`refine` (generator arguments scaled by a level) remains for the benchmarks' scenes.
"""

from __future__ import annotations

import copy
import math
import numbers
import os
from pathlib import Path

import numpy as np
import yaml

#: the non-linear FEM reference of each dimension (2D: St Venant-Kirchhoff, 3D: neo-Hookean)
_REFERENCE_LAW = {2: "fem_svk", 3: "fem_neohookean"}


def _cell_dims():
    """Cell type -> dimension, of every cell type some mass-spring model runs on."""
    from msslib import models

    return {cell: spec.dim for spec in models.registry().values() if spec.kind == "mss" for cell in spec.cells}


_DIM = _cell_dims()


def _models_for(cell_type):
    """The models compared on ``cell_type`` cells: every mass-spring model of the registry that runs
    on them, then linear FEM and the dimension's non-linear reference."""
    from msslib import models

    return [*models.for_cells(cell_type, "mss"), "fem_linear", _REFERENCE_LAW[_DIM[cell_type]]]


#: cell type -> models compared by default (from the registry of msslib.models)
MODELS = {cell: _models_for(cell) for cell in _DIM}
#: cell type -> the converged reference model
REFERENCE = {cell: _REFERENCE_LAW[dim] for cell, dim in _DIM.items()}
SCALED = {"nx", "ny", "nz", "n", "n_rings"}


def _raw(scene):
    """The scene as a plain mapping, and the directory its relative paths refer to."""
    if isinstance(scene, dict):
        return copy.deepcopy(scene), Path.cwd()
    if not isinstance(scene, (str, os.PathLike)):
        raise ValueError(f"scene must be a scene file or a mapping, got {type(scene).__name__} {scene!r}")
    path = Path(scene)
    if not path.is_file():
        raise FileNotFoundError(f"scene file not found: {str(scene)!r}")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"scene file {str(scene)!r} is not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ValueError(f"scene file {str(scene)!r}: invalid YAML: {' '.join(str(exc).split())}") from None
    if raw is None:
        raise ValueError(f"scene file {str(scene)!r} is empty; planning needs a scene with a mesh generator")
    if not isinstance(raw, dict):
        raise ValueError(f"scene file {str(scene)!r}: expected a mapping (a scene), got {type(raw).__name__}")
    return raw, path.resolve().parent


def _scaled(path, value, level, kind):
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, str)):
        raise ValueError(f"{path}: expected a number, got {value!r}")
    try:
        number = float(value)
    except (ValueError, OverflowError):
        raise ValueError(f"{path}: expected a number, got {value!r}") from None
    if not math.isfinite(number) or number <= 0:
        raise ValueError(f"{path}: expected a finite number > 0, got {value!r}")
    if kind == "count":
        if number != int(number):
            raise ValueError(f"{path}: expected an integer (a number of cells), got {value!r}")
        return int(number) * level
    return number / level


def refine(raw: dict, level: int) -> dict:
    """The scene with its generator's resolution arguments scaled by ``level``."""
    level = _level("level", level)
    if not isinstance(raw, dict):
        raise ValueError(f"scene: expected a mapping, got {type(raw).__name__}")
    out = copy.deepcopy(raw)
    geo = out.get("geometry", {})
    if not isinstance(geo, dict) or "generator" not in geo:
        raise ValueError("scene.geometry: planning needs a generator (a mesh file has one resolution)")
    args = geo.setdefault("args", {})
    if not isinstance(args, dict):
        raise ValueError(f"scene.geometry.args: expected a mapping, got {args!r}")
    scaled = False
    for k in list(args):
        if k in SCALED:
            args[k] = _scaled(f"scene.geometry.args.{k}", args[k], level, "count")
            scaled = True
        elif k == "h":
            args[k] = _scaled(f"scene.geometry.args.{k}", args[k], level, "size")
            scaled = True
    if not scaled:
        raise ValueError(f"scene.geometry.args: no resolution argument among {sorted(SCALED | {'h'})}")
    return out


def _level(name, value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)) or value < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


#: the most runs per (model, level) of :func:`measure_front`: the median of 100 runs already
#: scatters about an eighth as much as one run (1.25 / sqrt(100)); more runs only multiply the
#: time the measurement takes (every model at every level runs that often, each up to the budget)
MAX_REPEATS = 100


def check_arguments(*, levels=(1, 2, 3), models=None, repeats=3, budget=30.0, max_error=None):
    """Validate the arguments of :func:`measure_front` (and ``max_error`` of :func:`choose`);
    ValueError naming the argument and what is allowed. Returns ``levels`` as a tuple of ints."""
    if isinstance(levels, (str, bytes)) or not isinstance(levels, (list, tuple, np.ndarray)):
        raise ValueError(f"levels must be a non-empty sequence of integers >= 1, got {levels!r}")
    levels = tuple(_level(f"levels[{i}]", v) for i, v in enumerate(levels))
    if not levels:
        raise ValueError("levels must be a non-empty sequence of integers >= 1, got none")
    twice = sorted({v for v in levels if levels.count(v) > 1})
    if twice:
        raise ValueError(f"levels must be distinct, got {list(levels)} ({', '.join(map(str, twice))} repeated)")
    if models is not None:
        if isinstance(models, str) or not isinstance(models, (list, tuple)) or not models:
            raise ValueError(f"models must be None or a non-empty list of model names, got {models!r}")
        from msslib.scene import MODELS as known

        for m in models:
            if m not in known:
                raise ValueError(f"models: unknown model {m!r}; expected some of {', '.join(known)}")
        if len(set(models)) != len(models):
            raise ValueError(f"models must be distinct, got {list(models)}")
    if isinstance(repeats, (bool, np.bool_)) or not isinstance(repeats, (numbers.Integral, np.integer)) or not (
            1 <= repeats <= MAX_REPEATS):
        raise ValueError(f"repeats must be an integer from 1 to {MAX_REPEATS} (more runs only lengthen the "
                         f"measurement), got {repeats!r}")
    if budget is not None:
        if isinstance(budget, (bool, np.bool_)) or not isinstance(budget, numbers.Real) or not (
                math.isfinite(budget) and budget > 0):
            raise ValueError(f"budget must be a finite number of seconds > 0 (or None for no limit), got {budget!r}")
    if max_error is not None:
        _max_error(max_error)
    return levels


def _max_error(value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not (
            math.isfinite(value) and value > 0):
        raise ValueError(f"max_error must be a finite number > 0 (a fraction of the largest reference "
                         f"displacement), got {value!r}")
    if value > 1:
        raise ValueError(f"max error {value:g} is {100 * value:g} % of the largest reference displacement; it is a "
                         f"fraction: did you mean {value:g} % (max error {value / 100:g})?")
    return float(value)


def _with_model(raw, model):
    """The scene with ``model``, keeping the scene's model options that ``model`` takes (its spec in
    :mod:`msslib.models`) except ``A``, ``published`` and ``terms`` (each model at its defaults)."""
    from msslib import models

    out = copy.deepcopy(raw)
    m = out.get("model")
    spec = models.registry().get(model)
    takes = {o.name for o in spec.options} - {"A"} if spec is not None else set()
    opts = {k: v for k, v in m.items() if k in takes} if isinstance(m, dict) else {}
    if spec is not None and spec.kind == "fem":
        sol = out.get("solver") or {}
        if isinstance(sol, dict) and sol.get("type") == "dynamic":
            raise ValueError("planning compares static solves; the scene is dynamic")
    out["model"] = {"type": model, **opts}
    return out


class RunTimeout(BaseException):  # not an Exception: solvers must not swallow it
    """A run exceeded its wall-time budget."""


def run_with_budget(scene, budget=None, *, cpu=False):
    """``run_scene(scene)`` stopped by :class:`RunTimeout` after ``budget`` seconds of wall time
    (``cpu=True``: of CPU time); no limit where the platform has no interval timers."""
    import signal

    from msslib.scene import run_scene

    if not budget or not hasattr(signal, "SIGALRM"):
        return run_scene(scene, progress=False)
    sig, timer, what = ((signal.SIGPROF, signal.ITIMER_PROF, "s of CPU time") if cpu
                        else (signal.SIGALRM, signal.ITIMER_REAL, "s"))

    def _alarm(_sig, _frame):
        raise RunTimeout(f"exceeded the budget of {budget:g} {what}")

    old = signal.signal(sig, _alarm)
    signal.setitimer(timer, budget)
    try:
        return run_scene(scene, progress=False)
    finally:
        signal.setitimer(timer, 0)
        signal.signal(sig, old)


def _run(raw, base_dir, budget=None):
    from msslib.scene import load_scene

    return run_with_budget(load_scene(raw, base_dir=base_dir), budget)


def check_scene(scene, *, levels=(1, 2, 3), models=None):
    """Validate a scene for planning without solving anything: a mapping or a scene file (a
    generated mesh or a mesh file), valid (:func:`msslib.scene.load_scene`) at every level with
    every model, a mesh that can be built at the first level, a static solver.  Returns
    ``(raw, base_dir, cell_type, models, reference_model)``; ValueError (or FileNotFoundError)
    naming what is wrong."""
    from msslib import models as registry
    from msslib.mesh import cells
    from msslib.planning.front import at_level, check_scene_levels
    from msslib.scene import load_scene, prepare

    levels = check_arguments(levels=levels, models=models)
    raw, base_dir = _raw(scene)
    scene_ = load_scene(raw, base_dir=base_dir)  # every key and value, with the usual messages
    if scene_.is_dynamic:
        raise ValueError("scene.solver: planning compares static solves; the scene is dynamic")
    setup = prepare(load_scene(at_level(raw, min(levels), "fem_linear"), base_dir=base_dir))  # the mesh, no solve
    cell_type = setup.mesh.cell_type
    quadratic = [n for n, c in cells.registry().items() if c.quadratic is not None]
    if cell_type not in quadratic:
        raise ValueError(f"scene.geometry: {cell_type} cells have no quadratic FEM element (scikit-fem has none), so "
                         f"plan has no reference to measure errors against; allowed: meshes of "
                         f"{', '.join(quadratic)} cells")
    if cell_type not in MODELS:
        raise ValueError(f"scene.geometry: planning knows no models for {cell_type} cells")
    models = list(models or MODELS[cell_type])
    fitting = list(registry.for_cells(cell_type))
    wrong = [m for m in models if m not in fitting]
    if wrong:
        raise ValueError(f"models: {', '.join(wrong)} cannot run on {cell_type} cells; expected some of "
                         f"{', '.join(fitting)}")
    ref_model = REFERENCE[cell_type]
    check_scene_levels(raw, base_dir, levels, models, ref_model)
    return raw, base_dir, cell_type, models, ref_model


#: the default of ``plan --time-limit`` (s): the estimated time of the whole measurement
DEFAULT_TIME_LIMIT = 150.0
#: the levels ``plan`` measures by default, within the time limit
DEFAULT_LEVELS = (1, 2, 3)


def check_time_limit(value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) or not (
            math.isfinite(value) and value > 0):
        raise ValueError(f"time_limit must be a finite number of seconds > 0, got {value!r}")
    return float(value)


def levels_within(scene, time_limit=DEFAULT_TIME_LIMIT, *, levels=DEFAULT_LEVELS, repeats=3, models=None,
                  calibrate=True):
    """The levels of ``levels`` that a plan measures within ``time_limit`` seconds: the finest
    ones are dropped (never the first) while the estimate of the whole measurement
    (:func:`msslib.planning.reference.estimate`, calibrated by a small reference solve on this
    machine unless ``calibrate`` is false) exceeds the limit.  Returns ``(levels, estimate,
    lines)``: the estimate of the levels kept and the lines that say so (the limit, each
    level's dofs, the reference's dofs, memory and time, the total)."""
    from msslib import models as registry
    from msslib.planning import reference as ref
    from msslib.planning.front import at_level
    from msslib.scene import load_scene, prepare

    time_limit = check_time_limit(time_limit)
    levels = check_arguments(levels=levels, models=models, repeats=repeats)
    raw, base_dir, cell_type, models, ref_model = check_scene(scene, levels=levels, models=models)
    setup = prepare(load_scene(at_level(raw, 1, ref_model), base_dir=base_dir))
    rate = ref.calibrate(setup, registry.get(ref_model).law) if calibrate else None
    kept = sorted(levels)
    est = ref.estimate(setup, kept, repeats=repeats, n_models=len(models), calibration=rate)
    while len(kept) > 1 and est["total_s"] > time_limit:
        kept = kept[:-1]
        est = ref.estimate(setup, kept, repeats=repeats, n_models=len(models), calibration=rate)
    lines = [f"time limit {time_limit:g} s (--time-limit): measuring levels {','.join(map(str, kept))}, estimated "
             f"{est['total_s']:.0f} s in all" + ("" if kept == sorted(levels) else
                                                 _dropped(levels, kept))]
    for lv in sorted(est["levels"]):
        e = est["levels"][lv]
        lines.append(f"  level {lv}: models {e['dofs']} dofs; reference {e['reference_dofs']} dofs, about "
                     f"{e['memory_bytes'] / 1e9:.2g} GB, about {e['reference_s']:.2g} s")
    return tuple(kept), est, lines


def _dropped(levels, kept):
    gone = [str(v) for v in sorted(levels) if v not in kept]
    return f" (level{'s' if len(gone) > 1 else ''} {','.join(gone)} would exceed it)"


def with_eta(progress, total_s, clock=None):
    """``progress`` with each line followed by the time elapsed and an estimate of the time left
    (the estimated total less the time elapsed; "overrunning" once the estimate is passed)."""
    import time

    clock = clock or time.perf_counter
    t0 = clock()

    def say(line):
        if progress is None:
            return
        elapsed = clock() - t0
        left = total_s - elapsed
        eta = f"about {left:.0f} s left" if left >= 0.5 else "past the estimate"
        progress(f"{line}  [{elapsed:.0f} s elapsed, {eta}]")

    return say


from msslib.planning.front import measure_front as measure_front  # noqa: E402 - the engine (public), after what it uses

FRONT_VARIABLES = ("wall_time", "error_max", "error_mean", "n_dofs", "status")
FRONT_ATTRS = ("reference_model", "reference_level")


def check_front(front, name="front"):
    """ValueError naming ``name`` unless ``front`` is a front of :func:`measure_front`."""
    import xarray as xr

    if not isinstance(front, xr.Dataset):
        raise ValueError(f"{name} must be an xarray Dataset from measure_front, got {type(front).__name__}")
    missing = [v for v in FRONT_VARIABLES if v not in front.variables] + [a for a in FRONT_ATTRS if a not in front.attrs]
    if missing or set(front["error_max"].dims) != {"model", "level"}:
        what = f"lacks {', '.join(map(repr, missing))}" if missing else "has the wrong dimensions"
        raise ValueError(f"{name} is not a front measured by msslib plan ({what})")
    return front


def reference_error(front) -> float:
    """The reference's own error estimate of a front (NaN when it has none)."""
    try:
        return float(front.attrs.get("reference_error", math.nan))
    except (TypeError, ValueError):
        return math.nan


def choose(front, max_error: float):
    """The cheapest measured (model, level) with ``error_max <= max_error``, or None.  A budget
    below the reference's own error estimate is refused (ValueError): the reference cannot tell
    which model meets it."""
    check_front(front)
    max_error = _max_error(max_error)
    ref_err = reference_error(front)
    if math.isfinite(ref_err) and max_error < ref_err:
        raise ValueError(f"max error {100 * max_error:.3g} % is below the reference's own error, about "
                         f"{100 * ref_err:.2g} % (its change under the last refinement, levels "
                         f"{front.attrs.get('reference_levels', '?')}): it cannot tell which model meets that budget; "
                         f"allowed: a budget of at least {100 * ref_err:.2g} %, or measure finer levels (--levels)")
    best = None
    for m in front.model.values:
        for lv in front.level.values:
            r = front.sel(model=m, level=lv)
            e, t = float(r.error_max), float(r.wall_time)
            if np.isfinite(e) and e <= max_error and (best is None or t < best[2]):
                best = (str(m), int(lv), t, e)
    return best


def report(front, max_error: float) -> list[str]:
    """The lines ``plan`` prints: the reference with its own error, the Pareto front and the
    choice, the reference's error beside it (flagged when the choice's margin is within it).
    ValueError when no measured point is within the budget, or the budget is below what the
    reference resolves."""
    best = choose(front, max_error)
    ref_err = reference_error(front)
    own = (f"own error about {100 * ref_err:.2g} % (change under its last refinement "
           f"{100 * float(front.attrs.get('reference_step_change', math.nan)):.2g} %)"
           if math.isfinite(ref_err) else "own error not estimated (one level only)")
    lines = [f"reference: {front.attrs['reference_model']} on level {front.attrs['reference_level']}, {own}"]
    for m, lv, t, e in pareto(front):
        lines.append(f"  front: {m:26s} level {lv}: {t:.3g} s, max error {100 * e:.3g} %")
    if best is None:
        smallest = float(front.error_max.min())
        shown = f"{100 * smallest:.3g} %" if math.isfinite(smallest) else "none (every run failed)"
        raise ValueError(f"no measured model/resolution reaches max error {max_error:g}; smallest measured: {shown}")
    m, lv, t, e = best
    note = ""
    if math.isfinite(ref_err):
        note = f" (reference's own error about {100 * ref_err:.2g} %"
        note += ", within the margin: the choice is uncertain)" if e + ref_err > max_error else ")"
    timing = "best CPU time" if front.attrs.get("timing") == "cpu" else "median wall time"
    lines.append(f"choice: {m} at resolution level {lv}: max error {100 * e:.3g} % <= {100 * max_error:.3g} %"
                 f"{note}, {timing} {t:.3g} s")
    from msslib.planning.front import ties

    tied = ties(front, best, max_error)
    if tied:
        r = front.sel(model=m, level=lv)
        lines.append(f"tie: within the timing spread ({float(r.time_min):.3g}-{float(r.time_max):.3g} s over "
                     f"{int(r.runs)} runs) of " + ", ".join(f"{tm} level {tl} ({a:.3g}-{b:.3g} s)" for tm, tl, a, b in tied)
                     + "; another run may choose any of them")
    return lines


def pareto(front):
    """(model, level, time, error) on the Pareto front: no other point is both faster and more accurate."""
    check_front(front)
    pts = [(str(m), int(lv), float(front.wall_time.sel(model=m, level=lv)), float(front.error_max.sel(model=m, level=lv)))
           for m in front.model.values for lv in front.level.values]
    pts = [p for p in pts if np.isfinite(p[2]) and np.isfinite(p[3])]
    return sorted((p for p in pts if not any(q[2] <= p[2] and q[3] <= p[3] and (q[2], q[3]) != (p[2], p[3]) for q in pts)),
                  key=lambda p: p[2])

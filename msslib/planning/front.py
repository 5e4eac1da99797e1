"""The speed-against-error engine: every (model, level) of a scene timed and measured against the
quadratic reference of :mod:`msslib.planning.reference`.  ``python -m msslib plan`` and the
paper's study (``experiments/performance``) both measure with :func:`measure_front`.

Levels: level ``k`` (``k >= 1``) is the scene's mesh, generated or read from a file, refined
uniformly ``k - 1`` times (``geometry.refine``, :func:`msslib.mesh.refine.uniform`, on top of a
``refine`` the scene asks for itself): nested meshes of one domain, every node of a level a node
of the finer ones.  The reference is the dimension's non-linear FEM law (2D St Venant-Kirchhoff,
3D neo-Hookean) with quadratic elements on the finest measured level (its dofs are the nodes of
the level above it), solved on up to two coarser levels too for its own error estimate.  A
model's error is measured at its own nodes: the largest Euclidean difference from the reference
there, relative to the largest reference displacement (``error_max``; ``error_mean`` the mean).

Timing (``cpu=False``, the default of ``plan``): the median wall time of ``repeats`` runs
(:func:`msslib.scene.run_scene`: mesh, model set-up and solve), a run stopped after ``budget``
seconds; ``cpu=True`` (the paper): the best CPU time of up to ``repeats`` runs after a warm-up run
on the coarsest level, stopped after ``budget`` seconds of CPU time (single-threaded, it is the
wall time on an idle machine and not inflated by other load).  Runs longer than ``long_run``
seconds are timed once.  The dataset keeps the median, smallest and largest time of the timed
runs (``time_median``, ``time_min``, ``time_max``): two points whose ranges overlap are not told
apart by the timing (:func:`ties`; ``plan`` says so when its choice ties with other candidates).
"""

from __future__ import annotations

import copy
import math
import time
import warnings

import numpy as np
import yaml


def at_level(raw, level: int, model: str, linear: bool = False):
    """The scene mapping of ``model`` on ``level`` (the scene's mesh refined ``level - 1`` more
    times); ``linear``: one solve with the stiffness at rest (``solver.linear``)."""
    from msslib.planning import _with_model

    out = _with_model(raw, model)
    geo = out["geometry"]
    geo["refine"] = int(geo.get("refine", 0) or 0) + int(level) - 1
    if linear:
        sol = out.get("solver") if isinstance(out.get("solver"), dict) else {}
        out["solver"] = {**sol, "linear": True}
    return out


def variants(models, linear_variants=False):
    """``(name, model, linear)`` of every measured variant: each model, and with
    ``linear_variants`` each mass-spring model's linearised solve (``NAME_linear``) after it."""
    from msslib import models as registry

    out = []
    for m in models:
        out.append((m, m, False))
        if linear_variants and registry.get(m).kind == "mss":
            out.append((f"{m}_linear", m, True))
    return out


def _timed(raw, base_dir, repeats, budget, cpu, long_run, spread=None):
    """``(time, best wall time, runs, dataset)``: the median wall time of ``repeats`` runs, or
    (``cpu``) the best CPU time; a run longer than ``long_run`` s ends the repeats.  ``spread``
    (a list) receives ``(median, min, max)`` of the times measured."""
    from msslib.planning import run_with_budget
    from msslib.scene import load_scene

    times, walls, ds = [], [], None
    for _ in range(repeats):
        scene = load_scene(raw, base_dir=base_dir)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # inverted cells etc. are recorded in the dataset
            c0 = time.process_time()
            ds = run_with_budget(scene, budget, cpu=cpu)
            c = time.process_time() - c0
        walls.append(float(ds.attrs["wall_time_s"]))
        times.append(c if cpu else walls[-1])
        if long_run is not None and times[-1] > long_run:
            break
    t = min(times) if cpu else float(np.median(times))
    if spread is not None:
        spread[:] = [float(np.median(times)), float(min(times)), float(max(times))]
    return t, min(walls), len(times), ds


def measure_front(scene, *, levels=(1, 2, 3), models=None, repeats=3, budget=30.0, progress=print, cpu=False,
                  linear_variants=False, warmup=False, long_run=None, reference_level=None):
    """Measure time and error of every (variant, level); returns an xarray Dataset.

    Every argument and the scene are checked before anything is run
    (:func:`msslib.planning.check_arguments`, :func:`msslib.planning.check_scene`).  A run that
    fails or exceeds ``budget`` seconds (None: no limit) is recorded in ``status`` (NaN time and
    error) instead of stopping the sweep: that a model breaks on a scene is a result too.  The
    attributes hold the reference: ``reference_model``, ``reference_level``,
    ``reference_error`` (its own error estimate, :mod:`msslib.planning.reference`),
    ``reference_step_change``, ``reference_observed_order``, ``reference_dofs``,
    ``reference_wall_time``, ``reference_max_displacement``, ``reference_locking_nu``.
    ``reference_level``: the level of the reference (default the finest measured; the level
    below it also works, its quadratic dofs being the finest level's nodes)."""
    import xarray as xr

    from msslib.metrics import displacement_error
    from msslib.planning import RunTimeout, check_arguments, check_scene
    from msslib.planning.reference import at_points, reference
    from msslib.scene import load_scene, prepare

    levels = check_arguments(levels=levels, models=models, repeats=repeats, budget=budget)
    raw, base_dir, cell_type, models, ref_model = check_scene(scene, levels=levels, models=models)
    say = progress or (lambda _s: None)
    repeats = int(repeats)
    t0 = time.perf_counter()
    from msslib import models as registry

    law = registry.get(ref_model).law

    def prepare_level(lv):
        return prepare(load_scene(at_level(raw, lv, ref_model), base_dir=base_dir))

    top = max(levels) if reference_level is None else int(reference_level)
    if top not in (max(levels), max(levels) - 1) or top < 1:
        raise ValueError(f"reference_level must be the finest level {max(levels)} or the one below it, got {top}")
    ref = reference(prepare_level, top, law, say)
    scale = ref["scale"]
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"the reference ({ref_model} on level {top}) does not move (largest displacement "
                         f"{scale:g} m): errors relative to it mean nothing; give the scene a load or a "
                         f"prescribed displacement")
    say(f"reference error estimate {100 * ref['error_estimate']:.2g} % of the largest displacement "
        f"(last refinement changed it by {100 * ref['step_change']:.2g} %)")
    names = variants(models, linear_variants)
    shape = (len(names), len(levels))
    wall, elapsed = np.full(shape, np.nan), np.full(shape, np.nan)
    err_max, err_mean = np.full(shape, np.nan), np.full(shape, np.nan)
    t_median, t_min, t_max = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    dofs, runs = np.zeros(shape, dtype=np.int64), np.zeros(shape, dtype=np.int64)
    status = np.full(shape, "ok", dtype=object)
    for i, (name, model, linear) in enumerate(names):
        if warmup:
            try:
                _timed(at_level(raw, min(levels), model, linear), base_dir, 1, budget, cpu, None)
            except (Exception, RunTimeout):  # noqa: BLE001 - the timed runs below record the failure
                say(f"{name}: the warm-up run failed")
        for j, lv in enumerate(levels):
            try:
                spread = []
                t, tw, n_runs, ds = _timed(at_level(raw, lv, model, linear), base_dir, repeats, budget, cpu, long_run,
                                           spread)
            except (Exception, RunTimeout) as exc:  # noqa: BLE001 - a model that fails on a scene is a result too
                status[i, j] = f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"
                say(f"{name} level {lv}: failed ({status[i, j]})")
                continue
            X = ds["rest_position"].transpose("node", "axis").values
            u = ds["displacement"].transpose("node", "axis").values
            e = displacement_error(u, at_points(ref["result"], X), relative_to=scale)
            wall[i, j], elapsed[i, j], err_max[i, j], err_mean[i, j] = t, tw, e.rel_max, e.rel_mean
            dofs[i, j], runs[i, j] = u.size, n_runs
            t_median[i, j], t_min[i, j], t_max[i, j] = spread
            if int(ds.attrs.get("inverted_cells", 0)):
                status[i, j] = f"ok, {int(ds.attrs['inverted_cells'])} inverted cells"
            say(f"{name} level {lv}: {u.size} dofs, {t:.3g} s, max error {100 * e.rel_max:.3g} %")
    what = (f"best CPU time of up to {repeats} runs (set-up and solve)" if cpu
            else f"median wall time of {repeats} runs (set-up and solve)")
    kind = "CPU time" if cpu else "wall time"
    nan_or = (lambda v: float(v) if v is not None else math.nan)
    return xr.Dataset(
        {
            "wall_time": (("model", "level"), wall, {"units": "s", "long_name": what}),
            "elapsed": (("model", "level"), elapsed, {"units": "s", "long_name": "best wall time"}),
            "error_max": (("model", "level"), err_max, {"units": "1", "long_name": "max node error / max reference displacement"}),
            "error_mean": (("model", "level"), err_mean, {"units": "1", "long_name": "mean node error / max reference displacement"}),
            "time_median": (("model", "level"), t_median, {"units": "s", "long_name": f"median {kind} of the timed runs"}),
            "time_min": (("model", "level"), t_min, {"units": "s", "long_name": f"smallest {kind} of the timed runs"}),
            "time_max": (("model", "level"), t_max, {"units": "s", "long_name": f"largest {kind} of the timed runs"}),
            "n_dofs": (("model", "level"), dofs, {"units": "1", "long_name": "degrees of freedom"}),
            "runs": (("model", "level"), runs, {"units": "1", "long_name": "timed runs"}),
            "status": (("model", "level"), status.astype(str), {"units": "1", "long_name": "ok or the error raised"}),
        },
        coords={"model": [n for n, _, _ in names], "level": list(levels)},
        attrs={"reference_model": f"{ref_model} ({ref['formulation']})", "reference_level": top,
               "reference_max_displacement": scale, "reference_error": ref["error_estimate"],
               "reference_step_change": ref["step_change"], "reference_observed_order": ref["observed_order"],
               "reference_levels": ",".join(map(str, ref["levels"])), "reference_dofs": ref["n_dofs"],
               "reference_wall_time": ref["wall_time"], "reference_locking_nu": nan_or(ref["locking"]),
               "scene": yaml.safe_dump(raw, sort_keys=False), "repeats": repeats, "cell_type": cell_type,
               "timing": "cpu" if cpu else "wall", "total_time_s": time.perf_counter() - t0},
    )


def check_scene_levels(raw, base_dir, levels, models, ref_model):
    """Every (level, model) scene loads (:func:`msslib.scene.load_scene`: its keys and values),
    and the finest level fits in memory, a mesh file's too (its size read from the file, the
    refinement estimated before anything is refined): :class:`msslib.errors.ResourceError`
    naming ``--levels``, the level and the size in GB otherwise."""
    from msslib.errors import ResourceError
    from msslib.scene import load_scene

    for level in sorted(levels):
        for model in dict.fromkeys([*models, ref_model]):
            try:
                scene = load_scene(copy.deepcopy(at_level(raw, level, model)), base_dir=base_dir)
            except ResourceError as exc:
                raise ResourceError(f"--levels {level}: {exc}") from None
    if "file" in scene.geometry:
        _check_file_levels(scene, max(levels), ref_model)


def _check_file_levels(scene, level, ref_model):
    """Refuse a level whose refinement of the scene's mesh file would not fit in memory."""
    from msslib import mesh as _mesh
    from msslib import models as registry
    from msslib.scene import resources

    geo = scene.geometry
    refine = int(geo.get("refine", 0) or 0)
    if not refine:
        return
    m = _mesh.read(geo["file"], coincident_nodes=scene.checks.get("coincident_nodes", "merge"))
    n_nodes, n_cells = resources.refined_mesh_size(m.n_nodes, m.n_cells, m.dim, refine)
    fem = registry.get(ref_model).kind == "fem"
    estimate = resources.run_memory(n_nodes, m.dim, fem=fem)
    what = (f"--levels {level}: the mesh file {geo['file'].name} ({m.n_nodes} nodes, {m.n_cells} cells) refined "
            f"{refine} times, about {n_nodes:.3g} nodes and {n_cells:.3g} cells for the {ref_model} reference")
    resources.check_memory(estimate, what, "use lower --levels (or set checks.max_memory_gb)",
                           scene.checks["max_memory_gb"])


def ties(front, choice, max_error):
    """The other points within ``max_error`` whose time range (``time_min`` to ``time_max`` of
    their timed runs) overlaps the range of ``choice`` (``(model, level, ...)``): the timing does
    not tell them from the choice.  ``[(model, level, time_min, time_max), ...]``, fastest first;
    empty when the front carries no ranges (an older file) or the choice ran once only."""
    if "time_min" not in front or "time_max" not in front:
        return []

    def span(m, lv):
        r = front.sel(model=m, level=lv)
        return float(r.time_min), float(r.time_max), int(r.runs)

    lo, hi, n = span(choice[0], choice[1])
    if not (np.isfinite(lo) and np.isfinite(hi)) or n < 2:
        return []
    out = []
    for m in front.model.values:
        for lv in front.level.values:
            if (str(m), int(lv)) == (str(choice[0]), int(choice[1])):
                continue
            e = float(front.error_max.sel(model=m, level=lv))
            a, b, _ = span(m, lv)
            if np.isfinite(e) and e <= max_error and np.isfinite(a) and np.isfinite(b) and a <= hi and lo <= b:
                out.append((str(m), int(lv), a, b))
    return sorted(out, key=lambda x: x[2])

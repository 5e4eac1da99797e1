"""Shared body of the speed-against-error studies: the library's engine
(:func:`msslib.planning.measure_front`, the one ``python -m msslib plan`` uses) with the paper's
settings, and the study's summaries (error decrease, rates, crossover budgets).

Levels: a study's level ``k`` (``k >= 0``) is the scene's mesh refined uniformly ``k`` times (the
engine's level ``k + 1``), so every level covers the same domain and the nodes of level ``k`` are
nodes of every finer level. The reference is the engine's: the scene's non-linear FEM law with
quadratic elements (:mod:`msslib.planning.reference`: locking-free near nu = 1/2), here on the
level below the finest (``below=1``: its dofs are exactly the finest level's nodes) or on the
finest (``below=0``), solved on up to two coarser levels for its own error estimate (Richardson
with the observed order). Every variant is compared with it at its own nodes: no interpolation.

Variants: each MSS model of the cell type (read from the registry, :data:`msslib.planning.MODELS`)
solved non-linearly (load-stepped Newton) and
linearly (one solve with its Hessian at rest, ``solver.linear``), linear FEM and the non-linear
FEM law. Timing: the CPU time of the
single-threaded run (mesh, model set-up and solve; its wall time on an idle machine, and unlike
the wall time not inflated by other load on a shared machine), after a warm-up run of the variant
on the coarsest level, best of ``REPEATS`` runs however long each run takes (``runs``), with the
median and range of the runs (``time_median``, ``time_min``, ``time_max``);
the best wall time is kept too (``elapsed``). A crossover is resolved (``crossover_resolved``)
only where the points on either side of it have time ranges that do not overlap. A run still going after ``BUDGET``
seconds of CPU time is stopped and recorded as such in ``status``.
"""

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")  # single thread, before numpy is imported

import math
from pathlib import Path

import numpy as np
import yaml

from experiments import script

HERE = Path(__file__).resolve().parent
REPEATS = 7  # timed runs of every (variant, level), long ones too (the median and the spread need them)
# s of CPU time after which a run is stopped (and recorded as such).  The slowest run that converges,
# Baudet's non-linear cantilever on level 4, takes 48-53 s on an idle core and went past 75 s in a
# full build beside another job (a fresh install's): the budget leaves room for that
BUDGET = 180.0

LAW = {"triangle": "fem_svk", "quad": "fem_svk", "tetra": "fem_neohookean", "hexahedron": "fem_neohookean"}


def measure(scene_file, levels, repeats, progress=print, below=1):
    """The front of a scene: the engine's dataset (levels renumbered from 0) with the study's
    summaries and the linearisation gap of the reference."""
    from msslib import models as registry
    from msslib.planning import MODELS, measure_front
    from msslib.planning.front import at_level
    from msslib.planning.reference import at_points
    from msslib.scene import load_scene, prepare

    raw = yaml.safe_load(Path(scene_file).read_text())
    base_dir = Path(scene_file).resolve().parent
    cell_type = prepare(load_scene(at_level(raw, 1, "fem_linear"), base_dir=base_dir)).mesh.cell_type
    engine_levels = [int(lv) + 1 for lv in levels]
    top = max(max(engine_levels) - below, 1)
    out = measure_front(scene_file, levels=engine_levels, models=MODELS[cell_type], repeats=repeats,
                        budget=BUDGET, progress=progress, cpu=True, linear_variants=True, warmup=True,
                        long_run=None, reference_level=top)
    out = out.assign_coords(level=[lv - 1 for lv in engine_levels])
    out.attrs["reference_level"] = int(out.attrs["reference_level"]) - 1
    out.attrs["reference_dofs"] = int(out.attrs["reference_dofs"])
    # the gap between the linear and the non-linear quadratic reference, at the finest level's nodes
    fine = prepare(load_scene(at_level(raw, max(engine_levels), "fem_linear"), base_dir=base_dir)).mesh.points
    setup = prepare(load_scene(at_level(raw, top, LAW[cell_type]), base_dir=base_dir))
    u_lin, u_nl = (at_points(_reference(setup, law), fine) for law in (None, registry.get(LAW[cell_type]).law))
    scale = float(out.attrs["reference_max_displacement"])
    out.attrs["linearisation_gap"] = float(np.linalg.norm(u_lin - u_nl, axis=1).max()) / scale
    emax = out.error_max.values
    names = [str(m) for m in out.model.values]
    decreasing = np.array([int(np.all(np.isfinite(r)) and np.all(np.diff(r) < 0)) for r in emax])
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.log2(emax[:, -2] / emax[:, -1]) if len(levels) > 1 else np.full(len(names), np.nan)
    out["decreasing"] = (("model",), decreasing, {"units": "1", "long_name": "1 if the max error decreases at every refinement"})
    out["last_rate"] = (("model",), rate, {"units": "1", "long_name": "log2 of the max-error ratio of the last two levels"})
    out["family"] = (("model",), np.array(["fem" if n.startswith("fem") else "mss" for n in names]),
                     {"units": "1", "long_name": "fem or mss"})
    out["reading"] = (("model",), np.array(readings(raw, names), dtype=str),
                      {"units": "1", "long_name": "reading of Baudet's correction force the variant ran (element: each "
                                                  "cube from the forces it receives from outside; boundary: from the "
                                                  "loaded surface); empty for the other models"})
    out.attrs.update({"cpu_budget_s": BUDGET, "cell_type": cell_type,
                      "baudet_reading": ",".join(sorted({str(r) for r in out.reading.values if str(r)})) or "none"})
    out.attrs.update(crossover(out))
    return with_summaries(out)


def readings(raw, variants):
    """The reading of Baudet's correction force of every variant name of a front (a model, or a
    model's linearised solve ``NAME_linear``) in the scene ``raw`` ("" where it does not apply)."""
    from msslib import models as registry

    known = set(registry.names())
    return [_reading(raw, v if v in known else v.removesuffix("_linear")) for v in variants]


def _reading(raw, model):
    """The reading of Baudet's correction force that ``model`` runs in the scene ``raw`` (its
    ``correction`` option as the engine passes it, else the default), "" for a model without it."""
    from msslib import models as registry
    from msslib.planning import _with_model

    options = {o.name: o.default for o in registry.get(model).options}
    if "correction" not in options:
        return ""
    return str(_with_model(raw, model)["model"].get("correction", options["correction"]))


def _reference(setup, law):
    """The quadratic reference of a prepared level with ``law`` (None: linear), as the engine's."""
    from msslib.planning.reference import nearly_incompressible, solve_setup

    locking = nearly_incompressible(setup) is not None
    return solve_setup(setup, order=2, law=law, volumetric="reduced" if locking else "full",
                       linear_solver="direct" if locking else "auto")


def with_summaries(front):
    """Add the coarsest and finest level's error and time per variant (``error_coarsest``,
    ``error_finest``, ``time_finest``), whether the finest run finished and its inverted cells
    (``finished_finest``, ``inverted_finest``, from ``status``) and ``finest_level``: names that
    exist whatever the levels."""
    lo, hi = front.level.values.min(), front.level.values.max()
    front["error_coarsest"] = front.error_max.sel(level=lo, drop=True).assign_attrs(
        units="1", long_name="max error on the coarsest level")
    front["error_finest"] = front.error_max.sel(level=hi, drop=True).assign_attrs(
        units="1", long_name="max error on the finest level")
    front["time_finest"] = front.wall_time.sel(level=hi, drop=True).assign_attrs(
        units="s", long_name="CPU time on the finest level")
    status = front.status.sel(level=hi, drop=True).values
    front["finished_finest"] = (("model",), np.array([int(str(x).startswith("ok")) for x in status]),
                                {"units": "1", "long_name": "1 if the run on the finest level finished"})
    front["inverted_finest"] = (("model",), np.array([int(str(x).split()[1]) if str(x).startswith("ok,") else 0
                                                      for x in status]),
                                {"units": "1", "long_name": "inverted cells at the end of the finest level's run"})
    front.attrs["finest_level"] = int(hi)
    return front


def crossover(front):
    """Who is fastest at each error budget, from the measured points (the Pareto front sorted by
    error; ``winners`` lists the budget intervals). ``crossover_error``: the error of the most
    accurate MSS point on the front (budgets below it: the fastest variant reaching them is FEM);
    ``mss_window_upper``: the budget from which an FEM point is fastest again (inf: an MSS is
    fastest for every larger budget); NaN when no MSS point is on the front. ``crossover_kind``:
    "single crossover" (FEM below, MSS above), "mss window" (FEM below, MSS between, FEM above),
    "fem everywhere", or the other patterns."""
    from msslib.planning import pareto

    fam = {str(m): str(f) for m, f in zip(front.model.values, front.family.values)}
    pts = sorted(pareto(front), key=lambda p: -p[3])  # least accurate (fastest) first
    intervals = []
    for k, (m, lv, t, e) in enumerate(pts):
        upper = pts[k - 1][3] if k else math.inf
        intervals.append(f"[{100 * e:.3g} %, {'inf' if upper == math.inf else f'{100 * upper:.3g} %'}): {m} level {lv} ({fam[m]}, {t:.3g} s)")
    families = [fam[m] for m, *_ in pts]
    mss = [k for k, f in enumerate(families) if f == "mss"]
    upper = math.nan
    if not mss:
        cross, kind = math.nan, "fem everywhere"
    else:
        cross = pts[mss[-1]][3]
        first = mss[0]  # the budgets at or above the error of the first MSS point's predecessor: FEM again
        upper = pts[first - 1][3] if first > 0 else math.inf
        contiguous = mss == list(range(first, mss[-1] + 1))
        fem_below = all(f == "fem" for f in families[mss[-1] + 1:]) and mss[-1] + 1 < len(pts)
        kind = ("single crossover" if contiguous and fem_below and first == 0 else
                "mss window" if contiguous and fem_below else "mss most accurate" if contiguous else "interleaved")
    return {"crossover_error": cross, "mss_window_upper": upper, "crossover_kind": kind,
            "winners": "; ".join(intervals), "crossover_resolved": (resolved := _resolved(front, pts, families)),
            "crossover_status": "resolved" if resolved else "unresolved"}


def _resolved(front, pts, families):
    """1 when at every change of family along the front (an MSS point next to an FEM point) the
    two points' time ranges (``time_min`` to ``time_max`` of their timed runs) do not overlap, each
    measured more than once: the timing tells them apart.  0 otherwise ("unresolved"), and where
    the front carries no ranges; 1 with no change of family (nothing to resolve)."""
    changes = [k for k in range(1, len(pts)) if families[k] != families[k - 1]]
    if not changes:
        return 1
    if "time_min" not in front or "time_max" not in front:
        return 0
    for k in changes:
        (m0, l0, *_), (m1, l1, *_) = pts[k - 1], pts[k]  # pts[k - 1] the faster
        a, b = front.sel(model=m0, level=l0), front.sel(model=m1, level=l1)
        if int(a.runs) < 2 or int(b.runs) < 2 or not float(a.time_max) < float(b.time_min):
            return 0
    return 1


def main(scene: str, levels, quick_levels=(0, 1), below=1):
    from msslib.results import write_result

    a = script.args(f"speed against error for {scene}")
    front = measure(HERE / "scenes" / scene, quick_levels if a.quick else levels, repeats=1 if a.quick else REPEATS,
                    progress=lambda s: print(s, flush=True), below=below)
    front.attrs["scene_file"] = f"experiments/performance/scenes/{scene}"
    front.attrs["threads"] = os.environ.get("OMP_NUM_THREADS", "default")
    if a.quick:
        front.attrs["quick"] = 1
    write_result(a.out, front)

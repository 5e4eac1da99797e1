"""Shared body of the speed-against-error studies: nested meshes of one domain, a quadratic-element
reference with its own error estimate, every model variant timed and measured at the same nodes.

Levels: level ``k`` is the scene's mesh refined uniformly ``k`` times (``geometry.refine``,
:func:`msslib.refine.uniform`), so every level covers the same domain and the nodes of level ``k``
are the first nodes of every finer level. The reference is the scene's non-linear FEM law with
quadratic elements (:mod:`reference`) on level ``R``, the finest level (``below=0``) or the one
below it (``below=1``: its dofs, at vertices and edge midpoints, face and cell centres, are exactly
the finest level's nodes); it is also solved on up to two coarser levels, and the observed order
``p`` of its change at the coarsest of these levels' nodes gives its error estimate
``|u2_R - u2_{R-1}| / (2^p - 1)`` (Richardson; with two levels only, the change itself). The
displacement of every variant at every node of its mesh is compared with the reference at the
same node: no interpolation. Errors are relative to the largest reference displacement. The
reference is solved in one load step (a hyperelastic static solution does not depend on the path;
Newton converges from rest at these loads) to a relative residual of 1e-10.

Variants: each MSS model of the cell type solved non-linearly (load-stepped Newton) and
linearly (one solve with its Hessian at rest, ``solver.linear``), linear FEM and the non-linear
FEM law. Timing: the CPU time of the single-threaded run (mesh, model set-up and solve; its wall
time on an idle machine, and unlike the wall time not inflated by other load on a shared machine),
after a warm-up run of the variant on the coarsest level, best of ``repeats`` runs (one run when a
run takes longer than ``LONG`` seconds); the best wall time is kept too (``elapsed``). A run still
going after ``BUDGET`` seconds of CPU time is stopped and recorded as such in ``status``.
"""

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")  # single thread, before numpy is imported

import argparse
import copy
import math
import time
import warnings
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
LONG = 2.0  # s: runs longer than this are timed once
BUDGET = 75.0  # s of CPU time after which a run is stopped (and recorded as such)

LAW = {"triangle": "fem_svk", "quad": "fem_svk", "tetra": "fem_neohookean", "hexahedron": "fem_neohookean"}


def variants(cell_type):
    """(name, model, linear) of every variant of a cell type."""
    from msslib.models import for_cells

    out = []
    for m in for_cells(cell_type, kind="mss"):  # every registered mass-spring model of these cells
        out += [(m, m, False), (f"{m}_linear", m, True)]
    return out + [("fem_linear", "fem_linear", False), (LAW[cell_type], LAW[cell_type], False)]


def scene_at(raw, level, model, linear=False):
    sc = copy.deepcopy(raw)
    sc["geometry"]["refine"] = int(level)
    sc["model"] = model
    if linear:
        sc["solver"] = {**sc.get("solver", {}), "linear": True}
    return sc


def _run(scene, budget):
    """run_scene, stopped by :class:`msslib.planning.RunTimeout` after ``budget`` seconds of CPU time."""
    from msslib.planning import run_with_budget

    return run_with_budget(scene, budget, cpu=True)


def timed(raw, base_dir, repeats, budget=BUDGET):
    """Best CPU time and best wall time of up to ``repeats`` runs, and the last result."""
    best, best_wall, ds = math.inf, math.inf, None
    for _ in range(repeats):
        scene = _load(raw, base_dir)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # inverted cells etc. are recorded in the dataset
            c0 = time.process_time()
            ds = _run(scene, budget)
            t = time.process_time() - c0
        best, best_wall = min(best, t), min(best_wall, float(ds.attrs["wall_time_s"]))
        if t > LONG:
            break
    return best, best_wall, ds


def _load(raw, base_dir):
    from msslib.scene import load_scene

    return load_scene(raw, base_dir=base_dir)


def reference(raw, base_dir, levels, law_model, progress, below=1):
    """Quadratic-element non-linear reference on the level ``below`` (1 or 0) levels under the
    finest (on the level below, its dofs are the finest level's nodes), solved on up to two coarser
    levels too for its error estimate."""
    from experiments.performance import reference as R
    from msslib.scene import FEM_MODELS, prepare

    law = FEM_MODELS[law_model]
    L = max(levels)
    top = max(L - below, 0)
    used = [lv for lv in (top - 2, top - 1, top) if lv >= 0]
    infos = {}
    for lv in used:
        setup = prepare(_load(scene_at(raw, lv, law_model), base_dir))
        _, infos[lv] = R.solve(setup, order=2, law=law, steps=1)
        progress(f"reference P2 {law} level {lv}: {infos[lv]['n_dofs']} dofs, {infos[lv]['wall_time']:.1f} s, "
                 f"Newton {infos[lv]['iterations']}")
    fine = prepare(_load(scene_at(raw, L, law_model), base_dir)).mesh
    u = R.at_points(infos[top], fine.points) if L > top else infos[top]["u_dofs"][: fine.n_nodes]
    setup = prepare(_load(scene_at(raw, top, law_model), base_dir))
    _, lin = R.solve(setup, order=2, law=None)
    u_lin = R.at_points(lin, fine.points)
    scale = float(np.linalg.norm(u, axis=1).max())
    out = {"u": u, "scale": scale, "law": law, "level": top, "n_dofs": infos[top]["n_dofs"],
           "wall_time": sum(i["wall_time"] for i in infos.values()) + lin["wall_time"],
           "linearisation_gap": float(np.linalg.norm(u_lin - u, axis=1).max()) / scale}
    step = p = math.nan
    if len(used) >= 2:  # the last step's change at the nodes of the finer one's vertices' level
        a, b = used[-2], used[-1]
        nb = prepare(_load(scene_at(raw, b, law_model), base_dir)).mesh.n_nodes
        xb = infos[b]["x_dofs"][:nb]
        step = float(np.linalg.norm(infos[b]["u_dofs"][:nb] - R.at_points(infos[a], xb), axis=1).max()) / scale
    if len(used) == 3:  # observed order: both steps at the coarsest level's vertices
        n0 = prepare(_load(scene_at(raw, used[0], law_model), base_dir)).mesh.n_nodes
        v = [infos[lv]["u_dofs"][:n0] for lv in used]
        c1, c2 = (float(np.linalg.norm(v[k + 1] - v[k], axis=1).max()) for k in (0, 1))
        p = math.log2(c1 / c2) if c1 > 0 and c2 > 0 else math.nan
    out["step_change"], out["observed_order"] = step, p
    # Richardson: the error left after the last step is its change / (2^p - 1); without an observed
    # positive order, the change itself
    out["error_estimate"] = step / (2.0**p - 1.0) if math.isfinite(p) and p > 0 else step
    return out


def measure(scene_file, levels, repeats, progress=print, below=1):
    """The front of a scene: an xarray Dataset (see the module docstring)."""
    import xarray as xr

    from msslib.metrics import displacement_error
    from msslib.planning import RunTimeout
    from msslib.scene import prepare

    raw = yaml.safe_load(Path(scene_file).read_text())
    base_dir = Path(scene_file).resolve().parent
    cell_type = prepare(_load(scene_at(raw, 0, "fem_linear"), base_dir)).mesh.cell_type
    law_model = LAW[cell_type]
    t0 = time.perf_counter()
    ref = reference(raw, base_dir, levels, law_model, progress, below)
    names = variants(cell_type)
    shape = (len(names), len(levels))
    wall, emax, emean = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    elapsed = np.full(shape, np.nan)
    dofs = np.zeros(shape, dtype=np.int64)
    runs = np.zeros(shape, dtype=np.int64)
    status = np.full(shape, "ok", dtype=object)
    for i, (name, model, linear) in enumerate(names):
        try:
            timed(scene_at(raw, min(levels), model, linear), base_dir, 1)  # warm-up (imports, compiled kernels)
        except (Exception, RunTimeout):  # noqa: BLE001 - the timed runs below record the failure
            progress(f"{name}: the warm-up run failed")
        for j, lv in enumerate(levels):
            try:
                t, tw, ds = timed(scene_at(raw, lv, model, linear), base_dir, repeats)
            except (Exception, RunTimeout) as exc:  # noqa: BLE001 - a variant that fails on a scene is a result too
                status[i, j] = f"{type(exc).__name__}: {' '.join(str(exc).split())[:160]}"
                progress(f"{name} level {lv}: failed ({status[i, j]})")
                continue
            u = ds["displacement"].transpose("node", "axis").values
            e = displacement_error(u, ref["u"][: len(u)], relative_to=ref["scale"])
            wall[i, j], elapsed[i, j], emax[i, j], emean[i, j], dofs[i, j] = t, tw, e.rel_max, e.rel_mean, u.size
            runs[i, j] = 1 if t > LONG else repeats
            if int(ds.attrs.get("inverted_cells", 0)):
                status[i, j] = f"ok, {int(ds.attrs['inverted_cells'])} inverted cells"
            progress(f"{name} level {lv}: {u.size} dofs, {t:.3g} s, max error {100 * e.rel_max:.3g} %")
    decreasing = np.array([int(np.all(np.isfinite(r)) and np.all(np.diff(r) < 0)) for r in emax])
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.log2(emax[:, -2] / emax[:, -1]) if len(levels) > 1 else np.full(len(names), np.nan)
    family = np.array(["fem" if m.startswith("fem") else "mss" for _, m, _ in names])
    out = xr.Dataset(
        {
            "wall_time": (("model", "level"), wall, {"units": "s", "long_name": "best CPU time of the single-threaded run "
                                                     "(set-up and solve), warm: its wall time on an idle machine"}),
            "elapsed": (("model", "level"), elapsed, {"units": "s", "long_name": "best elapsed wall time (machine shared)"}),
            "error_max": (("model", "level"), emax, {"units": "1", "long_name": "max node error / max reference displacement"}),
            "error_mean": (("model", "level"), emean, {"units": "1", "long_name": "mean node error / max reference displacement"}),
            "n_dofs": (("model", "level"), dofs, {"units": "1", "long_name": "degrees of freedom"}),
            "runs": (("model", "level"), runs, {"units": "1", "long_name": "timed runs (best taken)"}),
            "status": (("model", "level"), status.astype(str), {"units": "1", "long_name": "ok or the error raised"}),
            "decreasing": (("model",), decreasing, {"units": "1", "long_name": "1 if the max error decreases at every refinement"}),
            "last_rate": (("model",), rate, {"units": "1", "long_name": "log2 of the max-error ratio of the last two levels"}),
            "family": (("model",), family, {"units": "1", "long_name": "fem or mss"}),
        },
        coords={"model": [n for n, _, _ in names], "level": list(levels)},
        attrs={"reference_model": f"{law_model} (quadratic elements)", "reference_level": ref["level"],
               "reference_max_displacement": ref["scale"], "reference_error": ref["error_estimate"],
               "reference_step_change": ref["step_change"], "reference_observed_order": ref["observed_order"],
               "reference_dofs": ref["n_dofs"], "reference_wall_time": ref["wall_time"],
               "linearisation_gap": ref["linearisation_gap"], "repeats": repeats, "long_run_s": LONG, "cpu_budget_s": BUDGET,
               "scene": yaml.safe_dump(raw, sort_keys=False), "cell_type": cell_type,
               "total_time_s": time.perf_counter() - t0},
    )
    out.attrs.update(crossover(out))
    return with_summaries(out)


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
            "winners": "; ".join(intervals)}


def main(scene: str, levels, quick_levels=(0, 1), below=1):
    from msslib.io import write_result

    p = argparse.ArgumentParser(description=f"speed against error for {scene}")
    p.add_argument("--out", required=True)
    p.add_argument("--quick", action="store_true")
    a = p.parse_args()
    front = measure(HERE / "scenes" / scene, quick_levels if a.quick else levels, repeats=1 if a.quick else 3,
                    progress=lambda s: print(s, flush=True), below=below)
    front.attrs["scene_file"] = f"experiments/performance/scenes/{scene}"
    front.attrs["threads"] = os.environ.get("OMP_NUM_THREADS", "default")
    if a.quick:
        front.attrs["quick"] = 1
    write_result(a.out, front)

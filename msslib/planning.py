"""Speed against error: measure the front of (model, resolution) for a scene, and choose from it.

:func:`measure_front` runs a scene at several resolutions with every model that fits its cells
(mass-spring variants, linear FEM, non-linear FEM), records the wall time (median of repeats, same
machine, same run) and the displacement error against a converged non-linear FEM reference computed
one level finer than the finest tested resolution, and returns an xarray Dataset. :func:`choose`
returns the cheapest measured (model, resolution) whose error is within a budget; the command line
``python -m msslib plan SCENE.yaml --max-error 0.05`` prints it with the numbers it rests on.

Resolution levels scale the scene's generator arguments: ``nx``, ``ny``, ``nz`` and ``n`` are
multiplied by the level, ``h`` (gmsh size) divided by it. Errors are relative to the largest
reference displacement (maximum over nodes of the Euclidean error).
"""

from __future__ import annotations

import copy
import time
from pathlib import Path

import numpy as np
import yaml

MODELS = {
    "triangle": ["lloyd_triangle", "van_gelder", "fem_linear", "fem_svk"],
    "quad": ["lloyd_square", "fem_linear", "fem_svk"],
    "tetra": ["lloyd_tetrahedron", "lloyd_tetrahedron_volume", "fem_linear", "fem_neohookean"],
    "hexahedron": ["baudet_cube", "golec_cube", "fem_linear", "fem_neohookean"],
}
REFERENCE = {"triangle": "fem_svk", "quad": "fem_svk", "tetra": "fem_neohookean", "hexahedron": "fem_neohookean"}
SCALED = {"nx", "ny", "nz", "n", "n_rings"}


def _raw(scene):
    if isinstance(scene, dict):
        return copy.deepcopy(scene), Path.cwd()
    path = Path(scene)
    if not path.is_file():
        raise FileNotFoundError(f"scene file not found: {str(scene)!r}")
    return yaml.safe_load(path.read_text(encoding="utf-8")), path.parent


def refine(raw: dict, level: int) -> dict:
    """The scene with its generator's resolution arguments scaled by ``level``."""
    out = copy.deepcopy(raw)
    geo = out.get("geometry", {})
    if "generator" not in geo:
        raise ValueError("scene.geometry: planning needs a generator (a mesh file has one resolution)")
    args = geo.setdefault("args", {})
    scaled = False
    for k in list(args):
        if k in SCALED:
            args[k] = int(args[k]) * level
            scaled = True
        elif k == "h":
            args[k] = float(args[k]) / level
            scaled = True
    if not scaled:
        raise ValueError(f"scene.geometry.args: no resolution argument among {sorted(SCALED | {'h'})}")
    return out


def _with_model(raw, model):
    out = copy.deepcopy(raw)
    m = out.get("model")
    opts = {k: v for k, v in m.items() if k not in ("type", "published", "terms", "A")} if isinstance(m, dict) else {}
    if model.startswith("fem"):
        opts = {k: v for k, v in opts.items() if k == "plane"}
        sol = out.get("solver", {})
        if sol.get("type") == "dynamic":
            raise ValueError("planning compares static solves; the scene is dynamic")
    out["model"] = {"type": model, **opts}
    return out


class RunTimeout(BaseException):  # not an Exception: solvers must not swallow it
    """A run exceeded its wall-time budget."""


def _run(raw, base_dir, budget=None):
    import signal

    from msslib.scene import load_scene, run_scene

    scene = load_scene(raw, base_dir=base_dir)
    if not budget or not hasattr(signal, "SIGALRM"):
        return run_scene(scene, progress=False)

    def _alarm(_sig, _frame):
        raise RunTimeout(f"exceeded the budget of {budget:g} s")

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, budget)
    try:
        return run_scene(scene, progress=False)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def measure_front(scene, *, levels=(1, 2, 3), models=None, repeats=3, budget=30.0, progress=print):
    """Measure time and error of every (model, level); returns an xarray Dataset.

    A run that fails or exceeds ``budget`` seconds is recorded in ``status`` (with NaN time and
    error) instead of stopping the sweep: that a model breaks on a scene is a result too."""
    import xarray as xr

    from msslib.experiment import interpolate
    from msslib.io import mesh_from_result
    from msslib.metrics import displacement_error

    raw, base_dir = _raw(scene)
    probe = _run(refine(raw, levels[0]), base_dir) if models is None else None
    cell_type = probe.cells.attrs["cell_type"] if probe is not None else None
    models = list(models or MODELS[cell_type])
    ref_model = REFERENCE[cell_type] if cell_type else "fem_neohookean"
    ref_level = max(levels) + 1
    t0 = time.perf_counter()
    ref = _run(_with_model(refine(raw, ref_level), ref_model), base_dir)
    if progress:
        progress(f"reference {ref_model} at level {ref_level}: {ref.sizes['node']} nodes, {time.perf_counter() - t0:.1f} s")
    ref_mesh = mesh_from_result(ref)
    u_ref = ref["displacement"].transpose("node", "axis").values
    scale = float(np.linalg.norm(u_ref, axis=1).max())
    shape = (len(models), len(levels))
    wall = np.full(shape, np.nan)
    err_max = np.full(shape, np.nan)
    err_mean = np.full(shape, np.nan)
    dofs = np.zeros(shape, dtype=np.int64)
    status = np.full(shape, "ok", dtype=object)
    for i, model in enumerate(models):
        for j, level in enumerate(levels):
            sc = _with_model(refine(raw, level), model)
            times = []
            try:
                for _ in range(repeats):
                    ds = _run(sc, base_dir, budget)
                    times.append(float(ds.attrs["wall_time_s"]))
            except (Exception, RunTimeout) as exc:  # a model that fails on a scene is a measured outcome
                status[i, j] = f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"
                if progress:
                    progress(f"{model} level {level}: failed ({status[i, j]})")
                continue
            X = ds["rest_position"].transpose("node", "axis").values
            u = ds["displacement"].transpose("node", "axis").values
            e = displacement_error(u, interpolate(ref_mesh, u_ref, X), relative_to=scale)
            wall[i, j], err_max[i, j], err_mean[i, j] = np.median(times), e.rel_max, e.rel_mean
            dofs[i, j] = u.size
            if progress:
                progress(f"{model} level {level}: {u.size} dofs, {wall[i, j]:.3g} s, max error {100 * e.rel_max:.3g} %")
    out = xr.Dataset(
        {
            "wall_time": (("model", "level"), wall, {"units": "s", "long_name": f"median wall time of {repeats} runs"}),
            "error_max": (("model", "level"), err_max, {"units": "1", "long_name": "max node error / max reference displacement"}),
            "error_mean": (("model", "level"), err_mean, {"units": "1", "long_name": "mean node error / max reference displacement"}),
            "n_dofs": (("model", "level"), dofs, {"units": "1", "long_name": "degrees of freedom"}),
            "status": (("model", "level"), status.astype(str), {"units": "1", "long_name": "ok or the error raised"}),
        },
        coords={"model": models, "level": list(levels)},
        attrs={"reference_model": ref_model, "reference_level": ref_level, "reference_max_displacement": scale,
               "scene": yaml.safe_dump(raw, sort_keys=False), "repeats": repeats},
    )
    return out


def choose(front, max_error: float):
    """The cheapest measured (model, level) with ``error_max <= max_error``, or None."""
    best = None
    for m in front.model.values:
        for lv in front.level.values:
            r = front.sel(model=m, level=lv)
            e, t = float(r.error_max), float(r.wall_time)
            if np.isfinite(e) and e <= max_error and (best is None or t < best[2]):
                best = (str(m), int(lv), t, e)
    return best


def pareto(front):
    """(model, level, time, error) on the Pareto front: no other point is both faster and more accurate."""
    pts = [(str(m), int(lv), float(front.wall_time.sel(model=m, level=lv)), float(front.error_max.sel(model=m, level=lv)))
           for m in front.model.values for lv in front.level.values]
    pts = [p for p in pts if np.isfinite(p[2]) and np.isfinite(p[3])]
    return sorted((p for p in pts if not any(q[2] <= p[2] and q[3] <= p[3] and (q[2], q[3]) != (p[2], p[3]) for q in pts)),
                  key=lambda p: p[2])

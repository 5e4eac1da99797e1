"""The study: every case of ``cases.yaml`` x every model column, each run a scene of
:func:`experiments.stability.scenes.scene` run by :func:`msslib.scene.run_scene`; this module
only loops, catches how a run ends and measures its outcome (one record per case and model)."""

from __future__ import annotations

import time
import warnings

import numpy as np

from experiments.stability.scenes import model_type, pick, reading, scene
from experiments.stability.shapes import shape_analysis
from msslib import mesh as M
from msslib.errors import DivergenceError, MsslibWarning, StabilityError
from msslib.scene import FEM_MODELS, load_scene, prepare, run_scene
from msslib.solvers import ConvergenceError, explicit_stability_limit

FIELDS = ("ran", "converged", "error", "volume_ratio", "min_volume_ratio", "n_inverted", "iterations", "stop_step",
          "stop_displacement", "dt_limit", "outcome")
REFERENCE = "fem_neohookean"  # the reference of the error, on the same mesh as the model


def record(ran=False, converged=False, error=np.nan, volume_ratio=np.nan, min_volume_ratio=np.nan,
           n_inverted=-1, outcome="", iterations=-1, stop_step=-1, stop_displacement=np.nan, dt_limit=np.nan) -> dict:
    """One (case, model) outcome, the fields of :data:`FIELDS`."""
    return {"ran": bool(ran), "converged": bool(converged), "error": float(error),
            "volume_ratio": float(volume_ratio), "min_volume_ratio": float(min_volume_ratio),
            "n_inverted": int(n_inverted), "iterations": int(iterations), "stop_step": int(stop_step),
            "stop_displacement": float(stop_displacement), "dt_limit": float(dt_limit),
            "outcome": " ".join(str(outcome).split())[:300]}


def short(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


def is_fem(spec) -> bool:
    model = spec["model"]
    return (model if isinstance(model, str) else model["type"]) in FEM_MODELS


def is_svk(spec) -> bool:
    """St Venant-Kirchhoff FEM, or a model whose energy is that element's on any mesh (registry
    exactness ``element`` on ``any`` mesh, e.g. Kikuuwe's edge-based tetrahedron)."""
    from msslib import models as registry

    name = model_type(spec)
    return name == "fem_svk" or any(e.level == "element" and e.mesh == "any" for e in registry.get(name).exact)


def run(sc):
    """``(dataset, None)``, or ``(None, record)`` for a scene refused (ValueError) or not converged."""
    try:
        return run_scene(sc, progress=False), None
    except ConvergenceError as exc:
        return None, record(ran=True, outcome=f"no convergence: {short(exc)}")
    except ValueError as exc:
        return None, record(outcome=f"refused: {short(exc)}")


def _mesh(ds, cells):
    return M.Mesh(ds["rest_position"].values, ds["cells"].values, cells)


def _iterations(ds) -> int:
    if "solver_total_iterations" in ds.attrs:  # MSS static
        return int(ds.attrs["solver_total_iterations"])
    its = ds.attrs.get("solver_iterations")  # non-linear FEM: per load step
    return -1 if its is None else int(np.sum(its))


def measured(ds, cells, t0, ref_u=None, *, svk=False) -> dict:
    """The record of a finished static run: error against ``ref_u`` (max nodal |u - u_ref| / max
    |u_ref|), volumes, inverted cells, Newton iterations."""
    mesh, u = _mesh(ds, cells), ds["displacement"].values
    V0 = M.cell_measures(mesh)
    V = M.cell_measures(M.Mesh(mesh.points + u, mesh.cells, cells))
    err = np.nan if ref_u is None else np.abs(u - ref_u).max() / np.abs(ref_u).max()
    n_inv, its = int((V <= 0).sum()), _iterations(ds)
    text = f"converged ({'' if its < 0 else f'{its} Newton iterations, '}{time.perf_counter() - t0:.2f} s)"
    if ds.attrs.get("solver_roundoff_steps", "[]") != "[]":
        text += (f"; at the round-off floor {ds.attrs['solver_roundoff_floor']:.2e} N "
                 f"(tol x F_ref {ds.attrs['solver_tol'] * ds.attrs['solver_force_scale']:.2e} N)")
    if n_inv:
        text += (f"; {n_inv} inverted elements (min V/V0 {(V / V0).min():.3f}): "
                 + ("SVK has no inversion barrier" if svk else "springs have no inversion barrier"))
    return record(True, True, err, V.sum() / V0.sum(), (V / V0).min(), n_inv, text, its)


# --------------------------------------------------------------------------------------------
# one function per way of measuring: static cases, the inverted input, shapes, dynamics
# --------------------------------------------------------------------------------------------


def static_case(name, case, data, quick) -> dict:
    """Cases ``sliding``, ``clamped``, ``contrast``, ``unloaded``, ``beam``: one static scene per model."""
    kind, out, refs = case["kind"], {}, {}

    def reference(cells):  # neo-Hookean FEM on the model's mesh
        if cells not in refs:
            refs[cells] = run(scene(name, case, cells, REFERENCE, data, quick))[0]
        return refs[cells]

    for column, spec in data["models"].items():
        cells, extra, note = spec["cells"], {}, ""
        ref_u = None
        if kind in ("sliding", "clamped", "contrast"):
            ref = reference(cells)
            ref_u = None if ref is None else ref["displacement"].values
            if kind == "sliding" and reading(spec) == "boundary" and ref is not None:
                # force control, so that the boundary reading's correction acts: the reference's top
                # reaction as a traction (the element reading's acts under displacement control too)
                size = float(case["size"])
                top = np.isclose(ref["rest_position"].values[:, 2], size)
                extra["traction"] = float(ref["reaction_force"].values[top, 2].sum()) / size**2
                note = "; force control (the FEM reaction on top as a traction), correction active"
            elif kind == "clamped" and reading(spec) == "boundary":
                note = "; displacement control: no external load, correction inactive"
        t0 = time.perf_counter()
        ds, failed = run(scene(name, case, cells, spec["model"], data, quick, **extra))
        if failed is not None:
            out[column] = failed
            continue
        rec = measured(ds, cells, t0, ref_u, svk=is_svk(spec))
        u = ds["displacement"].values
        if kind == "unloaded":  # max |u| / edge length
            rec["error"] = np.abs(u).max() / float(case["size"])
        elif kind == "beam":  # tip deflection / Euler-Bernoulli q L^4 / (8 E I) - 1
            E, L, w = float(case["E"]), float(case["length"]), float(case["width"])
            w_eb = data["density"] * 9.81 * w**2 * L**4 / (8.0 * E * w**4 / 12.0)
            tip = -float(u[:, 2].min())
            rec["error"] = tip / w_eb - 1.0
            note = f"; tip {1e3 * tip:.3f} mm, Euler-Bernoulli {1e3 * w_eb:.3f} mm"
        rec["outcome"] = (rec["outcome"] + note)[:300]
        out[column] = rec
    return out


def inverted_case(name, case, data, quick) -> dict:
    """A mesh with one cell numbered backwards: the scene loader must say so (a warning; or refuse
    it), and the re-ordered mesh must give the result of the consistently numbered one (error:
    max nodal |u - u_ref| / max |u_ref| against that run)."""
    out = {}
    for column, spec in data["models"].items():
        cells, model = spec["cells"], spec["model"]
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MsslibWarning)
            ds, failed = run(scene(name, case, cells, model, data, quick))
        if failed is not None:
            out[column] = dict(failed, outcome=failed["outcome"].replace("refused: ", "detected: ", 1))
            continue
        said = [str(w.message) for w in caught if "numbered against the others" in str(w.message)]
        ref, _ = run(scene(name, case, cells, model, data, quick, flip=False))
        rec = measured(ds, cells, t0, None if ref is None else ref["displacement"].values)
        rec["outcome"] = (f"detected and re-ordered: {said[0]}" if said else
                          "NOT DETECTED: the cell numbered backwards was accepted without a word; " + rec["outcome"])
        out[column] = record(**{**rec, "outcome": rec["outcome"][:300]})
    return out


def shape_case(name, case, data, quick):
    """``({lloyd_tetrahedron: record}, shape data)``: the element analysis of :mod:`.shapes`."""
    text, values = shape_analysis(name, float(data["E"]), float(case["nu"]))
    return {"lloyd_tetrahedron": record(ran=True, converged=True, outcome=text)}, values


def dynamic_case(name, case, data, quick) -> dict:
    """``explicit``: symplectic Euler at ``factor`` x the stability limit of the model at rest, as a
    user would run it (refused up front), then with ``allow_unstable`` until the divergence
    detector stops it; ``implicit``: implicit Euler at that step (must stay finite).  MSS only."""
    out, factor, steps = {}, float(case["factor"]), int(pick(case["steps"], quick))
    for column, spec in data["models"].items():
        if is_fem(spec):
            continue
        cells, model = spec["cells"], spec["model"]
        static_sc = scene(name, case, cells, model, data, quick, static=True)
        system = prepare(load_scene(static_sc)).model
        x0, limit = system.x0, explicit_stability_limit(system, system.x0)
        u_static = np.abs(run_scene(static_sc, progress=False)["displacement"].values).max()
        dt = factor * limit
        if case["kind"] == "implicit":
            sc = scene(name, case, cells, model, data, quick, dt=dt, t_end=steps * dt, method="implicit_euler")
            sc["output"] = {"history": True}  # the largest displacement over every step
            ds, failed = run(sc)
            if failed is not None:
                out[column] = failed
                continue
            u = ds["displacement_history"].values
            umax = np.abs(u).max()
            out[column] = record(True, bool(np.isfinite(u).all()), error=umax / u_static, dt_limit=limit,
                                 outcome=f"stable: max |u| = {umax / u_static:.3f} x static max |u| over {steps} "
                                 "steps (numerical damping)")
            continue
        kw = {"dt": dt, "t_end": steps * dt}
        try:
            run_scene(scene(name, case, cells, model, data, quick, **kw), progress=False)
            refused, detail = f"NOT REFUSED at {factor:g} x the limit {limit:.4g} s", ""
        except StabilityError as exc:
            refused, detail = "refused", f"; {short(exc)[:120]}"
        try:
            run_scene(scene(name, case, cells, model, data, quick, allow_unstable=True, **kw), progress=False)
            out[column] = record(True, True, dt_limit=limit, outcome=f"{refused}; NOT DETECTED: no divergence in {steps} steps with "
                                 f"allow_unstable{detail}")
            continue
        except DivergenceError as exc:
            stop = exc
        # how wrong the body was: the last state against a stable run (half the limit) to the same time
        t_last = (stop.step - 1) * dt
        x_ref = x0
        if t_last > 0:
            ref = run_scene(scene(name, case, cells, model, data, quick, dt=0.5 * limit, t_end=t_last),
                            progress=False)
            x_ref = x0 + ref["displacement"].values.ravel()
        wrong = float(np.abs(stop.x_last - x_ref).max()) / u_static
        moved = stop.max_displacement / u_static
        state = "finite" if np.isfinite(stop.x_last).all() else "NON-FINITE"
        out[column] = record(ran=True, error=wrong, stop_step=stop.step, stop_displacement=moved, dt_limit=limit,
                             outcome=f"{refused}; allow_unstable: stopped at step {stop.step}, off a stable run by "
                             f"{wrong:.2g} x static (max |u| {moved:.3g} x static, {stop.quantity}, last state "
                             f"{state}){detail}")
    return out


KINDS = {"sliding": static_case, "clamped": static_case, "contrast": static_case, "unloaded": static_case,
         "beam": static_case, "inverted": inverted_case, "explicit": dynamic_case, "implicit": dynamic_case}


def run_all(data, quick=False, log=print):
    """``(cases, shape data)``: per case a record per model it applies to; per shape its data."""
    cases, shape_data = {}, {}
    for name, case in data["cases"].items():
        log(name)
        if case["kind"] == "shape":
            cases[name], shape_data[name] = shape_case(name, case, data, quick)
        else:
            cases[name] = KINDS[case["kind"]](name, case, data, quick)
    shape_data["regular"] = shape_analysis("regular", float(data["E"]))[1]
    return cases, shape_data

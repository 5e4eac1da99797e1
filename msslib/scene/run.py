"""Solving a scene: FEM references, static (non-linear or linear) and dynamic mass-spring runs, and
:func:`run_scene`, which returns the result dataset."""

from __future__ import annotations

import contextlib
import math
import time
from typing import Callable

import numpy as np

from msslib import models as _models
from msslib.scene.prepare import Setup, prepare
from msslib.scene.progress import TextProgress, compile_notice
from msslib.scene.schema import load_scene


def _moduli(scene):
    E = [m.E for m in scene.materials]
    nu = [m.nu for m in scene.materials]
    if len(E) == 1:
        return E[0], nu[0]
    return np.array(E), np.array(nu)


def _solve_fem(setup: Setup, report):
    from msslib import fem
    from msslib.solvers import ConvergenceError

    scene, mesh = setup.scene, setup.mesh
    E = [m.E for m in scene.materials]
    nu = [m.nu for m in scene.materials]
    body = None
    if setup.gravity is not None:
        body = setup.cell_density[:, None] * setup.gravity[None, :]
    kw = dict(fixed=setup.fixed, prescribed=setup.prescribed, nodal_forces=setup.surface_forces, body_force=body)
    if mesh.dim == 2:
        kw.update(thickness=setup.thickness, plane=scene.model_options["plane"])
    law = _models.get(scene.model).law
    kw.update(pressure_keywords(setup, fem.solve_linear if law is None or scene.solver.get("linear")
                                else fem.solve_nonlinear))
    if law is None or scene.solver.get("linear"):
        res = fem.solve_linear(mesh, E, nu, **kw)
    else:
        s = scene.solver
        try:
            res = fem.solve_nonlinear(mesh, E, nu, law=law, steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"],
                                      progress=lambda k, n: report(k / n, f"load step {k}/{n}"), **kw)
        except RuntimeError as exc:
            raise ConvergenceError(f"{scene.model}: {exc}") from None
    stats = {"type": "static", **res.stats}
    return {"displacement": res.displacement, "reaction": res.reaction, "stats": stats,
            "extra_attrs": {"strain_energy": res.strain_energy}}


def pressure_keywords(setup: Setup, solve) -> dict:
    """``{"pressures": setup.pressures}`` for the FEM function ``solve``, or ``{}`` without pressure
    loads; a ValueError naming the load when ``solve`` takes no pressures."""
    import inspect

    if not setup.pressures:
        return {}
    if "pressures" not in inspect.signature(solve).parameters:
        i = next(i for i, load in enumerate(setup.scene.loads) if load["type"] == "pressure")
        raise ValueError(f"scene.loads[{i}]: the FEM reference ({solve.__name__}) takes no pressure loads in this "
                         f"version; allowed for {setup.scene.model}: gravity, nodal_force, traction")
    return {"pressures": setup.pressures}


def _solve_mss_static(setup: Setup, report):
    from msslib.solvers import static_solve

    model, s = setup.model, setup.scene.solver

    def cb(info):
        report(info["load"], f"load {info['load']:.3g} it {info['iteration']} |r| {info['residual']:.2e}")

    if s.get("linear"):
        return _solve_mss_linear(setup)
    res = static_solve(model, model.x0, load_steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"], progress=cb)
    u = (res.x - model.x0).reshape(-1, model.dim)
    stats = {
        "type": "static", "load_steps": s["load_steps"], "tol": s["tol"], "n_load_steps": res.n_load_steps,
        "n_cuts": res.n_cuts, "iterations": res.iterations, "total_iterations": res.total_iterations,
        "final_residual": res.residuals[-1][-1] if res.residuals and res.residuals[-1] else 0.0,
        "force_scale": res.force_scale, "roundoff_floor": res.roundoff_floor, "threshold": res.threshold,
        "roundoff_steps": res.roundoff_steps, "line_search_merit": res.line_search_merit, "wall_time": res.wall_time,
        "messages": res.messages,
    }
    energy = model.energy(res.x, 1.0)
    extra = {"potential_energy": "None" if energy is None else energy}
    return {"displacement": u, "reaction": model.reaction(res.x, 1.0), "stats": stats, "extra_attrs": extra}


def _solve_mss_linear(setup: Setup):
    """One sparse solve with the model's stiffness (Hessian) at rest: the linearised MSS, by the
    solver layer of :mod:`msslib.solvers` (the policy of every solve, as linear FEM's)."""
    import scipy.sparse as sp

    from msslib.fem.newton import SOLVER, linear_solve

    model, t0 = setup.model, time.perf_counter()
    x = model.apply_prescribed(model.x0, 1.0)
    du, free = x - model.x0, model.free
    K, f = model.stiffness(model.x0, 1.0), model.force(model.x0, 1.0)
    K = K.tocsr()
    # linear theory, as linear FEM: a follower pressure acts on the rest surface, without its load stiffness
    followers = [t for t in model.terms if getattr(t, "follow", False)]
    for t in followers:
        rows, cols = t.hessian_pattern()
        K = (K - sp.csr_matrix((t.hessian_values(model.x0), (rows, cols)), shape=K.shape)).tocsr()
    symmetric = all(t.symmetric for t in model.terms if t not in followers)
    du[free], how = linear_solve(K, f[free] - K[free][:, ~free] @ du[~free], free, model.x0.reshape(-1, model.dim),
                                 model.dim, symmetric=symmetric)
    reaction = np.where(free, 0.0, K @ du - f).reshape(-1, model.dim)  # of the linearised forces
    stats = {"type": "static", "linear": True, "wall_time": time.perf_counter() - t0,
             "solver": f"one solve with the stiffness at rest, {SOLVER}: {how}"}
    return {"displacement": du.reshape(-1, model.dim), "reaction": reaction, "stats": stats,
            "extra_attrs": {"potential_energy": "None"}}


def _solve_mss_dynamic(setup: Setup, report):
    from msslib.stepping import Simulator

    model, s = setup.model, setup.scene.solver
    curve = s.get("load_curve")
    sim = Simulator(model, dt=s["dt"], method=s["method"], damping=s["damping"],
                    allow_unstable=s.get("allow_unstable", False), load=1.0 if curve is None else curve)
    dt, t_end, every = s["dt"], s["t_end"], s["save_every"]
    n_steps = int(np.ceil(t_end / dt - 1e-9)) if t_end > 0 else 0
    n, dim = model.n_nodes, model.dim
    keep = setup.scene.output["history"]
    ts, xs, vs, rs, kes, pes = [], [], [], [], [], []

    def save(step):
        ts.append(sim.t)
        if keep:
            xs.append(sim.x.copy())
            vs.append(sim.v.copy())
            rs.append(np.array(sim.reaction))
            kes.append(sim.kinetic_energy())
            pes.append(sim.potential_energy())
        report(step / max(n_steps, 1), f"t = {sim.t:.4g} s")

    save(0)
    done = 0
    while done < n_steps:  # the steps between two saved states in one call
        k = min(every - done % every, n_steps - done)
        last = done + k == n_steps
        if last and k > 1:
            sim.step(k - 1)
        if last:  # the last step is shortened to end exactly at t_end
            sim.step(1, h=t_end - (n_steps - 1) * dt, t_new=float(t_end))
        else:
            sim.step(k)
        done += k
        save(done)
    stats = dict(sim.stats)
    stats["wall_time"] = sim.wall_time
    stats["messages"] = sim.messages
    stats["engine"] = sim.engine
    stats["n_steps"] = n_steps
    out = {"displacement": sim.displacement.copy(), "reaction": np.array(sim.reaction),
           "stats": {"type": "dynamic", **stats}, "extra_attrs": {}}
    if keep:
        n_t = len(ts)
        out["history"] = {"time": np.array(ts), "displacement": (np.array(xs) - model.x0.reshape(n, dim)),
                          "velocity": np.array(vs).reshape(n_t, n, dim), "reaction": np.array(rs).reshape(n_t, n, dim)}
        extra = {"kinetic_energy": (("time",), np.array(kes), {"units": "J", "long_name": "kinetic energy"})}
        if pes and pes[0] is not None:  # a conservative model
            extra["potential_energy"] = (("time",), np.array(pes, dtype=float),
                                         {"units": "J", "long_name": "potential energy (internal minus load work)"})
        out["extra_vars"] = extra
    return out


def _family(model: str) -> str:
    """The family of ``model`` (whose kernels it compiles), or its name."""
    try:
        return _models.get(model).family or model
    except Exception:  # an unknown model is refused elsewhere
        return model


def run_scene(scene, progress=True):
    """Build and solve a scene (a :class:`Scene`, a path or a dict) and return its result dataset.

    ``progress``: True draws a text progress bar on stderr for runs longer than half a second
    (and says in one line when numba compiles kernels, on the first run of a model family:
    ``msslib: compiling the FAMILY kernels (first run only, cached afterwards) ...``; the rate and
    the time left do not count the compile), False/None is silent, a callable receives
    ``(fraction, text)``.  Raises ValueError /
    FileNotFoundError for bad scenes, :class:`msslib.solvers.ConvergenceError` when a static solve
    fails and :class:`msslib.solvers.DivergenceError` when a dynamic run blows up.

    The final state, and every saved state of a dynamic run with ``output.history``, is checked
    for inverted and collapsed cells (:func:`msslib.mesh.quality.guard`, for every model and cell type):
    the result records ``inverted_cells``, ``collapsed_cells``, ``min_relative_jacobian``, ... (0
    counts for a clean run) and the cell variables ``cell_state`` and ``relative_jacobian``; a
    flagged state is one :class:`msslib.errors.MsslibWarning`, or with ``checks: {inverted:
    error}`` an :class:`msslib.errors.UnphysicalStateError` (no dataset is returned).
    """
    from msslib.results import make_dataset
    from msslib.mesh.quality import guard

    scene = load_scene(scene)
    t0 = time.perf_counter()
    bar = None
    if progress is True:
        total = None
        if scene.is_dynamic:  # time steps per second and the time left
            total = math.ceil(scene.solver["t_end"] / scene.solver["dt"] - 1e-9) if scene.solver["t_end"] > 0 else None
        bar = TextProgress(label=scene.name, total=total, unit="steps")
        report: Callable = bar
    elif callable(progress):
        report = progress
    else:
        def report(_fraction, _text=""):
            return None
    # a first run compiles numba kernels (seconds to a minute): said in one line, not in the pace
    notice = compile_notice(bar, _family(scene.model)) if bar is not None else contextlib.nullcontext()
    try:
        with notice:
            setup = prepare(scene)
            if scene.is_fem:
                out = _solve_fem(setup, report)
            elif scene.is_dynamic:
                out = _solve_mss_dynamic(setup, report)
            else:
                out = _solve_mss_static(setup, report)
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    hist = out.get("history") or {}
    guard_attrs, guard_vars = guard(
        setup.mesh, out["displacement"], history_displacement=hist.get("displacement"),
        history_time=hist.get("time"), policy=scene.checks["inverted"], label=f"{scene.name} ({scene.model})")

    springs = k = rest = None
    if setup.model is not None:
        sp = [t for t in setup.model.terms if t.kind == "springs"]
        if sp:
            springs = np.concatenate([t.pairs for t in sp])
            k = np.concatenate([t.k for t in sp])
            rest = np.concatenate([t.rest_length for t in sp])
    E, nu = _moduli(scene)
    extra_attrs = dict(out.get("extra_attrs", {}))
    energy = extra_attrs.pop("potential_energy", None)  # static MSS: a number, or "None" without one
    attrs = {"scene_name": scene.name, "scene_description": scene.description,
             "model_published": scene.model_options.get("published", False),
             "model_terms": list(scene.model_options["terms"]) if scene.model_options.get("terms") else None,
             **extra_attrs, **guard_attrs}
    if scene.model_options.get("A") is not None:
        attrs["model_A"] = scene.model_options["A"]
    if scene.model_options.get("correction") is not None:
        attrs["model_correction"] = scene.model_options["correction"]
    extra_vars = {**(out.get("extra_vars") or {}), **guard_vars}
    if energy is not None and not isinstance(energy, str):
        extra_vars["potential_energy"] = ((), float(energy), {
            "units": "J", "long_name": "potential energy of the final state (internal minus load work)"})
    return make_dataset(
        setup.mesh, out["displacement"], model=scene.model, E=E, nu=nu, scene=scene.text,
        density=[m.density for m in scene.materials],
        material_names=None if scene.material_groups is None else list(scene.material_groups),
        thickness=setup.thickness if setup.mesh.dim == 2 else None,
        springs=springs, spring_constant=k, rest_length=rest, reaction=out["reaction"], fixed=setup.fixed,
        history=out.get("history"), solver_stats=out["stats"], wall_time=wall,
        extra_vars=extra_vars, extra_attrs=attrs,
    )

"""Static equilibrium: load-stepped Newton with line search (:func:`static_solve`)."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from msslib.errors import ConvergenceError

from .context import _release_context, linear_solve_context, _static_context
from .linear import solve_linear_system
from .submatrices import submatrix, _submatrix_bsr
from .policy import _wants_blocks
from .protocol import (
    StaticResult,
    _accepts_out,
    energy_or_none,
    reference_force_scale,
    free_mask,
    is_conservative,
    load_vector,
    NewtonFailure,
    _with_prescribed,
)
from .roundoff import (
    force_magnitude_norm,
    _roundoff_floor_at,
    convergence_threshold,
    roundoff_floor,
    roundoff_note,
)

ARMIJO_C = 1e-4
MAX_BACKTRACKS = 20


def _line_search(problem, x, dx, free, load, r, rnorm, e0, use_energy, resolve=None):
    """Backtracking (halving) line search. Returns (x_new, r_new, rnorm_new, e_new, alpha).

    Without an energy, a step ``alpha`` is accepted when it decreases ``||r||^2`` (Armijo) or,
    failing that, when it passes the natural monotonicity test (Deuflhard): the simplified Newton
    correction ``resolve(r_new)`` (the same tangent solved with the trial residual) is at most
    ``(1 - alpha / 2) ||dx||``.  The residual norm alone is a badly scaled merit for slender
    bodies: the full Newton step of a bending problem leaves a residual, quadratic in the
    rotation, in the stiff stretching directions that is far larger than the bending residual it
    removes, although the step is right to within a small correction; halving then creeps
    towards the solution by tiny steps (hundreds of iterations and load-step halvings where the
    energy line search takes three iterations).  The displacement correction measures the error
    in the units of the unknowns and accepts such a step."""
    slope = -float(r @ dx)  # d/dalpha energy(x + alpha dx) at alpha = 0 (grad energy = -force)
    energy_merit = use_energy and e0 is not None and slope < 0.0
    dx_norm = float(np.linalg.norm(dx))
    alpha = 1.0
    for _ in range(MAX_BACKTRACKS + 1):
        xt = x.copy()
        xt[free] += alpha * dx
        with np.errstate(all="ignore"):
            rt = np.asarray(problem.force(xt, load), dtype=float)[free]
        rtn = float(np.linalg.norm(rt))
        if np.isfinite(rtn):
            if energy_merit:
                et = energy_or_none(problem, xt, load)
                if et is not None and np.isfinite(et):
                    if et <= e0 + ARMIJO_C * alpha * slope:
                        return xt, rt, rtn, et, alpha
                    # energy differences drowned in round-off: judge by the residual instead
                    noise = 64 * np.finfo(float).eps * (abs(e0) + abs(et))
                    if abs(et - e0) <= noise and rtn < rnorm:
                        return xt, rt, rtn, et, alpha
            else:
                # merit 0.5 ||r||^2, whose slope along the exact Newton direction is -||r||^2
                if rtn**2 <= (1.0 - 2.0 * ARMIJO_C * alpha) * rnorm**2 or _natural_monotone(
                        resolve, rt, alpha, dx_norm):
                    et = energy_or_none(problem, xt, load) if use_energy else None
                    return xt, rt, rtn, et, alpha
        alpha *= 0.5
    raise NewtonFailure(f"line search failed (no sufficient decrease down to step length {2 * alpha:.1e})")


def _natural_monotone(resolve, r_trial, alpha, dx_norm) -> bool:
    """Deuflhard's natural monotonicity test of a damped Newton step ``alpha dx``: the simplified
    Newton correction ``resolve(r_trial)`` (the step's tangent, the trial residual) is at most
    ``(1 - alpha / 2) ||dx||`` (for a linear problem it is ``(1 - alpha) ||dx||``)."""
    if resolve is None or not dx_norm > 0.0:
        return False
    try:
        dx_bar = resolve(r_trial)
    except NewtonFailure:
        return False
    bar = float(np.linalg.norm(dx_bar))
    return bool(np.isfinite(bar) and bar <= (1.0 - 0.5 * alpha) * dx_norm)


_ETA_MAX = 0.1  # loosest relative tolerance of the iterative linear solves (first iterations)
_ETA_GAMMA = 0.9


#: the diagonal shift of a singular tangent's Newton steps, relative to its largest diagonal entry
_SHIFT = 1e-9


def _shifted(K, rel):
    """``K + mu I`` with ``mu = rel * max |diag K|`` (a copy, in ``K``'s format): the Newton step of a
    tangent with zero-stiffness modes (a lattice that is a mechanism at rest, such as Baudet's cube
    one cube thick) then stays out of those modes instead of taking the round-off of the
    factorisation in them; the residual decides convergence as before, so the equilibrium found is
    the same."""
    mu = rel * float(np.abs(K.diagonal()).max())
    out = K.copy()
    if out.format == "bsr":
        bs = out.blocksize[0]
        rows = np.repeat(np.arange(out.shape[0] // bs), np.diff(out.indptr))
        out.data[out.indices == rows] += mu * np.eye(bs)
    else:
        out = out.tocsr()
        out.setdiag(out.diagonal() + mu)
    return out


def _forcing_term(rnorm, rnorm_prev, eta_prev, threshold):
    """Relative tolerance of the iterative linear solve of a Newton step (inexact Newton,
    Eisenstat & Walker's second choice): ``eta = 0.9 (|r_k| / |r_k-1|)^2``, kept above
    ``0.9 eta_k-1^2`` when that is not small (so that it does not drop too fast), at most
    ``_ETA_MAX``; and never tighter than what brings the linear part of the next residual 10x
    below the convergence threshold (no over-solving), nor than 1e-10.  Loose while far from the
    solution, tight near it; it does not change the convergence test of the Newton iteration.
    Direct solvers ignore it."""
    if not rnorm > 0:
        return 1e-10
    if rnorm_prev is None or not rnorm_prev > 0:
        eta = _ETA_MAX
    else:
        eta = _ETA_GAMMA * (rnorm / rnorm_prev) ** 2
        if eta_prev is not None and _ETA_GAMMA * eta_prev**2 > 0.1:
            eta = max(eta, _ETA_GAMMA * eta_prev**2)
    eta = min(eta, _ETA_MAX)
    return float(min(_ETA_MAX, max(eta, 0.1 * threshold / rnorm, 1e-10)))


def _newton(problem, x, free, load, threshold, max_iter, line_search, linear_solver,
            symmetric, use_energy, messages, progress, step_index, solver_context=None, scales=None):
    """Newton iteration at a fixed load. Returns (x, iterations, residual history).

    Converged when the residual is at most ``max(threshold, floor)``.  ``scales`` (a dict kept
    across the load steps of a solve) holds ``"floor"``, the round-off floor, None until known:
    it is computed from the first tangent assembled (``|K| |x|`` plus ``scales["load_abs"]``,
    the absolute load on the free dofs), so that no extra assembly is needed; for a problem with
    ``force_magnitude`` (protocol), from it at every iterate.

    Raises NewtonFailure with attributes ``iteration`` and ``residual`` on failure."""
    if scales is None:
        scales = {"floor": None, "load_abs": 0.0}
    with np.errstate(all="ignore"):
        r = np.asarray(problem.force(x, load), dtype=float)[free]
    rnorm = float(np.linalg.norm(r))
    history = [rnorm]
    context = linear_solve_context(problem, x, free) if solver_context is None else solver_context
    e = energy_or_none(problem, x, load) if (line_search and use_energy) else None
    it = 0
    rnorm_prev = eta_prev = None
    magnitude_of = getattr(problem, "force_magnitude", None)

    def update_floor():  # the floor at the current iterate, from the problem's force magnitude
        if callable(magnitude_of):
            with np.errstate(all="ignore"):
                m = float(np.linalg.norm(np.asarray(magnitude_of(x, load), dtype=float)[free]))
            scales["floor"] = roundoff_floor(m) if np.isfinite(m) else None

    def fail(reason):
        floor = scales.get("floor")
        if floor is not None and rnorm > floor:
            reason = f"{reason}; residual {rnorm:.3e} is above the round-off floor {floor:.3e}"
        exc = NewtonFailure(reason)
        exc.iteration = it
        exc.residual = rnorm
        exc.x, exc.r = x, r  # the failing iterate and its free residual, for the hint of the message
        return exc

    def target():
        return convergence_threshold(1.0, threshold, scales.get("floor"))

    if not np.isfinite(rnorm):
        raise fail("non-finite force at the initial guess")
    update_floor()
    # the full tangent's values can be refilled in place when only its free block is passed on
    # (the block is a copy); saves allocating (and page-faulting) a new value array per iteration
    refill = not free.all() and _accepts_out(problem)
    K_full = None
    K = context.get("K")  # an earlier solve's or load step's: its values array is refilled
    blocks = context.get("blocks")  # None: not decided yet; True: BSR node blocks; False: CSR
    # a problem that fills the free node blocks itself (Model.stiffness_blocks) spares forming
    # the full tangent and copying its free block out of it
    direct_blocks = context.get("direct_blocks", callable(getattr(problem, "stiffness_blocks", None)))
    # the natural monotonicity test stays on while the Newton corrections contract: a step it
    # accepted (the residual norm rose) must be followed by a smaller correction, else it was a
    # drift, not progress (a 1000x stiffness contrast drifts so), and the residual test alone
    # decides the rest of this load step
    monotone, monotone_step = not use_energy, None
    while rnorm > target():
        if it >= max_iter:
            raise fail(f"no convergence in {max_iter} iterations")
        with np.errstate(all="ignore"):
            filled = {}
            if blocks is None:
                def block_tangent():
                    if direct_blocks and "node_free" in context:
                        filled["K"] = problem.stiffness_blocks(x, load, out=K, node_free=context["node_free"])
                    return filled.get("K")

                blocks = context["blocks"] = _wants_blocks(lambda: problem.stiffness(x, load), free,
                                                           linear_solver, symmetric, context, block_tangent)
            K_new = None
            if blocks and direct_blocks:
                K_new = filled.get("K")  # filled for the decision already
                if K_new is None:
                    K_new = problem.stiffness_blocks(x, load, out=K, node_free=context["node_free"])
                if K_new is None:
                    direct_blocks = context["direct_blocks"] = False
            if K_new is None:
                K_full = problem.stiffness(x, load, out=K_full) if refill else problem.stiffness(x, load)
                # the previous block is no longer needed (a kept AMG hierarchy is a preconditioner
                # only): its value array is reused, which saves page-faulting a new one each
                # iteration
                if blocks:
                    K_new = _submatrix_bsr(K_full, context["node_free"], context["dim"], out=K, plans=context)
                    if K_new is None:  # not made of node blocks: CSR from now on
                        blocks = context["blocks"] = False
                if not blocks:
                    K_new = submatrix(K_full, free, out=K, plans=context)
            K = context["K"] = K_new
        if scales.get("floor") is None and not callable(magnitude_of):  # from this tangent: no extra assembly
            scales["floor"] = roundoff_floor(force_magnitude_norm(K, x[free], scales.get("load_abs", 0.0)))
            if rnorm <= target():
                break
        it += 1
        try:
            rtol = _forcing_term(rnorm, rnorm_prev, eta_prev, target())
            eta_prev, rnorm_prev = rtol, rnorm
            K_step = _shifted(K, context["shift"]) if context.get("shift") else K
            dx = solve_linear_system(K_step, r, linear_solver, symmetric, messages, context, rtol,
                               truncate=bool(line_search and use_energy))
        except NewtonFailure as exc:
            raise fail(str(exc)) from None
        dx_norm = float(np.linalg.norm(dx))
        if monotone_step is not None and dx_norm >= monotone_step:
            monotone = False
        if line_search:
            try:
                resolve = None if not monotone else (  # the same tangent, for the natural monotonicity test
                    lambda b, K=K_step, rtol=rtol: solve_linear_system(K, b, linear_solver, symmetric, messages, context,
                                                                        rtol))
                rnorm_before = rnorm
                x, r, rnorm, e, alpha = _line_search(problem, x, dx, free, load, r, rnorm, e, use_energy, resolve)
                armijo = rnorm**2 <= (1.0 - 2.0 * ARMIJO_C * alpha) * rnorm_before**2
                monotone_step = None if (armijo or not monotone) else dx_norm
            except NewtonFailure as exc:
                raise fail(str(exc)) from None
        else:
            x = x.copy()
            x[free] += dx
            with np.errstate(all="ignore"):
                r = np.asarray(problem.force(x, load), dtype=float)[free]
            rnorm = float(np.linalg.norm(r))
            if not np.isfinite(rnorm):
                raise fail("non-finite force after a full Newton step")
        update_floor()
        history.append(rnorm)
        if progress is not None:
            progress({"load_step": step_index, "load": load, "iteration": it, "residual": rnorm,
                      "threshold": target()})
    return x, it, history


def floor_text(floor):
    return "not computed" if floor is None else f"{floor:.3e}"


def static_solve(problem, x0, *, load_steps: int = 1, tol: float = 1e-8, max_iter: int = 50,
                 line_search: bool = True, linear_solver="auto", progress: Callable | None = None,
                 max_cuts: int = 10, force_scale: float | None = None,
                 on_load_step: Callable[[int, float], None] | None = None) -> StaticResult:
    """Equilibrium ``force(x, 1) = 0`` on the free dofs by load-stepped Newton.

    Parameters
    ----------
    problem : see the module docstring for the protocol.
    x0 : initial positions ``(n_dof,)`` (constrained dofs hold their values, or are set by
        ``problem.apply_prescribed(x, load)`` at every load level).
    load_steps : number of equal load increments from 0 to 1.
    tol : relative tolerance; converged when ``||force[free]||_2 <= max(tol * F_ref, floor)``, the
        floor being the round-off level of the forces (module docstring).
    max_iter : Newton iterations allowed per load step before the step counts as failed.
    line_search : backtracking with the Armijo condition on the energy when ``problem.energy``
        returns a number and the Newton direction descends it, otherwise on ``||force[free]||^2``
        or, where that fails, Deuflhard's natural monotonicity test (the simplified Newton
        correction with the same tangent at most ``(1 - alpha / 2)`` times the step; one more
        linear solve per such trial).
    linear_solver : ``"auto"``, ``"direct"``, ``"cg"``, or a callable ``(K_free, rhs) -> dx``.
        ``"direct"``: for symmetric systems a banded Cholesky in a bandwidth-reducing ordering
        (computed once per sparsity pattern) when it is cheap, banded LU when the tangent is
        indefinite, else MKL Pardiso from 5,000 unknowns where installed, else sparse LU
        (minimum-degree ordering); non-symmetric (not merely to round-off): the same Pardiso or
        sparse LU.
        ``"cg"``: CG preconditioned by pyamg smoothed aggregation if installed (node blocks and
        rigid-body modes when the free dofs are whole nodes; the hierarchy is reused across
        Newton iterations, load steps and successive solves of the same problem, from the same
        initial coordinates and with the same ``linear_solver``, as long as CG converges fast
        with it: the problem keeps it, with the matrix of the Newton systems), falling back to
        LU; the CG tolerance follows an
        inexact-Newton forcing term (loose far from the solution, tight near it; the Newton
        convergence test is unchanged), and a CG run that meets negative
        curvature returns its last iterate under the energy line search (truncated Newton).
        ``"auto"``: direct up to ``ITERATIVE_THRESHOLD`` = 2 000 free dofs or while the banded
        Cholesky is cheap (``n (b + 1)^2 <= BAND_AUTO_COST``), else CG for symmetric systems.
    progress : optional callable receiving a dict ``{load_step, load, iteration, residual,
        threshold}`` after each Newton iteration.
    max_cuts : how many times in a row a failing load increment may be halved; the increment is
        also never halved below ``1 / (load_steps * 2**max_cuts)`` (near a limit point,
        alternating successes and halvings would otherwise creep towards it forever).  After a
        converged increment the next one is doubled, up to the nominal ``1 / load_steps``.
    force_scale : overrides ``F_ref`` of the convergence criterion (the round-off floor still applies).
    on_load_step : optional callable ``(accepted_steps, load)`` called after each converged load
        increment.

    Raises
    ------
    ConvergenceError when a load increment still fails after ``max_cuts`` halvings.
    """
    t_start = time.perf_counter()
    if load_steps < 1:
        raise ValueError("load_steps must be >= 1")
    free = free_mask(problem)
    x = np.array(x0, dtype=float).reshape(-1)
    if x.shape != (int(problem.n_dof),):
        raise ValueError(f"x0 must have {problem.n_dof} entries, got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 contains non-finite values")
    symmetric = bool(getattr(problem, "symmetric", True))
    use_energy = line_search and is_conservative(problem, x, 1.0)
    merit = "none" if not line_search else ("energy" if use_energy else "residual")
    f_load = load_vector(problem, x)
    scale = float(force_scale) if force_scale is not None else reference_force_scale(problem, x, free, f_load)
    threshold = tol * scale
    with np.errstate(all="ignore"):
        load_abs = np.abs(f_load[free])
    load_abs[~np.isfinite(load_abs)] = 0.0
    scales = {"floor": None, "load_abs": load_abs}  # the round-off floor: from the first tangent
    roundoff_steps: list[int] = []
    messages: list[str] = []

    iterations: list[int] = []
    residuals: list[list[float]] = []
    loads: list[float] = []
    nominal = 1.0 / load_steps
    # AMG hierarchy and matrix kept across iterations, load steps and solves of this problem
    solver_context = _static_context(problem, x, free, linear_solver)
    solver_context.pop("shift", None)  # judged afresh by each solve
    try:
        lam = 0.0
        dlam = nominal
        n_cuts = 0
        cuts_this_step = 0
        while lam < 1.0 - 1e-14:
            target = min(1.0, lam + dlam)
            if 1.0 - target < 1e-12:
                target = 1.0
            step_index = len(loads) + 1  # the load step being attempted (1-based, accepted steps + 1)
            guess = _with_prescribed(problem, x, target)
            try:
                x_new, it, hist = _newton(problem, guess, free, target, threshold, max_iter, line_search,
                                          linear_solver, symmetric, use_energy, messages, progress, step_index,
                                          solver_context, scales)
            except NewtonFailure as exc:
                if "shift" not in solver_context and cuts_this_step == 0 and not callable(linear_solver):
                    # before halving: the same step again with a shifted tangent (zero-stiffness modes)
                    solver_context["shift"] = _SHIFT
                    messages.append(f"load step {step_index} to load {target:.6g} failed at iteration "
                                    f"{exc.iteration} ({exc}); again with the tangent shifted by {_SHIFT:g} of its "
                                    "largest diagonal entry (zero-stiffness modes)")
                    continue
                dlam = 0.5 * (target - lam)
                if cuts_this_step >= max_cuts or dlam < nominal * 0.5**max_cuts * (1.0 - 1e-12):
                    k = int(np.floor(lam / nominal + 1e-9)) + 1  # the nominal step it belongs to
                    from msslib.hints import failure_hint

                    hint = failure_hint(problem, getattr(exc, "x", x), getattr(exc, "r", None), free)
                    raise ConvergenceError(
                        f"static_solve did not converge: load step {step_index} (nominal step {k} of {load_steps}), "
                        f"load factor {target:.6g} "
                        f"(last converged load factor {lam:.6g}, increment {target - lam:.3g} after "
                        f"{cuts_this_step} halvings), iteration {exc.iteration}, residual {exc.residual:.3e} "
                        f"(threshold {convergence_threshold(tol, scale, scales['floor']):.3e} = max(tol {tol:.1e} "
                        f"x F_ref {scale:.3e}, round-off floor {floor_text(scales['floor'])})): {exc}"
                        + (f"; {hint}" if hint else ""),
                        load_step=step_index, load=target, iteration=exc.iteration, residual=exc.residual,
                        x_last=x.copy(),
                    ) from None
                cuts_this_step += 1
                n_cuts += 1
                messages.append(f"load step {step_index} to load {target:.6g} failed at iteration "
                                f"{exc.iteration} ({exc}); halving the increment to {dlam:.3g}")
                continue
            x = x_new
            lam = target
            if hist[-1] > threshold:  # accepted at the round-off floor, above tol x F_ref
                roundoff_steps.append(step_index)
                messages.append(f"load step {step_index}: {roundoff_note(hist[-1], scales['floor'], threshold)}")
            iterations.append(it)
            residuals.append(hist)
            loads.append(lam)
            dlam = min(nominal, 2.0 * dlam)  # grow back towards the nominal increment
            cuts_this_step = 0
            if on_load_step is not None:
                on_load_step(len(loads), lam)

        if scales["floor"] is None:  # converged without assembling a tangent: for the record
            scales["floor"] = _roundoff_floor_at(problem, x, free, load_abs)
        return StaticResult(
            x=x, converged=True, iterations=iterations, residuals=residuals, loads=loads,
            wall_time=time.perf_counter() - t_start, n_load_steps=len(loads), n_cuts=n_cuts,
            force_scale=scale, line_search_merit=merit, messages=messages,
            cg_iterations=int(solver_context.get("cg_iterations", 0)),
            tol=float(tol), roundoff_floor=float(scales["floor"]),
            threshold=convergence_threshold(tol, scale, scales["floor"]), roundoff_steps=roundoff_steps,
        )
    finally:
        _release_context(solver_context)

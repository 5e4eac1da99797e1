"""Time integration (:func:`integrate`): symplectic Euler, velocity Verlet, implicit Euler, with
the divergence detector of the explicit schemes."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
from numba import njit

from msslib.errors import ConvergenceError, DivergenceError

from msslib.solvers import protocol
from msslib.solvers.context import linear_solve_context
from msslib.solvers.linear import solve_linear_system
from msslib.solvers.submatrices import submatrix
from msslib.solvers.protocol import TINY, DynamicResult
from msslib.solvers.roundoff import force_magnitude_norm, convergence_threshold, roundoff_floor
from msslib.solvers.stability import EXPLICIT_METHODS, mass_vector, resolve_damping
from msslib.stepping.check import PendingCheck, remember, settle, stability_check
from msslib.solvers.statics import ARMIJO_C, MAX_BACKTRACKS, floor_text


def _bbox_size(problem, x0):
    dim = getattr(problem, "dim", None)
    if dim and x0.size % int(dim) == 0 and x0.size:
        pts = x0.reshape(-1, int(dim))
        size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    else:
        size = float(np.ptp(x0)) if x0.size else 0.0
    if size <= 0.0:
        size = float(np.max(np.abs(x0))) if x0.size else 0.0
    return size if size > 0.0 else 1.0


# Divergence detector of the explicit schemes.  An explicit step above the stability limit makes
# the top modes grow by a real factor lambda < -1 per step (|lambda| = 1.9 at 1.05 x the limit,
# 3.5 at 1.2 x, 14 at 2 x): the forces and velocities flip sign every step and their amplitude
# grows geometrically.  The amplitude is measured by
#     J = a.M a + v.K v      (a = M^-1 f at x_n, v the velocity that moved x_n-1 to x_n),
# the energy of the time derivative (v, a) of the motion: for a linear undamped system it is
# conserved (the derivative obeys the same equations, the constant loads drop out), damping only
# lowers it, and geometric stiffening changes it moderately.  K v is not assembled:
# K (x_n - x_n-1) = -(f_n - f_n-1), from the force both schemes evaluate after each drift.  An
# unstable mode multiplies its share of J by lambda^2 every step, and J weights mode i by
# omega_i^2, so that the top modes show in it long before they show in the displacement.
# Divergence is declared when J exceeds G times its reference (its
# smallest value so far, or the J of a top-mode amplitude _FLOOR_SIZE x the body size, whichever
# is larger) while the force flips sign (f_n . M^-1 f_n-1 < 0; physical motion, resolved in time,
# does not), or exceeds _GROWTH_ANY times it in any case.  In a stable linear run the J of one
# mode varies within a factor (1 + r) / (1 - r), r = dt omega / 2 (computed for both schemes: 19
# at r = 0.9, 199 at 0.99), reached when that mode carries all of J; G is _GROWTH_SAFETY times
# that bound at r = dt / limit, at least _GROWTH_MIN (and _GROWTH_MIN for a step over the limit,
# allow_unstable).  On a cantilever released under gravity J stays within 6 % of its start
# (measured at 0.5 to 0.999 x the limit).
_GROWTH_MIN = 100.0


_GROWTH_SAFETY = 10.0
_GROWTH_ANY = 1e10
_FLOOR_SIZE = 1e-8


def relative_potential_energy(problem, x, load, cache: dict | None = None):
    """The potential energy at ``x`` measured from the reference positions ``x0`` of ``problem``:
    ``E(x, load) - E(x0, load) + E(x0, 0)``, the internal energy minus the work of the loads on the
    displacement ``x - x0`` (for a constant load ``f``: ``E_int(x) - load f.(x - x0)``), so that it
    does not change when the whole mesh is moved.  None for a model with a non-conservative term.
    ``cache`` (a dict) keeps ``E(x0, load) - E(x0, 0)`` per load factor."""
    e = protocol.energy_or_none(problem, x, load)
    if e is None:
        return None
    x0 = getattr(problem, "x0", None)
    if not isinstance(x0, np.ndarray) or x0.size != np.size(x):  # no reference positions: E as it is
        return e
    key = float(load)
    shift = None if cache is None else cache.get(key)
    if shift is None:
        shift = protocol.energy_or_none(problem, x0, load) - protocol.energy_or_none(problem, x0, 0.0)
        if cache is not None:
            cache[key] = shift
    return float(e - shift)


def _growth_threshold(ratio):
    """G of the detector for ``dt = ratio x`` the stability limit (see the comment above)."""
    if not ratio < 1.0:
        return _GROWTH_MIN
    return float(min(max(_GROWTH_MIN, _GROWTH_SAFETY * (1.0 + ratio) / (1.0 - ratio)), 0.01 * _GROWTH_ANY))


@njit(cache=True, nogil=True)
def _monitor(vf, u, f_late, f_early, f_r, mf, x, x_ref):
    """One pass over the state: ``(v.M v, f_late.M^-1 f_early, u.(f_late - f_early), f_r.M^-1 f_r,
    max |x - x_ref|)``."""
    q = 0.0
    pf = 0.0
    ku = 0.0
    r = 0.0
    for i in range(vf.shape[0]):
        q += mf[i] * vf[i] * vf[i]
        pf += f_late[i] * f_early[i] / mf[i]
        ku += u[i] * (f_late[i] - f_early[i])
        r += f_r[i] * f_r[i] / mf[i]
    dmax = 0.0
    for i in range(x.shape[0]):
        d = abs(x[i] - x_ref[i])
        if d > dmax:
            dmax = d
    return q, pf, ku, r, dmax


def integrate(problem, x0, v0, *, dt: float, t_end: float, method: str = "symplectic_euler",
              damping=None, save_every: int = 1, progress: Callable | None = None,
              newton_tol: float = 1e-8, load: float = 1.0, newton_max_iter: int = 30,
              linear_solver="auto", blowup: float = 1e3, allow_unstable: bool = False) -> DynamicResult:
    """Integrate ``M dv/dt = force(x, load) - C v``, ``dx/dt = v`` from ``t = 0`` to ``t_end``.

    Parameters
    ----------
    method : ``"symplectic_euler"`` (``v+ = v + dt M^-1 (f(x) - C v)``, ``x+ = x + dt v+``; first
        order), ``"velocity_verlet"`` (second order; the mass-proportional damping of the second
        half-kick is treated implicitly) or ``"implicit_euler"`` (Newton on
        ``M (v+ - v) / dt = f(x + dt v+) - C v+`` with the Jacobian ``M + dt C + dt^2 K``; the
        derivative of ``K`` in the ``beta K v`` term is neglected). ``n_steps = ceil(t_end / dt)``;
        the last step is shortened to end exactly at ``t_end``.
    damping : scalar mass-proportional coefficient ``alpha`` or Rayleigh pair ``(alpha, beta)``,
        ``C = alpha M + beta K``. ``None`` (default) takes ``problem.damping`` if present, else 0;
        pass ``0.0`` to force an undamped run.
    save_every : save every n-th step (the initial and the final state are always saved).
    progress : optional callable receiving ``{step, t, n_steps}`` at each saved step.
    newton_tol : implicit Euler converges when ``||R[free]|| <= max(newton_tol * max(||M v_n||,
        dt ||f(x_n)||, dt F_ref), floor)`` with ``R`` the momentum residual, ``F_ref`` as in the
        static criterion and ``floor`` the round-off floor of ``||M v_n|| + dt || |K| |x| + |f_ext| ||``
        (:func:`roundoff_floor`, ``K`` at ``x0``).
    load : constant load factor passed to ``problem.force``.
    blowup : last-resort divergence bound: ``max |x - x0| > blowup * bounding-box size of x0``.
    allow_unstable : explicit methods only.  Before the run, the stability limit of the model at
        ``x0`` (:func:`check_time_step`: ``2 / omega_max`` of ``M^-1 K`` on the free dofs, lowered
        by the damping where it does, :func:`critical_time_step`) is computed and a ``dt`` above
        it raises :class:`msslib.errors.StabilityError`; ``allow_unstable=True`` runs it anyway
        (the divergence detector below still stops it).

    Divergence: after every step the state is checked (one fused pass over the free dofs): a
    non-finite velocity or a displacement beyond the ``blowup`` bound raises
    :class:`DivergenceError`, and for the explicit methods so does the growth of the explicit
    instability: ``J = a.M a + v.K v``, the energy of the time derivative of the motion (constant
    for a linear undamped system, lowered by damping; ``K v`` from the difference of the last two
    forces, nothing assembled), grown over its smallest value by more than ten times what a
    stable step allows, ``(1 + r) / (1 - r)`` for ``r = dt / limit`` (at least 100-fold), while
    the force flips sign from step to step, or 1e10-fold in any case (see the comment at
    ``_GROWTH_MIN``).  ``J`` weights mode ``i`` by ``omega_i^2``, so a run over the limit is
    stopped within a few steps of its top modes outgrowing the load's share in them, before the
    body is visibly wrong (a 0.2 m cantilever under gravity at 1.2 x the limit: after 9 steps,
    0.2 mm from a stable run, 2 % of its static deflection).  The error names the at-rest limit
    computed before the run.

    ``stats`` holds, besides those of :class:`DynamicResult`, ``stability_limit``,
    ``stability_limit_undamped``, ``omega_max`` and ``dt_over_limit`` (explicit methods; None
    for implicit Euler) and ``allow_unstable``.

    Raises
    ------
    StabilityError (a ValueError) when an explicit ``dt`` exceeds the limit at rest and
    ``allow_unstable`` is False; DivergenceError when the run diverges; ConvergenceError when the
    implicit Newton iteration fails.
    """
    if not (dt > 0) or not (t_end >= 0):
        raise ValueError("dt must be positive and t_end non-negative")
    if save_every < 1:
        raise ValueError("save_every must be >= 1")
    stepper = Integrator(problem, x0, v0, dt=dt, method=method, damping=damping, load=load,
                         newton_tol=newton_tol, newton_max_iter=newton_max_iter, linear_solver=linear_solver,
                         blowup=blowup, allow_unstable=allow_unstable)
    n_steps = int(np.ceil(t_end / dt - 1e-9)) if t_end > 0 else 0
    stepper.stats["n_steps"] = n_steps
    ts, xs, vs, kes, pes = [], [], [], [], []
    shift_cache: dict = {}

    def save(step, t):
        ts.append(t)
        xs.append(stepper.x.copy())
        vs.append(stepper.v.copy())
        kes.append(stepper.kinetic_energy())
        if stepper.conservative:
            pes.append(relative_potential_energy(problem, stepper.x, load, shift_cache))
        if progress is not None:
            progress({"step": step, "t": t, "n_steps": n_steps})

    save(0, 0.0)
    for step in range(1, n_steps + 1):
        h = dt if step < n_steps else t_end - (n_steps - 1) * dt
        stepper.step(h, t_new=step * dt if step < n_steps else float(t_end))
        if step % save_every == 0 or step == n_steps:
            save(step, stepper.t)
    stats = stepper.stats
    stats["wall_time"] = time.perf_counter() - stepper.t_start
    stats["messages"] = stepper.messages
    return DynamicResult(
        t=np.array(ts), x=np.array(xs), v=np.array(vs), x_final=stepper.x.copy(), v_final=stepper.v.copy(),
        kinetic_energy=np.array(kes), potential_energy=np.array(pes, dtype=float) if stepper.conservative else None,
        stats=stats,
    )


class Integrator:
    """The time stepper of :func:`integrate`, one step at a time: the engine of
    :class:`msslib.stepping.Simulator` for every model and scheme (the fused spring-network
    kernel aside).

    Built from the state ``x0, v0`` (copied) with the arguments of :func:`integrate`; the
    stability check of the explicit schemes runs here, once.  :meth:`step` advances by ``h`` and
    runs the divergence checks of :func:`integrate`.  Between steps a caller may change
    ``load`` (the load factor), ``extra`` (nodal forces added to ``problem.force``, ``(n_dof,)``
    or None) and, through ``drive`` (called as ``drive(t, x)`` after each drift, before the force
    at the new state is evaluated), the positions of the dofs that are not free.  ``free``
    (optional) is a mask of the dofs that move; it may hold fewer dofs than the problem's (driven
    dofs), never more.
    """

    def __init__(self, problem, x0, v0, *, dt: float, method: str = "symplectic_euler", damping=None,
                 load: float = 1.0, newton_tol: float = 1e-8, newton_max_iter: int = 30, linear_solver="auto",
                 blowup: float = 1e3, allow_unstable: bool = False, free=None, drive=None):
        self.t_start = time.perf_counter()
        methods = ("symplectic_euler", "velocity_verlet", "implicit_euler")
        if method not in methods:
            raise ValueError(f"method must be one of {methods}, got {method!r}")
        if not (dt > 0):
            raise ValueError("dt must be positive")
        self.problem, self.method, self.dt, self.load = problem, method, float(dt), load
        self.newton_tol, self.newton_max_iter, self.linear_solver = newton_tol, newton_max_iter, linear_solver
        n = int(problem.n_dof)
        model_free = protocol.free_mask(problem)
        if free is None:
            free = model_free
        else:
            free = np.asarray(free, dtype=bool).reshape(-1)
            if free.shape != (n,) or np.any(free & ~model_free):
                raise ValueError("free must be a mask of the problem's free dofs")
        self.free = free
        mass = mass_vector(problem)
        if np.any(mass[free] <= 0):
            raise ValueError("masses of free dofs must be positive")
        self.mass = mass
        self.alpha, self.beta = resolve_damping(problem, damping)
        x = np.array(x0, dtype=float).reshape(-1)
        v = np.array(v0, dtype=float).reshape(-1)
        if x.shape != (n,) or v.shape != (n,):
            raise ValueError(f"x0 and v0 must have {n} entries")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise ValueError("x0 and v0 must be finite")
        v[~free] = 0.0
        self.x_ref = x.copy()
        self.bound = blowup * _bbox_size(problem, self.x_ref)
        self.symmetric = bool(getattr(problem, "symmetric", True))
        self.explicit = method in EXPLICIT_METHODS
        self.extra = None
        self.drive = drive
        self.t = 0.0
        self.n_taken = 0
        stats = {"n_steps": 0, "dt": dt, "method": method, "n_force_evals": 0, "n_newton_iterations": 0,
                 "n_linear_solves": 0, "damping": (self.alpha, self.beta), "stability_limit": None,
                 "stability_limit_undamped": None, "omega_max": None, "dt_over_limit": None,
                 "stability_estimate": None, "allow_unstable": bool(allow_unstable)}
        self.stats = stats
        if drive is not None:
            drive(0.0, x)
        self.limit = self._pending = None
        if self.explicit:  # see msslib.stepping.check: pending on a thread, or decided here
            got = stability_check(problem, x, dt, free=free, method=method, damping=(self.alpha, self.beta),
                                  load=load, allow_unstable=allow_unstable)
            if isinstance(got, PendingCheck):  # its information None until then
                self._pending, self._restore_to = got, (x.copy(), v.copy(), 0.0, 0, 0.0)
            else:
                stats.update(got)
        self.conservative = protocol.is_conservative(problem, x, load)
        self.mf = mass[free]
        self.inv_m = 1.0 / self.mf
        self.messages: list[str] = []
        if self.explicit and (stats["dt_over_limit"] or 0.0) > 1.0:
            self.messages.append(f"dt = {dt:.6g} s is {stats['dt_over_limit']:.3g} x the explicit stability limit "
                                 f"{stats['stability_limit']:.6g} s of the model at rest (allow_unstable)")
        # the plans of the free-dof submatrices and, for implicit Euler, the kept AMG hierarchy
        self.solver_context = linear_solve_context(problem, x, free)
        self.f_scale = self.magnitude = None
        if method == "implicit_euler":
            f_load = protocol.load_vector(problem, x)
            self.f_scale = protocol.reference_force_scale(problem, x, free, f_load)
            with np.errstate(all="ignore"):
                K0 = submatrix(problem.stiffness(x, load), free, plans=self.solver_context)
                self.magnitude = force_magnitude_norm(K0, x[free], np.nan_to_num(np.abs(load * f_load[free])))
        # divergence detector (explicit methods): see _GROWTH_MIN; its scales from the check
        self.j_min = None
        # the amplitude sqrt(J) the loads and paths put in since the start (see note_input)
        self.a_in = 0.0
        if self._pending is None:
            self._use_check()
        self._fixed = np.flatnonzero(~free)
        m_mean = float(self.mf.mean()) if self.mf.size else 1.0
        self._m_fixed = np.maximum(mass[self._fixed], m_mean)
        self._load_norm = None
        self.flips = 0  # steps in a row whose force flipped sign
        self._zeros = np.zeros(int(free.sum()))
        self.x, self.v = x, v
        with np.errstate(all="ignore"):
            self.f = self.force(x) if self.explicit else None  # explicit schemes: the force after each drift
            if self.explicit and not np.any(v[free]):  # from rest: J_0 = a.M a
                j = float(np.sum(self.f * self.f * self.inv_m))
                self.j_min = j if np.isfinite(j) else None

    def _use_check(self):
        """The at-rest limit and the detector's scales from the stability check's ``omega_max``."""
        omega = self.stats["omega_max"] or 0.0
        finite = self.explicit and np.isfinite(omega)
        self.limit, self._omega2 = self.stats["stability_limit"], omega**2 if finite else 0.0
        self.j_floor = (omega**4 * float(self.mf.sum()) * (_FLOOR_SIZE * _bbox_size(self.problem, self.x_ref)) ** 2
                        if finite else 0.0)
        self.growth = _growth_threshold(self.stats["dt_over_limit"]) if self.explicit else None

    def restart_detector(self):
        """Set the detector's reference from the current force and velocity (after the caller set
        ``extra`` or ``load`` and re-evaluated the force): from rest, ``J_0 = a.M a``."""
        if not self.explicit:
            return
        if self._pending is not None:  # the state a refused first call returns to
            remember(self)
        self.j_min = None
        self.flips = 0
        if not np.any(np.asarray(self.v).reshape(-1)[self.free]):
            f = self._free_force()
            with np.errstate(all="ignore"):
                j = float(np.sum(f * f * self.inv_m))
            self.j_min = j if np.isfinite(j) else None

    def _free_force(self):
        return self.f

    def note_input(self, x_fixed_before, x_fixed_after, load_before, extra_before):
        """Add to ``a_in`` the amplitude ``sqrt(J)`` that one step's change of the inputs can put
        into the motion: a move ``du`` of the dofs that do not move freely (paths, prescribed
        displacements) changes the force on the free dofs by ``K du``, at most
        ``omega_max^2 |du|_M`` in the ``M^-1`` norm of J; a change of the load factor or of the
        extra nodal forces by its ``M^-1`` norm.  The detector measures growth against this scale
        too, so that a body at rest driven by a tool or a ramped load (J ~ 0 at the start) is not
        taken for an instability."""
        if self._pending is not None:
            settle(self)
        a = 0.0
        if self._fixed.size and x_fixed_before is not None:
            du = np.asarray(x_fixed_after, dtype=float) - np.asarray(x_fixed_before, dtype=float)
            a += self._omega2 * float(np.sqrt(np.sum(self._m_fixed * du * du)))
        if self.load != load_before:
            if self._load_norm is None:
                f_load = protocol.load_vector(self.problem, self.x_ref)[self.free]
                self._load_norm = float(np.sqrt(np.sum(f_load * f_load * self.inv_m)))
            a += abs(float(self.load) - float(load_before)) * self._load_norm
        if self.extra is not extra_before:
            new = self.extra[self.free] if self.extra is not None else 0.0
            old = extra_before[self.free] if extra_before is not None else 0.0
            d = np.broadcast_to(np.asarray(new - old, dtype=float), self.mf.shape)
            a += float(np.sqrt(np.sum(d * d * self.inv_m)))
        if np.isfinite(a):
            self.a_in += a

    def _fixed_positions(self):
        return self.x[self._fixed] if self.drive is not None and self._fixed.size else None

    def force(self, xx):
        """The force on the free dofs at ``xx`` (with ``load`` and ``extra``)."""
        self.stats["n_force_evals"] += 1
        f = np.asarray(self.problem.force(xx, self.load), dtype=float)
        if self.extra is not None:
            f = f + self.extra
        return f[self.free]

    def full_force(self):
        """The total nodal force ``(n_dof,)`` at the current state (one force evaluation)."""
        f = np.asarray(self.problem.force(self.x, self.load), dtype=float)
        return f + self.extra if self.extra is not None else f

    def kinetic_energy(self) -> float:
        return 0.5 * float(self.mass[self.free] @ (self.v[self.free] ** 2))

    def evaluate(self):
        """The force of the current state with the current loads (explicit schemes keep it)."""
        self.f = self.force(self.x) if self.explicit else None

    def reaction(self):
        """Minus the total force on the dofs that do not move, 0 on the free ones (flat, N)."""
        f = self.full_force() if self.explicit else np.asarray(self.problem.force(np.ravel(self.x), self.load),
                                                                dtype=float)
        return np.where(self.free, 0.0, -f)

    def steps(self, n: int, h: float | None = None, t_new: float | None = None) -> None:
        """``n`` calls of :meth:`step`; ``t_new`` is the time after the last one."""
        for i in range(n):
            self.step(h, t_new if i + 1 == n else None)

    def _damping_force(self, xx, vf):
        """-(alpha M + beta K) v on the free dofs, ``vf`` the free velocities."""
        out = -self.alpha * self.mf * vf if self.alpha else np.zeros_like(vf)
        if self.beta:
            out = out - self.beta * (submatrix(self.problem.stiffness(xx, self.load), self.free,
                                                plans=self.solver_context) @ vf)
        return out

    def _drift(self, x, w, h, t_new):
        x = x.copy()
        x[self.free] += h * w
        if self.drive is not None:
            self.drive(t_new, x)
        return x

    def step(self, h: float | None = None, t_new: float | None = None) -> None:
        """Advance by ``h`` (default ``dt``) to ``t_new`` (default ``t + h``), then check the state."""
        h = self.dt if h is None else float(h)
        t_new = self.t + h if t_new is None else float(t_new)
        step = self.n_taken + 1
        free, alpha, beta, inv_m = self.free, self.alpha, self.beta, self.inv_m
        x, v, f = self.x, self.v, self.f
        x_prev, v_prev = x, v  # not modified below (x and v are replaced by new arrays)
        inputs = (self._fixed_positions(), self.load, self.extra) if self.drive is not None else None
        with np.errstate(all="ignore"):
            vf = v[free]
            jterms = None  # (velocity u, f_late, f_early, f for a.M a, step h): K u = -(f_late - f_early) / h
            if self.method == "symplectic_euler":
                a = (f + self._damping_force(x, vf)) * inv_m
                vf = vf + h * a
                x = self._drift(x, vf, h, t_new)
                f_old, f = f, self.force(x)  # at x_n, for the next step and the monitor
                jterms = (vf, f, f_old, f, h)
            elif self.method == "velocity_verlet":
                a = (f + self._damping_force(x, vf)) * inv_m
                v_half = vf + 0.5 * h * a
                x = self._drift(x, v_half, h, t_new)
                f_old, f = f, self.force(x)
                jterms = (v_half, f, f_old, f, h)
                # second half-kick: mass-proportional damping at v+ (implicit), beta K at v_half
                g = f - beta * (submatrix(self.problem.stiffness(x, self.load), free, plans=self.solver_context)
                                @ v_half) if beta else f
                vf = (v_half + 0.5 * h * inv_m * g) / (1.0 + 0.5 * h * alpha)
            else:
                xd = self._drift(x, np.zeros_like(vf), 0.0, t_new)  # the driven dofs at t_new
                if self.extra is not None:
                    raise ValueError("implicit_euler takes no extra nodal forces; use the load factor")
                vf = _implicit_euler_step(self.problem, xd, vf, h, free, self.mf, alpha, beta, self.load,
                                          self.newton_tol, self.newton_max_iter, self.f_scale, self.linear_solver,
                                          self.symmetric, self.stats, self.messages, step, t_new,
                                          self.solver_context, self.magnitude)
                x = xd.copy()
                x[free] += h * vf
            v = np.zeros(v.size)
            v[free] = vf
            self.x, self.v, self.f = x, v, f
            if inputs is not None:
                self.note_input(inputs[0], self._fixed_positions(), inputs[1], inputs[2])
            self.t = t_new
            self.n_taken = step
            self.stats["n_steps"] = max(self.stats["n_steps"], step)
            u_j, f_late, f_early, f_r, h_j = jterms if jterms is not None else (self._zeros,) * 4 + (1.0,)
            q, pf, ku, r, dmax = _monitor(vf, u_j, f_late, f_early, f_r, self.mf, x, self.x_ref)
            self.observe(q, pf, ku, r, dmax, h_j, step, t_new, x_prev, v_prev, jterms is not None)

    def observe(self, q, pf, ku, r, dmax, h, step, t, x_prev, v_prev, explicit_terms=True):
        """The divergence checks of one step from its monitor values (see :func:`_monitor`);
        raises :class:`DivergenceError` (and the pending stability check's refusal)."""
        if self._pending is not None:
            settle(self)
        if not (np.isfinite(q) and dmax <= self.bound):
            _check_state(self.problem, self._flat_x(), self.v, self.x_ref, self.bound, step, t, self.dt, self.method,
                         x_prev, v_prev, self.limit)
        if self.explicit and explicit_terms:
            self.flips = self.flips + 1 if pf < 0.0 else 0
            J = r - ku / h
            J = J if J == J else float("inf")
            self.j_min = J if self.j_min is None else min(self.j_min, J)
            j_ref = max(self.j_min, self.j_floor, self.a_in * self.a_in, TINY)
            if (J > self.growth * j_ref and self.flips >= 1) or J > _GROWTH_ANY * j_ref:
                _raise_growth(self._flat_x(), self.x_ref, step, t, self.dt, self.method, x_prev, v_prev, self.limit,
                              J / j_ref, self.flips)

    def _flat_x(self):
        """The positions as a flat array (the network engine keeps them in node records)."""
        return self.x


def _implicit_euler_step(problem, x, vf, h, free, mf, alpha, beta, load, tol, max_iter, f_scale,
                         linear_solver, symmetric, stats, messages, step, t_new, solver_context=None,
                         magnitude=None):
    """Backward Euler velocity update on the free dofs (Newton with residual backtracking)."""
    f0 = np.asarray(problem.force(x, load), dtype=float)[free]
    mv = float(np.linalg.norm(mf * vf))
    scale = max(mv, h * float(np.linalg.norm(f0)), h * f_scale, TINY)
    floor = roundoff_floor(mv + h * magnitude) if magnitude is not None else None
    threshold = convergence_threshold(tol, scale, floor)

    def residual(w):
        xt = x.copy()
        xt[free] += h * w
        stats["n_force_evals"] += 1
        f = np.asarray(problem.force(xt, load), dtype=float)[free]
        R = mf * (w - vf) - h * (f - alpha * mf * w)
        if beta:
            R = R + h * beta * (submatrix(problem.stiffness(xt, load), free, plans=solver_context) @ w)
        return R, xt

    w = vf.copy()
    R, xt = residual(w)
    rn = float(np.linalg.norm(R))
    it = 0
    while not (rn <= threshold):
        if it >= max_iter or not np.isfinite(rn):
            raise ConvergenceError(
                f"implicit Euler Newton iteration did not converge at step {step}, t = {t_new:.6g} s: "
                f"iteration {it}, residual {rn:.3e} (threshold {threshold:.3e}, round-off floor "
                f"{floor_text(floor)})",
                iteration=it, residual=rn, x_last=x.copy(), step=step, time=t_new, load=load)
        it += 1
        K = submatrix(problem.stiffness(xt, load), free, plans=solver_context)
        J = sp.diags(mf * (1.0 + h * alpha)) + (h * h + h * beta) * K
        try:
            dw = solve_linear_system(sp.csr_matrix(J), -R, linear_solver, symmetric, messages, solver_context)
        except protocol.NewtonFailure as exc:
            raise ConvergenceError(
                f"implicit Euler linear solve failed at step {step}, t = {t_new:.6g} s, iteration {it}: {exc}",
                iteration=it, residual=rn, x_last=x.copy(), step=step, time=t_new, load=load) from None
        stats["n_linear_solves"] += 1
        lam = 1.0
        for _ in range(MAX_BACKTRACKS + 1):
            Rt, xtt = residual(w + lam * dw)
            rtn = float(np.linalg.norm(Rt))
            if np.isfinite(rtn) and rtn <= (1.0 - ARMIJO_C * lam) * rn:
                break
            lam *= 0.5
        else:
            raise ConvergenceError(
                f"implicit Euler line search failed at step {step}, t = {t_new:.6g} s, iteration {it}, "
                f"residual {rn:.3e} (threshold {threshold:.3e}, round-off floor {floor_text(floor)})",
                iteration=it, residual=rn, x_last=x.copy(), step=step, time=t_new, load=load)
        w = w + lam * dw
        R, xt, rn = Rt, xtt, rtn
    stats["n_newton_iterations"] += it
    return w


def _limit_hint(dt, limit):
    """The at-rest stability limit, as the hint of a divergence message ('' for implicit Euler)."""
    if limit is None:
        return ""
    ratio = dt / limit if limit > 0 else float("inf")
    hint = (f"; dt = {dt:.7g} s is {ratio:.3g} x the explicit stability limit {limit:.7g} s of the model "
            f"at rest (computed before the run)")
    if ratio <= 1.0:
        hint += (": within it, so the deformation made the run unstable (a stiffer deformed state, or "
                 "energy pumped into the top modes by the non-linearity); reduce dt or use implicit_euler")
    return hint


def _raise_growth(x, x_ref, step, t, dt, method, x_prev, v_prev, limit, growth, flips):
    disp = np.abs(x - x_ref)
    dof = int(np.argmax(disp))
    how = "while the force flips sign from step to step" if flips >= 1 else "without the force flipping sign"
    raise DivergenceError(
        f"{method} diverged: the energy of the velocity and acceleration fields (v.K v + a.M a, constant "
        f"in a stable run) grew {growth:.3g}-fold {how}, the explicit instability, at step {step}, "
        f"t = {t:.6g} s, max |u| = {disp[dof]:.3e} m{_limit_hint(dt, limit)}",
        step=step, time=t, quantity="growth", dof=dof, value=float(growth), x_last=x_prev, v_last=v_prev,
        dt=dt, stability_limit=limit, max_displacement=float(disp[dof]))


def _check_state(problem, x, v, x_ref, bound, step, t, dt, method, x_prev, v_prev, limit=None):
    """Raise DivergenceError if x or v is non-finite or the displacement exceeds ``bound``;
    ``limit`` (the at-rest stability limit of an explicit run, or None) goes into the message."""
    quantity = None
    if not np.all(np.isfinite(v)):
        dof = int(np.flatnonzero(~np.isfinite(v))[0])
        quantity, value = "velocity", v[dof]
    elif not np.all(np.isfinite(x)):
        dof = int(np.flatnonzero(~np.isfinite(x))[0])
        quantity, value = "position", x[dof]
    else:
        disp = np.abs(x - x_ref)
        dof = int(np.argmax(disp))
        if disp[dof] > bound:
            quantity, value = "displacement", x[dof] - x_ref[dof]
    if quantity is None:
        return
    if quantity == "displacement":
        what = f"displacement of dof {dof} = {value:.3e} exceeds the bound {bound:.3e}"
    else:
        what = f"{quantity} of dof {dof} = {value}"
    with np.errstate(all="ignore"):
        umax = float(np.nanmax(np.abs(np.ravel(x_prev) - x_ref))) if x_prev is not None and np.size(x_prev) else 0.0
    raise DivergenceError(
        f"{method} diverged: {what} at step {step}, t = {t:.6g} s{_limit_hint(dt, limit)}",
        step=step, time=t, quantity=quantity, dof=dof, value=float(value), x_last=x_prev, v_last=v_prev,
        dt=dt, stability_limit=limit, max_displacement=umax,
    )

"""The problem protocol (see :mod:`msslib.solvers`): reading a problem, the results, the force
scale ``F_ref`` of the convergence test."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

TINY = np.finfo(float).tiny


@dataclass
class StaticResult:
    """Outcome of :func:`static_solve`.

    ``converged`` is always True in a returned result (failures raise :class:`ConvergenceError`).
    ``iterations[i]``, ``residuals[i]`` and ``loads[i]`` belong to the i-th *accepted* load step;
    ``residuals[i]`` lists the absolute free-dof residual norms, starting with the one of the
    initial guess of that step. ``force_scale`` is ``F_ref`` of the convergence criterion,
    ``roundoff_floor`` the round-off floor and ``threshold = max(tol * F_ref, roundoff_floor)``;
    ``roundoff_steps`` lists the load steps (1-based) accepted at the floor, above ``tol * F_ref``
    (each with a line in ``messages``).
    ``cg_iterations`` counts the preconditioned CG iterations of all linear solves (0 when only
    direct solves were used).
    """

    x: np.ndarray
    converged: bool
    iterations: list[int]
    residuals: list[list[float]]
    loads: list[float]
    wall_time: float
    n_load_steps: int
    n_cuts: int
    force_scale: float
    line_search_merit: str
    messages: list[str] = field(default_factory=list)
    cg_iterations: int = 0
    tol: float = float("nan")
    roundoff_floor: float = float("nan")
    threshold: float = float("nan")
    roundoff_steps: list[int] = field(default_factory=list)

    @property
    def total_iterations(self) -> int:
        return int(sum(self.iterations))


@dataclass
class DynamicResult:
    """Outcome of :func:`integrate`.

    ``t`` has shape ``(n_saved,)``; ``x`` and ``v`` have shape ``(n_saved, n_dof)``. The initial
    state and the final state are always saved. ``kinetic_energy`` is saved alongside;
    ``potential_energy`` too when ``problem.energy`` is not None (else it is None).
    ``stats`` holds ``n_steps``, ``dt``, ``method``, ``n_force_evals``, ``n_newton_iterations``,
    ``n_linear_solves``, ``wall_time`` and ``damping`` (alpha, beta).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    x_final: np.ndarray
    v_final: np.ndarray
    kinetic_energy: np.ndarray
    potential_energy: np.ndarray | None
    stats: dict


class NewtonFailure(Exception):
    """Internal: a Newton iteration could not proceed (reason in the message)."""


def free_mask(problem) -> np.ndarray:
    n = int(problem.n_dof)
    free = getattr(problem, "free", None)
    if free is None:
        return np.ones(n, dtype=bool)
    free = np.asarray(free, dtype=bool)
    if free.shape != (n,):
        raise ValueError(f"problem.free must have shape ({n},), got {free.shape}")
    return free


def _with_prescribed(problem, x, load):
    fn = getattr(problem, "apply_prescribed", None)
    if fn is None:
        return x
    return np.array(fn(np.array(x, dtype=float), load), dtype=float)


def energy_or_none(problem, x, load):
    fn = getattr(problem, "energy", None)
    if fn is None:
        return None
    e = fn(x, load)
    return None if e is None else float(e)


def is_conservative(problem, x, load) -> bool:
    return energy_or_none(problem, x, load) is not None


def _accepts_out(problem) -> bool:
    """Whether ``problem.stiffness`` takes ``out=`` (refill a matrix it returned earlier)."""
    import inspect

    try:
        return "out" in inspect.signature(problem.stiffness).parameters
    except (TypeError, ValueError):
        return False


def load_vector(problem, x0):
    """The load-proportional force at ``x0``: ``force(x0, 1) - force(x0, 0)`` (all dofs)."""
    with np.errstate(all="ignore"):
        return np.asarray(problem.force(x0, 1.0), dtype=float) - np.asarray(problem.force(x0, 0.0), dtype=float)


def reference_force_scale(problem, x0, free, f_ext=None):
    """``F_ref`` of the convergence criterion (module docstring); ``f_ext`` the load vector if known."""
    if f_ext is None:
        f_ext = load_vector(problem, x0)
    s = float(np.linalg.norm(f_ext[free]))
    if np.isfinite(s) and s > TINY:
        return s
    xp = _with_prescribed(problem, x0, 1.0)
    # displacement control: the linear force of the prescribed motion, K(x0) (xp - x0), is a scale
    # that stays finite even when the prescribed state happens to be force-free (e.g. a mirror image)
    with np.errstate(all="ignore"):
        s = float(np.linalg.norm(problem.stiffness(x0, 1.0) @ (xp - x0)))
    if np.isfinite(s) and s > TINY:
        return s
    with np.errstate(all="ignore"):
        s = float(np.linalg.norm(np.asarray(problem.force(xp, 1.0), dtype=float)))
    if np.isfinite(s) and s > TINY:
        return s
    return 1.0

"""Generic static and dynamic solvers for discrete mechanical systems (mass-spring networks, FEM).

The solvers know nothing about springs or elements: they talk to a *problem* object through the
duck-typed protocol below. Any object providing these attributes works.

Problem protocol
----------------
``n_dof`` : int
    Number of degrees of freedom. The state ``x`` is a flat float array of node positions,
    ``n_nodes * dim`` long, interleaved by node (``x[dim * i + a]`` is coordinate ``a`` of node ``i``).
``force(x, load=1.0)`` -> ndarray ``(n_dof,)``
    Total force on every dof: internal forces plus ``load`` times the external forces. Internal
    forces may contain non-conservative terms that depend on ``load`` (follower or circulatory
    forces), so the result depends on ``load`` and not only on ``x``.
``stiffness(x, load=1.0)`` -> scipy.sparse matrix ``(n_dof, n_dof)``
    Tangent stiffness ``K = -d force / d x`` at the same load. May be non-symmetric. Optionally
    with ``out=``: refill a matrix returned by an earlier call in place.
``stiffness_blocks(x, load=1.0, out=None, node_free=None)`` -> BSR matrix or None, optional
    The rows and columns of ``K`` of the nodes ``node_free`` as ``dim x dim`` node blocks. When
    present (and not None), Newton systems solved by AMG-preconditioned CG are taken from it and
    the full tangent is not formed.
``energy(x, load=1.0)`` -> float or None
    Total potential energy (internal energy minus ``load`` times the work of the external forces),
    so that ``force = -grad energy``. Return ``None`` when the system is not conservative; the
    line search then works on the residual norm instead of the energy.
``free`` : bool ndarray ``(n_dof,)``
    Mask of the unconstrained dofs. Constrained dofs keep the value they have in ``x``.
``symmetric`` : bool, optional (default True)
    False when ``stiffness`` may be non-symmetric; the iterative (CG) linear solver is then used
    only for a tangent found symmetric to round-off (:func:`msslib.solvers.policy.as_symmetric`).
``apply_prescribed(x, load)`` -> ndarray, optional
    Returns a copy of ``x`` whose constrained dofs are set to their prescribed value at load
    factor ``load`` (prescribed motions scaled by the load). Without it, constrained dofs simply
    keep their value from ``x0``. Only :func:`static_solve` uses it.
``mass`` : ndarray ``(n_dof,)``
    Lumped masses (one value per dof; repeat a node's mass for each of its coordinates). Only the
    dynamics needs it.
``damping`` : float or (alpha, beta), optional
    Default damping for :func:`msslib.stepping.integrate`: a scalar is a mass-proportional coefficient ``alpha``;
    a pair is Rayleigh damping ``C = alpha * M + beta * K``.
``dim`` : int, optional
    Spatial dimension: the bounding box of the divergence check, and the node blocks (with the
    rigid-body modes) of the AMG preconditioner when the free dofs are whole nodes.
``force_magnitude(x, load)`` -> ndarray ``(n_dof,)``, optional
    The per-dof size of what the force sums, for the round-off floor (below); when present the
    floor is taken from it at every Newton iterate instead of from ``|K| |x| + |f_ext|`` once.

A static solve keeps its linear-solver state (plans of the free-dof submatrices and band
orderings, the AMG hierarchy, the matrix of the Newton systems) in a
:class:`~msslib.solvers.context.SolverContext` that the problem itself keeps for its next solve
(an attribute; a problem that takes none keeps nothing).

Static solution
---------------
:func:`static_solve` runs Newton's method with the analytic stiffness on the free dofs, with a
backtracking line search, and increases the load factor from 0 to 1 in ``load_steps`` equal steps,
halving a step (up to ``max_cuts`` times in a row, never below ``1 / (load_steps 2^max_cuts)``)
whenever its Newton iteration fails, and doubling it again (up to the nominal step) after each
converged one.

Convergence criterion. With ``r = force(x, load)[free]``, a load step has converged when::

    ||r||_2 <= max(tol * F_ref, floor)

where ``F_ref``, the physical force scale, is computed once, at the start:

1. ``force_scale`` if the caller passes it; otherwise
2. ``||f_ext[free]||_2`` with ``f_ext = force(x0, 1) - force(x0, 0)`` (the load-proportional
   force at the initial state, i.e. the external load), if it is larger than the smallest normal
   float (``numpy.finfo(float).tiny``); otherwise (pure displacement control)
3. ``||K(x0) (apply_prescribed(x0, 1) - x0)||_2`` (the linear reaction of the prescribed motion),
   if nonzero; else ``||force(apply_prescribed(x0, 1), 1)||_2`` over *all* dofs, if nonzero;
4. else 1.0 (an absolute criterion).

and ``floor`` is the round-off floor of the forces (:func:`roundoff_floor`)::

    floor = ROUNDOFF_FACTOR * eps * || |K| |x| + |f_ext| ||_2   (free dofs, ROUNDOFF_FACTOR = 1)

``|K| |x|`` (entrywise absolute tangent times absolute positions) is the size of what the forces
sum: they are computed from absolute positions, and rounding the positions by ``eps`` changes
them by about ``eps |K| |x|``.  A Newton iteration driven to stagnation stalls at 0.04 to 0.11 x
this (measured on Golec, Baudet and Lloyd models and, with their magnitude below, on the FEM
references), so the floor is reached and nothing below it is resolvable: an unloaded problem
converges at once (0 iterations), and a stiff or slender body whose ``tol * F_ref`` lies below
the round-off (a 1 m beam in SI units under its own weight) converges at the floor instead of
failing.  The floor is computed once per solve, from the first tangent the Newton iteration
assembles (no extra assembly; one ``|K| |x|`` product, 1-2 % of a solve).  A load step accepted
at the floor, above ``tol * F_ref``, is listed in ``StaticResult.roundoff_steps`` with a
"converged to round-off" line in ``messages``; a residual above the floor is never accepted (the
failure message then gives both numbers).  The FEM references (:func:`msslib.fem.solve_nonlinear`) are
solved by the same Newton iteration (:mod:`msslib.solvers.displacement`), with
``|| |K| |u| + sum |f_e| + |f_ext| ||`` at each iterate as the magnitude (``force_magnitude``).

The same absolute threshold is used at every load level.

Dynamics
--------
:func:`msslib.stepping.integrate` advances ``M dv/dt = force(x, load) - C v`` with symplectic Euler, velocity
Verlet or implicit Euler. Constrained dofs keep their initial position and have zero velocity.
An explicit run first checks its step against the stability limit of the model at rest
(:func:`check_time_step`: ``2 / omega_max``, lowered by the damping where it does,
:func:`critical_time_step`; ``omega_max`` from a cheap bound when the step is within the limit
it gives -- on 3D spring models the first pass of :func:`directional_bound`, else Gershgorin's
:func:`omega_max_bound` --, on spring models from a few more passes of the directional bound or a
certified short Lanczos run, else from Lanczos, :func:`explicit_stability_limit`, kept for a
model and state that did not change) and refuses a larger ``dt`` with
:class:`msslib.errors.StabilityError` unless ``allow_unstable=True``. After every step the state
is checked: a non-finite velocity, a displacement ``max |x - x0|`` beyond ``blowup * size``
(``size`` the bounding-box diagonal of ``x0``), or, for the explicit schemes, the signature of
the explicit instability (the force flipping sign from step to step while ``a.M a + v.K v``, the
energy of the time derivative of the motion, grows far beyond what a stable step allows) raises
:class:`DivergenceError`, whose message names the at-rest limit.

Modules (each imports only those above it)
-------------------------------------------
:mod:`~msslib.solvers.protocol` (reading a problem, results, ``F_ref``),
:mod:`~msslib.solvers.memo` (the process-wide memo of plans), :mod:`~msslib.solvers.submatrices`
(free-dof submatrices by cached plans, :class:`PlanCache`),
:mod:`~msslib.solvers.amg_kernels`, :mod:`~msslib.solvers.amg_cycle`, :mod:`~msslib.solvers.amg`
(smoothed-aggregation AMG: compiled kernels, V-cycle, set-up),
:mod:`~msslib.solvers.direct` (banded Cholesky / LU, SuperLU),
:mod:`~msslib.solvers.policy` (the choice of the linear solver, :func:`choose_linear_solver`),
:mod:`~msslib.solvers.linear` (the linear solves), :mod:`~msslib.solvers.context` (solver
contexts), :mod:`~msslib.solvers.roundoff` (the convergence test), :mod:`~msslib.solvers.statics`
(:func:`static_solve`), :mod:`~msslib.solvers.displacement` (the FEM references through
:func:`static_solve`), :mod:`~msslib.solvers.certificate` and
:mod:`~msslib.solvers.directional` (the stability check's bounds and certificates),
:mod:`~msslib.solvers.stability` (explicit stability limit).  Time
stepping (:func:`msslib.stepping.integrate`, the :class:`~msslib.stepping.Simulator`) builds on
these in :mod:`msslib.stepping`.  :class:`ConvergenceError` and
:class:`DivergenceError` are defined in :mod:`msslib.errors`.
"""

from __future__ import annotations

from msslib.errors import ConvergenceError, DivergenceError

from . import (  # noqa: F401 - the modules, for monkeypatching where a name is looked up
    amg,
    amg_cycle,
    amg_kernels,
    context,
    direct,
    displacement,
    linear,
    policy,
    protocol,
    roundoff,
    stability,
    statics,
    submatrices,
)
from .amg_cycle import VCYCLE_SINGLE  # noqa: F401
from .context import SolverContext  # noqa: F401
from .direct import BAND_COST_MAX, BAND_PLAN_MAX_DOFS  # noqa: F401
from .submatrices import PlanCache  # noqa: F401
from .policy import BAND_AUTO_COST, ITERATIVE_THRESHOLD, choose_linear_solver  # noqa: F401
from .protocol import DynamicResult, StaticResult
from .roundoff import EPS, ROUNDOFF_FACTOR, convergence_threshold, roundoff_floor, roundoff_note  # noqa: F401
from .directional import directional_bound
from .stability import (  # noqa: F401
    EXPLICIT_METHODS,
    check_time_step,
    critical_time_step,
    explicit_stability_limit,
    omega_max_bound,
)
from .statics import static_solve

__all__ = [
    "ConvergenceError",
    "DivergenceError",
    "DynamicResult",
    "StaticResult",
    "check_time_step",
    "choose_linear_solver",
    "convergence_threshold",
    "critical_time_step",
    "directional_bound",
    "explicit_stability_limit",
    "omega_max_bound",
    "roundoff_floor",
    "static_solve",
]

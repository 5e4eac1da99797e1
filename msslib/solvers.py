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
    False when ``stiffness`` is non-symmetric; the iterative (CG) linear solver is then never used.
``apply_prescribed(x, load)`` -> ndarray, optional
    Returns a copy of ``x`` whose constrained dofs are set to their prescribed value at load
    factor ``load`` (prescribed motions scaled by the load). Without it, constrained dofs simply
    keep their value from ``x0``. Only :func:`static_solve` uses it.
``mass`` : ndarray ``(n_dof,)``
    Lumped masses (one value per dof; repeat a node's mass for each of its coordinates). Only the
    dynamics needs it.
``damping`` : float or (alpha, beta), optional
    Default damping for :func:`integrate`: a scalar is a mass-proportional coefficient ``alpha``;
    a pair is Rayleigh damping ``C = alpha * M + beta * K``.
``dim`` : int, optional
    Spatial dimension: the bounding box of the divergence check, and the node blocks (with the
    rigid-body modes) of the AMG preconditioner when the free dofs are whole nodes.

Static solution
---------------
:func:`static_solve` runs Newton's method with the analytic stiffness on the free dofs, with a
backtracking line search, and increases the load factor from 0 to 1 in ``load_steps`` equal steps,
halving a step (up to ``max_cuts`` times) whenever its Newton iteration fails.

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
failure message then gives both numbers).  The FEM references (:func:`msslib.fem.solve_nonlinear`) use
the same test (:func:`convergence_threshold`) with their own ``F_ref`` and
``|| |K| |u| + sum |f_e| + |f_ext| ||`` as the magnitude.

The same absolute threshold is used at every load level.

Dynamics
--------
:func:`integrate` advances ``M dv/dt = force(x, load) - C v`` with symplectic Euler, velocity
Verlet or implicit Euler. Constrained dofs keep their initial position and have zero velocity.
An explicit run first computes the stability limit of the model at rest (:func:`check_time_step`:
``2 / omega_max`` from :func:`explicit_stability_limit`, lowered by the damping where it does,
:func:`critical_time_step`) and refuses a larger ``dt`` with
:class:`msslib.errors.StabilityError` unless ``allow_unstable=True``. After every step the state
is checked: a non-finite velocity, a displacement ``max |x - x0|`` beyond ``blowup * size``
(``size`` the bounding-box diagonal of ``x0``), or, for the explicit schemes, the signature of
the explicit instability (the force flipping sign from step to step while ``a.M a + v.K v``, the
energy of the time derivative of the motion, grows far beyond what a stable step allows) raises
:class:`DivergenceError`, whose message names the at-rest limit.
"""

from __future__ import annotations

import threading
import time
import warnings
import weakref
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from msslib.blas_threads import BLOCKED_BANDWIDTH, one_blas_thread

__all__ = [
    "ConvergenceError",
    "DivergenceError",
    "StaticResult",
    "DynamicResult",
    "static_solve",
    "integrate",
    "explicit_stability_limit",
    "critical_time_step",
    "check_time_step",
    "roundoff_floor",
    "convergence_threshold",
]

TINY = np.finfo(float).tiny
ITERATIVE_THRESHOLD = 2_000  # free dofs above which "auto" may use preconditioned CG (symmetric)
BAND_AUTO_COST = 1.5e8  # ... unless the banded Cholesky costs at most this n (b + 1)^2
BAND_PLAN_MAX_DOFS = 50_000  # no bandwidth-reducing ordering is computed above this size
# Measured on the gravity-loaded Golec cube lattice (benchmarks/statics.py), single thread, whole
# static solves: 1944 dofs banded Cholesky 0.033 s vs AMG-CG 0.040 s; 3630 dofs SuperLU 0.44 s
# (banded too wide) vs AMG-CG 0.083 s; 6084 dofs 1.37 s vs 0.16 s.  SuperLU's fill grows like
# n^(4/3..2) in 3D; slender bodies keep a narrow band and stay direct.


class ConvergenceError(RuntimeError):
    """Newton's method failed (static load step or implicit time step).

    Attributes ``load_step``, ``load``, ``iteration``, ``residual`` (absolute free-dof residual
    norm), ``x_last`` (the last converged state, finite) and, for dynamics, ``step`` and ``time``.
    """

    def __init__(self, message, *, load_step=None, load=None, iteration=None, residual=None,
                 x_last=None, step=None, time=None):
        super().__init__(message)
        self.load_step = load_step
        self.load = load
        self.iteration = iteration
        self.residual = residual
        self.x_last = x_last
        self.step = step
        self.time = time


class DivergenceError(RuntimeError):
    """A time integration blew up.

    Attributes ``step`` (index of the offending step, 1-based), ``time``, ``quantity``
    (``"position"``, ``"velocity"``, ``"displacement"`` or ``"growth"``: the explicit
    instability, ``value`` then the growth factor), ``dof``, ``value``, the last finite state
    ``x_last``, ``v_last`` (the state before the offending step), ``dt``, ``stability_limit`` (the
    limit of the model at rest computed before an explicit run; None for implicit Euler) and
    ``max_displacement`` (``max |x - x0|`` when it was stopped).
    """

    def __init__(self, message, *, step, time, quantity, dof, value, x_last=None, v_last=None, dt=None,
                 stability_limit=None, max_displacement=None):
        super().__init__(message)
        self.step = step
        self.time = time
        self.quantity = quantity
        self.dof = dof
        self.value = value
        self.x_last = x_last
        self.v_last = v_last
        self.dt = dt
        self.stability_limit = stability_limit
        self.max_displacement = max_displacement


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


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------

class _NewtonFailure(Exception):
    """Internal: a Newton iteration could not proceed (reason in the message)."""


def _free_mask(problem) -> np.ndarray:
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


def _energy_or_none(problem, x, load):
    fn = getattr(problem, "energy", None)
    if fn is None:
        return None
    e = fn(x, load)
    return None if e is None else float(e)


def _is_conservative(problem, x, load) -> bool:
    return _energy_or_none(problem, x, load) is not None


# Free-dof extraction plans, kept across calls (Newton iterations, time steps, repeated solves of
# the same problem): the positions in ``K.data`` of the free-free entries of a given sparsity
# pattern.  An entry is reused only for the very same pattern (the same index arrays, or equal
# ones) and free mask; it holds references to the pattern arrays, so their ids cannot be recycled.
_PLAN_CACHE: list = []
_PLAN_CACHE_SIZE = 4


def _same_readonly(a, b):
    """True when ``a`` and ``b`` are the same read-only memory (scipy wraps index arrays passed
    with ``copy=False`` in new views, so ``is`` is not enough).  The cache keeps ``a`` alive, so
    its address cannot be recycled; read-only memory cannot be changed behind our back."""
    return a is b or (not a.flags.writeable and not b.flags.writeable and a.dtype == b.dtype
                      and a.shape == b.shape and a.strides == b.strides
                      and a.__array_interface__["data"][0] == b.__array_interface__["data"][0])


def _pattern_key_matches(entry, K, free):
    if entry["shape"] != K.shape or entry["free_n"] != free.size:
        return False
    if _same_readonly(entry["indptr"], K.indptr) and _same_readonly(entry["indices"], K.indices):
        same = True
    else:
        same = (entry["indptr"].shape == K.indptr.shape and entry["indices"].shape == K.indices.shape
                and np.array_equal(entry["indptr"], K.indptr) and np.array_equal(entry["indices"], K.indices))
        if same:  # remember the new arrays: the next call is then an identity check
            entry["indptr"], entry["indices"] = K.indptr, K.indices
    return same and np.array_equal(entry["free"], free)


def _accepts_out(problem) -> bool:
    """Whether ``problem.stiffness`` takes ``out=`` (refill a matrix it returned earlier)."""
    import inspect

    try:
        return "out" in inspect.signature(problem.stiffness).parameters
    except (TypeError, ValueError):
        return False


@njit(cache=True, nogil=True)
def _plan_count(indptr, indices, free, sub_indptr):
    """Row pointers of the free-free block; returns its number of entries."""
    r = 0
    n = 0
    sub_indptr[0] = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            if free[indices[p]]:
                n += 1
        r += 1
        sub_indptr[r] = n
    return n


@njit(cache=True, nogil=True)
def _plan_fill(indptr, indices, free, new_index, sub_indices):
    """New column indices of the free-free entries."""
    n = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if free[j]:
                sub_indices[n] = new_index[j]
                n += 1


@njit(cache=True, nogil=True)
def _gather_free(indptr, indices, data, free, out):
    """Values of the free-free entries, row by row (walks the pattern with the free mask rather
    than storing their positions: one array fewer to allocate and touch per pattern)."""
    n = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            if free[indices[p]]:
                out[n] = data[p]
                n += 1


_U = np.uint64  # unsigned indices: numba then skips its wraparound test of negative ones


@njit(cache=True, nogil=True)
def _is_node_blocked(indptr, indices, dim):
    """Whether a CSR pattern (sorted indices) is made of whole ``dim x dim`` node blocks: the
    ``dim`` rows of every node have the same columns, which come in whole nodes."""
    n_nodes = (indptr.shape[0] - 1) // dim
    if n_nodes * dim != indptr.shape[0] - 1:
        return False
    for a in range(n_nodes):
        r0 = indptr[_U(dim * a)]
        L = indptr[_U(dim * a + 1)] - r0
        if L % dim != 0:
            return False
        for i in range(1, dim):
            if indptr[_U(dim * a + i + 1)] - indptr[_U(dim * a + i)] != L or indptr[_U(dim * a + i)] != r0 + i * L:
                return False
        for t in range(0, L, dim):
            c0 = indices[_U(r0 + t)]
            if c0 % dim != 0:
                return False
            for i in range(dim):
                for j in range(dim):
                    if indices[_U(r0 + i * L + t + j)] != c0 + j:
                        return False
    return True


@njit(cache=True, nogil=True)
def _bsr_plan(indptr, indices, node_free, new_node, dim, bptr, bind):
    """Block row pointers and block column indices of the free-free node blocks (``bind`` is
    filled when it is long enough); returns the number of blocks."""
    nb = 0
    r = 0
    bptr[0] = 0
    for a in range(node_free.shape[0]):
        if not node_free[a]:
            continue
        r0 = indptr[_U(dim * a)]
        L = indptr[_U(dim * a + 1)] - r0
        for t in range(0, L, dim):
            b = indices[_U(r0 + t)] // dim
            if node_free[_U(b)]:
                if nb < bind.shape[0]:
                    bind[_U(nb)] = new_node[_U(b)]
                nb += 1
        r += 1
        bptr[r] = nb
    return nb


@njit(cache=True, nogil=True)
def _gather_free_bsr(indptr, indices, data, node_free, dim, out):
    """Values of the free-free node blocks, block-major (BSR), from a node-blocked CSR."""
    k = 0
    for a in range(node_free.shape[0]):
        if not node_free[a]:
            continue
        r0 = indptr[_U(dim * a)]
        L = indptr[_U(dim * a + 1)] - r0
        for t in range(0, L, dim):
            if node_free[_U(indices[_U(r0 + t)] // dim)]:
                for i in range(dim):
                    q = r0 + i * L + t
                    for j in range(dim):
                        out[_U(k), _U(i), _U(j)] = data[_U(q + j)]
                k += 1


def _submatrix_bsr(K, node_free, dim, out=None):
    """Free-free block of a node-blocked CSR ``K`` (sorted indices, canonical) as a BSR matrix
    of ``dim x dim`` blocks, or None when ``K`` is not node-blocked.

    The block index arrays are computed once per pattern and node mask.  AMG works on the node
    blocks anyway: gathering them straight from ``K`` skips the free-free CSR (values and
    indices) and its conversion to BSR (three arrays of the size of ``K`` fewer to allocate and
    fill per solve).  ``out``: an earlier result for the same pattern and mask, whose values are
    overwritten (and which is returned)."""
    if not (sp.issparse(K) and K.format == "csr" and K.has_canonical_format) or K.shape[0] != K.shape[1]:
        return None
    entry = _bsr_entry(K, node_free, dim)
    if entry is None:
        return None
    node_free = entry["free"]
    if (out is not None and sp.issparse(out) and out.format == "bsr"
            and _same_readonly(out.indices, entry["bind"]) and out.data.shape == (entry["nblocks"], dim, dim)
            and out.data.dtype == K.data.dtype and out.data.flags.writeable):
        _gather_free_bsr(K.indptr, K.indices, K.data, node_free, dim, out.data)
        return out
    vals = np.empty((entry["nblocks"], dim, dim), dtype=K.data.dtype)
    _gather_free_bsr(K.indptr, K.indices, K.data, node_free, dim, vals)
    A = sp.bsr_matrix((vals, entry["bind"], entry["bptr"]), shape=entry["sub_shape"], copy=False)
    A.has_sorted_indices = True
    return A


def _bsr_entry(K, node_free, dim):
    """The cached free-node block plan of ``K`` (see :func:`_submatrix_bsr`), or None."""
    if not (sp.issparse(K) and K.format == "csr" and K.has_canonical_format) or K.shape[0] != K.shape[1]:
        return None
    node_free = np.asarray(node_free, dtype=bool)
    if K.shape[0] != dim * node_free.size:
        return None
    key = ("bsr", dim)
    entry = None
    for i, e in enumerate(_PLAN_CACHE):
        if e.get("kind") == key and _pattern_key_matches(e, K, node_free):
            entry = e
            break
    if entry is None:
        if not _is_node_blocked(K.indptr, K.indices, dim):
            entry = {"kind": key, "shape": K.shape, "free_n": node_free.size, "free": node_free.copy(),
                     "indptr": K.indptr, "indices": K.indices, "blocked": False}
        else:
            idx_t = np.int32 if K.nnz < 2**31 else np.int64
            new_node = (np.cumsum(node_free) - 1).astype(idx_t)
            n_free = int(node_free.sum())
            bptr = np.empty(n_free + 1, dtype=idx_t)
            nb = _bsr_plan(K.indptr, K.indices, node_free, new_node, dim, bptr, np.empty(0, dtype=idx_t))
            bind = np.empty(nb, dtype=idx_t)
            _bsr_plan(K.indptr, K.indices, node_free, new_node, dim, bptr, bind)
            bptr.flags.writeable = False
            bind.flags.writeable = False
            entry = {"kind": key, "shape": K.shape, "free_n": node_free.size, "free": node_free.copy(),
                     "indptr": K.indptr, "indices": K.indices, "blocked": True, "bptr": bptr,
                     "bind": bind, "nblocks": nb, "sub_shape": (dim * n_free, dim * n_free)}
        _PLAN_CACHE.insert(0, entry)
        del _PLAN_CACHE[_PLAN_CACHE_SIZE:]
    return entry if entry["blocked"] else None


@njit(cache=True, nogil=True)
def _eccentricity(ptr, ind):
    """Largest breadth-first distance from node 0 of the graph ``(ptr, ind)``; -1 when some
    node is not reached."""
    n = ptr.shape[0] - 1
    if n == 0:
        return 0
    depth = np.full(n, -1, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    depth[0] = 0
    queue[0] = 0
    head, tail = 0, 1
    while head < tail:
        a = queue[head]
        head += 1
        for p in range(ptr[a], ptr[a + 1]):
            b = ind[p]
            if depth[b] < 0:
                depth[b] = depth[a] + 1
                queue[tail] = b
                tail += 1
    if tail < n:
        return -1
    return depth[queue[tail - 1]]


def _band_surely_wide(entry, dim) -> bool:
    """True when no ordering can make the banded Cholesky cheap, from a bound that costs one
    breadth-first search: a graph of ``n`` vertices and diameter ``D`` has bandwidth at least
    ``(n - 1) / D``, and ``D <= 2 e`` for the eccentricity ``e`` of any vertex (the dofs of a
    node are neighbours, so the dof graph has the diameter of the node graph).  Spares compact
    bodies the bandwidth-reducing orderings, which cost more than the whole solve there."""
    e = int(_eccentricity(entry["bptr"], entry["bind"]))
    if e <= 0:
        return False
    n = dim * (len(entry["bptr"]) - 1)
    b = (n - 1) / (2.0 * e)
    return n * (b + 1.0) ** 2 > BAND_AUTO_COST


def _submatrix_plan(K, free):
    for i, entry in enumerate(_PLAN_CACHE):
        if entry.get("kind") is None and _pattern_key_matches(entry, K, free):
            if i:
                _PLAN_CACHE.insert(0, _PLAN_CACHE.pop(i))
            return entry
    n_free = int(free.sum())
    idx_t = np.int32 if K.nnz < 2**31 else np.int64
    new_index = (np.cumsum(free) - 1).astype(idx_t)  # increasing: sorted rows stay sorted
    sub_indptr = np.empty(n_free + 1, dtype=idx_t)
    n_keep = _plan_count(K.indptr, K.indices, free, sub_indptr)
    sub_indices = np.empty(n_keep, dtype=idx_t)
    _plan_fill(K.indptr, K.indices, free, new_index, sub_indices)
    entry = {"shape": K.shape, "free_n": free.size, "free": free.copy(), "indptr": K.indptr,
             "indices": K.indices, "nnz": n_keep, "sub_indptr": sub_indptr, "sub_indices": sub_indices,
             "sub_shape": (n_free, n_free)}
    entry["sub_indptr"].flags.writeable = False
    entry["sub_indices"].flags.writeable = False
    _PLAN_CACHE.insert(0, entry)
    del _PLAN_CACHE[_PLAN_CACHE_SIZE:]
    return entry


def _submatrix(K, free, out=None):
    """Free-free block of ``K`` (CSR, sorted indices).  For a canonical CSR input the index arrays
    of the block are computed once per sparsity pattern and reused (each call only gathers the
    values), and the returned matrices share these (read-only) index arrays.  ``out``: an earlier result
    for the same pattern and mask, whose values are overwritten (and which is returned)."""
    if not (sp.issparse(K) and K.format == "csr"):
        K = sp.csr_matrix(K)
    if free.all():
        return K
    if not K.has_canonical_format:
        K = K.copy()
        K.sum_duplicates()
    if K.shape[0] != K.shape[1]:
        idx = np.flatnonzero(free)
        return sp.csr_matrix(K[idx][:, idx])
    plan = _submatrix_plan(K, free)
    if (out is not None and _same_readonly(out.indices, plan["sub_indices"])
            and out.data.shape == (plan["nnz"],) and out.data.dtype == K.data.dtype
            and out.data.flags.writeable):
        _gather_free(K.indptr, K.indices, K.data, free, out.data)
        return out
    vals = np.empty(plan["nnz"], dtype=K.data.dtype)
    _gather_free(K.indptr, K.indices, K.data, free, vals)
    A = sp.csr_matrix((vals, plan["sub_indices"], plan["sub_indptr"]),
                      shape=plan["sub_shape"], copy=False)
    A.has_sorted_indices = True
    A.has_canonical_format = True
    return A


def _cg(A, b, M, rtol, maxiter):
    try:
        return spla.cg(A, b, rtol=rtol, atol=0.0, M=M, maxiter=maxiter)
    except TypeError:  # scipy < 1.12 spells it tol
        return spla.cg(A, b, tol=rtol, atol=0.0, M=M, maxiter=maxiter)


_IC0_KERNELS = None


def _ic0_kernels():
    """Compile (lazily, with numba when available) the IC(0) factorisation and triangular solves."""
    global _IC0_KERNELS
    if _IC0_KERNELS is not None:
        return _IC0_KERNELS

    def factor(indptr, indices, data, n):
        # In place on the lower triangle (CSR, sorted indices, diagonal last in each row).
        # Returns -1 on success or the row index where a non-positive pivot appeared.
        for i in range(n):
            a, b = indptr[i], indptr[i + 1]
            for p in range(a, b - 1):
                k = indices[p]
                s = data[p]
                # dot product of rows i and k over columns j < k
                q, r = a, indptr[k]
                rend = indptr[k + 1] - 1
                while q < p and r < rend:
                    jq, jr = indices[q], indices[r]
                    if jq == jr:
                        s -= data[q] * data[r]
                        q += 1
                        r += 1
                    elif jq < jr:
                        q += 1
                    else:
                        r += 1
                data[p] = s / data[indptr[k + 1] - 1]
            d = data[b - 1]
            for p in range(a, b - 1):
                d -= data[p] * data[p]
            if not d > 0.0:
                return i
            data[b - 1] = np.sqrt(d)
        return -1

    def solve(indptr, indices, data, n, rhs):
        y = rhs.copy()
        for i in range(n):  # L y = rhs
            a, b = indptr[i], indptr[i + 1]
            s = y[i]
            for p in range(a, b - 1):
                s -= data[p] * y[indices[p]]
            y[i] = s / data[b - 1]
        for i in range(n - 1, -1, -1):  # L^T z = y
            a, b = indptr[i], indptr[i + 1]
            y[i] /= data[b - 1]
            zi = y[i]
            for p in range(a, b - 1):
                y[indices[p]] -= data[p] * zi
        return y

    try:
        import numba

        factor = numba.njit(cache=False)(factor)
        solve = numba.njit(cache=False)(solve)
    except ImportError:  # pure Python: correct, but slow
        pass
    _IC0_KERNELS = (factor, solve)
    return _IC0_KERNELS


def _ic0_preconditioner(A):
    """Incomplete Cholesky IC(0) of an SPD matrix as a LinearOperator; on breakdown the diagonal
    is shifted, ``A + shift * diag(A)``, with the shift grown until the factorisation succeeds."""
    factor, solve = _ic0_kernels()
    A = sp.csr_matrix(A)
    lower = sp.tril(A, format="csr")
    lower.sum_duplicates()
    lower.sort_indices()
    n = A.shape[0]
    diag = A.diagonal()
    if np.any(diag <= 0):
        raise ValueError("IC(0) needs a positive diagonal")
    indptr = lower.indptr.astype(np.int64)
    indices = lower.indices.astype(np.int64)
    if np.any(indices[indptr[1:] - 1] != np.arange(n)):
        raise ValueError("IC(0) needs a structurally nonzero diagonal")
    shift = 0.0
    for _ in range(12):
        data = lower.data.astype(float).copy()
        data[indptr[1:] - 1] += shift * diag
        if factor(indptr, indices, data, n) < 0:
            return spla.LinearOperator(A.shape, matvec=lambda b: solve(indptr, indices, data, n, np.asarray(b, dtype=float).ravel()),
                                       dtype=float)
        shift = 1e-3 if shift == 0.0 else 4.0 * shift
    raise ValueError("IC(0) broke down even with a diagonal shift")


def _rigid_body_modes(coords, dim):
    """Near-null space of elasticity on free nodes: ``dim`` translations and the rotations about
    the centroid, ``(n_nodes * dim, 3 | 6)``, dofs interleaved by node."""
    c = coords - coords.mean(axis=0)
    nn = len(c)
    if dim == 2:
        B = np.zeros((2 * nn, 3))
        B[0::2, 0] = B[1::2, 1] = 1.0
        B[0::2, 2], B[1::2, 2] = -c[:, 1], c[:, 0]
        return B
    B = np.zeros((3 * nn, 6))
    B[0::3, 0] = B[1::3, 1] = B[2::3, 2] = 1.0
    B[1::3, 3], B[2::3, 3] = -c[:, 2], c[:, 1]
    B[0::3, 4], B[2::3, 4] = c[:, 2], -c[:, 0]
    B[0::3, 5], B[1::3, 5] = -c[:, 1], c[:, 0]
    scale = np.abs(B[:, dim:]).max()
    if scale > 0:
        B[:, dim:] /= scale
    return B


_SA_SMOOTHERS = (("block_gauss_seidel", {"sweep": "forward", "iterations": 1}),
                 ("block_gauss_seidel", {"sweep": "backward", "iterations": 1}))
_SA_OPTIONS = dict(strength=("symmetric", {"theta": 0.0}),
                   smooth=("jacobi", {"omega": 4.0 / 3.0, "weighting": "block"}), improve_candidates=None,
                   max_coarse=500, coarse_solver="splu", presmoother=_SA_SMOOTHERS[0],
                   postsmoother=_SA_SMOOTHERS[1])


@njit(cache=True, nogil=True)
def _block_diag_inverse(indptr, indices, data):
    """Inverses of the diagonal blocks of a square BSR matrix, ``(n_block_rows, d, d)`` (NaN
    where a diagonal block is missing; a singular block raises)."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    out = np.full((n, d, d), np.nan)
    for i in range(n):
        for p in range(indptr[i], indptr[i + 1]):
            if indices[p] == i:
                if d == 3:  # by cofactors: a LAPACK call per block costs 10x more
                    a = data[p]
                    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
                    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
                    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
                    det = a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02
                    scale = max(np.abs(a[0]).max(), np.abs(a[1]).max(), np.abs(a[2]).max())
                    if not (abs(det) > 1e-14 * scale**3):  # singular to working precision
                        raise np.linalg.LinAlgError("singular diagonal block")
                    r = 1.0 / det
                    o = out[i]
                    o[0, 0], o[1, 0], o[2, 0] = c00 * r, c01 * r, c02 * r
                    o[0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * r
                    o[1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * r
                    o[2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * r
                    o[0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * r
                    o[1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * r
                    o[2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * r
                else:
                    out[i] = np.linalg.inv(data[p])
                break
    return out


@njit(cache=True, nogil=True)
def _block_diag(indptr, indices, data):
    """The diagonal blocks of a square BSR matrix, ``(n_block_rows, d, d)`` (zero where one is
    missing)."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    out = np.zeros((n, d, d))
    for i in range(n):
        for p in range(indptr[i], indptr[i + 1]):
            if indices[p] == i:
                out[i] = data[p]
                break
    return out


@njit(cache=True, nogil=True)
def _block_rows_times(dinv, v):
    """``D^-1 v`` for block-diagonal ``dinv`` ``(n, d, d)``."""
    n, d, _ = dinv.shape
    out = np.empty(n * d)
    for i in range(n):
        for r in range(d):
            s = 0.0
            for q in range(d):
                s += dinv[i, r, q] * v[i * d + q]
            out[i * d + r] = s
    return out


@njit(inline="always", nogil=True, fastmath={"contract"})
def _row_times(a_ptr, a_ind, a_data, i, t_ptr, t_ind, t_data, mark, ks, y, values):
    """Block row ``i`` of ``A T`` (``A`` BSR with square blocks ``d``, ``T`` BSR with blocks
    ``(d, m)``) into the dense accumulator ``y[K]`` over the block columns ``K`` it reaches,
    listed in ``ks`` (first ``nk`` entries, unsorted; ``mark[K] == i`` marks them).  Returns
    ``nk``.  With ``values`` False only the block columns are found.  3 x 3 blocks of ``A`` have
    unrolled loops."""
    d = a_data.shape[1]
    m = t_data.shape[2]
    nk = 0
    for q in range(a_ptr[_U(i)], a_ptr[_U(i + 1)]):
        j = a_ind[_U(q)]
        for pt in range(t_ptr[_U(j)], t_ptr[_U(j + 1)]):
            K = t_ind[_U(pt)]
            if mark[_U(K)] != i:
                mark[_U(K)] = i
                ks[nk] = K
                nk += 1
                if values:
                    y[_U(K)] = 0.0
            if not values:
                continue
            if d == 3:
                Aq = a_data[_U(q)]
                a00, a01, a02 = Aq[0, 0], Aq[0, 1], Aq[0, 2]
                a10, a11, a12 = Aq[1, 0], Aq[1, 1], Aq[1, 2]
                a20, a21, a22 = Aq[2, 0], Aq[2, 1], Aq[2, 2]
                Tp = t_data[_U(pt)]
                Y = y[_U(K)]
                for c in range(m):
                    t0, t1, t2 = Tp[0, c], Tp[1, c], Tp[2, c]
                    Y[0, c] += a00 * t0 + a01 * t1 + a02 * t2
                    Y[1, c] += a10 * t0 + a11 * t1 + a12 * t2
                    Y[2, c] += a20 * t0 + a21 * t1 + a22 * t2
            else:
                for r in range(d):
                    for s in range(d):
                        av = a_data[_U(q), r, s]
                        for c in range(m):
                            y[_U(K), r, c] += av * t_data[_U(pt), s, c]
    return nk


@njit(cache=True, nogil=True, fastmath={"contract"})
def _smoothed_prolongator(a_ptr, a_ind, a_data, dinv, t_ptr, t_ind, t_data, scale, nc, p_ptr, p_ind, p_data):
    """``P = T + scale D^-1 A T`` block row by block row, with ``A`` BSR (square blocks ``d``),
    ``dinv`` its inverse diagonal blocks and ``T`` the tentative prolongator (BSR, blocks
    ``(d, m)``, ``nc`` block columns).  With ``p_ind`` empty, only the block row pointers
    ``p_ptr`` are filled (the pattern of ``A T``: the coarse blocks of the rows of ``T`` that
    row ``i`` of ``A`` reaches, sorted); then ``p_ind`` and ``p_data`` are filled.  Returns
    False when a block of ``T`` has no place in ``A T`` (a row of ``A`` without its diagonal
    block)."""
    n = a_ptr.shape[0] - 1
    d = a_data.shape[1]
    m = t_data.shape[2]
    fill = p_ind.shape[0] > 0
    mark = np.full(nc, -1, dtype=np.int64)
    slot = np.zeros(nc, dtype=np.int64)
    ks = np.empty(nc, dtype=np.int64)
    y = np.empty((nc, d, m))
    tmp = np.empty((d, m))
    if not fill:
        p_ptr[0] = 0
    for i in range(n):
        nk = _row_times(a_ptr, a_ind, a_data, i, t_ptr, t_ind, t_data, mark, ks, y, fill)
        for pt in range(t_ptr[i], t_ptr[i + 1]):
            if mark[t_ind[pt]] != i:
                return False
        if not fill:
            p_ptr[i + 1] = p_ptr[i] + nk
            continue
        ksort = np.sort(ks[:nk])
        base = p_ptr[i]
        for u in range(nk):
            K = ksort[u]
            slot[K] = base + u
            p_ind[base + u] = K
            for r in range(d):
                for c in range(m):
                    s = 0.0
                    for q in range(d):
                        s += dinv[i, r, q] * y[K, q, c]
                    tmp[r, c] = s
            for r in range(d):
                for c in range(m):
                    p_data[base + u, r, c] = scale * tmp[r, c]
        for pt in range(t_ptr[i], t_ptr[i + 1]):
            p_data[slot[t_ind[pt]]] += t_data[pt]
    return True


@njit(inline="always", nogil=True, fastmath={"contract"})
def _acc_block_times(data, q, x, j, acc, sign):
    """``acc += sign data[q] x_j`` for the block ``data[q]`` (``(d, c)``) and the block ``j``
    of ``x`` (``c`` entries); inlined into the generic block kernels."""
    c = data.shape[2]
    for r in range(data.shape[1]):
        t = 0.0
        for k in range(c):
            t += data[_U(q), _U(r), _U(k)] * x[_U(j * c + k)]
        acc[r] += sign * t


@njit(inline="always", nogil=True, fastmath={"contract"})
def _solve_diag_block(dinv, i, r, x):
    """``x_i = D_i^-1 r`` with the inverse diagonal block ``dinv[i]``; inlined."""
    d = dinv.shape[1]
    for p in range(d):
        t = 0.0
        for c in range(d):
            t += dinv[_U(i), _U(p), _U(c)] * r[c]
        x[_U(i * d + p)] = t


@njit(cache=True, nogil=True, fastmath={"contract"})
def _block_gauss_seidel_sweep(indptr, indices, data, dinv, x, b, forward):
    """One block Gauss-Seidel sweep on a square BSR system, in place on ``x``: block row by
    block row (last to first when not ``forward``), ``x_i = D_i^-1 (b_i - sum_{j != i} A_ij x_j)``
    with the inverse diagonal blocks ``dinv``."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    r = np.empty(d)
    for t in range(n):
        i = t if forward else n - 1 - t
        for p in range(d):
            r[p] = b[_U(i * d + p)]
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            j = indices[_U(q)]
            if j != i:
                _acc_block_times(data, q, x, j, r, -1.0)
        _solve_diag_block(dinv, i, r, x)


class _BlockGaussSeidel:
    """A pyamg level smoother ``(A, x, b)``: one block Gauss-Seidel sweep, compiled; the same
    sweep as pyamg's ``block_gauss_seidel`` at a third of its cost (its block loops are generic
    in the block size at run time)."""

    def __init__(self, dinv, forward: bool):
        self.dinv, self.forward = dinv, forward

    def __call__(self, A, x, b):
        if x.ndim != 1 or not x.flags.c_contiguous or x.dtype != np.float64:
            raise TypeError("block Gauss-Seidel needs a contiguous float64 vector")
        _block_gauss_seidel_sweep(A.indptr, A.indices, A.data, self.dinv, x,
                                  np.ascontiguousarray(b, dtype=np.float64).ravel(), self.forward)


def _compiled_smoothers(ml, dinv0=None):
    """Replace the smoothers of the square-block BSR levels of a pyamg hierarchy (all but the
    coarsest) by the compiled block Gauss-Seidel: forward before the coarse correction,
    backward after (a symmetric V-cycle, as the options in ``_SA_SMOOTHERS``)."""
    for k, lvl in enumerate(ml.levels[:-1]):
        A = lvl.A
        if not (sp.issparse(A) and A.format == "bsr" and A.blocksize[0] == A.blocksize[1]):
            continue
        try:
            dinv = dinv0 if (k == 0 and dinv0 is not None) else _block_diag_inverse(A.indptr, A.indices, A.data)
        except np.linalg.LinAlgError:  # a singular diagonal block: pyamg's smoother stays
            continue
        if not np.all(np.isfinite(dinv)):
            continue
        lvl.presmoother = _BlockGaussSeidel(dinv, True)
        lvl.postsmoother = _BlockGaussSeidel(dinv, False)
    return ml


@njit(cache=True, nogil=True, fastmath={"contract"})
def _bsr_matvec(indptr, indices, data, x, y):
    """``y = A x`` for a BSR matrix ``A`` (blocks ``(d, c)``), compiled (scipy's generic block
    loop reaches about half the memory bandwidth on 3 x 3 blocks)."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    acc = np.empty(d)
    for i in range(n):
        for r in range(d):
            acc[r] = 0.0
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            _acc_block_times(data, q, x, indices[_U(q)], acc, 1.0)
        for r in range(d):
            y[_U(i * d + r)] = acc[r]


@njit(cache=True, nogil=True, fastmath={"contract"})
def _gs_forward_from_zero(indptr, indices, data, dinv, b, x, s):
    """A forward block Gauss-Seidel sweep from ``x = 0`` (sorted block indices): only the blocks
    left of the diagonal are read.  ``s`` receives the partial residuals
    ``b_i - sum_{j < i} A_ij x_j`` for :func:`_residual_restrict`."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    r = np.empty(d)
    for i in range(n):
        for p in range(d):
            r[p] = b[_U(i * d + p)]
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            j = indices[_U(q)]
            if j >= i:
                break
            _acc_block_times(data, q, x, j, r, -1.0)
        for p in range(d):
            s[_U(i * d + p)] = r[p]
        _solve_diag_block(dinv, i, r, x)


@njit(cache=True, nogil=True, fastmath={"contract"})
def _residual_restrict(indptr, indices, data, x, s, p_ptr, p_ind, p_data, bc):
    """After :func:`_gs_forward_from_zero`: the residual ``r_i = s_i - sum_{j >= i} A_ij x_j``
    (only the blocks from the diagonal on are read) restricted at once, ``bc += P^T r``
    (``P`` BSR with blocks ``(d, m)``, ``bc`` zeroed by the caller)."""
    n = indptr.shape[0] - 1
    d = data.shape[1]
    m = p_data.shape[2]
    r = np.empty(d)
    for i in range(n):
        for p in range(d):
            r[p] = s[_U(i * d + p)]
        for q in range(indptr[_U(i + 1)] - 1, indptr[_U(i)] - 1, -1):
            j = indices[_U(q)]
            if j < i:
                break
            _acc_block_times(data, q, x, j, r, -1.0)
        for pp in range(p_ptr[_U(i)], p_ptr[_U(i + 1)]):
            J = p_ind[_U(pp)]
            for c in range(m):
                t = bc[_U(J * m + c)]
                for p in range(d):
                    t += p_data[_U(pp), _U(p), _U(c)] * r[p]
                bc[_U(J * m + c)] = t


@njit(cache=True, nogil=True, fastmath={"contract"})
def _prolong_add(p_ptr, p_ind, p_data, xc, x):
    """``x += P xc`` (``P`` BSR with blocks ``(d, m)``)."""
    n = p_ptr.shape[0] - 1
    d = p_data.shape[1]
    m = p_data.shape[2]
    for i in range(n):
        for pp in range(p_ptr[_U(i)], p_ptr[_U(i + 1)]):
            J = p_ind[_U(pp)]
            for p in range(d):
                t = x[_U(i * d + p)]
                for c in range(m):
                    t += p_data[_U(pp), _U(p), _U(c)] * xc[_U(J * m + c)]
                x[_U(i * d + p)] = t


@njit(inline="always", nogil=True, fastmath={"contract"})
def _block3_times(B, x0, x1, x2):
    """``B (x0, x1, x2)`` for a 3 x 3 block ``B`` (inlined into the unrolled kernels below)."""
    return (B[0, 0] * x0 + B[0, 1] * x1 + B[0, 2] * x2,
            B[1, 0] * x0 + B[1, 1] * x1 + B[1, 2] * x2,
            B[2, 0] * x0 + B[2, 1] * x1 + B[2, 2] * x2)


@njit(cache=True, nogil=True, fastmath={"contract"})
def _bsr3_matvec(indptr, indices, data, x, y):
    """:func:`_bsr_matvec` unrolled for 3 x 3 blocks (about a third faster: it then runs near
    the memory bandwidth)."""
    for i in range(indptr.shape[0] - 1):
        a0 = a1 = a2 = 0.0
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            j = _U(3 * indices[_U(q)])
            b0, b1, b2 = _block3_times(data[_U(q)], x[j], x[j + _U(1)], x[j + _U(2)])
            a0 += b0
            a1 += b1
            a2 += b2
        y[_U(3 * i)], y[_U(3 * i + 1)], y[_U(3 * i + 2)] = a0, a1, a2


@njit(cache=True, nogil=True, fastmath={"contract"})
def _gs3_forward_from_zero(indptr, indices, data, dinv, b, x, s):
    """:func:`_gs_forward_from_zero` unrolled for 3 x 3 blocks."""
    for i in range(indptr.shape[0] - 1):
        r0, r1, r2 = b[_U(3 * i)], b[_U(3 * i + 1)], b[_U(3 * i + 2)]
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            jb = indices[_U(q)]
            if jb >= i:
                break
            j = _U(3 * jb)
            b0, b1, b2 = _block3_times(data[_U(q)], x[j], x[j + _U(1)], x[j + _U(2)])
            r0 -= b0
            r1 -= b1
            r2 -= b2
        s[_U(3 * i)], s[_U(3 * i + 1)], s[_U(3 * i + 2)] = r0, r1, r2
        x[_U(3 * i)], x[_U(3 * i + 1)], x[_U(3 * i + 2)] = _block3_times(dinv[_U(i)], r0, r1, r2)


@njit(cache=True, nogil=True, fastmath={"contract"})
def _residual3_restrict(indptr, indices, data, x, s, p_ptr, p_ind, p_data, bc):
    """:func:`_residual_restrict` unrolled for 3 x 3 blocks of ``A``."""
    m = p_data.shape[2]
    for i in range(indptr.shape[0] - 1):
        r0, r1, r2 = s[_U(3 * i)], s[_U(3 * i + 1)], s[_U(3 * i + 2)]
        for q in range(indptr[_U(i + 1)] - 1, indptr[_U(i)] - 1, -1):
            jb = indices[_U(q)]
            if jb < i:
                break
            j = _U(3 * jb)
            b0, b1, b2 = _block3_times(data[_U(q)], x[j], x[j + _U(1)], x[j + _U(2)])
            r0 -= b0
            r1 -= b1
            r2 -= b2
        for pp in range(p_ptr[_U(i)], p_ptr[_U(i + 1)]):
            J = _U(p_ind[_U(pp)] * m)
            Q = p_data[_U(pp)]
            for c in range(m):
                bc[J + _U(c)] += Q[0, c] * r0 + Q[1, c] * r1 + Q[2, c] * r2


@njit(cache=True, nogil=True, fastmath={"contract"})
def _gs3_backward(indptr, indices, data, dinv, x, b):
    """A backward block Gauss-Seidel sweep (as :func:`_block_gauss_seidel_sweep`) unrolled for
    3 x 3 blocks."""
    n = indptr.shape[0] - 1
    for t in range(n):
        i = n - 1 - t
        r0, r1, r2 = b[_U(3 * i)], b[_U(3 * i + 1)], b[_U(3 * i + 2)]
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            jb = indices[_U(q)]
            if jb != i:
                j = _U(3 * jb)
                b0, b1, b2 = _block3_times(data[_U(q)], x[j], x[j + _U(1)], x[j + _U(2)])
                r0 -= b0
                r1 -= b1
                r2 -= b2
        x[_U(3 * i)], x[_U(3 * i + 1)], x[_U(3 * i + 2)] = _block3_times(dinv[_U(i)], r0, r1, r2)


# The finest level of the compiled V-cycle reads its matrix and prolongator in single precision
# (the arithmetic stays double): the cycle is then exactly the V-cycle of the rounded matrices,
# a symmetric preconditioner as good as the unrounded one (relative changes ~6e-8 of the
# entries), and the finest level, memory-bound at large sizes, reads half the bytes.
VCYCLE_SINGLE = True


class _VCycle:
    """The V-cycle of a smoothed-aggregation hierarchy as a preconditioner (``M @ r``), compiled
    level by level: the same cycle as pyamg's ``aspreconditioner(cycle="V")`` with the
    smoothers of :func:`_compiled_smoothers` (forward block Gauss-Seidel from zero, residual,
    restriction ``P^T``, coarse correction, prolongation, backward sweep), but

    * without the two residual norms of the finest level that pyamg's ``solve`` computes around
      each cycle (two products with the finest matrix of the about seven per application);
    * the forward sweep from zero reads only the blocks left of the diagonal, and the residual
      after it only the others (it is zero on the part the sweep solved), fused with the
      restriction ``P^T r`` (no ``R`` is needed);
    * compiled products with the BSR matrices.

    Work vectors are kept per level, so one operator must not be applied concurrently."""

    def __init__(self, ml, dinvs, single=False):
        self.ml = ml
        self.levels = []
        for k, (lvl, dinv) in enumerate(zip(ml.levels[:-1], dinvs)):
            A, P = lvl.A, lvl.P
            f32 = single and k == 0
            self.levels.append({"A": A, "P": P, "dinv": dinv, "s": np.empty(A.shape[0]),
                                "bc": np.empty(P.shape[1]), "xc": np.empty(P.shape[1]),
                                "a_data": A.data.astype(np.float32) if f32 else A.data,
                                "p_data": P.data.astype(np.float32) if f32 else P.data})
        self.single = bool(single)
        self.coarse_A = ml.levels[-1].A
        self.coarse_solver = ml.coarse_solver
        self.shape = ml.levels[0].A.shape
        self.dtype = np.dtype(float)

    @classmethod
    def build(cls, ml, single=None):
        """The compiled V-cycle of ``ml``, or None when a level does not fit (a non-BSR or
        non-square-block matrix, a prolongator whose block rows differ, or no compiled
        smoother).  ``single`` (default ``VCYCLE_SINGLE``): the finest level's matrix and
        prolongator are read in single precision (see :data:`VCYCLE_SINGLE`)."""
        if len(ml.levels) < 2:
            return None
        dinvs = []
        for lvl in ml.levels[:-1]:
            A, P = lvl.A, getattr(lvl, "P", None)
            sm = lvl.presmoother
            if not (sp.issparse(A) and A.format == "bsr" and A.blocksize[0] == A.blocksize[1]
                    and sp.issparse(P) and P.format == "bsr" and P.blocksize[0] == A.blocksize[0]
                    and isinstance(sm, _BlockGaussSeidel) and isinstance(lvl.postsmoother, _BlockGaussSeidel)
                    and A.dtype == np.float64 and P.dtype == np.float64):
                return None
            A.sort_indices()
            dinvs.append(sm.dinv)
        return cls(ml, dinvs, VCYCLE_SINGLE if single is None else single)

    def update(self, A):
        """Take the values of ``A`` (the next Newton matrix, same pattern as the finest level's)
        for the finest level's smoothing and residual, as the kept hierarchy does with a matrix
        refilled in place; the prolongator, the inverse diagonal blocks and the coarse levels
        stay.  Returns False (nothing changed) when ``A`` has another pattern."""
        L = self.levels[0]
        A0 = L["A"]
        if not (sp.issparse(A) and A.format == "bsr" and A.shape == A0.shape and A.blocksize == A0.blocksize
                and A.data.shape == L["a_data"].shape):
            return False
        if not (A.indices is A0.indices or _same_readonly(A.indices, A0.indices)
                or (A.indptr.shape == A0.indptr.shape and np.array_equal(A.indices, A0.indices)
                    and np.array_equal(A.indptr, A0.indptr))):
            return False
        if L["a_data"] is not A.data:
            if L["a_data"].dtype == A.data.dtype and L["a_data"] is A0.data:
                L["a_data"] = A.data  # double precision: read the new matrix itself
            else:
                np.copyto(L["a_data"], A.data, casting="same_kind")
        L["A"] = A
        return True

    def refresh_diagonal(self):
        """Invert the finest level's diagonal blocks anew, from the matrix of the last
        :meth:`update`.  The sweeps assume that they solve the diagonal blocks exactly: with the
        inverses of an older matrix the cycle is not symmetric, and CG with it stalled (the
        cylinder scene, 2 568 dofs: no convergence in 1 013 iterations at the first solve of the
        next load step; 4 iterations with the inverses refreshed).
        False (nothing changed) when a diagonal block is singular."""
        A = self.levels[0]["A"]
        try:
            dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
        except np.linalg.LinAlgError:
            return False
        if not np.all(np.isfinite(dinv)):
            return False
        self.levels[0]["dinv"] = dinv
        return True

    def _cycle(self, k, b, x):
        if k == len(self.levels):
            x[:] = np.asarray(self.coarse_solver(self.coarse_A, b), dtype=float).ravel()
            return
        L = self.levels[k]
        A, P, dinv, a, p = L["A"], L["P"], L["dinv"], L["a_data"], L["p_data"]
        three = A.blocksize[0] == 3
        (_gs3_forward_from_zero if three else _gs_forward_from_zero)(A.indptr, A.indices, a, dinv, b, x, L["s"])
        bc, xc = L["bc"], L["xc"]
        bc.fill(0.0)
        (_residual3_restrict if three else _residual_restrict)(A.indptr, A.indices, a, x, L["s"],
                                                               P.indptr, P.indices, p, bc)
        self._cycle(k + 1, bc, xc)
        _prolong_add(P.indptr, P.indices, p, xc, x)
        if three:
            _gs3_backward(A.indptr, A.indices, a, dinv, x, b)
        else:
            _block_gauss_seidel_sweep(A.indptr, A.indices, a, dinv, x, b, False)

    def __matmul__(self, b):
        b = np.ascontiguousarray(np.asarray(b, dtype=np.float64).ravel())
        x = np.empty_like(b)
        self._cycle(0, b, x)
        return x

    matvec = __matmul__


def _matvec_of(A):
    """A function ``v -> A v``: compiled for float64 BSR matrices, else ``A @ v``."""
    if sp.issparse(A) and A.format == "bsr" and A.dtype == np.float64:
        kernel = _bsr3_matvec if A.blocksize == (3, 3) else _bsr_matvec

        def mv(v):
            y = np.empty(A.shape[0])
            kernel(A.indptr, A.indices, A.data, np.ascontiguousarray(v, dtype=np.float64), y)
            return y
        return mv
    return lambda v: np.asarray(A @ v, dtype=float).ravel()


def _block_jacobi_radius(A, dinv, steps: int = 15, seed: int = 0) -> float:
    """Largest eigenvalue of ``D^-1 A`` (``D`` the block diagonal of the SPD ``A``) by Lanczos
    in the ``D`` inner product, where ``D^-1 A`` is self-adjoint: the largest Ritz value after
    ``steps`` matrix-vector products (a slight underestimate, as pyamg's Arnoldi estimate)."""
    n = A.shape[0]
    v = np.random.default_rng(seed).standard_normal(n)
    dblocks = _block_diag(A.indptr, A.indices, A.data)  # D itself, for the D inner product
    matvec = _matvec_of(A)

    def dmul(w):
        return _block_rows_times(dblocks, w)

    v /= np.sqrt(v @ dmul(v))
    v_prev = np.zeros(n)
    beta = 0.0
    alphas, betas = [], []
    for _ in range(min(steps, n)):
        u = matvec(v)
        alpha = float(v @ u)
        w = _block_rows_times(dinv, u) - alpha * v - beta * v_prev
        beta = float(np.sqrt(max(w @ dmul(w), 0.0)))
        alphas.append(alpha)
        if beta <= 1e-12 * abs(alpha):
            break
        betas.append(beta)
        v_prev, v = v, w / beta
    k = len(alphas)
    Tk = np.diag(alphas) + np.diag(betas[:k - 1], 1) + np.diag(betas[:k - 1], -1)
    return float(np.linalg.eigvalsh(Tk)[-1])


@njit(cache=True, nogil=True, fastmath={"contract"})
def _galerkin_numeric(a_ptr, a_ind, a_data, p_ptr, p_ind, p_data, c_ptr, c_ind, c_data):
    """Upper block triangle (``K >= J``) of ``C = P^T A P`` added into ``c_data``, on the
    pattern ``(c_ptr, c_ind)`` (sorted, containing that of the product), fine block row by fine
    block row: the row ``y = (A P)_i`` in a dense accumulator over the coarse blocks it
    touches, then ``C_JK += P_iJ^T y_K`` for the blocks ``P_iJ`` of that row.  No ``A P`` is
    stored; 3 x d blocks of ``A`` have unrolled loops."""
    n = a_ptr.shape[0] - 1
    nc = c_ptr.shape[0] - 1
    d = a_data.shape[1]
    m = p_data.shape[2]
    mark = np.full(nc, -1, dtype=np.int64)
    ks = np.empty(nc, dtype=np.int64)
    colpos = np.zeros(nc, dtype=np.int64)
    y = np.empty((nc, d, m))
    for i in range(n):
        nk = _row_times(a_ptr, a_ind, a_data, i, p_ptr, p_ind, p_data, mark, ks, y, True)
        for pp in range(p_ptr[_U(i)], p_ptr[_U(i + 1)]):
            J = p_ind[_U(pp)]
            for t in range(c_ptr[_U(J)], c_ptr[_U(J + 1)]):
                colpos[_U(c_ind[_U(t)])] = t
            for u in range(nk):
                K = ks[u]
                if K < J:
                    continue
                t = colpos[_U(K)]
                if d == 3:
                    Pp = p_data[_U(pp)]
                    Y = y[_U(K)]
                    Ct = c_data[_U(t)]
                    for r in range(m):
                        p0, p1, p2 = Pp[0, r], Pp[1, r], Pp[2, r]
                        for c in range(m):
                            Ct[r, c] += p0 * Y[0, c] + p1 * Y[1, c] + p2 * Y[2, c]
                else:
                    for r in range(m):
                        for s in range(d):
                            pv = p_data[_U(pp), s, r]
                            for c in range(m):
                                c_data[_U(t), r, c] += pv * y[_U(K), s, c]


@njit(cache=True, nogil=True)
def _mirror_lower(c_ptr, c_ind, c_data):
    """Blocks below the diagonal of a block-symmetric BSR (symmetric pattern, sorted indices)
    set to the transposes of their mirror images above it."""
    nc = c_ptr.shape[0] - 1
    m = c_data.shape[1]
    for J in range(nc):
        for t in range(c_ptr[J], c_ptr[J + 1]):
            K = c_ind[t]
            if K >= J:
                break
            lo, hi = c_ptr[K], c_ptr[K + 1]
            while lo < hi:
                mid = (lo + hi) // 2
                if c_ind[mid] < J:
                    lo = mid + 1
                else:
                    hi = mid
            for r in range(m):
                for c in range(m):
                    c_data[t, r, c] = c_data[lo, c, r]


def _galerkin(A, P):
    """Coarse matrix ``P^T A P`` (BSR, blocks ``(m, m)``) of a symmetric BSR ``A`` (square
    blocks, sorted indices) and a BSR prolongator ``P`` (blocks ``(d, m)``).  The block
    pattern comes from products of the block patterns (cheap: one scalar per block); the values
    from :func:`_galerkin_numeric`, which computes the upper block triangle only (the product
    is symmetric) without forming ``A P`` (several times larger than ``A``: 290 MB at 3e5 dofs
    with scipy's product), 3x faster than scipy's block products at 1e5 dofs."""
    nb = A.indptr.shape[0] - 1
    d, m = P.blocksize
    nc = P.shape[1] // m
    A.sort_indices()
    Ab = sp.csr_matrix((np.ones(A.indices.shape[0]), A.indices, A.indptr), shape=(nb, nb))
    Pb = sp.csr_matrix((np.ones(P.indices.shape[0]), P.indices, P.indptr), shape=(nb, nc))
    Cb = (Pb.T.tocsr() @ (Ab @ Pb)).tocsr()
    Cb.sort_indices()
    data = np.zeros((Cb.indices.shape[0], m, m))
    _galerkin_numeric(A.indptr, A.indices, A.data, P.indptr, P.indices, P.data, Cb.indptr, Cb.indices, data)
    _mirror_lower(Cb.indptr, Cb.indices, data)
    A_c = sp.bsr_matrix((data, Cb.indices, Cb.indptr), shape=(nc * m, nc * m), copy=False)
    A_c.has_sorted_indices = True
    return A_c


def _sa_solver(A, B, dim):
    """pyamg smoothed aggregation on the BSR ``A`` (``dim x dim`` blocks) with near-null space
    ``B``, as ``pyamg.smoothed_aggregation_solver(A, B, **_SA_OPTIONS)`` builds it, except that
    the finest level (by far the largest) is built here with less memory and time: the
    prolongator ``P = T - (omega / rho) D^-1 A T`` is formed block row by block row in one
    compiled pass (:func:`_smoothed_prolongator`; pyamg forms ``D^-1 A`` and its scaled copy,
    two more matrices of the size of ``A``, and ``A T`` with scipy's block product), ``rho``
    comes from Lanczos in the ``D`` inner product (15 products with ``A``, instead of Arnoldi on
    ``D^-1 A``), and the coarse matrix from the compiled :func:`_galerkin`.  Coarser levels are
    pyamg's.  Returns None when ``A`` does not fit (pyamg is then
    used as is)."""
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers
    from pyamg.strength import symmetric_strength_of_connection
    import pyamg

    if A.shape[0] // dim <= _SA_OPTIONS["max_coarse"]:
        return None
    C = symmetric_strength_of_connection(A, theta=_SA_OPTIONS["strength"][1]["theta"])
    AggOp, _ = standard_aggregation(C)
    T, B_c = fit_candidates(AggOp, B)
    T = T.tobsr(blocksize=(dim, B.shape[1]))
    try:
        dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    except np.linalg.LinAlgError:  # a singular diagonal block
        return None
    if not np.all(np.isfinite(dinv)):
        return None
    rho = _block_jacobi_radius(A, dinv)
    if not (np.isfinite(rho) and rho > 0):
        return None
    omega = _SA_OPTIONS["smooth"][1]["omega"]
    m, nc = B.shape[1], T.shape[1] // B.shape[1]
    p_ptr = np.empty(A.indptr.shape[0], dtype=np.int64)
    args = (A.indptr, A.indices, A.data, dinv, T.indptr, T.indices, T.data, -omega / rho, nc, p_ptr)
    if not _smoothed_prolongator(*args, np.empty(0, dtype=np.int64), np.empty((0, dim, m))):
        return None
    p_ind = np.empty(p_ptr[-1], dtype=A.indices.dtype)
    p_data = np.empty((p_ptr[-1], dim, m))
    _smoothed_prolongator(*args, p_ind, p_data)
    P = sp.bsr_matrix((p_data, p_ind, p_ptr.astype(A.indices.dtype)), shape=(A.shape[0], T.shape[1]), copy=False)
    P.has_sorted_indices = True
    R = _LazyTranspose(P)  # the compiled V-cycle needs no R; pyamg's cycle gets it on first use
    A_c = _galerkin(A, P)
    A_c.symmetry = "symmetric"
    coarse = pyamg.smoothed_aggregation_solver(A_c.tobsr(blocksize=(B.shape[1], B.shape[1])), B=B_c, **_SA_OPTIONS)
    top = MultilevelSolver.Level()
    top.A, top.B, top.P, top.R = A, B, P, R
    ml = MultilevelSolver([top] + coarse.levels, coarse_solver=_SA_OPTIONS["coarse_solver"])
    pre, post = _SA_SMOOTHERS
    change_smoothers(ml, [(pre[0], dict(pre[1], Dinv=dinv))] + [pre] * (len(ml.levels) - 2),
                     [(post[0], dict(post[1], Dinv=dinv))] + [post] * (len(ml.levels) - 2))
    return _compiled_smoothers(ml, dinv)


class _LazyTranspose:
    """``P^T`` as pyamg's restriction ``R``, formed on the first product (the compiled V-cycle
    restricts with ``P`` itself: no transposed copy of the finest prolongator is made)."""

    def __init__(self, P):
        self.P = P
        self.shape = (P.shape[1], P.shape[0])
        self.dtype = P.dtype
        self._T = None

    def __matmul__(self, v):
        if self._T is None:
            self._T = self.P.T.tobsr()
        return self._T @ v

    def tocsr(self):
        return self.P.T.tocsr()


def _amg_preconditioner(A, context):
    """pyamg smoothed aggregation; with node-aligned free dofs (``context['dim']`` and
    ``context['coords']`` of the free nodes) it works on dim x dim blocks (BSR) with the rigid
    body modes as near-null space, which is what makes it scale on elasticity; otherwise scalar
    with the constant vector.  Raises ImportError without pyamg.

    Options (``_SA_OPTIONS``): prolongation smoothing weighted by the inverse diagonal blocks;
    one forward block Gauss-Seidel sweep before and one backward sweep after the coarse
    correction, a symmetric V-cycle (CG needs it) at half the cost of symmetric sweeps; the
    coarsest level by sparse LU (pyamg's default dense pseudo-inverse costs O(n^3) and took
    minutes on the ~10^4-unknown coarse levels of 10^5-dof lattices).  The finest level of the
    block case is built by :func:`_sa_solver`; the cycle is applied by :class:`_VCycle` when
    every level fits it (pyamg's ``aspreconditioner`` otherwise)."""
    import pyamg  # optional

    dim = context.get("dim") if context else None
    coords = context.get("coords") if context else None
    if not (sp.issparse(A) and A.format == "bsr" and dim and A.blocksize == (dim, dim)):
        A = sp.csr_matrix(A)
    if dim and coords is not None and A.shape[0] == dim * len(coords) and len(coords) > 0:
        A = A.tobsr(blocksize=(dim, dim))  # no copy when it already is
        B = _rigid_body_modes(coords, dim)
        ml = _sa_solver(A, B, dim)
        if ml is None:
            ml = _compiled_smoothers(pyamg.smoothed_aggregation_solver(A, B=B, **_SA_OPTIONS))
    else:
        ml = pyamg.smoothed_aggregation_solver(A, max_coarse=500, coarse_solver="splu")
    cycle = _VCycle.build(ml)
    return cycle if cycle is not None else ml.aspreconditioner(cycle="V")


def _preconditioner(A, context=None):
    try:
        return _amg_preconditioner(A, context)
    except ImportError:
        return _ic0_preconditioner(A)


BAND_COST_MAX = 4e8  # n * (bandwidth + 1)^2 above which the banded Cholesky is not tried
_BAND_CACHE: list = []


def _bandwidth(A, perm):
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    return int(np.max(np.abs(inv[rows] - inv[A.indices]))) if A.nnz else 0


def _band_plan(A, context):
    """Ordering and scatter map of the banded (LAPACK ``pbtrf``) Cholesky of a symmetric CSR
    matrix with sorted indices, computed once per sparsity pattern.  Candidate orderings:
    reverse Cuthill-McKee, and, for node-aligned dofs with known coordinates, slices across the
    longest side of the bounding box (node by node, dofs of a node together).  The one with the
    smallest bandwidth wins.  Returns None when the estimated cost ``n (b + 1)^2`` exceeds
    ``BAND_COST_MAX``."""
    for entry in _BAND_CACHE:
        if _same_readonly(entry["indices"], A.indices) and _same_readonly(entry["indptr"], A.indptr):
            return entry["plan"]
        if (entry["indices"].shape == A.indices.shape and entry["indptr"].shape == A.indptr.shape
                and np.array_equal(entry["indices"], A.indices) and np.array_equal(entry["indptr"], A.indptr)):
            return entry["plan"]
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    n = A.shape[0]
    pattern = sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    candidates = [np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), dtype=np.int64)]
    dim = context.get("dim") if context else None
    coords = context.get("coords") if context else None
    if dim and coords is not None and n == dim * len(coords) and len(coords):
        ext = np.ptp(coords, axis=0)
        axes = np.argsort(ext)  # shortest first: lexsort's last key is the primary one
        nodes = np.lexsort(tuple(np.round(coords[:, a] / max(ext.max(), TINY), 9) for a in axes))
        candidates.append((dim * nodes[:, None] + np.arange(dim)).ravel())
    widths = [_bandwidth(A, p) for p in candidates]
    k = int(np.argmin(widths))
    perm, bw = candidates[k], widths[k]
    plan = None
    if n * (bw + 1.0) ** 2 <= BAND_COST_MAX:
        inv = np.empty_like(perm)
        inv[perm] = np.arange(n)
        rows = inv[np.repeat(np.arange(n), np.diff(A.indptr))]
        cols = inv[A.indices]
        lower = np.flatnonzero(rows >= cols)
        # LAPACK lower band storage: ab[i - j, j] = A[i, j] (i, j in the permuted numbering);
        # general band storage (for the LU fallback): ab[bw + i - j, j] = A[i, j]; both arrays
        # in Fortran order (LAPACK's), as flat positions (a C-ordered array would be copied on
        # every call)
        plan = {"perm": perm, "bw": bw, "src": lower,
                "dst": (rows[lower] - cols[lower]) + cols[lower] * (bw + 1),
                "dst_full": (bw + rows - cols) + cols * (2 * bw + 1)}
    _BAND_CACHE.insert(0, {"indices": A.indices, "indptr": A.indptr, "plan": plan})
    del _BAND_CACHE[_PLAN_CACHE_SIZE:]
    return plan


def _band_is_cheap(A, context):
    if A.shape[0] > BAND_PLAN_MAX_DOFS or not (sp.issparse(A) and A.format == "csr" and A.has_canonical_format):
        return False
    plan = _band_plan(A, context)
    return plan is not None and A.shape[0] * (plan["bw"] + 1.0) ** 2 <= BAND_AUTO_COST


def _banded_cholesky_solve(A, b, context):
    """Solve with the banded Cholesky of ``A`` (symmetric, CSR); None when ``A`` is not
    positive definite or its bandwidth is too large (the caller then uses SuperLU)."""
    from scipy.linalg import LinAlgError, cho_solve_banded, cholesky_banded, lapack

    if A.shape[0] > BAND_PLAN_MAX_DOFS or not (sp.issparse(A) and A.format == "csr" and A.has_canonical_format):
        return None
    plan = _band_plan(A, context)
    if plan is None:
        return None
    n, bw, perm = A.shape[0], plan["bw"], plan["perm"]
    bp = np.asarray(b, dtype=float)[perm]
    y = None
    state = context if context is not None else {}
    if not state.get("band_indefinite"):
        # the band array is kept in the context (a solve's Newton iterations, a run's time
        # steps) and refilled: no new pages per factorisation
        ab = state.get("band_ab")
        if ab is None or ab.shape != (bw + 1, n):
            ab = state["band_ab"] = np.zeros((bw + 1, n), order="F")
        else:
            ab.fill(0.0)
        flat = ab.reshape(-1, order="F")  # a view (Fortran-contiguous)
        flat[plan["dst"]] = A.data[plan["src"]]
        try:
            with one_blas_thread(bw >= BLOCKED_BANDWIDTH):  # msslib.blas_threads: shared cores
                cb = cholesky_banded(ab, lower=True, overwrite_ab=True, check_finite=False)
                y = cho_solve_banded((cb, True), bp, check_finite=False)
        except LinAlgError:  # not positive definite: banded LU (partial pivoting) from now on
            state["band_indefinite"] = True
    if y is None:
        if 2.0 * n * (bw + 1.0) * (2 * bw + 1.0) > 2 * BAND_COST_MAX:
            return None
        # LAPACK gbtrf/gbtrs on a band array kept in the context and refilled, with the bw rows
        # of room for the pivoting fill that gbtrf needs (solve_banded would allocate the band
        # array and then copy it into a larger one on every call)
        rows = 3 * bw + 1
        ab = state.get("band_lu")
        if ab is None or ab.shape != (rows, n):
            ab = state["band_lu"] = np.zeros((rows, n), order="F")
        else:
            ab.fill(0.0)
        dst = plan.get("dst_lu")
        if dst is None:  # general band storage with kl extra rows: ab[2 bw + i - j, j] = A[i, j]
            full = plan["dst_full"]
            dst = plan["dst_lu"] = (full // (2 * bw + 1)) * rows + full % (2 * bw + 1) + bw
        ab.reshape(-1, order="F")[dst] = A.data
        with one_blas_thread(bw >= BLOCKED_BANDWIDTH):
            lu, piv, info = lapack.dgbtrf(ab, bw, bw, overwrite_ab=1)
            if info == 0:
                y, info = lapack.dgbtrs(lu, bw, bw, bp, piv, overwrite_b=1)
        if info != 0:  # exactly singular (info > 0 from gbtrf) or bad input
            return None
    x = np.empty(n)
    x[perm] = y
    return x if np.all(np.isfinite(x)) else None


def _direct_solve(A, b, symmetric, context=None):
    """Symmetric: banded Cholesky in a bandwidth-reducing ordering when it is cheap and the matrix
    is positive definite; otherwise SuperLU with the minimum-degree ordering of A^T + A (less fill
    than the default COLAMD on lattice stiffnesses).  Non-symmetric: SuperLU with COLAMD."""
    if symmetric:
        x = _banded_cholesky_solve(A, b, context)
        if x is not None:
            return x
    spec = "MMD_AT_PLUS_A" if symmetric else "COLAMD"
    return spla.splu(sp.csc_matrix(A), permc_spec=spec).solve(np.asarray(b, dtype=float))


def _linear_solve(A, b, method, symmetric, messages, context=None, rtol=1e-10, truncate=False):
    """Solve ``A x = b``; raise _NewtonFailure when the matrix is singular or the solve fails.

    ``context`` (optional dict) holds ``dim`` and ``coords`` (free nodes) for the AMG near-null
    space and a ``cache`` where the AMG hierarchy is kept and reused for the next matrices
    (Newton iterations, load steps, later static solves of the same problem, time steps) as long
    as CG converges fast with it (a kept one is given up as soon as CG passes that limit); a kept
    compiled V-cycle smooths with each new matrix's values and diagonal blocks
    (:meth:`_VCycle.update`, :meth:`_VCycle.refresh_diagonal`).  ``rtol`` is the CG tolerance
    (relative to ``||b||``).  With ``truncate``, a CG run that meets negative
    curvature returns its last iterate (truncated Newton: used under an energy line search)
    instead of falling back to sparse LU."""
    if callable(method):
        x = np.asarray(method(A, b), dtype=float)
        if not np.all(np.isfinite(x)):
            raise _NewtonFailure("user linear solver returned non-finite values")
        return x
    if method not in ("auto", "direct", "cg"):
        raise ValueError(f"linear_solver must be 'auto', 'direct', 'cg' or a callable, got {method!r}")
    n = A.shape[0]
    use_cg = method == "cg" or (method == "auto" and symmetric and n > ITERATIVE_THRESHOLD
                                and not _band_is_cheap(A, context))
    if use_cg:
        cache = context.setdefault("cache", {}) if context is not None else {}
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                maxiter = max(1000, int(20 * np.sqrt(n)))
                M = cache.get("M") if cache.get("shape") == A.shape else None
                reused = M is not None
                if reused and isinstance(M, _VCycle) and M.update(A):  # smooth with this matrix
                    M.refresh_diagonal()
                if M is None:
                    M = _preconditioner(A, context)
                # iterations per decade of residual reduction: comparable across tolerances
                decades = max(1.0, -np.log10(max(rtol, 1e-300)))
                limit = 2.0 * cache.get("per_decade", maxiter) * decades + 10
                # a kept hierarchy is given up as soon as CG exceeds the limit, not at maxiter
                x, info, its = _pcg(A, b, M, rtol, min(maxiter, int(limit) + 1) if reused else maxiter)
                total = its
                if reused and (info > 0 or its > limit):
                    # the kept hierarchy no longer fits the matrix: rebuild it and solve again
                    M = _preconditioner(A, context)
                    reused = False
                    x, info, its = _pcg(A, b, M, rtol, maxiter)
                    total += its
                if not reused and info == 0:
                    cache.update(M=M, shape=A.shape, per_decade=its / decades)
                if context is not None:
                    context["cg_iterations"] = context.get("cg_iterations", 0) + total
            if np.all(np.isfinite(x)):
                if info == 0:
                    return x
                if info < 0 and truncate:
                    # negative curvature: the CG iterate reached so far (a descent direction of
                    # the energy); the line search and the Newton test decide what it is worth
                    if context is not None:
                        context["negative_curvature"] = context.get("negative_curvature", 0) + 1
                    return x
            cache.clear()
            what = "met negative curvature" if info < 0 else f"did not converge in {maxiter} iterations"
            messages.append(f"CG {what}; falling back to sparse LU")
        except (RuntimeError, ValueError, ArithmeticError) as exc:
            cache.clear()
            messages.append(f"preconditioned CG failed ({exc}); falling back to sparse LU")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            x = _direct_solve(A, b, symmetric, context)
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise _NewtonFailure(f"singular stiffness matrix ({exc})") from None
    if not np.all(np.isfinite(x)):
        raise _NewtonFailure("linear solve produced non-finite values (singular stiffness?)")
    return x


def _pcg(A, b, M, rtol, maxiter):
    """Preconditioned conjugate gradients from zero, stopping at ``||b - A x|| <= rtol ||b||``.

    Returns ``(x, info, iterations)``: ``info`` 0 when converged, 1 when ``maxiter`` was reached,
    -1 when a search direction of non-positive curvature ``p.A p <= 0`` was met (``A`` or the
    preconditioner is not positive definite); ``x`` is then the last iterate, or the
    preconditioned residual direction scaled by ``r.z / |p.A p|`` if that happens at the first
    iteration (for an SPD preconditioner, both are descent directions of ``x.A x / 2 - b.x``)."""
    b = np.asarray(b, dtype=float)
    n = b.shape[0]
    x = np.zeros(n)
    bnorm = float(np.linalg.norm(b))
    if bnorm == 0.0:
        return x, 0, 0
    tol = rtol * bnorm
    matvec = _matvec_of(A)
    r = b.copy()
    z = np.asarray(M @ r, dtype=float).ravel()
    rz = float(r @ z)
    p = z.copy()
    for k in range(1, maxiter + 1):
        Ap = matvec(p)
        pAp = float(p @ Ap)
        if not (pAp > 0.0 and rz > 0.0):
            if k == 1:
                scale = rz / abs(pAp) if pAp != 0.0 and np.isfinite(pAp) and rz > 0 else 1.0
                x = p * scale
            return x, -1, k
        alpha = rz / pAp
        x += alpha * p
        r -= alpha * Ap
        if float(np.linalg.norm(r)) <= tol:
            return x, 0, k
        z = np.asarray(M @ r, dtype=float).ravel()
        rz_new = float(r @ z)
        p *= rz_new / rz
        p += z
        rz = rz_new
    return x, 1, maxiter


def _cg_counted(A, b, M, rtol, maxiter, callback):
    try:
        return spla.cg(A, b, rtol=rtol, atol=0.0, M=M, maxiter=maxiter, callback=callback)
    except TypeError:  # scipy < 1.12 spells it tol
        return spla.cg(A, b, tol=rtol, atol=0.0, M=M, maxiter=maxiter, callback=callback)


def _solver_context(problem, x, free):
    """Context of :func:`_linear_solve`: spatial dimension and coordinates of the free nodes when
    the free dofs are whole nodes (all or none of a node's dofs free)."""
    dim = getattr(problem, "dim", None)
    ctx = {"cache": {}}
    try:
        dim = int(dim) if dim else 0
    except (TypeError, ValueError):
        dim = 0
    if dim in (2, 3) and free.size % dim == 0:
        f = free.reshape(-1, dim)
        whole = f.all(axis=1)
        if np.array_equal(whole, f.any(axis=1)):
            ctx["dim"] = dim
            ctx["node_free"] = whole
            ctx["coords"] = np.asarray(x, dtype=float).reshape(-1, dim)[whole]
    return ctx


# The linear-solver state of the last static solve of each problem (weak keys: it goes with the
# problem): the AMG hierarchy and the matrix of the Newton systems, whose values array is then
# refilled.  The next solve of the same problem with the same free nodes, initial coordinates
# and linear solver starts with them, as the Newton iterations of one solve do: the hierarchy
# is kept while CG converges fast with it (load steps, parameter sweeps and repeated solves of
# one model keep their tangent's pattern and, largely, its values), rebuilt otherwise.
_STATIC_CONTEXTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _static_context(problem, x, free, linear_solver):
    """The solver context of a static solve (see :func:`_solver_context`): the one left by the
    previous solve of ``problem`` when it is compatible and not in use (another thread), else a
    new one, kept for the next solve.  Release it with :func:`_release_context`."""
    ctx = _solver_context(problem, x, free)
    if not isinstance(linear_solver, str):  # a user solver: nothing to keep
        return ctx
    ctx["linear_solver"] = linear_solver
    try:
        old = _STATIC_CONTEXTS.get(problem)
    except TypeError:  # not weakly referable or not hashable
        return ctx
    if (old is not None and old.get("linear_solver") == linear_solver and old.get("dim") == ctx.get("dim")
            and old["free"].shape == free.shape and np.array_equal(old["free"], free)
            and np.array_equal(old.get("coords"), ctx.get("coords")) and old["lock"].acquire(blocking=False)):
        old["cg_iterations"] = 0
        old.pop("negative_curvature", None)
        old.pop("band_indefinite", None)  # judged afresh by each solve
        return old
    if old is not None and old["lock"].locked():  # in use: this solve keeps its own
        return ctx
    ctx["free"] = free.copy()
    ctx["lock"] = threading.Lock()
    ctx["lock"].acquire()
    try:
        _STATIC_CONTEXTS[problem] = ctx
    except TypeError:
        pass
    return ctx


def _release_context(ctx):
    lock = ctx.get("lock")
    if lock is not None and lock.locked():
        lock.release()


def _load_vector(problem, x0):
    """The load-proportional force at ``x0``: ``force(x0, 1) - force(x0, 0)`` (all dofs)."""
    with np.errstate(all="ignore"):
        return np.asarray(problem.force(x0, 1.0), dtype=float) - np.asarray(problem.force(x0, 0.0), dtype=float)


def _force_scale(problem, x0, free, f_ext=None):
    """``F_ref`` of the convergence criterion (module docstring); ``f_ext`` the load vector if known."""
    if f_ext is None:
        f_ext = _load_vector(problem, x0)
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


# --------------------------------------------------------------------------------------------
# round-off floor of the residual
# --------------------------------------------------------------------------------------------

EPS = np.finfo(float).eps
ROUNDOFF_FACTOR = 1.0  # the floor is ROUNDOFF_FACTOR * eps * (force magnitude scale)
# Measured (Newton driven to stagnation with tol = 1e-30): the residual stalls at 0.04-0.11 x
# eps * || |K| |x| + |f_ext| || on Golec, Baudet and Lloyd models (slender beam, compression,
# tetrahedra, membranes), and at 0.10-0.14 x eps * || |K| |u| + sum |f_e| + |f_ext| || for the
# FEM references (St Venant-Kirchhoff and neo-Hookean, hexahedra and tetrahedra); the floor is
# about ten times the stall, so a solve reaches it, and nothing far above it is accepted.


def roundoff_floor(magnitude: float) -> float:
    """Smallest residual norm a force evaluation can resolve: ``ROUNDOFF_FACTOR * eps * magnitude``,
    ``magnitude`` the norm of the per-dof size of what the force sums (for models whose forces
    are computed from absolute positions, ``|| |K| |x| + |f_ext| ||`` on the free dofs; for a
    displacement-based FEM, ``|| |K| |u| + sum_e |f_e| + |f_ext| ||``)."""
    return float(ROUNDOFF_FACTOR * EPS * magnitude)


def convergence_threshold(tol: float, force_scale: float, floor: float | None) -> float:
    """The shared Newton convergence test: converged when ``||r|| <= max(tol * F_ref, floor)``."""
    t = float(tol) * float(force_scale)
    return t if floor is None or not np.isfinite(floor) else max(t, float(floor))


def roundoff_note(residual: float, floor: float, target: float) -> str:
    """The message of a solve that stopped at the round-off floor instead of ``tol * F_ref``."""
    return (f"converged to round-off: residual {residual:.3e} at the round-off floor {floor:.3e} "
            f"(tol x F_ref = {target:.3e} is below what double precision resolves for these forces)")


@njit(cache=True, nogil=True)
def _abs_matvec_csr(indptr, indices, data, z, out):
    for i in range(indptr.shape[0] - 1):
        acc = 0.0
        for q in range(indptr[i], indptr[i + 1]):
            acc += abs(data[q]) * z[indices[q]]
        out[i] = acc


@njit(cache=True, nogil=True)
def _abs_matvec_bsr(indptr, indices, data, z, out):
    d = data.shape[1]
    for bi in range(indptr.shape[0] - 1):
        for a in range(d):
            acc = 0.0
            for q in range(indptr[bi], indptr[bi + 1]):
                j = indices[q] * d
                for b in range(d):
                    acc += abs(data[q, a, b]) * z[j + b]
            out[bi * d + a] = acc


@njit(cache=True, nogil=True)
def _abs_matvec_bsr3(indptr, indices, data, z, out):
    for bi in range(indptr.shape[0] - 1):
        a0 = a1 = a2 = 0.0
        for q in range(indptr[bi], indptr[bi + 1]):
            j = 3 * indices[q]
            z0, z1, z2 = z[j], z[j + 1], z[j + 2]
            B = data[q]
            a0 += abs(B[0, 0]) * z0 + abs(B[0, 1]) * z1 + abs(B[0, 2]) * z2
            a1 += abs(B[1, 0]) * z0 + abs(B[1, 1]) * z1 + abs(B[1, 2]) * z2
            a2 += abs(B[2, 0]) * z0 + abs(B[2, 1]) * z1 + abs(B[2, 2]) * z2
        out[3 * bi], out[3 * bi + 1], out[3 * bi + 2] = a0, a1, a2


def _abs_times(K, z):
    """``|K| z`` (entrywise absolute values of ``K``; ``z >= 0``), without copying ``K``."""
    out = np.empty(K.shape[0])
    z = np.ascontiguousarray(z, dtype=float)
    if sp.issparse(K) and K.format == "csr":
        _abs_matvec_csr(K.indptr, K.indices, np.ascontiguousarray(K.data, dtype=float), z, out)
    elif sp.issparse(K) and K.format == "bsr" and K.blocksize[0] == K.blocksize[1]:
        kernel = _abs_matvec_bsr3 if K.blocksize[0] == 3 else _abs_matvec_bsr
        kernel(K.indptr, K.indices, np.ascontiguousarray(K.data, dtype=float), z, out)
    else:
        out[:] = abs(K) @ z
    return out


def _force_magnitude(K_free, x_free, load_abs_free) -> float:
    """``|| |K| |x| + |f_ext| ||`` on the free dofs: the size of what a force computed from the
    absolute positions ``x`` sums (rounding ``x`` by eps changes the force by about eps times it)."""
    with np.errstate(all="ignore"):
        s = float(np.linalg.norm(_abs_times(K_free, np.abs(x_free)) + load_abs_free))
    return s if np.isfinite(s) else float("inf")


def _roundoff_floor_at(problem, x, free, load_abs_free, load=1.0) -> float:
    """The round-off floor at state ``x`` (assembles the tangent once)."""
    with np.errstate(all="ignore"):
        K = _submatrix(problem.stiffness(x, load), free)
    return roundoff_floor(_force_magnitude(K, x[free], load_abs_free))


# --------------------------------------------------------------------------------------------
# statics
# --------------------------------------------------------------------------------------------

_ARMIJO_C = 1e-4
_MAX_BACKTRACKS = 20


def _line_search(problem, x, dx, free, load, r, rnorm, e0, use_energy):
    """Backtracking (halving) line search. Returns (x_new, r_new, rnorm_new, e_new, alpha)."""
    slope = -float(r @ dx)  # d/dalpha energy(x + alpha dx) at alpha = 0 (grad energy = -force)
    energy_merit = use_energy and e0 is not None and slope < 0.0
    alpha = 1.0
    for _ in range(_MAX_BACKTRACKS + 1):
        xt = x.copy()
        xt[free] += alpha * dx
        with np.errstate(all="ignore"):
            rt = np.asarray(problem.force(xt, load), dtype=float)[free]
        rtn = float(np.linalg.norm(rt))
        if np.isfinite(rtn):
            if energy_merit:
                et = _energy_or_none(problem, xt, load)
                if et is not None and np.isfinite(et):
                    if et <= e0 + _ARMIJO_C * alpha * slope:
                        return xt, rt, rtn, et, alpha
                    # energy differences drowned in round-off: judge by the residual instead
                    noise = 64 * np.finfo(float).eps * (abs(e0) + abs(et))
                    if abs(et - e0) <= noise and rtn < rnorm:
                        return xt, rt, rtn, et, alpha
            else:
                # merit 0.5 ||r||^2, whose slope along the exact Newton direction is -||r||^2
                if rtn**2 <= (1.0 - 2.0 * _ARMIJO_C * alpha) * rnorm**2:
                    et = _energy_or_none(problem, xt, load) if use_energy else None
                    return xt, rt, rtn, et, alpha
        alpha *= 0.5
    raise _NewtonFailure(f"line search failed (no sufficient decrease down to step length {2 * alpha:.1e})")


_ETA_MAX = 0.1  # loosest relative tolerance of the iterative linear solves (first iterations)
_ETA_GAMMA = 0.9


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


def _wants_blocks(full_tangent, free, method, symmetric, context, block_tangent=None):
    """Whether the Newton systems go to AMG-CG as BSR node blocks: symmetric, whole free nodes,
    and CG chosen (``"cg"``, or ``"auto"`` above the size where the banded Cholesky is tried,
    or between ``ITERATIVE_THRESHOLD`` and it when the band is too wide).  ``full_tangent()``
    gives the full stiffness when the decision needs its pattern (mid sizes only);
    ``block_tangent()`` (optional) the free node blocks or None: when their graph alone shows
    the band too wide, the full tangent is not formed."""
    if not (symmetric and method in ("auto", "cg") and context.get("dim") and "node_free" in context):
        return False
    n = int(free.sum())
    if method == "cg" or n > BAND_PLAN_MAX_DOFS:
        return True
    if n <= ITERATIVE_THRESHOLD:
        return False
    Kb = block_tangent() if block_tangent is not None else None
    if Kb is not None and _band_surely_wide({"bptr": Kb.indptr, "bind": Kb.indices}, context["dim"]):
        return True
    K_full = full_tangent()
    entry = _bsr_entry(K_full, context["node_free"], context["dim"])
    if entry is not None and _band_surely_wide(entry, context["dim"]):
        return True
    return not _band_is_cheap(_submatrix(K_full, free), context)


def _newton(problem, x, free, load, threshold, max_iter, line_search, linear_solver,
            symmetric, use_energy, messages, progress, step_index, solver_context=None, scales=None):
    """Newton iteration at a fixed load. Returns (x, iterations, residual history).

    Converged when the residual is at most ``max(threshold, floor)``.  ``scales`` (a dict kept
    across the load steps of a solve) holds ``"floor"``, the round-off floor, None until known:
    it is computed from the first tangent assembled (``|K| |x|`` plus ``scales["load_abs"]``,
    the absolute load on the free dofs), so that no extra assembly is needed.

    Raises _NewtonFailure with attributes ``iteration`` and ``residual`` on failure."""
    if scales is None:
        scales = {"floor": None, "load_abs": 0.0}
    with np.errstate(all="ignore"):
        r = np.asarray(problem.force(x, load), dtype=float)[free]
    rnorm = float(np.linalg.norm(r))
    history = [rnorm]
    context = _solver_context(problem, x, free) if solver_context is None else solver_context
    e = _energy_or_none(problem, x, load) if (line_search and use_energy) else None
    it = 0
    rnorm_prev = eta_prev = None

    def fail(reason):
        floor = scales.get("floor")
        if floor is not None and rnorm > floor:
            reason = f"{reason}; residual {rnorm:.3e} is above the round-off floor {floor:.3e}"
        exc = _NewtonFailure(reason)
        exc.iteration = it
        exc.residual = rnorm
        return exc

    def target():
        return convergence_threshold(1.0, threshold, scales.get("floor"))

    if not np.isfinite(rnorm):
        raise fail("non-finite force at the initial guess")
    # the full tangent's values can be refilled in place when only its free block is passed on
    # (the block is a copy); saves allocating (and page-faulting) a new value array per iteration
    refill = not free.all() and _accepts_out(problem)
    K_full = None
    K = context.get("K")  # an earlier solve's or load step's: its values array is refilled
    blocks = context.get("blocks")  # None: not decided yet; True: BSR node blocks; False: CSR
    # a problem that fills the free node blocks itself (Model.stiffness_blocks) spares forming
    # the full tangent and copying its free block out of it
    direct_blocks = context.get("direct_blocks", callable(getattr(problem, "stiffness_blocks", None)))
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
                    K_new = _submatrix_bsr(K_full, context["node_free"], context["dim"], out=K)
                    if K_new is None:  # not made of node blocks: CSR from now on
                        blocks = context["blocks"] = False
                if not blocks:
                    K_new = _submatrix(K_full, free, out=K)
            K = context["K"] = K_new
        if scales.get("floor") is None:  # from the tangent just assembled: no extra assembly
            scales["floor"] = roundoff_floor(_force_magnitude(K, x[free], scales.get("load_abs", 0.0)))
            if rnorm <= target():
                break
        it += 1
        try:
            rtol = _forcing_term(rnorm, rnorm_prev, eta_prev, target())
            eta_prev, rnorm_prev = rtol, rnorm
            dx = _linear_solve(K, r, linear_solver, symmetric, messages, context, rtol,
                               truncate=bool(line_search and use_energy))
        except _NewtonFailure as exc:
            raise fail(str(exc)) from None
        if line_search:
            try:
                x, r, rnorm, e, _ = _line_search(problem, x, dx, free, load, r, rnorm, e, use_energy)
            except _NewtonFailure as exc:
                raise fail(str(exc)) from None
        else:
            x = x.copy()
            x[free] += dx
            with np.errstate(all="ignore"):
                r = np.asarray(problem.force(x, load), dtype=float)[free]
            rnorm = float(np.linalg.norm(r))
            if not np.isfinite(rnorm):
                raise fail("non-finite force after a full Newton step")
        history.append(rnorm)
        if progress is not None:
            progress({"load_step": step_index, "load": load, "iteration": it, "residual": rnorm,
                      "threshold": target()})
    return x, it, history


def _floor_text(floor):
    return "not computed" if floor is None else f"{floor:.3e}"


def static_solve(problem, x0, *, load_steps: int = 1, tol: float = 1e-8, max_iter: int = 50,
                 line_search: bool = True, linear_solver="auto", progress: Callable | None = None,
                 max_cuts: int = 10, force_scale: float | None = None) -> StaticResult:
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
        returns a number and the Newton direction descends it, otherwise on ``||force[free]||^2``.
    linear_solver : ``"auto"``, ``"direct"``, ``"cg"``, or a callable ``(K_free, rhs) -> dx``.
        ``"direct"``: for symmetric systems a banded Cholesky in a bandwidth-reducing ordering
        (computed once per sparsity pattern) when it is cheap, banded LU when the tangent is
        indefinite, else sparse LU (minimum-degree ordering); non-symmetric: sparse LU.
        ``"cg"``: CG preconditioned by pyamg smoothed aggregation if installed (node blocks and
        rigid-body modes when the free dofs are whole nodes; the hierarchy is reused across
        Newton iterations, load steps and successive solves of the same problem, from the same
        initial coordinates and with the same ``linear_solver``, as long as CG converges fast
        with it: the problem keeps it, weakly, with the matrix of the Newton systems) or else
        by incomplete Cholesky IC(0), falling back to LU; the CG tolerance follows an
        inexact-Newton forcing term (loose far from the solution, tight near it; the Newton
        convergence test is unchanged), and a CG run that meets negative
        curvature returns its last iterate under the energy line search (truncated Newton).
        ``"auto"``: direct up to ``ITERATIVE_THRESHOLD`` = 2 000 free dofs or while the banded
        Cholesky is cheap (``n (b + 1)^2 <= BAND_AUTO_COST``), else CG for symmetric systems.
    progress : optional callable receiving a dict ``{load_step, load, iteration, residual,
        threshold}`` after each Newton iteration.
    max_cuts : how many times a failing load increment may be halved (in total, for one step).
    force_scale : overrides ``F_ref`` of the convergence criterion (the round-off floor still applies).

    Raises
    ------
    ConvergenceError when a load increment still fails after ``max_cuts`` halvings.
    """
    t_start = time.perf_counter()
    if load_steps < 1:
        raise ValueError("load_steps must be >= 1")
    free = _free_mask(problem)
    x = np.array(x0, dtype=float).reshape(-1)
    if x.shape != (int(problem.n_dof),):
        raise ValueError(f"x0 must have {problem.n_dof} entries, got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 contains non-finite values")
    symmetric = bool(getattr(problem, "symmetric", True))
    use_energy = line_search and _is_conservative(problem, x, 1.0)
    merit = "none" if not line_search else ("energy" if use_energy else "residual")
    f_load = _load_vector(problem, x)
    scale = float(force_scale) if force_scale is not None else _force_scale(problem, x, free, f_load)
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
            except _NewtonFailure as exc:
                if cuts_this_step >= max_cuts:
                    raise ConvergenceError(
                        f"static_solve did not converge: load step {step_index}, load factor {target:.6g} "
                        f"(last converged load factor {lam:.6g}, increment {target - lam:.3g} after "
                        f"{cuts_this_step} halvings), iteration {exc.iteration}, residual {exc.residual:.3e} "
                        f"(threshold {convergence_threshold(tol, scale, scales['floor']):.3e} = max(tol {tol:.1e} "
                        f"x F_ref {scale:.3e}, round-off floor {_floor_text(scales['floor'])})): {exc}",
                        load_step=step_index, load=target, iteration=exc.iteration, residual=exc.residual,
                        x_last=x.copy(),
                    ) from None
                dlam = 0.5 * (target - lam)
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
            if cuts_this_step:  # grow back towards the nominal increment
                dlam = min(nominal, 2.0 * dlam)
            cuts_this_step = 0

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


# --------------------------------------------------------------------------------------------
# dynamics
# --------------------------------------------------------------------------------------------

def _mass_vector(problem):
    m = np.asarray(getattr(problem, "mass"), dtype=float).reshape(-1)
    if m.shape != (int(problem.n_dof),):
        raise ValueError(f"problem.mass must have shape ({problem.n_dof},), got {m.shape}")
    return m


EXPLICIT_METHODS = ("symplectic_euler", "velocity_verlet")
_EIG_TOL = 1e-4  # ARPACK's tolerance for omega_max^2: the Ritz residual is added (see below)


def _omega_max_squared(problem, x, load: float = 1.0) -> float:
    """Largest eigenvalue of ``M^-1 K`` on the free dofs at ``x`` (an estimate from above; see
    :func:`explicit_stability_limit`).  0.0 when no eigenvalue is positive."""
    free = _free_mask(problem)
    m = _mass_vector(problem)[free]
    if np.any(m <= 0):
        raise ValueError("masses of free dofs must be positive")
    K = _submatrix(problem.stiffness(np.asarray(x, dtype=float), load), free)
    d = sp.diags(1.0 / np.sqrt(m))
    A = sp.csr_matrix(d @ K @ d)
    symmetric = bool(getattr(problem, "symmetric", True))
    n = A.shape[0]
    if n == 0:
        return 0.0
    if n <= 400:
        dense = A.toarray()
        lam = np.linalg.eigvalsh(0.5 * (dense + dense.T)).max() if symmetric else np.abs(np.linalg.eigvals(dense)).max()
        return max(float(lam), 0.0)
    v0 = np.random.default_rng(0).standard_normal(n)
    try:
        if symmetric:
            w, V = spla.eigsh(A, k=1, which="LA", tol=_EIG_TOL, v0=v0)
        else:
            w, V = spla.eigs(A, k=1, which="LM", tol=_EIG_TOL, v0=v0)
        v = V[:, 0] / np.linalg.norm(V[:, 0])
        theta = w[0]
        # the Ritz value is at most the top eigenvalue; with the norm of its residual added it is
        # an upper bound when the Ritz pair approximates the top eigenpair (Lanczos from a random
        # start: in practice always); the residual is at most _EIG_TOL * theta
        res = float(np.linalg.norm(A @ v - theta * v))
        lam = (float(theta.real) if symmetric else float(abs(theta))) + res
    except (spla.ArpackNoConvergence, spla.ArpackError):
        v = v0 / np.linalg.norm(v0)
        lam = 0.0
        for _ in range(500):
            w = A @ v
            lam_new = float(np.linalg.norm(w))
            if lam_new == 0.0:
                break
            v = w / lam_new
            if abs(lam_new - lam) <= 1e-8 * lam_new:
                lam = lam_new
                break
            lam = lam_new
        if symmetric:  # Rayleigh quotient plus residual
            Av = A @ v
            theta = float(v @ Av)
            lam = max(lam, theta + float(np.linalg.norm(Av - theta * v)))
    return max(float(lam), 0.0)


def explicit_stability_limit(problem, x, load: float = 1.0) -> float:
    """Critical time step ``2 / omega_max`` of the explicit schemes at state ``x`` (undamped).

    ``omega_max^2`` is the largest eigenvalue of ``M^-1 K`` on the free dofs, computed as the
    largest eigenvalue of ``M^-1/2 K M^-1/2``: dense for up to 400 free dofs (exact), else
    Lanczos (ARPACK ``eigsh``, largest algebraic, relative tolerance 1e-4; ``eigs`` and the
    largest modulus for a non-symmetric ``K``) with the residual norm of the Ritz pair added to
    the Ritz value.  The Ritz value never exceeds the top eigenvalue, and with its residual
    added it bounds it from above whenever the pair approximates the top eigenpair, which Lanczos
    from a random start does in practice: the limit is then accurate to about 1e-4 and errs on
    the safe (small) side (measured on Golec lattices of 3.6e3 to 1e5 dofs: 1e-7 to 2e-4 below the
    exact value, 0.005 to 0.3 s).  Power iteration is the fallback.  Returns ``inf`` when no
    eigenvalue is positive.  See :func:`critical_time_step` for the effect of damping.
    """
    lam = _omega_max_squared(problem, x, load)
    return 2.0 / np.sqrt(lam) if lam > 0 else float("inf")


def _spectral_radius(method, h, omega, alpha, beta):
    """Spectral radius of the one-step map of the scheme ``method`` (as :func:`integrate` runs it)
    on the mode ``u'' = -omega^2 u - (alpha + beta omega^2) u'`` (arrays broadcast)."""
    h, w = np.broadcast_arrays(np.asarray(h, dtype=float), np.asarray(omega, dtype=float))
    w2 = w * w
    c = alpha + beta * w2
    if method == "symplectic_euler":  # v+ = (1 - h c) v - h w2 x; x+ = x + h v+
        a11, a12 = 1.0 - h * h * w2, h * (1.0 - h * c)
        a21, a22 = -h * w2, 1.0 - h * c
    else:  # velocity Verlet: explicit half-kick, drift, half-kick with beta at v_half, alpha implicit
        hx, hv = -0.5 * h * w2, 1.0 - 0.5 * h * c  # v_half = hx x + hv v
        a11, a12 = 1.0 + h * hx, h * hv  # x+ = x + h v_half
        g = 1.0 / (1.0 + 0.5 * h * alpha)
        a21 = g * (hx - 0.5 * h * w2 * a11 - 0.5 * h * beta * w2 * hx)
        a22 = g * (hv - 0.5 * h * w2 * a12 - 0.5 * h * beta * w2 * hv)
    tr, det = a11 + a22, a11 * a22 - a12 * a21
    disc = np.sqrt((tr * tr - 4.0 * det).astype(complex))
    return np.maximum(np.abs(0.5 * (tr + disc)), np.abs(0.5 * (tr - disc)))


def critical_time_step(omega_max: float, method: str = "symplectic_euler", alpha: float = 0.0,
                       beta: float = 0.0) -> float:
    """Largest stable step of the explicit ``method`` (as :func:`integrate` runs it) for modal
    frequencies up to ``omega_max`` with damping ``C = alpha M + beta K`` (modal damping
    ``c = alpha + beta omega^2``).

    * undamped, both schemes: ``2 / omega_max``;
    * symplectic Euler (damping explicit): ``(sqrt(c^2 + 4 omega^2) - c) / omega^2`` at
      ``omega_max``, below ``2 / omega_max`` for any damping (the top mode binds: the bound
      decreases with omega);
    * velocity Verlet: mass-proportional damping (implicit in the second half-kick) leaves
      ``2 / omega_max`` unchanged; with ``beta > 0`` the limit is the first step at which any
      mode up to ``omega_max`` (200 sampled) becomes unstable, found by a scan and bisection on
      the modal amplification matrices, at most ``2 / omega_max`` (heavily overdamped top modes
      can be stable beyond it, for a stable set that is not an interval; such steps are refused).
    """
    if method not in EXPLICIT_METHODS:
        raise ValueError(f"method must be one of {EXPLICIT_METHODS}, got {method!r}")
    omega = float(omega_max)
    if not (omega > 0) or not np.isfinite(omega):
        if omega == float("inf"):
            return 0.0
        # no stiffness: only the damping limits the step (symplectic Euler: h alpha < 2)
        return 2.0 / alpha if method == "symplectic_euler" and alpha > 0 else float("inf")
    undamped = 2.0 / omega
    if alpha == 0.0 and beta == 0.0:
        return undamped
    if method == "symplectic_euler":
        c = alpha + beta * omega * omega
        # (sqrt(c^2 + 4 w^2) - c) / w^2, written without cancellation for large c
        return 4.0 / (np.sqrt(c * c + 4.0 * omega * omega) + c)
    if beta == 0.0:
        return undamped
    modes = omega * np.concatenate([np.geomspace(1e-3, 0.9, 100, endpoint=False), np.linspace(0.9, 1.0, 100)])

    def stable(h):
        return float(_spectral_radius(method, h, modes, alpha, beta).max()) <= 1.0 + 1e-12

    hs = undamped * np.arange(1, 2001) / 2000.0
    radius = _spectral_radius(method, hs[:, None], modes[None, :], alpha, beta).max(axis=1)
    bad = np.flatnonzero(radius > 1.0 + 1e-12)
    if len(bad) == 0:
        return undamped
    if bad[0] == 0:
        lo, hi = 0.0, hs[0]
    else:
        lo, hi = hs[bad[0] - 1], hs[bad[0]]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return float(lo)


def check_time_step(problem, x, dt: float, *, method: str = "symplectic_euler", damping=None,
                    load: float = 1.0, allow_unstable: bool = False, omega_max: float | None = None) -> dict:
    """The stability limit of an explicit run from state ``x`` (the model at rest, prescribed
    displacements applied) and its check: raises :class:`msslib.errors.StabilityError` when
    ``dt`` exceeds it, unless ``allow_unstable``.

    Returns ``{"stability_limit", "stability_limit_undamped", "omega_max", "dt_over_limit"}``:
    :func:`critical_time_step` of the damping (``None``: ``problem.damping``) at ``omega_max``
    from :func:`explicit_stability_limit` (or ``omega_max`` if given: a value computed earlier
    for the same state)."""
    alpha, beta = _resolve_damping(problem, damping)
    omega = float(np.sqrt(_omega_max_squared(problem, x, load))) if omega_max is None else float(omega_max)
    limit = critical_time_step(omega, method, alpha, beta)
    undamped = 2.0 / omega if omega > 0 else float("inf")
    ratio = dt / limit if limit > 0 else float("inf")
    info = {"stability_limit": float(limit), "stability_limit_undamped": float(undamped), "omega_max": omega,
            "dt_over_limit": float(ratio)}
    if ratio > 1.0 and not allow_unstable:
        from msslib.errors import StabilityError

        raise StabilityError(
            f"{method}: time step dt = {dt:.7g} s is {ratio:.3g} x the explicit stability limit {limit:.7g} s "
            f"of the model at rest ({_limit_origin(limit, undamped, omega)}): the run would diverge; "
            f"use dt <= {limit:.7g} s or method implicit_euler (allow_unstable runs it anyway: "
            f"solver.allow_unstable in a scene)")
    return info


def _limit_origin(limit, undamped, omega):
    text = f"2/omega_max, omega_max = {omega:.6g} rad/s"
    if limit < undamped * (1.0 - 1e-12):
        text += f", lowered from {undamped:.6g} s by the damping"
    return text


def _resolve_damping(problem, damping):
    if damping is None:
        damping = getattr(problem, "damping", None)
    if damping is None:
        return 0.0, 0.0
    if np.ndim(damping) == 0:
        return float(damping), 0.0
    alpha, beta = damping
    return float(alpha), float(beta)


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
    t_start = time.perf_counter()
    methods = ("symplectic_euler", "velocity_verlet", "implicit_euler")
    if method not in methods:
        raise ValueError(f"method must be one of {methods}, got {method!r}")
    if not (dt > 0) or not (t_end >= 0):
        raise ValueError("dt must be positive and t_end non-negative")
    if save_every < 1:
        raise ValueError("save_every must be >= 1")
    n = int(problem.n_dof)
    free = _free_mask(problem)
    mass = _mass_vector(problem)
    if np.any(mass[free] <= 0):
        raise ValueError("masses of free dofs must be positive")
    alpha, beta = _resolve_damping(problem, damping)
    x = np.array(x0, dtype=float).reshape(-1)
    v = np.array(v0, dtype=float).reshape(-1)
    if x.shape != (n,) or v.shape != (n,):
        raise ValueError(f"x0 and v0 must have {n} entries")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError("x0 and v0 must be finite")
    v[~free] = 0.0
    x_ref = x.copy()
    bound = blowup * _bbox_size(problem, x_ref)
    symmetric = bool(getattr(problem, "symmetric", True))
    explicit = method in EXPLICIT_METHODS
    n_steps = int(np.ceil(t_end / dt - 1e-9)) if t_end > 0 else 0
    stats = {"n_steps": n_steps, "dt": dt, "method": method, "n_force_evals": 0,
             "n_newton_iterations": 0, "n_linear_solves": 0, "damping": (alpha, beta),
             "stability_limit": None, "stability_limit_undamped": None, "omega_max": None,
             "dt_over_limit": None, "allow_unstable": bool(allow_unstable)}
    limit = None
    if explicit:
        with np.errstate(all="ignore"):
            stats.update(check_time_step(problem, x, dt, method=method, damping=(alpha, beta), load=load,
                                         allow_unstable=allow_unstable))
        limit = stats["stability_limit"]
    conservative = _is_conservative(problem, x, load)
    mf = mass[free]
    inv_m = 1.0 / mf
    messages: list[str] = []
    if explicit and stats["dt_over_limit"] > 1.0:
        messages.append(f"dt = {dt:.6g} s is {stats['dt_over_limit']:.3g} x the explicit stability limit "
                        f"{limit:.6g} s of the model at rest (allow_unstable)")

    def force(xx):
        stats["n_force_evals"] += 1
        return np.asarray(problem.force(xx, load), dtype=float)[free]

    def damping_force(xx, vf):
        """-(alpha M + beta K) v on the free dofs, ``vf`` the free velocities."""
        out = -alpha * mf * vf if alpha else np.zeros_like(vf)
        if beta:
            out = out - beta * (_submatrix(problem.stiffness(xx, load), free) @ vf)
        return out

    f_scale = magnitude = None
    solver_context = None
    if method == "implicit_euler":
        f_load = _load_vector(problem, x)
        f_scale = _force_scale(problem, x, free, f_load)
        with np.errstate(all="ignore"):
            K0 = _submatrix(problem.stiffness(x, load), free)
            magnitude = _force_magnitude(K0, x[free], np.nan_to_num(np.abs(load * f_load[free])))
        solver_context = _solver_context(problem, x, free)

    ts, xs, vs, kes, pes = [], [], [], [], []

    def save(step, t):
        ts.append(t)
        xs.append(x.copy())
        vs.append(v.copy())
        kes.append(0.5 * float(mass[free] @ (v[free] ** 2)))
        if conservative:
            pes.append(_energy_or_none(problem, x, load))
        if progress is not None:
            progress({"step": step, "t": t, "n_steps": n_steps})

    # divergence detector (explicit methods): see _GROWTH_MIN
    omega = stats["omega_max"] or 0.0
    j_floor = (omega**4 * float(mf.sum()) * (_FLOOR_SIZE * _bbox_size(problem, x_ref)) ** 2
               if explicit and np.isfinite(omega) else 0.0)
    j_min = None
    growth = _growth_threshold(stats["dt_over_limit"]) if explicit else None
    flips = 0  # steps in a row whose force flipped sign
    zeros = np.zeros(int(free.sum()))

    save(0, 0.0)
    t = 0.0
    with np.errstate(all="ignore"):
        f = force(x) if explicit else None  # the explicit schemes evaluate the force after each drift
        if explicit and not np.any(v[free]):  # from rest: J_0 = a.M a
            j_min = float(np.sum(f * f * inv_m))
            j_min = j_min if np.isfinite(j_min) else None
        for step in range(1, n_steps + 1):
            h = dt if step < n_steps else t_end - (n_steps - 1) * dt
            x_prev, v_prev = x, v  # not modified below (x and v are replaced by new arrays)
            vf = vf_old = v[free]
            jterms = None  # (velocity u, f_late, f_early, f for a.M a, step h): K u = -(f_late - f_early) / h
            if method == "symplectic_euler":
                a = (f + damping_force(x, vf)) * inv_m
                vf = vf + h * a
                x = x.copy()
                x[free] += h * vf
                f_old, f = f, force(x)  # at x_n, for the next step and the monitor
                jterms = (vf, f, f_old, f, h)
            elif method == "velocity_verlet":
                a = (f + damping_force(x, vf)) * inv_m
                v_half = vf + 0.5 * h * a
                x = x.copy()
                x[free] += h * v_half
                f_old, f = f, force(x)
                jterms = (v_half, f, f_old, f, h)
                # second half-kick: mass-proportional damping at v+ (implicit), beta K at v_half
                g = f - beta * (_submatrix(problem.stiffness(x, load), free) @ v_half) if beta else f
                vf = (v_half + 0.5 * h * inv_m * g) / (1.0 + 0.5 * h * alpha)
            else:
                vf = _implicit_euler_step(problem, x, vf, h, free, mf, alpha, beta, load, newton_tol,
                                          newton_max_iter, f_scale, linear_solver, symmetric, stats,
                                          messages, step, t + h, solver_context, magnitude)
                x = x.copy()
                x[free] += h * vf
            v = np.zeros(n)
            v[free] = vf
            t = step * dt if step < n_steps else float(t_end)
            u_j, f_late, f_early, f_r, h_j = jterms if jterms is not None else (zeros, zeros, zeros, zeros, 1.0)
            q, pf, ku, r, dmax = _monitor(vf, u_j, f_late, f_early, f_r, mf, x, x_ref)
            if not (np.isfinite(q) and dmax <= bound):
                _check_state(problem, x, v, x_ref, bound, step, t, dt, method, x_prev, v_prev, limit)
            if explicit:
                if jterms is not None:
                    flips = flips + 1 if pf < 0.0 else 0
                    J = r - ku / h_j
                    J = J if J == J else float("inf")
                    j_min = J if j_min is None else min(j_min, J)
                    j_ref = max(j_min, j_floor, TINY)
                    if (J > growth * j_ref and flips >= 1) or J > _GROWTH_ANY * j_ref:
                        _raise_growth(x, x_ref, step, t, dt, method, x_prev, v_prev, limit, J / j_ref, flips)
            if step % save_every == 0 or step == n_steps:
                save(step, t)

    stats["wall_time"] = time.perf_counter() - t_start
    stats["messages"] = messages
    return DynamicResult(
        t=np.array(ts), x=np.array(xs), v=np.array(vs), x_final=x.copy(), v_final=v.copy(),
        kinetic_energy=np.array(kes), potential_energy=np.array(pes, dtype=float) if conservative else None,
        stats=stats,
    )


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
            R = R + h * beta * (_submatrix(problem.stiffness(xt, load), free) @ w)
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
                f"{_floor_text(floor)})",
                iteration=it, residual=rn, x_last=x.copy(), step=step, time=t_new, load=load)
        it += 1
        K = _submatrix(problem.stiffness(xt, load), free)
        J = sp.diags(mf * (1.0 + h * alpha)) + (h * h + h * beta) * K
        try:
            dw = _linear_solve(sp.csr_matrix(J), -R, linear_solver, symmetric, messages, solver_context)
        except _NewtonFailure as exc:
            raise ConvergenceError(
                f"implicit Euler linear solve failed at step {step}, t = {t_new:.6g} s, iteration {it}: {exc}",
                iteration=it, residual=rn, x_last=x.copy(), step=step, time=t_new, load=load) from None
        stats["n_linear_solves"] += 1
        lam = 1.0
        for _ in range(_MAX_BACKTRACKS + 1):
            Rt, xtt = residual(w + lam * dw)
            rtn = float(np.linalg.norm(Rt))
            if np.isfinite(rtn) and rtn <= (1.0 - _ARMIJO_C * lam) * rn:
                break
            lam *= 0.5
        else:
            raise ConvergenceError(
                f"implicit Euler line search failed at step {step}, t = {t_new:.6g} s, iteration {it}, "
                f"residual {rn:.3e} (threshold {threshold:.3e}, round-off floor {_floor_text(floor)})",
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
        umax = float(np.nanmax(np.abs(x_prev - x_ref))) if x_prev.size else 0.0
    raise DivergenceError(
        f"{method} diverged: {what} at step {step}, t = {t:.6g} s{_limit_hint(dt, limit)}",
        step=step, time=t, quantity=quantity, dof=dof, value=float(value), x_last=x_prev, v_last=v_prev,
        dt=dt, stability_limit=limit, max_displacement=umax,
    )

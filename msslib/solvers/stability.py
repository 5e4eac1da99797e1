"""The stability limit of the explicit schemes and its check before a run."""

from __future__ import annotations

import hashlib
import threading

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .certificate import (  # noqa: F401  (the check's stages; tests reach them here too)
    _CERT_MAX_STEPS,
    _CW_MAX_PRODUCTS,
    CERTIFICATE_FAILURE,
    _abs_row_product,
    _row_layout,
    _row_product,
    _scaled_operator,
    _spring_abs_prep,
    _spring_prep,
    _spring_terms,
    certified_omega_max,
    certified_springs,
    collatz_wielandt_bound,
    mass_vector,
    spring_rows,
)
from .directional import directional_bound, directional_setup
from .protocol import free_mask
from .submatrices import submatrix

EXPLICIT_METHODS = ("symplectic_euler", "velocity_verlet")
# the passes of the directional bound that count as cheap (check_time_step's cheap_only): each
# costs about one force evaluation
_CHEAP_PASSES = 8
_EIG_TOL = 1e-4  # ARPACK's tolerance for omega_max^2: the Ritz residual is added (see below)


def _scaled_stiffness(problem, x, load):
    """``M^-1/2 K M^-1/2`` on the free dofs at ``x`` (CSR)."""
    free = free_mask(problem)
    m = mass_vector(problem)[free]
    if np.any(m <= 0):
        raise ValueError("masses of free dofs must be positive")
    K = submatrix(problem.stiffness(np.asarray(x, dtype=float), load), free)
    d = sp.diags(1.0 / np.sqrt(m))
    return sp.csr_matrix(d @ K @ d)


def omega_max_squared(problem, x, load: float = 1.0) -> float:
    """Largest eigenvalue of ``M^-1 K`` on the free dofs at ``x`` (an estimate from above; see
    :func:`explicit_stability_limit`).  0.0 when no eigenvalue is positive."""
    A = _scaled_stiffness(problem, x, load)
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


def _omega_allowed(dt, method, alpha, beta, hi) -> float | None:
    """The largest ``omega_max`` whose stability limit (:func:`critical_time_step`) is at least
    ``dt``, searched below ``hi``; None where the limit is not monotone in omega (velocity
    Verlet with ``beta > 0``)."""
    if (alpha == 0.0 and beta == 0.0) or (method == "velocity_verlet" and beta == 0.0):
        return 2.0 / dt
    if method != "symplectic_euler":
        return None
    lo = 0.0  # the symplectic Euler limit decreases with omega
    if critical_time_step(hi, method, alpha, beta) >= dt:
        return hi
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if critical_time_step(mid, method, alpha, beta) >= dt else (lo, mid)
    return lo


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
    lam = omega_max_squared(problem, x, load)
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


def _abs_row_sums(problem, x, load, isq):
    """Row sums of ``|D K D|`` (``D = diag(isq)``): the problem's own bound when it has one
    (:meth:`msslib.system.Model.stiffness_row_bound`), else from its assembled stiffness."""
    own = getattr(problem, "stiffness_row_bound", None)
    if own is not None:
        return np.asarray(own(x, load, isq), dtype=float)
    from msslib.terms.bounds import csr_abs_rows

    K = sp.csr_matrix(problem.stiffness(np.asarray(x, dtype=float), load))
    K.sort_indices()
    out = np.zeros(K.shape[0])
    csr_abs_rows(K.indptr, K.indices.astype(np.int64), np.asarray(K.data, dtype=float), isq, out)
    return out


def omega_max_bound(problem, x, load: float = 1.0) -> tuple[float, np.ndarray]:
    """A cheap upper bound of ``omega_max`` at ``x`` and the row sums it comes from.

    Gershgorin's theorem on ``M^-1/2 K M^-1/2`` over the free dofs: every eigenvalue is at most
    the largest row sum of absolute values, which the terms add up themselves (3D springs in one
    pass over the springs, about one force evaluation) or which comes from the assembled
    stiffness.  It never lies below the top eigenvalue; on Lloyd's tetrahedral springs it lies
    1.8-2.5 times above it (a step up to 0.63-0.75 of the limit is accepted on the bound alone:
    0.66 at 122 k springs, 0.63 at 945 k), on Golec's lattices about 1.9 times (0.72)."""
    free = free_mask(problem)
    m = mass_vector(problem)
    if np.any(m[free] <= 0):
        raise ValueError("masses of free dofs must be positive")
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    rows = _abs_row_sums(problem, np.asarray(x, dtype=float).reshape(-1), load, isq)
    top = float(rows[free].max()) if free.any() else 0.0
    return (float(np.sqrt(top)) if np.isfinite(top) else float("inf")), rows


def _spectrum_key(x, load, rows) -> tuple:
    """What the top eigenvalue depends on: the state, the load factor and (through the bound's
    row sums, which change with every constant, mass and fixed dof) the model."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(x, dtype=float).tobytes())
    h.update(np.ascontiguousarray(rows).tobytes())
    return h.hexdigest(), float(load)


def _lanczos_omega(problem, x, load, rows) -> tuple[float, bool]:
    """``omega_max`` by Lanczos, kept on the problem for the same state, load and constants:
    ``(omega, reused)``."""
    key = _spectrum_key(x, load, rows)
    cache = getattr(problem, "_spectrum_cache", None)
    if cache is not None and key in cache:
        return cache[key], True
    omega = float(np.sqrt(omega_max_squared(problem, x, load)))
    _keep(problem, key, omega)
    return omega, False


def _kept(problem, key, dt, method, alpha, beta):
    """``(omega, origin)`` of an estimate kept for this state that decides ``dt`` (eigsh's, or a
    certified or Collatz-Wielandt bound that covers it), else None."""
    cache = getattr(problem, "_spectrum_cache", None) or {}
    if key in cache:
        return cache[key], "lanczos (reused)"
    kept = cache.get(("certified",) + key)
    if kept is not None and dt <= critical_time_step(kept, method, alpha, beta):
        return kept, "certified (reused)"
    kept = cache.get(("bound",) + key)
    if kept is not None and dt <= critical_time_step(kept, method, alpha, beta):
        return kept, "bound (reused)"
    return None


def _cheap_bound(problem, x, load):
    """``(bound, rows, setup)``: the cheap bound of ``omega_max``, the per-dof or per-node
    values it is the largest of (they change with every constant, mass and fixed dof: the
    model's part of the key of a kept estimate) and, for a 3D spring model with dead loads,
    :func:`directional_setup` (else None).  There the cheap bound is the directional bound's
    first pass (:func:`directional_bound` with weights 1), made in the same loop over the
    springs that prepares the next passes, and tighter than Gershgorin's
    (:func:`omega_max_bound`, the bound of every other model): it accepts steps up to 0.80
    (Golec's lattice) and 0.79 (Lloyd's tetrahedra, 122 k springs) of the limit, against 0.72
    and 0.66."""
    setup = directional_setup(problem, x, free_mask(problem))
    if setup is None:
        return (*omega_max_bound(problem, x, load), None)
    g = setup[5]
    top = float(g.max()) if g.size else 0.0
    return (float(np.sqrt(top)) if np.isfinite(top) else float("inf")), g, setup


def _certified(problem, x, load, rows, dt, method, alpha, beta, bound, setup=None, cheap_only=False):
    """``(omega, origin)`` from an estimate kept for this state (:func:`_kept`), else from
    :func:`directional_bound`, :func:`collatz_wielandt_bound` or :func:`certified_omega_max`
    when one of them accepts ``dt`` (kept), else None (the caller asks eigsh).  ``cheap_only``:
    the kept estimates and at most :data:`_CHEAP_PASSES` passes of the directional bound."""
    key = _spectrum_key(x, load, rows)
    kept = _kept(problem, key, dt, method, alpha, beta)
    if kept is not None:
        return kept
    target = _omega_allowed(dt, method, alpha, beta, bound)
    if target is None or not bool(getattr(problem, "symmetric", True)):
        return None
    free = free_mask(problem)
    if free.sum() <= 400:  # the dense path is exact and cheap
        return None
    lam, passes = directional_bound(problem, x, free, target * target, setup,
                                    max_passes=_CHEAP_PASSES if cheap_only else None)
    if lam is not None:
        _keep(problem, ("bound",) + key, float(np.sqrt(lam)))
        return float(np.sqrt(lam)), f"bound, directional ({passes} passes)"
    if cheap_only:
        return None
    springs = _spring_terms(problem)
    layout = None if springs is None else _row_layout(springs, x.size // 3)  # shared by both stages
    lam, products = collatz_wielandt_bound(problem, x, free, target * target, layout)
    if lam is not None:
        _keep(problem, ("bound",) + key, float(np.sqrt(lam)))
        return float(np.sqrt(lam)), f"bound, Collatz-Wielandt ({products} products)"
    seed = int(key[0][:16], 16)
    rows = None if springs is None else spring_rows(x, springs, _free_isq(problem, free), layout)
    if rows is not None:  # 3D springs: the whole run in one compiled call
        omega, steps = certified_springs(rows, target, seed)
    else:
        matvec, n, shift = _scaled_operator(problem, x, load, free)
        omega, steps = certified_omega_max(matvec, n, shift, target, seed)
    if omega is None:
        return None
    _keep(problem, ("certified",) + key, omega)
    return omega, f"certified ({steps} Lanczos steps)"


def _free_isq(problem, free):
    """``M^-1/2`` on the free dofs, 0 on the others."""
    m = mass_vector(problem)
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    return isq


_CACHE_LOCK = threading.Lock()  # checks of the same model may run on several threads


def _keep(problem, key, omega):
    """Keep ``omega`` on the problem under ``key`` (the eight newest)."""
    with _CACHE_LOCK:
        _keep_locked(problem, key, omega)


def _keep_locked(problem, key, omega):
    try:
        if getattr(problem, "_spectrum_cache", None) is None:
            problem._spectrum_cache = {}
        if len(problem._spectrum_cache) >= 8:
            problem._spectrum_cache.pop(next(iter(problem._spectrum_cache)))
        problem._spectrum_cache[key] = omega
    except (AttributeError, TypeError):  # a problem that takes no attributes: no reuse
        pass


def check_time_step(problem, x, dt: float, *, method: str = "symplectic_euler", damping=None,
                    load: float = 1.0, allow_unstable: bool = False, omega_max: float | None = None,
                    estimate: str = "auto", cheap_only: bool = False) -> dict | None:
    """The stability limit of an explicit run from state ``x`` (the model at rest, prescribed
    displacements applied) and its check: raises :class:`msslib.errors.StabilityError` when
    ``dt`` exceeds it, unless ``allow_unstable``.

    ``estimate="auto"`` first takes the cheap bound (safe: the limit it gives is at most the true
    one): on a model of 3D springs and dead loads the first pass of
    :func:`msslib.solvers.directional.directional_bound`, else :func:`omega_max_bound`
    (Gershgorin's); a ``dt`` within that limit is accepted without more work.  A larger ``dt``
    (symmetric stiffness, over 400 free dofs) is next tried, on a model of 3D springs and dead
    loads, by the further passes of the directional bound (deterministic, safe like the bound;
    two passes of about one force evaluation decide 0.9 of the limit on the benchmark's
    networks), by :func:`collatz_wielandt_bound` (deterministic; up to 16 products with the
    absolute stiffness), then by
    :func:`certified_omega_max`: a short Lanczos run (about 30 products with the mass-scaled
    stiffness at 0.9 of the limit, 45 at 0.95; 3D springs without assembling a matrix) whose
    bound holds except with probability :data:`CERTIFICATE_FAILURE` (1e-9); the limit it reports
    is then a safe lower bound just above ``dt``.  Only a ``dt`` it cannot certify (closer to
    the limit, or over it) asks for the Lanczos estimate of :func:`explicit_stability_limit`.
    Both are kept on the problem and reused while state, load and constants are unchanged.
    ``estimate="lanczos"`` always takes the Lanczos estimate (reused likewise).

    Returns ``{"stability_limit", "stability_limit_undamped", "omega_max", "dt_over_limit",
    "stability_estimate", "omega_max_bound"}``: :func:`critical_time_step` of the damping
    (``None``: ``problem.damping``) at ``omega_max``; ``stability_estimate`` says where
    ``omega_max`` comes from (``"bound"``, ``"bound, directional (k passes)"``,
    ``"bound, Collatz-Wielandt (k products)"`` or ``"bound (reused)"``: the limit is a safe lower
    bound of the true one,
    ``"certified (k Lanczos steps)"`` or ``"certified (reused)"``: likewise, except with
    probability 1e-9, ``"lanczos"``, ``"lanczos (reused)"`` or ``"given"``, when ``omega_max`` is
    passed: a value computed earlier for the same state).

    ``cheap_only``: return None instead of running the certificates or eigsh, when neither the
    bound, a kept estimate nor :data:`_CHEAP_PASSES` passes of the directional bound decide
    ``dt`` (:class:`msslib.stepping.generic.Integrator` then runs the whole check on a second
    thread while the first steps run)."""
    if estimate not in ("auto", "lanczos"):
        raise ValueError(f"estimate must be 'auto' or 'lanczos', got {estimate!r}")
    alpha, beta = resolve_damping(problem, damping)
    bound = None
    if omega_max is not None:
        omega, origin = float(omega_max), "given"
    else:
        x = np.asarray(x, dtype=float).reshape(-1)
        bound, rows, setup = _cheap_bound(problem, x, load)
        certified = None
        if estimate == "auto" and dt <= critical_time_step(bound, method, alpha, beta):
            omega, origin = bound, "bound"
        elif estimate == "auto" and (certified := _certified(problem, x, load, rows, dt, method, alpha, beta,
                                                             bound, setup, cheap_only)) is not None:
            omega, origin = certified
        elif cheap_only:
            return None
        else:
            omega, reused = _lanczos_omega(problem, x, load, rows)
            origin = "lanczos (reused)" if reused else "lanczos"
    limit = critical_time_step(omega, method, alpha, beta)
    undamped = 2.0 / omega if omega > 0 else float("inf")
    ratio = dt / limit if limit > 0 else float("inf")
    info = {"stability_limit": float(limit), "stability_limit_undamped": float(undamped), "omega_max": omega,
            "dt_over_limit": float(ratio), "stability_estimate": origin, "omega_max_bound": bound}
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


def mass_proportional_alpha(problem, damping, who: str) -> float:
    """``alpha`` of a damping that must be mass-proportional (``damping`` as :func:`integrate`
    takes it; None: ``problem.damping``); a Rayleigh ``beta`` is a ValueError naming ``who``."""
    alpha, beta = resolve_damping(problem, damping)
    if beta:
        raise ValueError(f"{who} supports mass-proportional damping only (beta = 0)")
    return alpha


def resolve_damping(problem, damping):
    if damping is None:
        damping = getattr(problem, "damping", None)
    if damping is None:
        return 0.0, 0.0
    if np.ndim(damping) == 0:
        return float(damping), 0.0
    alpha, beta = damping
    return float(alpha), float(beta)

"""The stability limit of the explicit schemes and its check before a run."""

from __future__ import annotations

import hashlib

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from .submatrices import submatrix
from .protocol import _free_mask


def _mass_vector(problem):
    m = np.asarray(getattr(problem, "mass"), dtype=float).reshape(-1)
    if m.shape != (int(problem.n_dof),):
        raise ValueError(f"problem.mass must have shape ({problem.n_dof},), got {m.shape}")
    return m


EXPLICIT_METHODS = ("symplectic_euler", "velocity_verlet")
_EIG_TOL = 1e-4  # ARPACK's tolerance for omega_max^2: the Ritz residual is added (see below)


def _scaled_stiffness(problem, x, load):
    """``M^-1/2 K M^-1/2`` on the free dofs at ``x`` (CSR)."""
    free = _free_mask(problem)
    m = _mass_vector(problem)[free]
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


# The certified short Lanczos run (see check_time_step): the probability that it accepts a step
# above the limit, and the most Lanczos steps it takes before it leaves the decision to eigsh.
CERTIFICATE_FAILURE = 1e-9
_CERT_MAX_STEPS = 64


@njit(cache=True, nogil=True)
def _spring_prep(x, conn, k, L0, isq, coef, shift_rows):
    """Per spring at ``x``: ``coef[s] = (n, k L0/l, k (1 - L0/l))`` (its Hessian block is
    ``k (L0/l n n^T + (1 - L0/l) I)``), and into ``shift_rows`` the Gershgorin row sums of the
    negative part (compressed springs, ``L0 > l``) of ``D K D``.  Returns False for coincident
    nodes."""
    for s in range(conn.shape[0]):
        a = 3 * conn[s, 0]
        b = 3 * conn[s, 1]
        d0 = x[b] - x[a]
        d1 = x[b + 1] - x[a + 1]
        d2 = x[b + 2] - x[a + 2]
        l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not l > 0.0:
            return False
        r = L0[s] / l
        coef[s, 0] = d0 / l
        coef[s, 1] = d1 / l
        coef[s, 2] = d2 / l
        coef[s, 3] = k[s] * r
        c = k[s] * (1.0 - r)
        coef[s, 4] = c
        if c < 0.0:
            for i in range(3):
                shift_rows[a + i] -= c * isq[a + i] * (isq[a + i] + isq[b + i])
                shift_rows[b + i] -= c * isq[b + i] * (isq[a + i] + isq[b + i])
    return True


@njit(cache=True, nogil=True)
def _spring_matvec(conn, coef, u, out):
    """``out += K u`` for springs prepared by :func:`_spring_prep`."""
    for s in range(conn.shape[0]):
        a = 3 * conn[s, 0]
        b = 3 * conn[s, 1]
        u0 = u[b] - u[a]
        u1 = u[b + 1] - u[a + 1]
        u2 = u[b + 2] - u[a + 2]
        n0 = coef[s, 0]
        n1 = coef[s, 1]
        n2 = coef[s, 2]
        t = coef[s, 3] * (n0 * u0 + n1 * u1 + n2 * u2)
        c = coef[s, 4]
        f0 = t * n0 + c * u0
        f1 = t * n1 + c * u1
        f2 = t * n2 + c * u2
        out[a] -= f0
        out[a + 1] -= f1
        out[a + 2] -= f2
        out[b] += f0
        out[b + 1] += f1
        out[b + 2] += f2


@njit(cache=True, nogil=True)
def _spring_abs_prep(x, conn, k, L0, isq, coef, diag):
    """For :func:`_abs_matvec`: per spring ``coef[s] = (|n|, k L0/l, |k (1 - L0/l)|)``, and into
    ``diag`` (nodes, 3, 3) the node blocks of ``D K D`` (signed sums).  False for coincident
    nodes."""
    for s in range(conn.shape[0]):
        na = conn[s, 0]
        nb = conn[s, 1]
        a = 3 * na
        b = 3 * nb
        d0 = x[b] - x[a]
        d1 = x[b + 1] - x[a + 1]
        d2 = x[b + 2] - x[a + 2]
        l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not l > 0.0:
            return False
        r = L0[s] / l
        kr = k[s] * r
        c = k[s] * (1.0 - r)
        n0, n1, n2 = d0 / l, d1 / l, d2 / l
        for p in range(3):
            np_ = n0 if p == 0 else (n1 if p == 1 else n2)
            for q in range(3):
                nq = n0 if q == 0 else (n1 if q == 1 else n2)
                h = kr * np_ * nq
                if p == q:
                    h += c
                diag[na, p, q] += h * isq[a + p] * isq[a + q]
                diag[nb, p, q] += h * isq[b + p] * isq[b + q]
        coef[s, 0] = abs(n0)
        coef[s, 1] = abs(n1)
        coef[s, 2] = abs(n2)
        coef[s, 3] = kr
        coef[s, 4] = abs(c)
    return True


@njit(cache=True, nogil=True)
def _abs_matvec(conn, coef, u, out):
    """``out += |H| u`` summed over the springs, with ``|H| <= k L0/l |n| |n|^T + |k (1 - L0/l)| I``
    (``u`` the vector scaled by ``M^-1/2``; the caller scales ``out`` and adds the node blocks)."""
    for s in range(conn.shape[0]):
        a = 3 * conn[s, 0]
        b = 3 * conn[s, 1]
        m0 = coef[s, 0]
        m1 = coef[s, 1]
        m2 = coef[s, 2]
        kr = coef[s, 3]
        c = coef[s, 4]
        ua0 = u[a]
        ua1 = u[a + 1]
        ua2 = u[a + 2]
        ub0 = u[b]
        ub1 = u[b + 1]
        ub2 = u[b + 2]
        ta = kr * (m0 * ua0 + m1 * ua1 + m2 * ua2)
        tb = kr * (m0 * ub0 + m1 * ub1 + m2 * ub2)
        out[a] += tb * m0 + c * ub0
        out[a + 1] += tb * m1 + c * ub1
        out[a + 2] += tb * m2 + c * ub2
        out[b] += ta * m0 + c * ua0
        out[b + 1] += ta * m1 + c * ua1
        out[b + 2] += ta * m2 + c * ua2


_CW_MAX_PRODUCTS = 16


def _spring_terms(problem):
    """The 3D spring terms (``k >= 0``) of a model made of them and dead loads only, else None."""
    from msslib.terms.internal import Springs

    terms = getattr(problem, "terms", None)
    if terms is None or int(getattr(problem, "dim", 0)) != 3:
        return None
    springs = []
    for t in terms:
        if type(t) is Springs and t.dim == 3 and not getattr(t, "scales_with_load", False) and np.all(t.k >= 0):
            springs.append(t)
        elif not (t.kind == "external" and t.abs_row_sums(np.zeros(0), 1.0, np.zeros(0), np.zeros(0))):
            return None
    return springs or None


def collatz_wielandt_bound(problem, x, free, lam_target: float) -> tuple[float | None, int]:
    """A deterministic bound of the top eigenvalue of ``A = M^-1/2 K M^-1/2`` (free dofs) of a
    3D spring model, tried up to ``lam_target``: ``(lam, products)`` with ``lam <= lam_target``,
    or None when it does not get there (or the model is not springs and dead loads only).

    Every eigenvalue of ``A`` is at most the spectral radius of ``|A|`` (entrywise), and that of
    any ``B >= |A|`` entrywise; for a nonnegative ``B`` and any positive ``w``,
    ``rho(B) <= max_i (B w)_i / w_i`` (Collatz-Wielandt), and ``rho(B) >= min_i (B w)_i / w_i``.
    ``w`` starts at 1 (the bound is then Gershgorin's) and follows power iterations with ``B``;
    the run stops when the upper bound reaches ``lam_target``, when the lower one exceeds it, or
    when the upper one, falling at its last rate, could not reach it within
    :data:`_CW_MAX_PRODUCTS` products.  On the benchmark's networks ``rho(|A|)`` accepts steps up
    to 0.91 (Lloyd's column, 122 k springs) and 0.897 (Golec's lattice) of the limit."""
    springs = _spring_terms(problem)
    if springs is None:
        return None, 0
    m = _mass_vector(problem)
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    x = np.ascontiguousarray(x, dtype=float).reshape(-1)
    diag = np.zeros((m.size // 3, 3, 3))
    prepared = []
    for t in springs:
        conn = np.ascontiguousarray(t.conn, dtype=np.int64)
        coef = np.empty((len(conn), 5))
        if not _spring_abs_prep(x, conn, np.asarray(t.k, dtype=float), np.asarray(t.rest_length, dtype=float), isq,
                                coef, diag):
            return None, 0
        prepared.append((conn, coef))
    absdiag = np.abs(diag)
    active = isq > 0.0
    w = active.astype(float)
    prev = None
    best = np.inf
    for k in range(1, _CW_MAX_PRODUCTS + 1):
        u = isq * w
        Bw = np.zeros(m.size)
        for conn, coef in prepared:
            _abs_matvec(conn, coef, u, Bw)
        Bw *= isq
        Bw += np.einsum("ipq,iq->ip", absdiag, w.reshape(-1, 3)).reshape(-1)
        ratio = Bw[active] / w[active]
        hi = float(ratio.max()) * (1.0 + 1e-12) if ratio.size else 0.0
        best = min(best, hi)
        if best <= lam_target:
            return best, k
        if float(ratio.min()) >= lam_target:
            return None, k  # rho(B) is above the target: no w brings the bound there
        if prev is not None and best - lam_target > (prev - best) * (_CW_MAX_PRODUCTS - k):
            return None, k
        prev = best
        w = Bw + 1e-9 * hi * w  # stays positive
        w /= w.max()
    return None, _CW_MAX_PRODUCTS


def _scaled_operator(problem, x, load, free):
    """``(matvec, n, shift)``: the product with ``A = D K D`` on all dofs (``D = M^-1/2`` on the
    free dofs, 0 elsewhere: the free block of :func:`_scaled_stiffness` and zeros), and
    ``shift >= 0`` with ``A + shift I`` positive semidefinite.

    A model whose internal terms are all 3D springs ``k/2 (l - L0)^2`` with ``k >= 0`` (and dead
    loads) runs without a matrix: each spring's block ``k (L0/l n n^T + (1 - L0/l) I)`` splits
    into a semidefinite part and, for a compressed spring, ``k (1 - L0/l) I`` < 0, whose
    Gershgorin bound is the shift (0 when no spring is compressed).  Any other model assembles
    its stiffness and takes minus Gershgorin's lower bound of its spectrum."""
    from msslib.terms.internal import Springs

    m = _mass_vector(problem)
    if np.any(m[free] <= 0):
        raise ValueError("masses of free dofs must be positive")
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    x = np.ascontiguousarray(x, dtype=float).reshape(-1)
    springs, ok = [], getattr(problem, "terms", None) is not None and int(getattr(problem, "dim", 0)) == 3
    for t in getattr(problem, "terms", None) or ():
        if not ok:
            break
        if type(t) is Springs and t.dim == 3 and not getattr(t, "scales_with_load", False) and np.all(t.k >= 0):
            springs.append(t)
        elif not (t.kind == "external" and t.abs_row_sums(np.zeros(0), 1.0, np.zeros(0), np.zeros(0))):
            ok = False  # a term with stiffness of its own: assemble
    if ok and springs:
        prepared, shift_rows = [], np.zeros(m.size)
        for t in springs:
            conn = np.ascontiguousarray(t.conn, dtype=np.int64)
            coef = np.empty((len(conn), 5))
            if not _spring_prep(x, conn, np.asarray(t.k, dtype=float), np.asarray(t.rest_length, dtype=float),
                                isq, coef, shift_rows):
                ok = False
                break
            prepared.append((conn, coef))
        if ok:
            def matvec(v):  # D K D v
                u = isq * v
                out = np.zeros(v.size)
                for conn, coef in prepared:
                    _spring_matvec(conn, coef, u, out)
                out *= isq
                return out

            return matvec, m.size, float(shift_rows.max()) if shift_rows.size else 0.0
    A = sp.csr_matrix(problem.stiffness(x, load), dtype=float, copy=True)
    A.data *= np.repeat(isq, np.diff(A.indptr)) * isq[A.indices]
    diag = A.diagonal()
    off = np.asarray(abs(A).sum(axis=1)).ravel() - np.abs(diag)
    shift = max(0.0, -float((diag - off).min())) if diag.size else 0.0
    return (lambda v: A @ v), A.shape[0], shift


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


def certified_omega_max(matvec, n: int, shift: float, omega_target: float, seed: int) -> tuple[float | None, int]:
    """Try to certify ``omega_max <= omega_target`` for the symmetric ``A`` of product
    ``matvec`` (size ``n``; ``A + shift I`` positive semidefinite) by a short Lanczos run from a
    random start: ``(omega, steps)`` with ``omega`` an upper bound of ``sqrt(lambda_max(A))`` at
    most ``omega_target``, or None when :data:`_CERT_MAX_STEPS` steps cannot certify it (or a
    Ritz value already exceeds the target: the step is over the limit).

    After ``k`` steps (full reorthogonalisation) the largest Ritz value ``theta_k`` of
    ``B = A + shift I`` never exceeds ``lambda_max(B)``, and from a start drawn uniformly on the
    sphere ``P(theta_k < (1 - eps) lambda_max(B)) <= 1.648 sqrt(n) exp(-sqrt(eps) (2k - 1))`` for
    every positive semidefinite ``B`` (Kuczynski and Wozniakowski, SIAM J. Matrix Anal. Appl.
    13 (1992), theorem 4.2).  With ``eps`` set so that the right side is
    :data:`CERTIFICATE_FAILURE`, ``theta_k / (1 - eps)`` bounds ``lambda_max(B)`` except with that
    probability.  The start is drawn from a generator seeded by ``seed`` (the caller's hash of
    the state), so a check is reproducible."""
    from scipy.linalg import eigvalsh_tridiagonal

    target = omega_target * omega_target + shift
    c = float(np.log(1.648 * np.sqrt(n) / CERTIFICATE_FAILURE))
    steps = min(_CERT_MAX_STEPS, n)
    Q = np.empty((steps, n))
    q = np.random.default_rng(seed).standard_normal(n)
    q /= np.linalg.norm(q)
    alpha, beta = [], []
    for j in range(steps):
        Q[j] = q
        w = matvec(q)
        if shift:
            w += shift * q
        a = float(q @ w)
        w -= a * q
        if j:
            w -= beta[-1] * Q[j - 1]
        basis = Q[: j + 1]
        w -= (basis @ w) @ basis  # full reorthogonalisation
        alpha.append(a)
        k = j + 1
        theta = float(eigvalsh_tridiagonal(np.array(alpha), np.array(beta),
                                           select="i", select_range=(j, j))[0]) if j else a
        theta = max(theta, 0.0) * (1.0 + 1e-9)  # round-off of the Ritz value
        eps = (c / (2 * k - 1)) ** 2
        if eps < 1.0 and theta / (1.0 - eps) <= target:
            return float(np.sqrt(max(theta / (1.0 - eps) - shift, 0.0))), k
        if theta >= target:
            return None, k  # a Ritz value above the target: the step is over the limit
        # the steps the bound would need if theta did not grow: give up early when too many
        if (c / np.sqrt(1.0 - theta / target) + 1.0) / 2.0 > steps:
            return None, k
        b = float(np.linalg.norm(w))
        if not b > 1e-13 * max(abs(a), theta, 1e-300):
            return None, k  # an invariant subspace: no further step
        beta.append(b)
        q = w / b
    return None, steps


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
    free = _free_mask(problem)
    m = _mass_vector(problem)
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
    try:
        if cache is None:
            cache = {}
            problem._spectrum_cache = cache
        if len(cache) >= 8:
            cache.pop(next(iter(cache)))
        cache[key] = omega
    except (AttributeError, TypeError):  # a problem that takes no attributes: no reuse
        pass
    return omega, False


def _certified(problem, x, load, rows, dt, method, alpha, beta, bound):
    """``(omega, origin)`` from an estimate kept for this state (eigsh's, or a certified or
    Collatz-Wielandt bound that covers ``dt``), else from :func:`collatz_wielandt_bound` or
    :func:`certified_omega_max` when one of them accepts ``dt`` (kept), else None (the caller
    asks eigsh)."""
    key = _spectrum_key(x, load, rows)
    cache = getattr(problem, "_spectrum_cache", None) or {}
    if key in cache:
        return cache[key], "lanczos (reused)"
    kept = cache.get(("certified",) + key)
    if kept is not None and dt <= critical_time_step(kept, method, alpha, beta):
        return kept, "certified (reused)"
    kept = cache.get(("bound",) + key)
    if kept is not None and dt <= critical_time_step(kept, method, alpha, beta):
        return kept, "bound, Collatz-Wielandt (reused)"
    target = _omega_allowed(dt, method, alpha, beta, bound)
    if target is None or not bool(getattr(problem, "symmetric", True)):
        return None
    free = _free_mask(problem)
    if free.sum() <= 400:  # the dense path is exact and cheap
        return None
    lam, products = collatz_wielandt_bound(problem, x, free, target * target)
    if lam is not None:
        _keep(problem, ("bound",) + key, float(np.sqrt(lam)))
        return float(np.sqrt(lam)), f"bound, Collatz-Wielandt ({products} products)"
    matvec, n, shift = _scaled_operator(problem, x, load, free)
    omega, steps = certified_omega_max(matvec, n, shift, target, int(key[0][:16], 16))
    if omega is None:
        return None
    _keep(problem, ("certified",) + key, omega)
    return omega, f"certified ({steps} Lanczos steps)"


def _keep(problem, key, omega):
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
                    estimate: str = "auto") -> dict:
    """The stability limit of an explicit run from state ``x`` (the model at rest, prescribed
    displacements applied) and its check: raises :class:`msslib.errors.StabilityError` when
    ``dt`` exceeds it, unless ``allow_unstable``.

    ``estimate="auto"`` first takes the cheap bound :func:`omega_max_bound` (safe: the limit it
    gives is at most the true one); a ``dt`` within that limit is accepted without more work.  A
    larger ``dt`` (symmetric stiffness, over 400 free dofs) is next tried, on a model of 3D
    springs and dead loads, by :func:`collatz_wielandt_bound` (deterministic, safe like the
    bound; up to 16 products with the absolute stiffness), then by
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
    ``omega_max`` comes from (``"bound"`` or ``"bound, Collatz-Wielandt (k products)"``: the
    limit is a safe lower bound of the true one,
    ``"certified (k Lanczos steps)"`` or ``"certified (reused)"``: likewise, except with
    probability 1e-9, ``"lanczos"``, ``"lanczos (reused)"`` or ``"given"``, when ``omega_max`` is
    passed: a value computed earlier for the same state)."""
    if estimate not in ("auto", "lanczos"):
        raise ValueError(f"estimate must be 'auto' or 'lanczos', got {estimate!r}")
    alpha, beta = _resolve_damping(problem, damping)
    bound = None
    if omega_max is not None:
        omega, origin = float(omega_max), "given"
    else:
        x = np.asarray(x, dtype=float).reshape(-1)
        bound, rows = omega_max_bound(problem, x, load)
        certified = None
        if estimate == "auto" and dt <= critical_time_step(bound, method, alpha, beta):
            omega, origin = bound, "bound"
        elif estimate == "auto" and (certified := _certified(problem, x, load, rows, dt, method, alpha, beta,
                                                             bound)) is not None:
            omega, origin = certified
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
    alpha, beta = _resolve_damping(problem, damping)
    if beta:
        raise ValueError(f"{who} supports mass-proportional damping only (beta = 0)")
    return alpha


def _resolve_damping(problem, damping):
    if damping is None:
        damping = getattr(problem, "damping", None)
    if damping is None:
        return 0.0, 0.0
    if np.ndim(damping) == 0:
        return float(damping), 0.0
    alpha, beta = damping
    return float(alpha), float(beta)

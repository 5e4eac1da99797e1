"""Cheap certificates of the explicit stability limit, used by
:func:`msslib.solvers.stability.check_time_step` before it asks for a Lanczos estimate: a
deterministic bound on the largest eigenvalue of the mass-scaled stiffness from its absolute values
(:func:`collatz_wielandt_bound`, spring models) and a short Lanczos run from a random start whose
failure probability is bounded (:func:`certified_omega_max`), with the matrix-free products of the
spring models they use."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit


def mass_vector(problem):
    m = np.asarray(problem.mass, dtype=float).reshape(-1)
    if m.shape != (int(problem.n_dof),):
        raise ValueError(f"problem.mass must have shape ({problem.n_dof},), got {m.shape}")
    return m


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
    m = mass_vector(problem)
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

    m = mass_vector(problem)
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

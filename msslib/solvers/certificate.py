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
from scipy.sparse.csgraph import reverse_cuthill_mckee

from msslib.terms.bounds import spring_delta as _spring_delta


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
        d0, d1, d2, l = _spring_delta(x, a, b)
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
def _spring_abs_prep(x, conn, k, L0, isq, coef, diag):
    """For :func:`_abs_row_product`: per spring ``coef[s] = (|n|, k L0/l, |k (1 - L0/l)|)``, and
    into ``diag`` (nodes, 3, 3) the node blocks of ``D K D`` (signed sums).  False for coincident
    nodes.  ``|H| <= k L0/l |n| |n|^T + |k (1 - L0/l)| I`` entrywise for the spring's block
    ``H``."""
    for s in range(conn.shape[0]):
        na = conn[s, 0]
        nb = conn[s, 1]
        a = 3 * na
        b = 3 * nb
        d0, d1, d2, l = _spring_delta(x, a, b)
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


_CW_MAX_PRODUCTS = 16


@njit(cache=True, nogil=True)
def _abs_row_product(R, rowptr, ib, coef, isq, absdiag, w, out):
    """``out = B w`` of :func:`collatz_wielandt_bound`: ``D |H| D`` of every spring (the bound of
    :func:`_spring_abs_prep`) between its two nodes plus the absolute node blocks ``absdiag`` of
    ``D K D``, for springs in rows by lower node (:func:`_row_layout`); ``R`` (nodes, 6) is
    scratch."""
    nn = rowptr.shape[0] - 1
    for i in range(nn):
        for p in range(3):
            R[i, p] = isq[3 * i + p] * w[3 * i + p]
            R[i, 3 + p] = 0.0
    for na in range(nn):
        ua0 = R[na, 0]
        ua1 = R[na, 1]
        ua2 = R[na, 2]
        ga0 = R[na, 3]
        ga1 = R[na, 4]
        ga2 = R[na, 5]
        for s in range(rowptr[na], rowptr[na + 1]):
            b = ib[s]
            m0 = coef[s, 0]
            m1 = coef[s, 1]
            m2 = coef[s, 2]
            kr = coef[s, 3]
            c = coef[s, 4]
            ub0 = R[b, 0]
            ub1 = R[b, 1]
            ub2 = R[b, 2]
            ta = kr * (m0 * ua0 + m1 * ua1 + m2 * ua2)
            tb = kr * (m0 * ub0 + m1 * ub1 + m2 * ub2)
            ga0 += tb * m0 + c * ub0
            ga1 += tb * m1 + c * ub1
            ga2 += tb * m2 + c * ub2
            R[b, 3] += ta * m0 + c * ua0
            R[b, 4] += ta * m1 + c * ua1
            R[b, 5] += ta * m2 + c * ua2
        a = 3 * na
        w0 = w[a]
        w1 = w[a + 1]
        w2 = w[a + 2]
        for p in range(3):
            g = ga0 if p == 0 else (ga1 if p == 1 else ga2)
            out[a + p] = isq[a + p] * g + absdiag[na, p, 0] * w0 + absdiag[na, p, 1] * w1 + absdiag[na, p, 2] * w2


@njit(cache=True, nogil=True)
def _cw_rows(rowptr, ib, coef, isq, absdiag, lam_target, max_products):
    """The power iterations of :func:`collatz_wielandt_bound` on springs in rows:
    ``(bound, products, accepted)``."""
    n = isq.shape[0]
    R = np.zeros((rowptr.shape[0] - 1, 6))
    w = np.zeros(n)
    Bw = np.empty(n)
    n_active = 0
    for i in range(n):
        if isq[i] > 0.0:
            w[i] = 1.0
            n_active += 1
    prev = -1.0
    best = np.inf
    for k in range(1, max_products + 1):
        _abs_row_product(R, rowptr, ib, coef, isq, absdiag, w, Bw)
        hi = 0.0
        lo = np.inf
        for i in range(n):
            if isq[i] > 0.0:
                r = Bw[i] / w[i]
                if not r <= hi:  # larger, or not a number
                    hi = r
                lo = min(lo, r)
        hi = hi * (1.0 + 1e-12) if n_active else 0.0
        if not hi < np.inf:  # not finite: no bound
            return best, k, False
        best = min(best, hi)
        if best <= lam_target:
            return best, k, True
        if lo >= lam_target:
            return best, k, False  # rho(B) is above the target: no w brings the bound there
        if prev >= 0.0 and best - lam_target > (prev - best) * (max_products - k):
            return best, k, False
        prev = best
        top = 0.0
        for i in range(n):
            wi = Bw[i] + 1e-9 * hi * w[i]  # stays positive
            w[i] = wi
            top = max(top, wi)
        for i in range(n):
            w[i] /= top
    return best, max_products, False


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


def collatz_wielandt_bound(problem, x, free, lam_target: float, layout=None) -> tuple[float | None, int]:
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
    rowptr, ib, conn, k, L0, order = layout if layout is not None else _row_layout(springs, m.size // 3)
    isq = _internal(isq, order)
    diag = np.zeros((m.size // 3, 3, 3))
    coef = np.empty((len(conn), 5))
    if not _spring_abs_prep(_internal(x, order), conn, k, L0, isq, coef, diag):
        return None, 0
    lam, products, ok = _cw_rows(rowptr, ib, coef, isq, np.abs(diag), float(lam_target), _CW_MAX_PRODUCTS)
    return (float(lam), int(products)) if ok else (None, int(products))


def _scaled_operator(problem, x, load, free):
    """``(matvec, n, shift)``: the product with ``A = D K D`` on all dofs (``D = M^-1/2`` on the
    free dofs, 0 elsewhere: the free block of :func:`_scaled_stiffness` and zeros), and
    ``shift >= 0`` with ``A + shift I`` positive semidefinite.

    A model whose internal terms are all 3D springs ``k/2 (l - L0)^2`` with ``k >= 0`` (and dead
    loads) runs without a matrix: each spring's block ``k (L0/l n n^T + (1 - L0/l) I)`` splits
    into a semidefinite part and, for a compressed spring, ``k (1 - L0/l) I`` < 0, whose
    Gershgorin bound is the shift (0 when no spring is compressed).  Any other model assembles
    its stiffness and takes minus Gershgorin's lower bound of its spectrum."""
    m = mass_vector(problem)
    if np.any(m[free] <= 0):
        raise ValueError("masses of free dofs must be positive")
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    x = np.ascontiguousarray(x, dtype=float).reshape(-1)
    springs = _spring_terms(problem)
    if springs is not None:
        rows = spring_rows(x, springs, isq)
        if rows is not None:
            rowptr, ib, coef, shift, isq_r, order = rows
            R = np.zeros((m.size // 3, 6))

            def matvec(v):  # D K D v
                out = np.empty(v.size)
                _row_product(R, rowptr, ib, coef, isq_r, _internal(v, order), 0.0, out)
                if order is None:
                    return out
                given = np.empty(v.size)
                given.reshape(-1, 3)[order] = out.reshape(-1, 3)
                return given

            return matvec, m.size, shift
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


# ---- the runs of a spring model in one compiled call: the springs stored once under their lower
# node (:func:`_row_layout`), the vector and the accumulator one record of six numbers per node (the
# fused step kernel's layout): a product reads each spring once and the other end in one cache line


@njit(cache=True, nogil=True)
def _rows_by_lower_node(conn, n_nodes, rowptr, order, ib):
    """Counting sort of the springs by lower node: ``rowptr``, ``order`` (slot -> spring), ``ib``."""
    for s in range(conn.shape[0]):
        rowptr[min(conn[s, 0], conn[s, 1]) + 1] += 1
    for i in range(n_nodes):
        rowptr[i + 1] += rowptr[i]
    fill = rowptr[:-1].copy()
    for s in range(conn.shape[0]):
        a = min(conn[s, 0], conn[s, 1])
        j = fill[a]
        fill[a] += 1
        order[j] = s
        ib[j] = max(conn[s, 0], conn[s, 1])


@njit(cache=True, nogil=True)
def _row_product(R, rowptr, ib, coef, isq, q, shift, w):
    """``w = (D K D + shift I) q`` and ``q.w`` for springs in rows (see above); ``R`` (nodes, 6) is
    scratch.  Spring ``(a, b)``, ``a < b``: its force on ``b`` is ``f = t n + c (u_b - u_a)``."""
    nn = rowptr.shape[0] - 1
    for i in range(nn):
        for p in range(3):
            R[i, p] = isq[3 * i + p] * q[3 * i + p]
            R[i, 3 + p] = 0.0
    dot = 0.0
    for na in range(nn):
        ua0 = R[na, 0]
        ua1 = R[na, 1]
        ua2 = R[na, 2]
        ga0 = R[na, 3]
        ga1 = R[na, 4]
        ga2 = R[na, 5]
        for s in range(rowptr[na], rowptr[na + 1]):
            b = ib[s]
            u0 = R[b, 0] - ua0
            u1 = R[b, 1] - ua1
            u2 = R[b, 2] - ua2
            n0 = coef[s, 0]
            n1 = coef[s, 1]
            n2 = coef[s, 2]
            t = coef[s, 3] * (n0 * u0 + n1 * u1 + n2 * u2)
            c = coef[s, 4]
            f0 = t * n0 + c * u0
            f1 = t * n1 + c * u1
            f2 = t * n2 + c * u2
            ga0 -= f0
            ga1 -= f1
            ga2 -= f2
            R[b, 3] += f0
            R[b, 4] += f1
            R[b, 5] += f2
        for p in range(3):
            j = 3 * na + p
            wj = isq[j] * (ga0 if p == 0 else (ga1 if p == 1 else ga2)) + shift * q[j]
            w[j] = wj
            dot += q[j] * wj
    return dot


@njit(cache=True, nogil=True)
def _sturm_count(alpha, beta, k, x):
    """Eigenvalues of the tridiagonal ``T_k`` (diagonal ``alpha``, off-diagonal ``beta``) below ``x``."""
    count = 0
    d = 1.0
    for i in range(k):
        b2 = beta[i - 1] * beta[i - 1] if i else 0.0
        d = alpha[i] - x - (b2 / d if i else 0.0)
        if d == 0.0:
            d = -1e-300
        if d < 0.0:
            count += 1
    return count


@njit(cache=True, nogil=True)
def _top_ritz(alpha, beta, k):
    """An upper end of a bracket of the largest eigenvalue of ``T_k`` (relative width 1e-13):
    bisection on Sturm counts inside Gershgorin's interval."""
    lo = np.inf
    hi = -np.inf
    for i in range(k):
        r = (abs(beta[i - 1]) if i else 0.0) + (abs(beta[i]) if i + 1 < k else 0.0)
        lo = min(lo, alpha[i] - r)
        hi = max(hi, alpha[i] + r)
    for _ in range(200):
        if hi - lo <= 1e-13 * max(abs(hi), abs(lo), 1e-300):
            break
        mid = 0.5 * (lo + hi)
        if _sturm_count(alpha, beta, k, mid) == k:  # every eigenvalue below mid
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True, nogil=True, fastmath=True)
def _reorthogonalise(Q, k, w, h):
    """``w -= Q_k^T (Q_k w)``: classical Gram-Schmidt against the first ``k`` rows of ``Q``."""
    n = w.shape[0]
    for r in range(k):
        s = 0.0
        for i in range(n):
            s += Q[r, i] * w[i]
        h[r] = s
    for r in range(k):
        hr = h[r]
        for i in range(n):
            w[i] -= hr * Q[r, i]


@njit(cache=True, nogil=True)
def _certified_rows(rowptr, ib, coef, isq, shift, q, target, c, max_steps, Q, alpha, beta):
    """The run of :func:`certified_omega_max` on springs in rows, from the unit vector ``q``:
    ``(bound of lambda_max(A + shift I) or -1.0, steps)``.

    The basis is kept semiorthogonal (Simon's partial reorthogonalisation): the recurrence of
    H. D. Simon (Math. Comp. 42 (1984) 115-142) estimates ``q_j . q_k`` from the Lanczos
    coefficients, with a round-off term of ``eps sqrt(n) ||T||`` per step on the pessimistic side,
    and the new vector (and the next) is reorthogonalised against the whole basis when an
    estimate exceeds ``sqrt(eps)``; the tridiagonal matrix is then the projection of ``A`` on the
    Krylov space to working precision, so its Ritz values are those of the fully
    reorthogonalised run to round-off."""
    n = q.shape[0]
    R = np.zeros((rowptr.shape[0] - 1, 6))
    w = np.empty(n)
    h = np.empty(max_steps)
    om_old = np.zeros(max_steps + 1)  # estimates of q_{j-1} . q_k
    om = np.zeros(max_steps + 1)  # of q_j . q_k
    om_new = np.zeros(max_steps + 1)
    om[0] = 1.0
    unit = 2.220446049250313e-16
    noise = unit * np.sqrt(n)
    force = False
    tnorm = 0.0
    Q[0, :] = q
    for j in range(max_steps):
        a = _row_product(R, rowptr, ib, coef, isq, q, shift, w)
        bj = beta[j - 1] if j else 0.0
        ww = 0.0
        for i in range(n):  # the three-term recurrence and |w|^2 in one pass
            wi = w[i] - a * q[i] - (bj * Q[j - 1, i] if j else 0.0)
            w[i] = wi
            ww += wi * wi
        alpha[j] = a
        k = j + 1
        theta = _top_ritz(alpha, beta, k) if j else a
        theta = max(theta, 0.0) * (1.0 + 1e-9)  # round-off of the Ritz value
        eps = (c / (2 * k - 1)) ** 2
        if eps < 1.0 and theta / (1.0 - eps) <= target:
            return theta / (1.0 - eps), k
        if theta >= target:
            return -1.0, k  # a Ritz value above the target: the step is over the limit
        if (c / np.sqrt(1.0 - theta / target) + 1.0) / 2.0 > max_steps:
            return -1.0, k  # too many steps would be needed if theta did not grow
        b = np.sqrt(ww)
        tnorm = max(tnorm, abs(a) + b + (beta[j - 1] if j else 0.0))
        if b > 0.0:  # Simon's recurrence for q_{j+1} . q_k, k <= j
            worst = 0.0
            for kk in range(j):
                v = (beta[kk] * om[kk + 1] + (alpha[kk] - a) * om[kk] - (beta[j - 1] * om_old[kk] if j else 0.0)
                     + (beta[kk - 1] * om[kk - 1] if kk else 0.0))
                v = (v + (noise * tnorm if v >= 0.0 else -noise * tnorm)) / b
                om_new[kk] = v
                worst = max(worst, abs(v))
            om_new[j] = noise * tnorm / b
            if force or worst > np.sqrt(unit):
                _reorthogonalise(Q, j + 1, w, h)
                b = np.sqrt(np.dot(w, w))
                for kk in range(j + 1):
                    om_new[kk] = noise
                force = not force  # the next vector too, once
            om_new[j + 1] = 1.0
            for kk in range(j + 2):
                om_old[kk] = om[kk]
                om[kk] = om_new[kk]
        if not b > 1e-13 * max(abs(a), theta, 1e-300):
            return -1.0, k  # an invariant subspace: no further step
        beta[j] = b
        if j + 1 < max_steps:
            for i in range(n):
                qi = w[i] / b
                q[i] = qi
                Q[j + 1, i] = qi
    return -1.0, max_steps


# a network this large whose numbering scatters its springs is renumbered by reverse Cuthill-McKee
# (945 k springs, 137 k nodes: 14 -> 8 ms a product for 54 ms; 18 k nodes: 0.68 -> 0.58 ms for 5 ms)
_RENUMBER_MIN_NODES = 65536
_RENUMBER_GAIN = 1.5  # by which the springs' mean index span must shrink


def _locality_order(conn, n_nodes):
    """``order`` (internal node ``i`` = given node ``order[i]``), or None to keep the numbering."""
    if n_nodes < _RENUMBER_MIN_NODES or not len(conn):
        return None
    g = sp.csr_matrix((np.ones(2 * len(conn), dtype=np.int8), (conn.ravel(), conn[:, ::-1].ravel())),
                      shape=(n_nodes, n_nodes))
    order = reverse_cuthill_mckee(g, symmetric_mode=True).astype(np.int64)
    new = np.empty(n_nodes, dtype=np.int64)
    new[order] = np.arange(n_nodes)
    span = float(np.abs(conn[:, 0] - conn[:, 1]).mean())
    return order if _RENUMBER_GAIN * float(np.abs(new[conn[:, 0]] - new[conn[:, 1]]).mean()) <= span else None


def _internal(a, order):
    """A per-dof array in the layout's numbering (``order``: :func:`_row_layout`)."""
    a = np.ascontiguousarray(a, dtype=float).reshape(-1)
    return a if order is None else np.ascontiguousarray(a.reshape(-1, 3)[order]).reshape(-1)


def _row_layout(springs, n_nodes):
    """The springs of the terms ``springs`` in rows by lower node: ``(rowptr, ib, conn, k, L0,
    order)``, ``conn`` (s, 2) the (lower, upper) nodes of each slot, ``k`` and ``L0`` its
    constants, in the numbering ``order`` (:func:`_locality_order`; None: the given one)."""
    conn = np.ascontiguousarray(np.concatenate([t.conn for t in springs]), dtype=np.int64)
    k = np.concatenate([np.asarray(t.k, dtype=float) for t in springs])
    L0 = np.concatenate([np.asarray(t.rest_length, dtype=float) for t in springs])
    order = _locality_order(conn, n_nodes)
    if order is not None:
        new = np.empty(n_nodes, dtype=np.int64)
        new[order] = np.arange(n_nodes)
        conn = new[conn]
    rowptr = np.zeros(n_nodes + 1, dtype=np.int64)
    slot = np.empty(len(conn), dtype=np.int64)
    ib = np.empty(len(conn), dtype=np.int64)
    _rows_by_lower_node(conn, n_nodes, rowptr, slot, ib)
    lower = np.repeat(np.arange(n_nodes, dtype=np.int64), np.diff(rowptr))
    return rowptr, ib, np.column_stack([lower, ib]), k[slot], L0[slot], order


def spring_rows(x, springs, isq, layout=None):
    """The springs of the terms ``springs`` at ``x`` in rows by lower node for
    :func:`certified_springs`: ``(rowptr, ib, coef, shift, isq, order)`` (``shift`` as in
    :func:`_scaled_operator`; ``isq`` and the products' vectors in the numbering ``order`` of
    :func:`_row_layout`), or None for coincident nodes.  ``layout``: :func:`_row_layout` of the
    same springs, when the caller has it."""
    x = np.ascontiguousarray(x, dtype=float).reshape(-1)
    rowptr, ib, conn, k, L0, order = layout if layout is not None else _row_layout(springs, x.size // 3)
    isq = _internal(isq, order)
    coef = np.empty((len(conn), 5))
    shift_rows = np.zeros(x.size)
    if not _spring_prep(_internal(x, order), conn, k, L0, isq, coef, shift_rows):
        return None
    return rowptr, ib, coef, float(shift_rows.max()) if shift_rows.size else 0.0, isq, order


def certified_springs(rows, omega_target: float, seed: int) -> tuple[float | None, int]:
    """:func:`certified_omega_max` for springs in rows (:func:`spring_rows`), the whole run in
    one compiled call: the same start vector (renumbered with the springs), steps and bound, with
    the Ritz value from Sturm bisection (upper end of its bracket) instead of LAPACK."""
    rowptr, ib, coef, shift, isq, order = rows
    n = isq.size
    target = omega_target * omega_target + shift
    c = float(np.log(1.648 * np.sqrt(n) / CERTIFICATE_FAILURE))
    steps = min(_CERT_MAX_STEPS, n)
    q = np.random.default_rng(seed).standard_normal(n)
    q = _internal(q / np.linalg.norm(q), order)
    lam, k = _certified_rows(rowptr, ib, coef, isq, shift, q, target, c, steps, np.empty((steps, n)),
                             np.zeros(steps), np.zeros(steps))
    return (None, int(k)) if lam < 0.0 else (float(np.sqrt(max(lam - shift, 0.0))), int(k))

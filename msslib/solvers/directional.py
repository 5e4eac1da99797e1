"""A deterministic bound of the explicit stability limit of 3D spring models that keeps the
directions of the springs (:func:`directional_bound`), used by
:func:`msslib.solvers.stability.check_time_step`: its first pass is the check's cheap bound on
such a model, a few more passes decide a step at 0.9 of the limit without any Lanczos run."""

from __future__ import annotations

import numpy as np
from numba import njit

from .certificate import _rows_by_lower_node, _spring_delta, _spring_terms, mass_vector

# the most passes of the directional bound (each about a third of a force evaluation)
_DIRECTIONAL_MAX_PASSES = 24


@njit(cache=True, nogil=True, inline="always")
def _add_spring(G, b, c, s0, s1, s2, s3, s4, s5, g0, g1, g2, g3, g4, g5):
    """A spring's ``c S`` (entries ``s``) into the other end ``b``'s sum ``G[b]`` and the row's
    own node sum ``g`` (returned)."""
    s0, s1, s2, s3, s4, s5 = c * s0, c * s1, c * s2, c * s3, c * s4, c * s5
    G[b, 0] += s0
    G[b, 1] += s1
    G[b, 2] += s2
    G[b, 3] += s3
    G[b, 4] += s4
    G[b, 5] += s5
    return g0 + s0, g1 + s1, g2 + s2, g3 + s3, g4 + s4, g5 + s5


@njit(cache=True, nogil=True)
def _directional_prep(x, conn, k, L0, rowptr, order, isq, w, S, G, g):
    """Per spring slot ``j`` (spring ``order[j]``, in rows by lower node: ``rowptr``) at ``x``:
    ``S[j]`` = the entries (xx, yy, zz, xy, xz, yz) of ``k (L0/l n n^T + max(1 - L0/l, 0) I)``, a
    positive semidefinite bound (Loewner order) of the spring's Hessian block
    ``k (L0/l n n^T + (1 - L0/l) I)``; in the same loop, the first pass of
    :func:`_directional_run` with the weights ``w`` into ``g`` (``G`` zero scratch, left zero).
    False for coincident nodes."""
    for na in range(rowptr.shape[0] - 1):
        wa = w[na]
        g0, g1, g2, g3, g4, g5 = G[na, 0], G[na, 1], G[na, 2], G[na, 3], G[na, 4], G[na, 5]
        for j in range(rowptr[na], rowptr[na + 1]):
            s = order[j]
            a = 3 * conn[s, 0]
            b = 3 * conn[s, 1]
            d0, d1, d2, l = _spring_delta(x, a, b)
            if not l > 0.0:
                return False
            il = 1.0 / l
            r = L0[s] * il
            n0, n1, n2 = d0 * il, d1 * il, d2 * il
            kr = k[s] * r
            cc = max(k[s] * (1.0 - r), 0.0)
            s0 = kr * n0 * n0 + cc
            s1 = kr * n1 * n1 + cc
            s2 = kr * n2 * n2 + cc
            s3 = kr * n0 * n1
            s4 = kr * n0 * n2
            s5 = kr * n1 * n2
            S[j, 0] = s0
            S[j, 1] = s1
            S[j, 2] = s2
            S[j, 3] = s3
            S[j, 4] = s4
            S[j, 5] = s5
            ob = (b if a == 3 * na else a) // 3  # the other end
            g0, g1, g2, g3, g4, g5 = _add_spring(G, ob, wa + w[ob], s0, s1, s2, s3, s4, s5, g0, g1, g2, g3, g4, g5)
        for e in range(6):
            G[na, e] = 0.0
        g[na] = _node_top(g0, g1, g2, g3, g4, g5, isq, 3 * na) if wa != 0.0 else 0.0
    return True


@njit(cache=True, nogil=True, inline="always")
def _sym3_top(a00, a11, a22, a01, a02, a12):
    """An upper bound of the largest eigenvalue of a symmetric 3x3 matrix ``A``, at most
    ``0.08 p`` above it, ``p`` the deviation of its eigenvalues from their mean ``q`` (the worst
    case is a double top eigenvalue), and ``q + 2 p`` (within ``2e-6 |q|``) when
    ``p <= 1e-6 |q|``.  With ``q`` the mean of the
    diagonal and ``B = A - q I``, the eigenvalues are ``q + mu`` for the roots ``mu`` of
    ``mu^3 - 3 p^2 mu - det B``, all in ``[-2p, 2p]``.  Four Newton steps from ``2 p`` stay above
    the largest root (the cubic is increasing and convex there), and a margin covers their
    rounding, whose scale is that of ``B`` (the polynomial of ``A`` itself loses everything to
    cancellation when ``A`` is nearly isotropic).  Four times cheaper than the closed form's
    arccos and cos."""
    q = (a00 + a11 + a22) / 3.0
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    off = a01 * a01 + a02 * a02 + a12 * a12
    p2 = (b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off) / 6.0
    p = np.sqrt(p2)
    det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02)
    mu = 2.0 * p
    if p <= 1e-6 * abs(q):  # nearly a multiple of the identity: q + 2 p is within 2e-6 of the top
        return q + mu + 1e-11 * (abs(q) + mu)
    for _ in range(4):
        f = (mu * mu - 3.0 * p2) * mu - det
        d = 3.0 * (mu * mu - p2)
        if not (f > 0.0 and d > 0.0):
            break
        mu -= f / d
    return q + mu + 1e-11 * (abs(q) + 2.0 * p)


@njit(cache=True, nogil=True, inline="always")
def _node_top(g0, g1, g2, g3, g4, g5, isq, a):
    """:func:`_sym3_top` of ``D G D`` for the node whose dofs start at ``a`` (``G`` its six
    entries, ``D`` its ``M^-1/2``), at least 0."""
    d0, d1, d2 = isq[a], isq[a + 1], isq[a + 2]
    return max(_sym3_top(g0 * d0 * d0, g1 * d1 * d1, g2 * d2 * d2, g3 * d0 * d1, g4 * d0 * d2, g5 * d1 * d2), 0.0)


@njit(cache=True, nogil=True)
def _directional_pass(rowptr, ib, S, isq, w, G, g):
    """One pass of :func:`_directional_run`: ``g`` of the weights ``w`` (``G`` zero scratch, left
    zero).  A node's sum is complete once its own row is done (the springs from lower nodes came
    before), so its eigenvalue is taken then, while it is in cache."""
    for a in range(rowptr.shape[0] - 1):
        wa = w[a]
        g0, g1, g2, g3, g4, g5 = G[a, 0], G[a, 1], G[a, 2], G[a, 3], G[a, 4], G[a, 5]
        for j in range(rowptr[a], rowptr[a + 1]):
            b = ib[j]
            g0, g1, g2, g3, g4, g5 = _add_spring(G, b, wa + w[b], S[j, 0], S[j, 1], S[j, 2], S[j, 3], S[j, 4], S[j, 5],
                                                 g0, g1, g2, g3, g4, g5)
        for e in range(6):
            G[a, e] = 0.0
        g[a] = _node_top(g0, g1, g2, g3, g4, g5, isq, 3 * a) if wa != 0.0 else 0.0


@njit(cache=True, nogil=True)
def _directional_run(rowptr, ib, S, isq, w, g, G, lam_target, max_passes):
    """The passes of :func:`directional_bound` on springs in rows by lower node (``rowptr``,
    ``ib``, ``S`` per slot), from the weights ``w`` and the first pass's ``g``
    (:func:`_directional_prep`): ``(bound, passes, accepted)``.  The update is
    ``w <- g(w)^2 / w`` until a pass does not lower the bound, then ``w <- g(w)`` from the best
    weights so far."""
    nn = rowptr.shape[0] - 1
    best = np.inf
    prev = -1.0
    w_best = w.copy()
    g_best = g.copy()
    power = 2.0
    k = 1
    while True:
        hi = 0.0
        lo = np.inf
        gmax = 0.0
        for a in range(nn):
            if w[a] != 0.0:
                ratio = g[a] / w[a]
                if not ratio <= hi:  # larger, or not a number
                    hi = ratio
                lo = min(lo, ratio)
                gmax = max(gmax, g[a])
        if not hi < np.inf:
            return best, k, False
        improved = hi < best
        if improved:
            best = hi
            w_best[:] = w
            g_best[:] = g
        if best <= lam_target:
            return best, k, True
        if lo >= lam_target or gmax == 0.0 or k >= max_passes:
            return best, k, False  # lo: the bound's own limit is above the target, no weights get there
        if not improved and power == 2.0:  # the bold update overshot: plain updates from the best weights
            power = 1.0
            w[:] = w_best
            g[:] = g_best
        elif prev >= 0.0 and best - lam_target > (prev - best) * (max_passes - k):
            return best, k, False  # falling at its last rate, it would not get there in time
        prev = best
        top = 0.0
        for i in range(nn):
            if w[i] != 0.0:
                w[i] = g[i] * (g[i] / w[i]) if power == 2.0 else g[i]
                top = max(top, w[i])
        for i in range(nn):
            if w[i] != 0.0:
                w[i] = max(w[i] / top, 1e-300)
        _directional_pass(rowptr, ib, S, isq, w, G, g)
        k += 1


def directional_setup(problem, x, free):
    """What :func:`directional_bound` runs on, for a 3D spring model with dead loads only (else,
    or for coincident nodes, None): ``(rowptr, ib, S, isq, w, g, G)``, the springs in rows by
    lower node with their bounds ``S`` (:func:`_directional_prep`), ``M^-1/2`` on the free
    dofs, the first weights (1 on the nodes with a free dof, 0 elsewhere), the first pass's node
    values ``g`` (its bound is ``max g``: the cheap bound of a spring model) and scratch, in one
    loop over the springs."""
    springs = _spring_terms(problem)
    if springs is None:
        return None
    m = mass_vector(problem)
    if np.any(m[free] <= 0):
        raise ValueError("masses of free dofs must be positive")
    isq = np.zeros(m.size)
    isq[free] = 1.0 / np.sqrt(m[free])
    nn = m.size // 3
    if len(springs) == 1:
        t = springs[0]
        conn, k, L0 = t.conn, np.asarray(t.k, dtype=float), np.asarray(t.rest_length, dtype=float)
        rowptr, order, ib = t.lower_node_rows(nn)
    else:
        conn = np.ascontiguousarray(np.concatenate([t.conn for t in springs]), dtype=np.int64)
        k = np.concatenate([np.asarray(t.k, dtype=float) for t in springs])
        L0 = np.concatenate([np.asarray(t.rest_length, dtype=float) for t in springs])
        rowptr = np.zeros(nn + 1, dtype=np.int64)
        order = np.empty(len(conn), dtype=np.int64)
        ib = np.empty(len(conn), dtype=np.int64)
        _rows_by_lower_node(conn, nn, rowptr, order, ib)
    S = np.empty((len(conn), 6))
    w = (isq.reshape(-1, 3) > 0.0).any(axis=1).astype(float)
    G = np.zeros((nn, 6))
    g = np.zeros(nn)
    if not _directional_prep(np.ascontiguousarray(x, dtype=float).reshape(-1), conn, k, L0, rowptr, order, isq, w, S,
                             G, g):
        return None
    return rowptr, ib, S, isq, w, g, G


def directional_bound(problem, x, free, lam_target: float, setup=None, max_passes=None) -> tuple[float | None, int]:
    """A deterministic bound of the top eigenvalue of ``M^-1 K`` (free dofs) of a 3D spring
    model, tried up to ``lam_target``: ``(lam, passes)`` with ``lam <= lam_target``, or None when
    it does not get there (or the model is not springs and dead loads only).

    For a spring ``s`` between nodes ``a`` and ``b`` with the positive semidefinite bound ``S_s``
    of its Hessian block (:func:`_directional_prep`) and any ``t > 0``,
    ``(u_b - u_a)^T S_s (u_b - u_a) <= (1 + t) u_a^T S_s u_a + (1 + 1/t) u_b^T S_s u_b``
    (Cauchy-Schwarz and Young).  With ``t = w_b / w_a`` for positive node weights ``w`` (0 on a
    node without free dofs, which does not move), ``u^T K u`` is at most a sum over the nodes of
    ``u_i^T G_i u_i / w_i`` with ``G_i`` the sum over its springs of ``(w_i + w_j) S_s``, so
    every eigenvalue of ``M^-1 K`` is at most ``max_i g_i(w) / w_i``, ``g_i`` the largest
    eigenvalue of ``M_i^-1/2 G_i M_i^-1/2`` on the node's free dofs.  Unlike Gershgorin's and
    Collatz-Wielandt's bounds, which take absolute values entry by entry, it keeps the
    directions of a node's springs: springs that pull a node in different directions do not add
    up.  ``w`` starts at 1 and follows ``w <- g(w)`` (a power iteration of the monotone,
    homogeneous map ``g``; any positive ``w`` gives a bound, so the update may be bold:
    ``w <- g(w)^2 / w`` while the bound falls, which halves the passes on the benchmark's
    networks, then ``w <- g(w)``); each pass is one loop over the springs and an upper bound of
    a 3x3 eigenvalue per node (:func:`_sym3_top`).  The run stops when the bound reaches ``lam_target``, when
    ``min_i g_i / w_i`` (which no weights can bring the bound below) exceeds it, or when the
    bound, falling at its last rate, would not reach it within :data:`_DIRECTIONAL_MAX_PASSES`.
    On the benchmark's networks (Golec's lattice of 95 k springs, Lloyd's tetrahedra of 122 k) it
    reaches 1.035-1.05 times the top eigenvalue within eight passes (steps up to 0.98 of the
    limit), 1.13-1.15 in two (0.94: a step at 0.9 of the limit takes two passes); with node masses spread over a factor of
    10 it still reaches 1.05-1.3 on small meshes (tests/test_stability_directional.py)."""
    setup = setup if setup is not None else directional_setup(problem, x, free)
    if setup is None:
        return None, 0
    rowptr, ib, S, isq, w, g, G = setup
    lam, passes, ok = _directional_run(rowptr, ib, S, isq, w.copy(), g.copy(), G, float(lam_target),
                                       _DIRECTIONAL_MAX_PASSES if max_passes is None else int(max_passes))
    return (float(lam), int(passes)) if ok else (None, int(passes))

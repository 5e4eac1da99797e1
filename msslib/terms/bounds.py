"""Row sums of ``|K|`` for a cheap, safe bound of the top eigenvalue (Gershgorin).

For the mass-scaled stiffness ``A = M^-1/2 K M^-1/2`` restricted to the free dofs, every
eigenvalue is at most ``max_i sum_j |A_ij|`` (Gershgorin's theorem), and ``|A_ij|`` of a sum of
terms is at most the sum of the terms' ``|A_ij|``; so each term may add its own row sums.
``isq`` is ``1 / sqrt(m)`` per dof, zero on the fixed dofs (which removes their rows and columns).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["spring3d_abs_rows", "spring3d_abs_row_terms", "spring_delta", "csr_abs_rows"]


@njit(cache=True, nogil=True, inline="always")
def spring_delta(x, a, b):
    """``(d0, d1, d2, l)``: the vector from the node at dofs ``a`` to the node at dofs ``b`` and its
    length (0 for coincident nodes)."""
    d0 = x[b] - x[a]
    d1 = x[b + 1] - x[a + 1]
    d2 = x[b + 2] - x[a + 2]
    return d0, d1, d2, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, nogil=True, inline="always")
def spring3d_abs_row_terms(x, a, b, k, L0, scale, isq):
    """One spring between the dofs ``a:a+3`` and ``b:b+3`` (see :func:`spring3d_abs_rows`):
    ``(r, n0, n1, n2, t0, t1, t2)``, ``r = L0 / l`` (infinite for coincident nodes), ``n`` the
    unit vector from ``a`` to ``b``, and ``t`` such that row ``a + i`` gains ``isq[a + i] t_i``
    and row ``b + i`` gains ``isq[b + i] t_i``."""
    d0, d1, d2, l = spring_delta(x, a, b)
    if l > 0.0:
        il = 1.0 / l
        r = L0 * il
        n0, n1, n2 = d0 * il, d1 * il, d2 * il
    else:  # coincident nodes: bound the block by its largest possible entries
        r = np.inf
        n0, n1, n2 = 1.0, 1.0, 1.0
    kk = abs(k) * abs(scale)
    c = abs(1.0 - r)
    # row i of the block: sum_j |H_ij| (isq_a_j + isq_b_j) = r |n_i| sum_j |n_j| s_j + |1 - r| s_i
    an0, an1, an2 = abs(n0), abs(n1), abs(n2)
    s0 = isq[a] + isq[b]
    s1 = isq[a + 1] + isq[b + 1]
    s2 = isq[a + 2] + isq[b + 2]
    dot = r * (an0 * s0 + an1 * s1 + an2 * s2)
    return r, n0, n1, n2, kk * (an0 * dot + c * s0), kk * (an1 * dot + c * s1), kk * (an2 * dot + c * s2)


@njit(cache=True, nogil=True)
def spring3d_abs_rows(x, conn, k, L0, scale, isq, out):
    """Springs ``k/2 (l - L0)^2``: Hessian block ``H = k (L0/l n n^T + (1 - L0/l) I)`` on the
    diagonal blocks and ``-H`` off them."""
    for s in range(conn.shape[0]):
        a = 3 * conn[s, 0]
        b = 3 * conn[s, 1]
        _, _, _, _, t0, t1, t2 = spring3d_abs_row_terms(x, a, b, k[s], L0[s], scale, isq)
        out[a] += isq[a] * t0
        out[a + 1] += isq[a + 1] * t1
        out[a + 2] += isq[a + 2] * t2
        out[b] += isq[b] * t0
        out[b + 1] += isq[b + 1] * t1
        out[b + 2] += isq[b + 2] * t2


@njit(cache=True, nogil=True)
def csr_abs_rows(indptr, indices, data, isq, out):
    """Any assembled stiffness (CSR, all dofs)."""
    for i in range(indptr.shape[0] - 1):
        ri = isq[i]
        if ri == 0.0:
            continue
        tot = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            tot += abs(data[p]) * isq[indices[p]]
        out[i] += ri * tot

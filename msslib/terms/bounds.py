"""Row sums of ``|K|`` for a cheap, safe bound of the top eigenvalue (Gershgorin).

For the mass-scaled stiffness ``A = M^-1/2 K M^-1/2`` restricted to the free dofs, every
eigenvalue is at most ``max_i sum_j |A_ij|`` (Gershgorin's theorem), and ``|A_ij|`` of a sum of
terms is at most the sum of the terms' ``|A_ij|``; so each term may add its own row sums.
``isq`` is ``1 / sqrt(m)`` per dof, zero on the fixed dofs (which removes their rows and columns).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["spring3d_abs_rows", "csr_abs_rows"]


@njit(cache=True, nogil=True)
def spring3d_abs_rows(x, conn, k, L0, scale, isq, out):
    """Springs ``k/2 (l - L0)^2``: Hessian block ``H = k (L0/l n n^T + (1 - L0/l) I)`` on the
    diagonal blocks and ``-H`` off them."""
    for s in range(conn.shape[0]):
        a = 3 * conn[s, 0]
        b = 3 * conn[s, 1]
        d0 = x[b] - x[a]
        d1 = x[b + 1] - x[a + 1]
        d2 = x[b + 2] - x[a + 2]
        l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if l > 0.0:
            r = L0[s] / l
            n0, n1, n2 = d0 / l, d1 / l, d2 / l
        else:  # coincident nodes: bound the block by its largest possible entries
            r = np.inf
            n0, n1, n2 = 1.0, 1.0, 1.0
        kk = abs(k[s]) * abs(scale)
        for i in range(3):
            ni = n0 if i == 0 else (n1 if i == 1 else n2)
            ra = isq[a + i]
            rb = isq[b + i]
            if ra == 0.0 and rb == 0.0:
                continue
            tot = 0.0
            for j in range(3):
                nj = n0 if j == 0 else (n1 if j == 1 else n2)
                h = r * abs(ni * nj)
                if i == j:
                    h += abs(1.0 - r)
                else:
                    h += 0.0
                tot += kk * h * (isq[a + j] + isq[b + j])
            out[a + i] += ra * tot
            out[b + i] += rb * tot


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

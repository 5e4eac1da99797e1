"""Compiled assembly of the finite-strain references' tangent: the element stiffness
``K_e[a i, b k] = sum_q dphi_a,J A_iJkL dphi_b,L dx`` formed element by element and added
straight into the values of a CSR matrix whose pattern (:func:`dof_pattern`) is computed once per
mesh: no element-matrix array, no COO triplets sorted on every Newton iteration."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit


def dof_pattern(nodes: np.ndarray, n_scalar: int, dim: int):
    """``(indptr, indices)`` (read-only, int64) of the interleaved-dof matrix of elements with
    scalar dofs ``nodes`` ``(nb, m)``: every dof of a node couples with every dof of the nodes
    sharing an element with it; a row's columns sorted, a node's ``dim`` columns adjacent."""
    nb, m = nodes.shape
    rows = np.repeat(nodes.T, nb, axis=1).ravel()
    cols = np.tile(nodes.T, (1, nb)).ravel()
    S = sp.csr_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(n_scalar, n_scalar))
    S.sum_duplicates()
    S.sort_indices()
    deg = np.diff(S.indptr)  # scalar neighbours per scalar row
    row_len = np.repeat(deg * dim, dim)  # dof row d i + a: dim columns per neighbour
    indptr = np.zeros(n_scalar * dim + 1, dtype=np.int64)
    np.cumsum(row_len, out=indptr[1:])
    # the columns of scalar row i, each expanded to dim dofs, repeated for the dim rows of node i
    expanded = (S.indices.astype(np.int64)[:, None] * dim + np.arange(dim)).ravel()  # per scalar row, in order
    starts = np.repeat(S.indptr[:-1] * dim, dim)
    lengths = row_len
    idx = np.repeat(starts - indptr[:-1], lengths) + np.arange(indptr[-1])
    indices = expanded[idx]
    indptr.flags.writeable = False
    indices.flags.writeable = False
    return indptr, indices


@njit(cache=True, nogil=True)
def _find(indices, lo, hi, col):
    while lo < hi:
        mid = (lo + hi) // 2
        if indices[mid] < col:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, nogil=True)
def add_tangent(dphi, A, dx, w, nodes, dim, indptr, indices, data):
    """Add ``w sum_q dphi[a, J] A[i, J, k, L] dphi[b, L] dx`` of every element to ``data`` (the
    values of the CSR matrix ``(indptr, indices)`` of :func:`dof_pattern`).  ``dphi`` ``(nb, d,
    m, q)``, ``A`` ``(d, d, d, d, m, q)``, ``dx`` ``(m, q)``, ``nodes`` ``(nb, m)``."""
    nb, d, m, nq = dphi.shape
    k = nb * d
    ke = np.zeros((k, k))
    G = np.empty((nb, d, d, d))
    for e in range(m):
        ke[:, :] = 0.0
        for q in range(nq):
            wq = dx[e, q] * w
            for a in range(nb):
                for i in range(d):
                    for kk in range(d):
                        for L in range(d):
                            s = 0.0
                            for J in range(d):
                                s += dphi[a, J, e, q] * A[i, J, kk, L, e, q]
                            G[a, i, kk, L] = s * wq
            for b in range(nb):
                for L in range(d):
                    g = dphi[b, L, e, q]
                    if g == 0.0:
                        continue
                    for a in range(nb):
                        for i in range(d):
                            r = a * d + i
                            for kk in range(d):
                                ke[r, b * d + kk] += G[a, i, kk, L] * g
        for a in range(nb):
            na = nodes[a, e]
            for i in range(d):
                row = na * dim + i
                lo, hi = indptr[row], indptr[row + 1]
                for b in range(nb):
                    p = _find(indices, lo, hi, nodes[b, e] * dim)
                    for kk in range(d):
                        data[p + kk] += ke[a * d + i, b * d + kk]

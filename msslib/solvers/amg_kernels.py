"""Compiled kernels of the smoothed-aggregation AMG: inverse diagonal blocks, the smoothed
prolongator, block Gauss-Seidel sweeps, BSR products, the fused residual-restriction and the
Galerkin product (see :mod:`msslib.solvers.amg` and :mod:`msslib.solvers.amg_cycle`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from .submatrices import _U


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
def _acc_product(out, a, b, a_transposed):
    """``out += a b`` (or ``a^T b``) for small dense blocks; the generic (not 3 x 3) path of the
    block products below, inlined."""
    for r in range(out.shape[0]):
        for s in range(b.shape[0]):
            av = a[s, r] if a_transposed else a[r, s]
            for c in range(out.shape[1]):
                out[r, c] += av * b[s, c]


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
                _acc_product(y[_U(K)], a_data[_U(q)], t_data[_U(pt)], False)
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


@njit(inline="always", nogil=True, fastmath={"contract"})
def _acc_block3(B, x, j, a0, a1, a2, sign):
    """``(a0, a1, a2) + sign B x[j:j + 3]`` for a 3 x 3 block ``B`` (inlined; ``sign`` is +-1)."""
    b0, b1, b2 = _block3_times(B, x[j], x[j + _U(1)], x[j + _U(2)])
    return a0 + sign * b0, a1 + sign * b1, a2 + sign * b2


@njit(cache=True, nogil=True, fastmath={"contract"})
def _bsr3_matvec(indptr, indices, data, x, y):
    """:func:`_bsr_matvec` unrolled for 3 x 3 blocks (about a third faster: it then runs near
    the memory bandwidth)."""
    for i in range(indptr.shape[0] - 1):
        a0 = a1 = a2 = 0.0
        for q in range(indptr[_U(i)], indptr[_U(i + 1)]):
            a0, a1, a2 = _acc_block3(data[_U(q)], x, _U(3 * indices[_U(q)]), a0, a1, a2, 1.0)
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
            r0, r1, r2 = _acc_block3(data[_U(q)], x, _U(3 * jb), r0, r1, r2, -1.0)
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
            r0, r1, r2 = _acc_block3(data[_U(q)], x, _U(3 * jb), r0, r1, r2, -1.0)
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
                r0, r1, r2 = _acc_block3(data[_U(q)], x, _U(3 * jb), r0, r1, r2, -1.0)
        x[_U(3 * i)], x[_U(3 * i + 1)], x[_U(3 * i + 2)] = _block3_times(dinv[_U(i)], r0, r1, r2)


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
                    _acc_product(c_data[_U(t)], p_data[_U(pp)], y[_U(K)], True)


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

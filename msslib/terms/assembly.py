"""Hessian assembly: element block patterns and the numba loops that add Hessian values into
the data of CSR and BSR matrices with a node-blocked pattern (see :class:`msslib.system.Model`).

Node-blocked pattern: node row ``a`` has ``deg = nptr[a + 1] - nptr[a]`` neighbour nodes
(itself included), each standing for a ``dim x dim`` block; dof row ``dim a + i`` lists
``dim b + j`` for the nodes ``b`` of node row ``a`` (sorted), ``j = 0..dim-1``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .jit import _FAST, UINT, njit_cached, _jit_fast

_inline = njit(inline="always", error_model="numpy", nogil=True, fastmath=_FAST)


@_inline
def _put(data, i, v, assign):
    """``data[i] = v`` with ``assign``, else ``data[i] += v``."""
    if assign:
        data[UINT(i)] = v
    else:
        data[UINT(i)] += v


@_inline
def _put_sym3(data, q, w, v00, v01, v02, v11, v12, v22, assign):
    """:func:`_put` of the symmetric 3 x 3 block ``[[v00, v01, v02], [v01, v11, v12],
    [v02, v12, v22]]`` whose rows start at ``q``, ``q + w`` and ``q + 2 w`` of the flat
    ``data``."""
    _put(data, q, v00, assign)
    _put(data, q + 1, v01, assign)
    _put(data, q + 2, v02, assign)
    _put(data, q + w, v01, assign)
    _put(data, q + w + 1, v11, assign)
    _put(data, q + w + 2, v12, assign)
    _put(data, q + 2 * w, v02, assign)
    _put(data, q + 2 * w + 1, v12, assign)
    _put(data, q + 2 * w + 2, v22, assign)


@_jit_fast
def _spring3d_hessian(x, rowptr, nb, k, L0, pos, nptr, diag, bmap, scale, assign, data):
    """Add ``scale`` times the spring Hessian to the flat values ``data`` of a node-blocked
    pattern (or, with ``assign``, overwrite the node rows the springs cover: valid when these
    springs hit every block of those rows exactly once, which saves zeroing and re-reading
    ``data``): those of a CSR matrix when ``bmap`` is empty, else those of a BSR matrix
    (``(n_blocks, 3, 3)``, flattened) that keeps some of the node blocks.

    Symmetric node layout: ``rowptr``/``nb``/``k``/``L0`` list for every node ``a`` *all* springs
    touching it (each spring twice, once from each end), so that node rows are filled one at a
    time, in order (no scattered writes; twice the arithmetic, which is cheaper than the cache
    misses).  Node row ``a`` has ``deg = nptr[a + 1] - nptr[a]`` neighbour nodes (itself
    included); ``pos`` gives the position ``p`` of the other node ``b`` in node row ``a`` per
    listed spring, ``diag`` that of ``a`` per node.  CSR: dof row ``3 a + i`` starts at
    ``9 nptr[a] + 3 i deg`` and entry ``(3 a + i, 3 b + j)`` sits at ``+ 3 p + j``.  BSR: block
    ``p`` of node row ``a`` goes to block ``bmap[nptr[a] + p]``, or nowhere when that is
    negative (rows and columns of constrained nodes); a row whose diagonal block is not kept is
    skipped whole.

    Per node row: (1) gather the differences ``d = x_a - x_b`` into a small local array,
    (2) compute the six distinct entries of every block there (a loop over contiguous memory,
    which the compiler vectorises: sqrt and division included), (3) write the blocks: for CSR
    the three dof rows one after the other.  With ``u = L0 / l`` the spring block is
    ``k [(1 - u) I + u d d^T / l^2]``; the off-diagonal blocks are minus it, the diagonal block
    the sum over the node's springs."""
    blocked = bmap.shape[0] > 0
    c = np.empty((9, 64))
    for na in range(rowptr.shape[0] - 1):
        q0 = nptr[na]
        if blocked:
            td = bmap[UINT(q0 + diag[na])]
            if td < 0:
                continue
            qd = 9 * td  # the diagonal block, rows w apart
            w = 3
        else:
            qd = 9 * q0 + 3 * diag[na]
            w = 3 * (nptr[na + 1] - q0)
        a = 3 * na
        s0 = rowptr[na]
        m = rowptr[na + 1] - s0
        if m > c.shape[1]:
            c = np.empty((9, 2 * m))
        xa0, xa1, xa2 = x[a], x[a + 1], x[a + 2]
        for j in range(m):
            b = 3 * nb[UINT(s0 + j)]
            c[6, j] = xa0 - x[UINT(b)]
            c[7, j] = xa1 - x[UINT(b + 1)]
            c[8, j] = xa2 - x[UINT(b + 2)]
        kk = k[s0:s0 + m]
        ll = L0[s0:s0 + m]
        for j in range(m):
            d0 = c[6, j]
            d1 = c[7, j]
            d2 = c[8, j]
            il = 1.0 / np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            ks = kk[j] * scale
            t = ks * ll[j] * il
            c10 = t - ks
            c14 = -t * il * il
            c[0, j] = d0 * d0 * c14 + c10
            c[1, j] = d0 * d1 * c14
            c[2, j] = d0 * d2 * c14
            c[3, j] = d1 * d1 * c14 + c10
            c[4, j] = d1 * d2 * c14
            c[5, j] = d2 * d2 * c14 + c10
        h00 = 0.0
        h01 = 0.0
        h02 = 0.0
        h11 = 0.0
        h12 = 0.0
        h22 = 0.0
        for j in range(m):
            h00 -= c[0, j]
            h01 -= c[1, j]
            h02 -= c[2, j]
            h11 -= c[3, j]
            h12 -= c[4, j]
            h22 -= c[5, j]
        if blocked:
            for j in range(m):
                tb = bmap[UINT(q0 + pos[UINT(s0 + j)])]
                if tb >= 0:
                    _put_sym3(data, 9 * tb, 3, c[0, j], c[1, j], c[2, j], c[3, j], c[4, j], c[5, j], assign)
        else:
            for i in range(3):  # dof row 3 a + i: block row i is (c[i0], c[i1], c[i2])
                r0 = 9 * q0 + i * w
                i0 = i if i < 2 else 2
                i1 = 1 if i == 0 else (3 if i == 1 else 4)
                i2 = 2 if i == 0 else (4 if i == 1 else 5)
                if assign:
                    for j in range(m):
                        q = r0 + 3 * pos[UINT(s0 + j)]
                        data[UINT(q)] = c[i0, j]
                        data[UINT(q + 1)] = c[i1, j]
                        data[UINT(q + 2)] = c[i2, j]
                else:
                    for j in range(m):
                        q = r0 + 3 * pos[UINT(s0 + j)]
                        data[UINT(q)] += c[i0, j]
                        data[UINT(q + 1)] += c[i1, j]
                        data[UINT(q + 2)] += c[i2, j]
        _put_sym3(data, qd, w, h00, h01, h02, h11, h12, h22, assign)


@_jit_fast
def spring3d_hessian_csr(x, rowptr, nb, k, L0, pos, nptr, diag, scale, assign, data):
    """:func:`_spring3d_hessian` into the values ``data`` of a CSR matrix."""
    _spring3d_hessian(x, rowptr, nb, k, L0, pos, nptr, diag, np.empty(0, dtype=np.int32), scale, assign, data)


@_jit_fast
def spring3d_hessian_bsr(x, rowptr, nb, k, L0, pos, nptr, diag, bmap, scale, assign, data):
    """:func:`_spring3d_hessian` into the ``(n_blocks, 3, 3)`` values ``data`` of a BSR matrix
    (``bmap`` not empty)."""
    _spring3d_hessian(x, rowptr, nb, k, L0, pos, nptr, diag, bmap, scale, assign, data.reshape(-1))


@njit_cached
def block_scatter_bsr(vals, conn, pos, nptr, bmap, scale, data):
    """:func:`block_scatter_csr` into the ``(n_blocks, dim, dim)`` values of a BSR matrix that
    keeps some of the node blocks (``bmap``: see :func:`_spring3d_hessian`)."""
    m, nv = conn.shape
    dim = data.shape[1]
    n_loc = nv * dim
    for e in range(m):
        for p in range(nv):
            q0 = nptr[conn[e, p]]
            for q in range(nv):
                tb = bmap[UINT(q0 + pos[e, p, q])]
                if tb < 0:
                    continue
                for i in range(dim):
                    off = (p * dim + i) * n_loc + q * dim
                    for j in range(dim):
                        data[UINT(tb), i, j] += scale * vals[e, off + j]


@njit_cached
def block_scatter_csr(vals, conn, pos, nptr, dim, scale, data):
    """Add ``scale`` times dense element blocks ``vals`` (m, (nv dim)^2, row-major) to CSR ``data``
    of a node-blocked pattern; ``pos[e, p, q]`` position of node ``conn[e, q]`` in node row
    ``conn[e, p]`` (see :func:`_spring3d_hessian`)."""
    m, nv = conn.shape
    n_loc = nv * dim
    for e in range(m):
        for p in range(nv):
            na = conn[e, p]
            ra = dim * dim * nptr[na]
            deg = dim * (nptr[na + 1] - nptr[na])
            for i in range(dim):
                row = ra + i * deg
                base = (p * dim + i) * n_loc
                for q in range(nv):
                    col = row + dim * pos[e, p, q]
                    off = base + q * dim
                    for j in range(dim):
                        data[col + j] += scale * vals[e, off + j]


@njit_cached
def scatter_add(data, slots, vals, scale):
    for i in range(slots.shape[0]):
        data[slots[i]] += scale * vals[i]


def block_pattern(conn: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and cols of dense element blocks, element-major, each block row-major."""
    m, nv = conn.shape
    dofs = (dim * conn[:, :, None] + np.arange(dim)).reshape(m, nv * dim)
    n_loc = nv * dim
    rows = np.repeat(dofs, n_loc, axis=1).ravel()
    cols = np.tile(dofs, (1, n_loc)).ravel()
    return rows, cols


@njit(cache=True, nogil=True)
def expand_block_pattern(nptr, ucol, dim, indices, indptr):
    """Dof-level CSR (indices, indptr) of a node-level pattern (nptr, ucol): every node entry
    becomes a dim x dim block; row ``dim a + i`` lists ``dim b + j`` for the nodes ``b`` of node
    row ``a`` (sorted), ``j = 0..dim-1``."""
    nn = nptr.shape[0] - 1
    for a in range(nn):
        deg = nptr[a + 1] - nptr[a]
        for i in range(dim):
            start = dim * dim * nptr[a] + i * dim * deg
            indptr[dim * a + i] = start
            q = start
            for e in range(nptr[a], nptr[a + 1]):
                for j in range(dim):
                    indices[q] = dim * ucol[e] + j
                    q += 1
    indptr[dim * nn] = dim * dim * nptr[nn]

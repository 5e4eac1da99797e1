"""Hessian assembly: element block patterns and the numba loops that add Hessian values into
the data of CSR and BSR matrices with a node-blocked pattern (see :class:`msslib.model.Model`).

Node-blocked pattern: node row ``a`` has ``deg = nptr[a + 1] - nptr[a]`` neighbour nodes
(itself included), each standing for a ``dim x dim`` block; dof row ``dim a + i`` lists
``dim b + j`` for the nodes ``b`` of node row ``a`` (sorted), ``j = 0..dim-1``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .jit import _U, _jit, _jit_fast


@_jit_fast
def _spring3d_hessian_csr(x, rowptr, nb, k, L0, pos, nptr, diag, scale, assign, data):
    """Add ``scale`` times the spring Hessian to CSR ``data`` of a node-blocked pattern (or, with
    ``assign``, overwrite the node rows the springs cover: valid when these springs hit every
    block of those rows exactly once, which saves zeroing and re-reading ``data``).

    Symmetric node layout: ``rowptr``/``nb``/``k``/``L0`` list for every node ``a`` *all* springs
    touching it (each spring twice, once from each end), so that dof rows are filled one node
    row at a time, in order (no scattered writes; twice the arithmetic, which is cheaper than
    the cache misses).  Node row ``a`` has ``deg = nptr[a + 1] - nptr[a]`` neighbour nodes
    (itself included); dof row ``3 a + i`` starts at ``9 nptr[a] + 3 i deg`` and entry
    ``(3 a + i, 3 b + j)`` sits at ``+ 3 p + j`` with ``p`` the position of ``b`` in node row
    ``a`` (``pos`` per listed spring, ``diag`` per node).

    Per node row: (1) gather the differences ``d = x_a - x_b`` into a small local array,
    (2) compute the six distinct entries of every block there (a loop over contiguous memory,
    which the compiler vectorises: sqrt and division included), (3) write the three dof rows
    one after the other.  With ``u = L0 / l`` the spring block is
    ``k [(1 - u) I + u d d^T / l^2]``; the off-diagonal blocks are minus it, the diagonal block
    the sum over the node's springs."""
    c = np.empty((9, 64))
    for na in range(rowptr.shape[0] - 1):
        a = 3 * na
        ra = 9 * nptr[na]
        deg = 3 * (nptr[na + 1] - nptr[na])
        s0 = rowptr[na]
        m = rowptr[na + 1] - s0
        if m > c.shape[1]:
            c = np.empty((9, 2 * m))
        xa0, xa1, xa2 = x[a], x[a + 1], x[a + 2]
        for j in range(m):
            b = 3 * nb[s0 + j]
            c[6, j] = xa0 - x[_U(b)]
            c[7, j] = xa1 - x[_U(b + 1)]
            c[8, j] = xa2 - x[_U(b + 2)]
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
        for i in range(3):  # dof row 3 a + i: block row i is (c[i0], c[i1], c[i2])
            r0 = ra + i * deg
            i0 = i if i < 2 else 2
            i1 = 1 if i == 0 else (3 if i == 1 else 4)
            i2 = 2 if i == 0 else (4 if i == 1 else 5)
            if assign:
                for j in range(m):
                    q = r0 + 3 * pos[_U(s0 + j)]
                    data[_U(q)] = c[i0, j]
                    data[_U(q + 1)] = c[i1, j]
                    data[_U(q + 2)] = c[i2, j]
            else:
                for j in range(m):
                    q = r0 + 3 * pos[_U(s0 + j)]
                    data[_U(q)] += c[i0, j]
                    data[_U(q + 1)] += c[i1, j]
                    data[_U(q + 2)] += c[i2, j]
        qd = ra + 3 * diag[na]
        if assign:
            data[_U(qd)] = h00
            data[_U(qd + 1)] = h01
            data[_U(qd + 2)] = h02
            data[_U(qd + deg)] = h01
            data[_U(qd + deg + 1)] = h11
            data[_U(qd + deg + 2)] = h12
            data[_U(qd + 2 * deg)] = h02
            data[_U(qd + 2 * deg + 1)] = h12
            data[_U(qd + 2 * deg + 2)] = h22
        else:
            data[_U(qd)] += h00
            data[_U(qd + 1)] += h01
            data[_U(qd + 2)] += h02
            data[_U(qd + deg)] += h01
            data[_U(qd + deg + 1)] += h11
            data[_U(qd + deg + 2)] += h12
            data[_U(qd + 2 * deg)] += h02
            data[_U(qd + 2 * deg + 1)] += h12
            data[_U(qd + 2 * deg + 2)] += h22


@_jit_fast
def _spring3d_hessian_bsr(x, rowptr, nb, k, L0, pos, nptr, diag, bmap, scale, assign, data):
    """:func:`_spring3d_hessian_csr` into the ``(n_blocks, 3, 3)`` values of a BSR matrix that
    keeps some of the node blocks: block ``p`` of node row ``a`` of the full node pattern goes
    to ``data[bmap[nptr[a] + p]]``, or nowhere when that is negative (rows and columns of
    constrained nodes); a row whose diagonal block is not kept is skipped whole.

    The gather and block arithmetic repeat those of :func:`_spring3d_hessian_csr` on purpose:
    moved into a shared compiled helper, they made the CSR refill (a benchmark target) 5-8 %
    slower."""
    c = np.empty((9, 64))
    for na in range(rowptr.shape[0] - 1):
        q0 = nptr[na]
        td = bmap[_U(q0 + diag[na])]
        if td < 0:
            continue
        a = 3 * na
        s0 = rowptr[na]
        m = rowptr[na + 1] - s0
        if m > c.shape[1]:
            c = np.empty((9, 2 * m))
        xa0, xa1, xa2 = x[a], x[a + 1], x[a + 2]
        for j in range(m):
            b = 3 * nb[_U(s0 + j)]
            c[6, j] = xa0 - x[_U(b)]
            c[7, j] = xa1 - x[_U(b + 1)]
            c[8, j] = xa2 - x[_U(b + 2)]
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
        for j in range(m):
            tb = bmap[_U(q0 + pos[_U(s0 + j)])]
            if tb < 0:
                continue
            u = _U(tb)
            if assign:
                data[u, 0, 0] = c[0, j]
                data[u, 0, 1] = c[1, j]
                data[u, 0, 2] = c[2, j]
                data[u, 1, 0] = c[1, j]
                data[u, 1, 1] = c[3, j]
                data[u, 1, 2] = c[4, j]
                data[u, 2, 0] = c[2, j]
                data[u, 2, 1] = c[4, j]
                data[u, 2, 2] = c[5, j]
            else:
                data[u, 0, 0] += c[0, j]
                data[u, 0, 1] += c[1, j]
                data[u, 0, 2] += c[2, j]
                data[u, 1, 0] += c[1, j]
                data[u, 1, 1] += c[3, j]
                data[u, 1, 2] += c[4, j]
                data[u, 2, 0] += c[2, j]
                data[u, 2, 1] += c[4, j]
                data[u, 2, 2] += c[5, j]
        u = _U(td)
        if assign:
            data[u, 0, 0] = h00
            data[u, 0, 1] = h01
            data[u, 0, 2] = h02
            data[u, 1, 0] = h01
            data[u, 1, 1] = h11
            data[u, 1, 2] = h12
            data[u, 2, 0] = h02
            data[u, 2, 1] = h12
            data[u, 2, 2] = h22
        else:
            data[u, 0, 0] += h00
            data[u, 0, 1] += h01
            data[u, 0, 2] += h02
            data[u, 1, 0] += h01
            data[u, 1, 1] += h11
            data[u, 1, 2] += h12
            data[u, 2, 0] += h02
            data[u, 2, 1] += h12
            data[u, 2, 2] += h22


@_jit
def _block_scatter_bsr(vals, conn, pos, nptr, bmap, scale, data):
    """:func:`_block_scatter_csr` into the ``(n_blocks, dim, dim)`` values of a BSR matrix that
    keeps some of the node blocks (``bmap``: see :func:`_spring3d_hessian_bsr`)."""
    m, nv = conn.shape
    dim = data.shape[1]
    n_loc = nv * dim
    for e in range(m):
        for p in range(nv):
            q0 = nptr[conn[e, p]]
            for q in range(nv):
                tb = bmap[_U(q0 + pos[e, p, q])]
                if tb < 0:
                    continue
                for i in range(dim):
                    off = (p * dim + i) * n_loc + q * dim
                    for j in range(dim):
                        data[_U(tb), i, j] += scale * vals[e, off + j]


@_jit
def _block_scatter_csr(vals, conn, pos, nptr, dim, scale, data):
    """Add ``scale`` times dense element blocks ``vals`` (m, (nv dim)^2, row-major) to CSR ``data``
    of a node-blocked pattern; ``pos[e, p, q]`` position of node ``conn[e, q]`` in node row
    ``conn[e, p]`` (see :func:`_spring3d_hessian_csr`)."""
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


@_jit
def _scatter_add(data, slots, vals, scale):
    for i in range(slots.shape[0]):
        data[slots[i]] += scale * vals[i]


def _block_pattern(conn: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and cols of dense element blocks, element-major, each block row-major."""
    m, nv = conn.shape
    dofs = (dim * conn[:, :, None] + np.arange(dim)).reshape(m, nv * dim)
    n_loc = nv * dim
    rows = np.repeat(dofs, n_loc, axis=1).ravel()
    cols = np.tile(dofs, (1, n_loc)).ravel()
    return rows, cols


@njit(cache=True, nogil=True)
def _expand_block_pattern(nptr, ucol, dim, indices, indptr):
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

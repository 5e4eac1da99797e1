"""numba loops of the internal terms: energy, gradient and Hessian blocks of springs (2D, 3D),
tetrahedron volumes and hexahedron volumes, element by element, and the fast 3D spring force.

``x`` flat positions, ``conn`` (m, nodes) int64, per-element parameters p, q.  Gradient loops
accumulate into ``g``; Hessian loops write one row-major block per element.  The element
arithmetic is that of the generated kernels of :mod:`msslib.generated.kernels`, compiled for
scalars and inlined (see :mod:`msslib.terms.jit` for the cache).
"""

from __future__ import annotations

import numpy as np

from msslib.generated import kernels as _K

from .jit import _U, _jit, _jit_fast

# kernels compiled for scalars (they also work on arrays in plain numpy)
_s2e, _s2g, _s2h = (_jit(f) for f in (_K.spring2d_energy, _K.spring2d_gradient, _K.spring2d_hessian))
_s3e, _s3g, _s3h = (_jit(f) for f in (_K.spring3d_energy, _K.spring3d_gradient, _K.spring3d_hessian))
_te, _tg, _th = (_jit(f) for f in (_K.tet_volume_energy, _K.tet_volume_gradient, _K.tet_volume_hessian))
_he, _hg, _hh = (_jit(f) for f in (_K.hex_volume_energy, _K.hex_volume_gradient, _K.hex_volume_hessian))


@_jit
def _spring2d_energy_loop(x, conn, k, L0):
    e = 0.0
    for s in range(conn.shape[0]):
        a, b = 2 * conn[s, 0], 2 * conn[s, 1]
        e += _s2e(x[a], x[a + 1], x[b], x[b + 1], k[s], L0[s])
    return e


@_jit
def _spring2d_gradient_loop(x, conn, k, L0, g):
    for s in range(conn.shape[0]):
        a, b = 2 * conn[s, 0], 2 * conn[s, 1]
        r = _s2g(x[a], x[a + 1], x[b], x[b + 1], k[s], L0[s])
        g[a] += r[0]
        g[a + 1] += r[1]
        g[b] += r[2]
        g[b + 1] += r[3]


@_jit
def _spring2d_hessian_loop(x, conn, k, L0, out):
    for s in range(conn.shape[0]):
        a, b = 2 * conn[s, 0], 2 * conn[s, 1]
        h = _s2h(x[a], x[a + 1], x[b], x[b + 1], k[s], L0[s])
        for i in range(16):
            out[s, i] = h[i]


@_jit
def _spring3d_energy_loop(x, conn, k, L0):
    e = 0.0
    for s in range(conn.shape[0]):
        a, b = 3 * conn[s, 0], 3 * conn[s, 1]
        e += _s3e(x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2], k[s], L0[s])
    return e


@_jit
def _spring3d_gradient_loop(x, conn, k, L0, g):
    for s in range(conn.shape[0]):
        a, b = 3 * conn[s, 0], 3 * conn[s, 1]
        r = _s3g(x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2], k[s], L0[s])
        for i in range(3):
            g[a + i] += r[i]
            g[b + i] += r[3 + i]


@_jit
def _spring3d_hessian_loop(x, conn, k, L0, out):
    for s in range(conn.shape[0]):
        a, b = 3 * conn[s, 0], 3 * conn[s, 1]
        h = _s3h(x[a], x[a + 1], x[a + 2], x[b], x[b + 1], x[b + 2], k[s], L0[s])
        for i in range(36):
            out[s, i] = h[i]


@_jit
def _gather3(x, nodes, c):
    for j in range(nodes.shape[0]):
        n = 3 * nodes[j]
        c[3 * j] = x[n]
        c[3 * j + 1] = x[n + 1]
        c[3 * j + 2] = x[n + 2]


@_jit
def _tet_energy_loop(x, conn, kv, V0):
    c = np.empty(12)
    e = 0.0
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        e += _te(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], kv[m], V0[m])
    return e


@_jit
def _tet_gradient_loop(x, conn, kv, V0, g):
    c = np.empty(12)
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        r = _tg(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], kv[m], V0[m])
        for j in range(4):
            n = 3 * conn[m, j]
            for d in range(3):
                g[n + d] += r[3 * j + d]


@_jit
def _tet_hessian_loop(x, conn, kv, V0, out):
    c = np.empty(12)
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        h = _th(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], kv[m], V0[m])
        for i in range(144):
            out[m, i] = h[i]


@_jit
def _hex_energy_loop(x, conn, kap, V0):
    c = np.empty(24)
    e = 0.0
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        e += _he(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11],
                 c[12], c[13], c[14], c[15], c[16], c[17], c[18], c[19], c[20], c[21], c[22], c[23],
                 kap[m], V0[m])
    return e


@_jit
def _hex_gradient_loop(x, conn, kap, V0, g):
    c = np.empty(24)
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        r = _hg(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11],
                c[12], c[13], c[14], c[15], c[16], c[17], c[18], c[19], c[20], c[21], c[22], c[23],
                kap[m], V0[m])
        for j in range(8):
            n = 3 * conn[m, j]
            for d in range(3):
                g[n + d] += r[3 * j + d]


@_jit
def _hex_hessian_loop(x, conn, kap, V0, out):
    c = np.empty(24)
    for m in range(conn.shape[0]):
        _gather3(x, conn[m], c)
        h = _hh(c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11],
                c[12], c[13], c[14], c[15], c[16], c[17], c[18], c[19], c[20], c[21], c[22], c[23],
                kap[m], V0[m])
        for i in range(576):
            out[m, i] = h[i]


# --------------------------------------------------------------------------------------------
# fast 3D spring loops (node-ordered layout).  The springs are sorted by their first node: the
# springs of node ``a`` are ``rowptr[a]:rowptr[a + 1]`` with other ends ``ib`` (int32) and
# constants ``k``, ``L0`` in that order.  The force of node ``a`` is accumulated in registers and
# written once; only the other end is scattered.  The arithmetic is that of the generated kernels
# (``c = k (L0 - l) / l``, ``g_a = -(x_a - x_b) c``, ``g_b = -g_a``), so the results agree with
# them to round-off (the summation order per node differs).  fastmath without reassociation.
# --------------------------------------------------------------------------------------------


@_jit_fast
def _spring3d_gradient_fast(x, rowptr, ib, k, L0, g):
    for na in range(rowptr.shape[0] - 1):
        a = 3 * na
        xa0, xa1, xa2 = x[a], x[a + 1], x[a + 2]
        ga0 = 0.0
        ga1 = 0.0
        ga2 = 0.0
        for s in range(rowptr[na], rowptr[na + 1]):
            b = 3 * ib[_U(s)]
            d0 = xa0 - x[_U(b)]
            d1 = xa1 - x[_U(b + 1)]
            d2 = xa2 - x[_U(b + 2)]
            l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            c = k[_U(s)] * (L0[_U(s)] - l) / l
            f0 = d0 * c
            f1 = d1 * c
            f2 = d2 * c
            ga0 -= f0
            ga1 -= f1
            ga2 -= f2
            g[_U(b)] += f0
            g[_U(b + 1)] += f1
            g[_U(b + 2)] += f2
        g[a] += ga0
        g[a + 1] += ga1
        g[a + 2] += ga2


@_jit_fast
def _spring3d_energy_fast(x, rowptr, ib, k, L0):
    e = 0.0
    for na in range(rowptr.shape[0] - 1):
        a = 3 * na
        for s in range(rowptr[na], rowptr[na + 1]):
            b = 3 * ib[s]
            d0 = x[a] - x[b]
            d1 = x[a + 1] - x[b + 1]
            d2 = x[a + 2] - x[b + 2]
            r = L0[s] - np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            e += 0.5 * k[s] * r * r
    return e

"""Force terms of a mass-spring system: springs, volume energies, external loads, corrections.

Every term works on the flat state ``x`` (node positions, ``n_nodes * dim`` long, interleaved by
node, see :mod:`msslib.solvers`) and shares one interface:

``energy(x) -> float or None``
    Potential energy of the term (J) at unit load; ``None`` for a non-conservative term.
``gradient(x) -> ndarray (n_dof,)``
    ``dW/dx`` (N): the force of the term is minus this.  For a non-conservative term it is simply
    minus its force (there is no ``W``).
``hessian_pattern() -> (rows, cols)``
    Dof indices of the term's Hessian entries, element by element (each element contributes a
    dense ``n_local x n_local`` row-major block).  The pattern depends only on the topology: it
    is computed once and cached.
``hessian_values(x) -> ndarray``
    Values of the entries of ``hessian_pattern()`` at ``x`` (N/m), filled by a numba loop.
``hessian_coo(x) -> (rows, cols, vals)``
    Convenience: the pattern and the values together (duplicates are to be summed).

Class attributes describe how a :class:`msslib.model.Model` combines the terms:
``conservative`` (False: the model's energy is ``None``), ``scales_with_load`` (True: external
terms whose contribution is multiplied by the load factor) and ``symmetric`` (Hessian symmetry).

Internal terms use the generated kernels of :mod:`msslib.generated.kernels` (energy, gradient and
Hessian of the exact energies the derivations linearise), compiled by numba on first use with
``cache=True``.  The first call of a kernel family compiles it (seconds; the hexahedron Hessian
about ten seconds); later processes load it from ``__pycache__``.  Note numba's cache tracks the
source file of the jitted loops only: after regenerating ``msslib/generated/kernels.py`` remove
the ``msslib/__pycache__/terms.*.nbi``/``.nbc`` files so the loops are recompiled.

Terms with no elements never call numba (cheap when absent).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from msslib.generated import kernels as _K


def _drop_stale_numba_cache() -> None:
    """numba's on-disk cache of the loops below is keyed on this file only, not on the generated
    kernels they inline: when ``msslib/generated/kernels.py`` changes (re-derived), drop it."""
    import hashlib
    from pathlib import Path

    try:
        cache_dir = Path(__file__).resolve().parent / "__pycache__"
        digest = hashlib.sha256(Path(_K.__file__).read_bytes()).hexdigest()
        stamp = cache_dir / "terms.kernels-sha256"
        if stamp.is_file() and stamp.read_text() == digest:
            return
        for f in cache_dir.glob("terms.*.nb[ic]"):
            f.unlink(missing_ok=True)
        cache_dir.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # read-only installation: numba falls back to compiling in memory
        pass


_drop_stale_numba_cache()

__all__ = [
    "Term",
    "Springs",
    "TetVolume",
    "HexVolume",
    "ExternalForce",
    "Gravity",
    "NodalForces",
    "Traction",
    "BaudetCorrection",
    "sum_external_forces",
]

_jit = njit(cache=True, error_model="numpy", nogil=True)

# kernels compiled for scalars (they also work on arrays in plain numpy)
_s2e, _s2g, _s2h = (_jit(f) for f in (_K.spring2d_energy, _K.spring2d_gradient, _K.spring2d_hessian))
_s3e, _s3g, _s3h = (_jit(f) for f in (_K.spring3d_energy, _K.spring3d_gradient, _K.spring3d_hessian))
_te, _tg, _th = (_jit(f) for f in (_K.tet_volume_energy, _K.tet_volume_gradient, _K.tet_volume_hessian))
_he, _hg, _hh = (_jit(f) for f in (_K.hex_volume_energy, _K.hex_volume_gradient, _K.hex_volume_hessian))


# --------------------------------------------------------------------------------------------
# numba loops.  ``x`` flat positions, ``conn`` (m, nodes) int64, per-element parameters p, q.
# Gradient loops accumulate into ``g``; Hessian loops write one row-major block per element.
# --------------------------------------------------------------------------------------------


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

_FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
_jit_fast = njit(cache=True, error_model="numpy", nogil=True, fastmath=_FAST)
# Indexing with an unsigned integer: numba wraps negative signed indices around (a compare, a
# shift and a conditional move per access), which doubles the instruction count of the scatter
# loops below; our indices are never negative, so the hot loops index through ``_U(i)``.
_U = np.uint64


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


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------


def _as_flat(x) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=float).ravel()


def _per_element(name, values, m) -> np.ndarray:
    values = np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=float), (m,)))
    return values.copy()


def _connectivity(name, conn, nodes) -> np.ndarray:
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    if conn.ndim != 2 or conn.shape[1] != nodes:
        raise ValueError(f"{name} must have shape (m, {nodes}), got {conn.shape}")
    if conn.size and conn.min() < 0:
        raise ValueError(f"{name} holds negative node ids")
    return conn


def _format_bad(ids, values, label, conn=None, max_report=10) -> str:
    parts = []
    for i in ids[:max_report]:
        nodes = f" (nodes {'-'.join(str(int(n)) for n in conn[i])})" if conn is not None else ""
        parts.append(f"{label} {int(i)}{nodes}: {float(values[i])!r}")
    more = f" and {len(ids) - max_report} more" if len(ids) > max_report else ""
    return ", ".join(parts) + more


def _block_pattern(conn: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and cols of dense element blocks, element-major, each block row-major."""
    m, nv = conn.shape
    dofs = (dim * conn[:, :, None] + np.arange(dim)).reshape(m, nv * dim)
    n_loc = nv * dim
    rows = np.repeat(dofs, n_loc, axis=1).ravel()
    cols = np.tile(dofs, (1, n_loc)).ravel()
    return rows, cols


# --------------------------------------------------------------------------------------------
# base classes
# --------------------------------------------------------------------------------------------


class Term:
    """Base class; see the module docstring for the interface."""

    conservative = True
    scales_with_load = False
    symmetric = True
    dim: int = 3

    def energy(self, x) -> float | None:  # pragma: no cover - abstract
        raise NotImplementedError

    def gradient(self, x) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def max_node(self) -> int:
        """Largest node id the term refers to (-1 if none); used to check it fits a mesh."""
        return -1

    def hessian_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty

    def hessian_values(self, x) -> np.ndarray:
        return np.zeros(0)

    def hessian_coo(self, x):
        rows, cols = self.hessian_pattern()
        return rows, cols, self.hessian_values(x)


class _ElementTerm(Term):
    """A term made of elements with ``conn`` (m, nodes), parameters ``p`` and ``q`` per element,
    and three numba loops."""

    _loops: tuple = ()
    _n_local: int = 0

    def __len__(self):
        return len(self.conn)

    def max_node(self) -> int:
        return int(self.conn.max()) if self.conn.size else -1

    def energy(self, x) -> float:
        if len(self.conn) == 0:
            return 0.0
        return float(self._loops[0](_as_flat(x), self.conn, self._p, self._q))

    def gradient(self, x) -> np.ndarray:
        x = _as_flat(x)
        g = np.zeros(x.size)
        if len(self.conn):
            self._loops[1](x, self.conn, self._p, self._q, g)
        return g

    def hessian_pattern(self):
        if getattr(self, "_pattern", None) is None:
            self._pattern = _block_pattern(self.conn, self.dim)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        out = np.empty((len(self.conn), self._n_local))
        if len(self.conn):
            self._loops[2](_as_flat(x), self.conn, self._p, self._q, out)
        return out.ravel()


# --------------------------------------------------------------------------------------------
# internal terms
# --------------------------------------------------------------------------------------------


class Springs(_ElementTerm):
    """Springs ``k/2 (|x_b - x_a| - L0)^2`` between node pairs.

    Parameters
    ----------
    pairs : (s, 2) int node ids.
    k : (s,) spring constants (N/m), finite and > 0.  A zero or negative constant (typically from
        a sliver or inverted element) raises ValueError naming the offending springs; it is never
        used silently.
    rest_length : (s,) rest lengths (m), finite and > 0.  A rest length that differs from the
        distance of the nodes in the mesh prestrains the spring (e.g. Lloyd's squares).
    dim : 2 or 3.
    """

    def __init__(self, pairs, k, rest_length, dim: int):
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.dim = dim
        self.conn = _connectivity("pairs", pairs, 2)
        s = len(self.conn)
        self.k = _per_element("k", k, s)
        self.rest_length = _per_element("rest_length", rest_length, s)
        bad = np.flatnonzero(~(np.isfinite(self.k) & (self.k > 0)))
        if len(bad):
            raise ValueError(
                f"{len(bad)} spring(s) with a non-positive or non-finite spring constant k (N/m), "
                f"e.g. from degenerate or inverted elements: {_format_bad(bad, self.k, 'spring', self.conn)}"
            )
        bad = np.flatnonzero(~(np.isfinite(self.rest_length) & (self.rest_length > 0)))
        if len(bad):
            raise ValueError(
                f"{len(bad)} spring(s) with a non-positive or non-finite rest length (m): "
                f"{_format_bad(bad, self.rest_length, 'spring', self.conn)}"
            )
        self._p, self._q = self.k, self.rest_length
        self._n_local = (2 * dim) ** 2
        self._loops = (
            (_spring2d_energy_loop, _spring2d_gradient_loop, _spring2d_hessian_loop)
            if dim == 2
            else (_spring3d_energy_loop, _spring3d_gradient_loop, _spring3d_hessian_loop)
        )
        self._layout = None

    def node_layout(self):
        """Node-ordered layout of the springs used by the fast 3D loops (built once, cached).

        Returns ``(order, rowptr, ib, k, L0)``: ``order`` the permutation of the springs sorted by
        first node (then second), ``rowptr`` (n_nodes + 1,) int64 offsets by first node, ``ib``
        int32 second nodes, and the constants in that order (contiguous float64)."""
        if self._layout is None:
            conn = self.conn
            n = int(conn.max()) + 1 if conn.size else 0
            order = np.lexsort((conn[:, 1], conn[:, 0]))
            rowptr = np.zeros(n + 1, dtype=np.int64)
            np.cumsum(np.bincount(conn[:, 0], minlength=n), out=rowptr[1:])
            idx_t = np.int32 if n < 2**31 else np.int64
            self._layout = (order, rowptr, np.ascontiguousarray(conn[order, 1], dtype=idx_t),
                            np.ascontiguousarray(self.k[order]), np.ascontiguousarray(self.rest_length[order]))
        return self._layout

    def symmetric_layout(self):
        """Both-ends layout for the fast Hessian: ``(order, rowptr, nb, k, L0)`` with every spring
        listed under each of its two nodes (``order`` indexes the ``2 s`` half-springs: ``i < s``
        is spring ``i`` seen from its first node, ``s + i`` from its second), sorted by node then
        neighbour."""
        if getattr(self, "_sym_layout", None) is None:
            conn = self.conn
            n = int(conn.max()) + 1 if conn.size else 0
            a = np.concatenate([conn[:, 0], conn[:, 1]])
            b = np.concatenate([conn[:, 1], conn[:, 0]])
            order = np.lexsort((b, a))
            rowptr = np.zeros(n + 1, dtype=np.int64)
            np.cumsum(np.bincount(a, minlength=n), out=rowptr[1:])
            idx_t = np.int32 if n < 2**31 else np.int64
            kk = np.concatenate([self.k, self.k])[order]
            ll = np.concatenate([self.rest_length, self.rest_length])[order]
            self._sym_layout = (order, rowptr, np.ascontiguousarray(b[order], dtype=idx_t), kk, ll)
        return self._sym_layout

    def energy(self, x) -> float:
        if self.dim != 3 or len(self.conn) == 0:
            return super().energy(x)
        _, rowptr, ib, k, L0 = self.node_layout()
        return float(_spring3d_energy_fast(_as_flat(x), rowptr, ib, k, L0))

    def gradient(self, x) -> np.ndarray:
        if self.dim != 3 or len(self.conn) == 0:
            return super().gradient(x)
        x = _as_flat(x)
        g = np.zeros(x.size)
        _, rowptr, ib, k, L0 = self.node_layout()
        if 3 * (len(rowptr) - 1) > x.size:
            raise IndexError(f"x has {x.size} entries, the springs refer to node {len(rowptr) - 2}")
        _spring3d_gradient_fast(x, rowptr, ib, k, L0, g)
        return g

    def gradient_reference(self, x) -> np.ndarray:
        """Gradient through the generated scalar kernel (the plain loop); for tests/benchmarks."""
        return super().gradient(x)

    @property
    def pairs(self) -> np.ndarray:
        return self.conn

    def lengths(self, x) -> np.ndarray:
        """Current length of every spring (m)."""
        p = _as_flat(x).reshape(-1, self.dim)
        return np.linalg.norm(p[self.conn[:, 1]] - p[self.conn[:, 0]], axis=1)

    def tensions(self, x) -> np.ndarray:
        """Spring tensions ``k (l - L0)`` (N), positive when stretched."""
        return self.k * (self.lengths(x) - self.rest_length)


def _check_rest_volumes(name, V0):
    bad = np.flatnonzero(~(np.isfinite(V0) & (V0 > 0)))
    if len(bad):
        raise ValueError(f"{name}: rest volumes V0 must be finite and > 0: {_format_bad(bad, V0, 'cell')}")


class TetVolume(_ElementTerm):
    """Lloyd's tetrahedron volume energy ``k_v / (2 V0^2) (V - V0)^2`` (V the signed volume).

    ``tets`` (m, 4) positively oriented, ``k_v`` (m,) in J (N m) — it may be negative (Lloyd's
    k_V is negative for nu < 3/13), only finiteness is checked — ``V0`` (m,) rest volumes > 0.
    """

    def __init__(self, tets, k_v, V0):
        self.dim = 3
        self.conn = _connectivity("tets", tets, 4)
        m = len(self.conn)
        self.k_v = _per_element("k_v", k_v, m)
        self.V0 = _per_element("V0", V0, m)
        if not np.isfinite(self.k_v).all():
            raise ValueError("TetVolume: k_v must be finite")
        _check_rest_volumes("TetVolume", self.V0)
        self._p, self._q = self.k_v, self.V0
        self._n_local = 144
        self._loops = (_tet_energy_loop, _tet_gradient_loop, _tet_hessian_loop)


class HexVolume(_ElementTerm):
    """Golec's hexahedron volume correction ``kappa / (2 V0) (V - V0)^2`` with the averaged-edge
    volume ``V`` (:func:`msslib.generated.kernels.hex_averaged_volume`).

    ``hexes`` (m, 8) in VTK order, ``kappa`` (m,) in Pa, ``V0`` (m,) rest volumes > 0 (use the
    averaged volume of the rest configuration so that the term is unloaded at rest).

    ``kappa`` may be negative: Golec's kappa is negative for nu < 1/4, where the term *lowers*
    the volumetric stiffness the springs give; it is then not convex by itself and only the sum
    with the springs is positive definite.  Only finiteness is checked.
    """

    def __init__(self, hexes, kappa, V0):
        self.dim = 3
        self.conn = _connectivity("hexes", hexes, 8)
        m = len(self.conn)
        self.kappa = _per_element("kappa", kappa, m)
        self.V0 = _per_element("V0", V0, m)
        if not np.isfinite(self.kappa).all():
            raise ValueError("HexVolume: kappa must be finite")
        _check_rest_volumes("HexVolume", self.V0)
        self._p, self._q = self.kappa, self.V0
        self._n_local = 576
        self._loops = (_hex_energy_loop, _hex_gradient_loop, _hex_hessian_loop)


# --------------------------------------------------------------------------------------------
# external (dead) loads, scaled by the load factor
# --------------------------------------------------------------------------------------------


class ExternalForce(Term):
    """A constant (dead) nodal force ``f`` (N, flat ``(n_dof,)``) at unit load.

    Energy ``-f . x``, gradient ``-f``, zero Hessian.  ``scales_with_load``: a model multiplies
    it by the load factor.
    """

    scales_with_load = True

    def __init__(self, forces, dim: int):
        forces = np.asarray(forces, dtype=float)
        if forces.ndim != 2 or forces.shape[1] != dim:
            raise ValueError(f"forces must have shape (n_nodes, {dim}), got {forces.shape}")
        if not np.isfinite(forces).all():
            raise ValueError("forces must be finite")
        self.dim = dim
        self.nodal = forces
        self.vector = forces.ravel().copy()

    @property
    def n_nodes(self) -> int:
        return len(self.nodal)

    def max_node(self) -> int:
        return self.n_nodes - 1

    @property
    def total(self) -> np.ndarray:
        """Resultant force (N), ``(dim,)``."""
        return self.nodal.sum(axis=0)

    def energy(self, x) -> float:
        return -float(self.vector @ _as_flat(x))

    def gradient(self, x) -> np.ndarray:
        return -self.vector.copy()


class NodalForces(ExternalForce):
    """Dead nodal loads ``f`` of shape ``(n_nodes, dim)`` (N)."""

    def __init__(self, forces):
        forces = np.asarray(forces, dtype=float)
        super().__init__(forces, forces.shape[1] if forces.ndim == 2 else 0)


class Gravity(ExternalForce):
    """Weight ``m_i g`` of every node: ``masses`` (n,) in kg, ``g`` (dim,) in m/s^2.

    Energy ``-sum_i m_i g . x_i``; constant force, zero Hessian.
    """

    def __init__(self, masses, g):
        masses = np.asarray(masses, dtype=float)
        g = np.asarray(g, dtype=float).ravel()
        if masses.ndim != 1:
            raise ValueError(f"masses must have shape (n_nodes,), got {masses.shape}")
        self.g = g
        super().__init__(masses[:, None] * g[None, :], len(g))


def _traction_nodal(points, facets, thickness):
    """Consistent nodal weights ``w`` (f, nodes): the force on node a of facet e is
    ``w[e, a] * traction[e]`` (reference configuration)."""
    x = points[facets]
    nf = facets.shape[1]
    if nf == 2:
        length = np.linalg.norm(x[:, 1] - x[:, 0], axis=1) * thickness
        return np.repeat(length[:, None] / 2.0, 2, axis=1)
    if nf == 3:
        area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
        return np.repeat(area[:, None] / 3.0, 3, axis=1)
    if nf == 4:
        # bilinear quad on [-1, 1]^2, corners counter-clockwise; 2 x 2 Gauss of N_a |dX/du x dX/dv|
        w = np.zeros((len(facets), 4))
        su = np.array([-1.0, 1.0, 1.0, -1.0])
        sv = np.array([-1.0, -1.0, 1.0, 1.0])
        for u in np.array([-1.0, 1.0]) / np.sqrt(3.0):
            for v in np.array([-1.0, 1.0]) / np.sqrt(3.0):
                du = 0.25 * ((x[:, 1] - x[:, 0]) * (1 - v) + (x[:, 2] - x[:, 3]) * (1 + v))
                dv = 0.25 * ((x[:, 3] - x[:, 0]) * (1 - u) + (x[:, 2] - x[:, 1]) * (1 + u))
                jac = np.linalg.norm(np.cross(du, dv), axis=1)
                n = 0.25 * (1 + su * u) * (1 + sv * v)
                w += jac[:, None] * n[None, :]
        return w
    raise ValueError(f"facets must have 2, 3 or 4 nodes, got {nf}")


class Traction(ExternalForce):
    """A traction (Pa) on boundary facets turned into consistent nodal dead loads.

    ``mesh`` gives the reference node positions; ``facets`` (f, 2|3|4) node ids (e.g. from
    :func:`msslib.mesh.boundary_facets`); ``traction`` (dim,) or (f, dim) in Pa, a fixed vector
    (not a follower pressure).  Two-node facets (2D edges) carry ``traction * length * thickness``
    (thickness in metres, 2D only) split in halves, triangles a third of ``traction * area`` per
    node, quads the exact consistent forces ``integral N_a traction dA`` of the bilinear facet
    (2 x 2 Gauss; exact for parallelograms).  ``total`` is the resultant.
    """

    def __init__(self, mesh, facets, traction, thickness: float = 1.0):
        facets = np.asarray(facets, dtype=np.int64)
        if facets.ndim != 2:
            raise ValueError(f"facets must have shape (f, 2|3|4), got {facets.shape}")
        facets = _connectivity("facets", facets, facets.shape[1])
        dim = mesh.dim
        if dim == 3 and thickness != 1.0:
            raise ValueError("thickness applies to 2D meshes only")
        if (dim == 2) != (facets.shape[1] == 2):
            raise ValueError(f"{dim}D meshes need {'2-node' if dim == 2 else '3- or 4-node'} facets")
        traction = np.broadcast_to(np.asarray(traction, dtype=float), (len(facets), dim))
        w = _traction_nodal(mesh.points, facets, float(thickness))
        nodal = np.zeros((mesh.n_nodes, dim))
        for d in range(dim):
            nodal[:, d] = np.bincount(facets.ravel(), weights=(w * traction[:, d:d + 1]).ravel(),
                                      minlength=mesh.n_nodes)
        self.facets = facets
        self.traction = np.array(traction)
        super().__init__(nodal, dim)


def sum_external_forces(terms, n_nodes: int, dim: int) -> np.ndarray:
    """Sum of the nodal forces ``(n_nodes, dim)`` at unit load of the :class:`ExternalForce`
    terms in ``terms`` (other terms are ignored)."""
    total = np.zeros((n_nodes, dim))
    for t in terms:
        if isinstance(t, ExternalForce):
            if t.nodal.shape != total.shape:
                raise ValueError(f"external term {type(t).__name__} has shape {t.nodal.shape}, expected {total.shape}")
            total += t.nodal
    return total


# --------------------------------------------------------------------------------------------
# Baudet's orthogonal correction (non-conservative, load dependent)
# --------------------------------------------------------------------------------------------

# local faces of a hexahedron (msslib.mesh order, right-hand normal outward) and the three pairs
# of opposite faces: bottom/top, y-min/y-max, x-max/x-min of a reference cube
_HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
_FACE_PAIRS = np.array([[0, 1], [2, 4], [3, 5]])


class BaudetCorrection(Term):
    """Baudet et al.'s orthogonal correction forces for hexahedral (cube) elements.

    Baudet's cube springs alone give the wrong Poisson contraction; the correction adds, for
    every element with an externally loaded face, forces on the four faces orthogonal to the
    elongation direction.  Construction (all at unit load, in the *reference* configuration):

    1. External forces ``loads`` (n, 3) (an array, or terms whose :class:`ExternalForce` parts are
       summed — pass only surface loads, not gravity) live on the nodes.  Candidate faces are the
       mesh's boundary faces, with outward unit normal ``n_f``.
    2. Sharing rule: the normal component ``f_a . n_f`` of the force of node ``a`` is shared
       equally among the boundary faces containing ``a`` *with the same normal* (coplanar faces
       of neighbouring elements). Faces with other normals get their own normal component, so at
       an edge or corner where loaded faces meet (pressure on a box) every face receives its full
       normal load. The elongation force of face ``f`` is ``F_f = sum_a (f_a . n_f) / m_af``
       (> 0 tension, < 0 compression, ``m_af`` the number of coplanar boundary faces at ``a``);
       for uniform normal tractions with consistent nodal forces it is exactly each face's normal
       resultant. A face is loaded when ``F_f != 0``. Limitation: a load tangential to a face
       (shear) at an edge node also has a normal component on the adjacent side face and is
       counted there.
    3. Per element and per pair of opposite faces the elongation force ``F_i`` is the one of the
       two faces with the larger magnitude (if both are loaded, as in a free cube pulled at both
       ends, the tension is counted once).
    4. The correction amplitude is ``F_perp = c F_i`` with ``c = factor`` per element (from
       :func:`msslib.parameters.baudet_cube` ``.correction_factor``: ``-(4 nu - 1) / 2`` derived
       for resultants per face, ``-(4 nu - 1) / 16`` as printed, see the errata).
       On each of the two other pairs of faces ``(j, j')`` the force ``F_perp d / 4`` is applied to
       each node of ``j`` and ``-F_perp d / 4`` to each node of ``j'``, ``d`` the unit vector from
       the centroid of ``j'`` to the centroid of ``j`` (the outward normal of ``j`` for a cube).
       For nu > 1/4, ``c < 0``: a stretched element is pinched on its sides.

    The two forces of a face pair are equal, opposite and collinear (they act along the line
    through both face centroids), so every element's correction has zero resultant force and zero
    moment, for any hexahedron shape.

    Directions are those of the reference configuration: the correction is a constant nodal force
    vector per unit load, scaled by the load factor.  Its Jacobian is therefore zero (no Hessian
    entries) and the static stiffness stays that of the springs.  It is treated as
    non-conservative (``energy`` returns None; Baudet's force is defined from the applied load,
    not from a potential), so a model containing it reports ``energy = None``.
    """

    conservative = False
    scales_with_load = True
    dim = 3

    def __init__(self, mesh, loads, factor):
        if mesh.cell_type != "hexahedron":
            raise ValueError(f"BaudetCorrection needs hexahedron cells, got {mesh.cell_type}")
        if not isinstance(loads, np.ndarray) and not np.isscalar(loads):
            try:
                loads = np.asarray(loads, dtype=float)
            except (TypeError, ValueError):
                loads = sum_external_forces(loads, mesh.n_nodes, 3)
        loads = np.asarray(loads, dtype=float)
        if loads.shape != (mesh.n_nodes, 3):
            raise ValueError(f"loads must have shape ({mesh.n_nodes}, 3), got {loads.shape}")
        factor = _per_element("factor", factor, mesh.n_cells)
        if not np.isfinite(factor).all():
            raise ValueError("BaudetCorrection: factor must be finite")
        self.factor = factor
        self.loads = loads
        self.face_force = self._face_elongation(mesh, loads)  # (m, 6)
        nodal = self._correction(mesh, self.face_force, factor)
        self.nodal = nodal
        self.vector = nodal.ravel()

    @staticmethod
    def _face_elongation(mesh, loads):
        m = mesh.n_cells
        faces = mesh.cells[:, _HEX_FACES]  # (m, 6, 4)
        flat = faces.reshape(-1, 4)
        _, inverse, counts = np.unique(np.sort(flat, axis=1), axis=0, return_inverse=True, return_counts=True)
        boundary = counts[inverse.ravel()] == 1
        p = mesh.points[flat]
        normal = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        fid = np.repeat(np.flatnonzero(boundary), 4)
        node = flat[boundary].ravel()
        proj = np.einsum("ij,ij->i", loads[node], normal[fid])
        # number of boundary faces at the node with the same (rounded) normal
        key = np.column_stack([node, np.round(normal[fid] * 1e6).astype(np.int64)])
        _, group, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        share = 1.0 / count[group.ravel()]
        face_force = np.bincount(fid, weights=share * proj, minlength=len(flat))
        return face_force.reshape(m, 6)

    @staticmethod
    def _correction(mesh, face_force, factor):
        m = mesh.n_cells
        nodal = np.zeros((mesh.n_nodes, 3))
        centroid = mesh.points[mesh.cells[:, _HEX_FACES]].mean(axis=2)  # (m, 6, 3)
        for i, (f0, f1) in enumerate(_FACE_PAIRS):
            a, b = face_force[:, f0], face_force[:, f1]
            F = np.where(np.abs(a) >= np.abs(b), a, b)
            loaded = F != 0.0
            if not loaded.any():
                continue
            amp = factor[loaded] * F[loaded] / 4.0  # per node
            cells = mesh.cells[loaded]
            for q, (j0, j1) in enumerate(_FACE_PAIRS):
                if q == i:
                    continue
                d = centroid[loaded, j1] - centroid[loaded, j0]
                d /= np.linalg.norm(d, axis=1, keepdims=True)
                fj = amp[:, None] * d
                for face, sign in ((j1, 1.0), (j0, -1.0)):
                    nodes = cells[:, _HEX_FACES[face]]  # (k, 4)
                    for c in range(3):
                        nodal[:, c] += np.bincount(nodes.ravel(), weights=np.repeat(sign * fj[:, c], 4),
                                                   minlength=mesh.n_nodes)
        return nodal

    def max_node(self) -> int:
        return len(self.nodal) - 1

    def energy(self, x):
        return None

    def gradient(self, x) -> np.ndarray:
        """Minus the correction force at unit load (independent of ``x``)."""
        return -self.vector.copy()

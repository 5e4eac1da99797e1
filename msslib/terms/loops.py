"""numba loops of the internal terms: energy, gradient and Hessian blocks of springs (2D, 3D),
tetrahedron volumes and hexahedron volumes, element by element, and the fast 3D spring force.

``x`` flat positions, ``conn`` (m, nodes) int64, per-element parameters p, q.  Gradient loops
accumulate into ``g``; Hessian loops write one row-major block per element.  The element
arithmetic is that of the generated kernels of :mod:`msslib.generated.kernels`, compiled for
scalars and inlined (see :mod:`msslib.terms.jit` for the cache).
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.core.errors import RequireLiteralValue, TypingError
from numba.extending import intrinsic, register_jitable

from msslib.generated import kernels as _K

from .jit import UINT, njit_cached, _jit_fast


@intrinsic
def _as_tuple(typingctx, c, n):
    """The first ``n`` entries (``n`` a compile-time constant) of the contiguous 1D array ``c``
    as a tuple, loaded at constant offsets (numba's ``to_fixed_tuple`` fills its tuple in a
    loop, which made the element loops up to 8 times slower)."""
    if not isinstance(n, types.IntegerLiteral):
        raise RequireLiteralValue("n must be a compile-time constant")
    if c.ndim != 1 or c.layout != "C":
        raise TypingError("_as_tuple takes a contiguous 1D array")
    size = n.literal_value
    sig = types.UniTuple(c.dtype, size)(c, n)

    def codegen(context, builder, signature, args):
        ptr = context.make_array(signature.args[0])(context, builder, args[0]).data
        vals = [builder.load(cgutils.gep_inbounds(builder, ptr, i)) for i in range(size)]
        return context.make_tuple(builder, signature.return_type, vals)

    return sig, codegen


@njit(inline="always", error_model="numpy", nogil=True)
def _gather(x, conn, m, dim, n, c):
    """The ``n`` coordinates (``dim`` per node) of the nodes of element ``m`` into ``c``."""
    for j in range(n // dim):
        a = dim * conn[m, j]
        for d in range(dim):
            c[dim * j + d] = x[a + d]


def _element_loops(kind, energy, gradient, hessian, dim, n):
    """The energy, gradient and Hessian loops of an element kind with ``n`` coordinates per
    element (``dim`` per node) and the generated kernels ``energy``, ``gradient``, ``hessian``
    (plain functions registered as jitable, compiled into the loops: numba's on-disk cache never
    finds a loop that holds a compiled function, whose pickled form differs from process to
    process; it does find one that holds the plain function).  The loops are named
    ``_<kind>_energy_loop`` etc. (numba names their cache files after them)."""

    def energy_loop(x, conn, p, q):
        c = np.empty(n)
        e = 0.0
        for m in range(conn.shape[0]):
            _gather(x, conn, m, dim, n, c)
            e += energy(*_as_tuple(c, n), p[m], q[m])
        return e

    def gradient_loop(x, conn, p, q, g):
        c = np.empty(n)
        for m in range(conn.shape[0]):
            _gather(x, conn, m, dim, n, c)
            r = gradient(*_as_tuple(c, n), p[m], q[m])
            for j in range(n // dim):
                a = dim * conn[m, j]
                for d in range(dim):
                    g[a + d] += r[dim * j + d]

    def hessian_loop(x, conn, p, q, out):
        c = np.empty(n)
        for m in range(conn.shape[0]):
            _gather(x, conn, m, dim, n, c)
            h = hessian(*_as_tuple(c, n), p[m], q[m])
            for i in range(n * n):
                out[m, i] = h[i]

    loops = (energy_loop, gradient_loop, hessian_loop)
    for loop, op in zip(loops, ("energy", "gradient", "hessian")):
        loop.__name__ = loop.__qualname__ = f"_{kind}_{op}_loop"
    for kernel in (energy, gradient, hessian):
        register_jitable(error_model="numpy")(kernel)
    return tuple(njit_cached(loop) for loop in loops)


_spring2d_energy_loop, _spring2d_gradient_loop, _spring2d_hessian_loop = _element_loops(
    "spring2d", _K.spring2d_energy, _K.spring2d_gradient, _K.spring2d_hessian, 2, 4)
_spring3d_energy_loop, _spring3d_gradient_loop, _spring3d_hessian_loop = _element_loops(
    "spring3d", _K.spring3d_energy, _K.spring3d_gradient, _K.spring3d_hessian, 3, 6)
_tet_energy_loop, _tet_gradient_loop, _tet_hessian_loop = _element_loops(
    "tet", _K.tet_volume_energy, _K.tet_volume_gradient, _K.tet_volume_hessian, 3, 12)
_hex_energy_loop, _hex_gradient_loop, _hex_hessian_loop = _element_loops(
    "hex", _K.hex_volume_energy, _K.hex_volume_gradient, _K.hex_volume_hessian, 3, 24)


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
            b = 3 * ib[UINT(s)]
            d0 = xa0 - x[UINT(b)]
            d1 = xa1 - x[UINT(b + 1)]
            d2 = xa2 - x[UINT(b + 2)]
            l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            c = k[UINT(s)] * (L0[UINT(s)] - l) / l
            f0 = d0 * c
            f1 = d1 * c
            f2 = d2 * c
            ga0 -= f0
            ga1 -= f1
            ga2 -= f2
            g[UINT(b)] += f0
            g[UINT(b + 1)] += f1
            g[UINT(b + 2)] += f2
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

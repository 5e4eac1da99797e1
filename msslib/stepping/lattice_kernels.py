"""The numba kernels of :class:`msslib.stepping.LatticeExplicit`.

Node arrays are lattice ordered (``q = i + NX (j + NY k)``), length ``N``, one array per
coordinate (structure of arrays).  The springs of one of the 13 lattice directions with flat
offset ``o`` are the node pairs ``(q, q + o)``: contiguous shifted slices, no indirect indexing,
no scattered writes.  The per-direction spring forces ``F`` and the per-cell hexahedron vectors
``W`` are stored with ``pad`` leading zeros so that the gathers at ``q - offset`` never go below
0.  The kernels run in the precision of the arrays they are given (float64 or float32).

fastmath as in :mod:`msslib.terms` (no reassociation: results stay deterministic and close to
the generated kernels); nogil, cached on disk (``MSSLIB_FASTEXPLICIT_NOCACHE=1`` compiles in
memory, e.g. to inspect the generated assembly).
"""

from __future__ import annotations

import os

import numpy as np
from numba import njit
from numba.core import types as _types
from numba.extending import overload as _overload

_CACHE = os.environ.get("MSSLIB_FASTEXPLICIT_NOCACHE", "") == ""
_FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
_jit = njit(cache=_CACHE, error_model="numpy", nogil=True, fastmath=_FAST)


def _tiny(x):
    """A positive number far below any squared spring length, in the precision of ``x``."""
    return 1e-300


@_overload(_tiny)
def _tiny_impl(x):
    if isinstance(x, _types.Float) and x.bitwidth == 32:
        return lambda x: np.float32(1e-30)
    return lambda x: 1e-300


def _as(x, v):
    """The constant ``v`` in the precision of ``x`` (a float64 literal would promote
    single-precision arithmetic to double)."""
    return v


@_overload(_as)
def _as_impl(x, v):
    if isinstance(x, _types.Float) and x.bitwidth == 32:
        return lambda x, v: np.float32(v)
    return lambda x, v: np.float64(v)


@_jit
def _spring_direction(X, Y, Z, o, n, k, L0, FX, FY, FZ):
    """Forces ``(x_p - x_{p+o}) k (L0 - l) / l = (x_p - x_{p+o}) k (L0 / l - 1)`` of the springs
    ``(p, p + o)``, p < n, into F[p] (zero for n <= p < len(F): the buffers are shared by the
    directions)."""
    Xb, Yb, Zb = X[o:], Y[o:], Z[o:]
    tiny = _tiny(X[0])  # empty slots (k = 0) stay finite
    one = _as(X[0], 1.0)
    for q in range(n):
        d0 = X[q] - Xb[q]
        d1 = Y[q] - Yb[q]
        d2 = Z[q] - Zb[q]
        r = one / np.sqrt(d0 * d0 + d1 * d1 + d2 * d2 + tiny)  # single: estimate + Newton step
        c = k[q] * (L0[q] * r - one)
        FX[q] = d0 * c
        FY[q] = d1 * c
        FZ[q] = d2 * c
    for q in range(n, FX.shape[0]):
        FX[q] = 0.0
        FY[q] = 0.0
        FZ[q] = 0.0


@_jit
def _accumulate(f, pad, o, N, g):
    """g_p += f_{p-o} - f_p (f padded with ``pad`` leading zeros); one component."""
    a = f[pad:pad + N]
    b = f[pad - o:pad - o + N]
    for q in range(N):
        g[q] += b[q] - a[q]


@_jit
def _spring_gradient(X, Y, Z, offs, nspan, K, L0, F, pad, G):
    N = X.shape[0]
    for d in range(offs.shape[0]):
        n = nspan[d]
        if n == 0:
            continue
        o = offs[d]
        _spring_direction(X, Y, Z, o, n, K[d], L0[d], F[0][pad:], F[1][pad:], F[2][pad:])
        for c in range(3):
            _accumulate(F[c], pad, o, N, G[c])


@_jit
def _hex_component(X, Y, Z, ncell, NX, S, kv, V0, comp, W0, W1, W2, W3):
    """Per cell slot q (corner 0 at node q): the averaged edge vectors ex, ey, ez (sums of the 4
    cell edges along each lattice axis), Golec's volume ``V = ex . (ey x ez) / 64`` and
    ``cs = kv (V - V0)`` with ``kv = kappa / (64 V0)`` (precomputed); ``dW/dx`` at corner (sx, sy, sz) (signs +-1) is
    ``sx A + sy B + sz C`` with ``A = cs ey x ez``, ``B = cs ez x ex``, ``C = cs ex x ey``.
    Stores component ``comp`` of W0 = A + B + C, W1 = A - B - C, W2 = A + B - C,
    W3 = -A + B - C.  (One loop per component: few output streams, so that it vectorises.)"""
    o1, o2, o3 = 1, NX + 1, NX
    o4, o5, o6, o7 = S, S + 1, S + NX + 1, S + NX
    X1, X2, X3, X4, X5, X6, X7 = X[o1:], X[o2:], X[o3:], X[o4:], X[o5:], X[o6:], X[o7:]
    Y1, Y2, Y3, Y4, Y5, Y6, Y7 = Y[o1:], Y[o2:], Y[o3:], Y[o4:], Y[o5:], Y[o6:], Y[o7:]
    Z1, Z2, Z3, Z4, Z5, Z6, Z7 = Z[o1:], Z[o2:], Z[o3:], Z[o4:], Z[o5:], Z[o6:], Z[o7:]
    sixtyfourth = _as(X[0], 1.0 / 64.0)
    for q in range(ncell):
        x0, x1, x2, x3, x4, x5, x6, x7 = X[q], X1[q], X2[q], X3[q], X4[q], X5[q], X6[q], X7[q]
        y0, y1, y2, y3, y4, y5, y6, y7 = Y[q], Y1[q], Y2[q], Y3[q], Y4[q], Y5[q], Y6[q], Y7[q]
        z0, z1, z2, z3, z4, z5, z6, z7 = Z[q], Z1[q], Z2[q], Z3[q], Z4[q], Z5[q], Z6[q], Z7[q]
        exx = (x1 - x0) + (x2 - x3) + (x5 - x4) + (x6 - x7)
        exy = (y1 - y0) + (y2 - y3) + (y5 - y4) + (y6 - y7)
        exz = (z1 - z0) + (z2 - z3) + (z5 - z4) + (z6 - z7)
        eyx = (x3 - x0) + (x2 - x1) + (x7 - x4) + (x6 - x5)
        eyy = (y3 - y0) + (y2 - y1) + (y7 - y4) + (y6 - y5)
        eyz = (z3 - z0) + (z2 - z1) + (z7 - z4) + (z6 - z5)
        ezx = (x4 - x0) + (x5 - x1) + (x6 - x2) + (x7 - x3)
        ezy = (y4 - y0) + (y5 - y1) + (y6 - y2) + (y7 - y3)
        ezz = (z4 - z0) + (z5 - z1) + (z6 - z2) + (z7 - z3)
        ax = eyy * ezz - eyz * ezy
        ay = eyz * ezx - eyx * ezz
        az = eyx * ezy - eyy * ezx
        V = (exx * ax + exy * ay + exz * az) * sixtyfourth
        cs = kv[q] * (V - V0[q])
        if comp == 0:
            a = ax
            b = ezy * exz - ezz * exy
            c = exy * eyz - exz * eyy
        elif comp == 1:
            a = ay
            b = ezz * exx - ezx * exz
            c = exz * eyx - exx * eyz
        else:
            a = az
            b = ezx * exy - ezy * exx
            c = exx * eyy - exy * eyx
        a *= cs
        b *= cs
        c *= cs
        W0[q] = a + b + c
        W1[q] = a - b - c
        W2[q] = a + b - c
        W3[q] = b - a - c


@_jit
def _hex_gather(W, pad, N, NX, S, G):
    """g_p += sum over the 8 cells having p as a corner (W padded with ``pad`` leading zeros):
    corner 0 -W0, 6 +W0, 1 +W1, 7 -W1, 2 +W2, 4 -W2, 3 +W3, 5 -W3 of the cell at p - offset(c),
    with W0 = A + B + C, W1 = A - B - C, W2 = A + B - C, W3 = -A + B - C."""
    o1, o2, o3 = 1, NX + 1, NX
    o4, o5, o6, o7 = S, S + 1, S + NX + 1, S + NX
    a = pad
    for d in range(3):
        g = G[d]
        w0, w6 = W[d][a:a + N], W[d][a - o6:a - o6 + N]
        w1, w7 = W[3 + d][a - o1:a - o1 + N], W[3 + d][a - o7:a - o7 + N]
        w2, w4 = W[6 + d][a - o2:a - o2 + N], W[6 + d][a - o4:a - o4 + N]
        w3, w5 = W[9 + d][a - o3:a - o3 + N], W[9 + d][a - o5:a - o5 + N]
        for q in range(N):
            g[q] += ((w6[q] - w0[q]) + (w1[q] - w7[q])) + ((w2[q] - w4[q]) + (w3[q] - w5[q]))


@_jit
def _hex_gradient(X, Y, Z, ncell, NX, S, kv, V0, W, pad, G):
    """Gradient of the hexahedron volume terms added to G.  ``W``: 12 scratch arrays of length
    ``pad + N`` (4 combinations x 3 components), zero in the first ``pad`` entries and beyond
    ``pad + ncell``."""
    if ncell == 0:
        return
    for d in range(3):
        _hex_component(X, Y, Z, ncell, NX, S, kv, V0, d, W[d][pad:], W[3 + d][pad:], W[6 + d][pad:],
                       W[9 + d][pad:])
    _hex_gather(W, pad, X.shape[0], NX, S, G)


@_jit
def _gradient(P, offs, nspan, K, L0, F, ncell, NX, S, kv, V0, W, pad, G):
    for d in range(3):
        G[d][:] = 0.0
    _spring_gradient(P[0], P[1], P[2], offs, nspan, K, L0, F, pad, G)
    _hex_gradient(P[0], P[1], P[2], ncell, NX, S, kv, V0, W, pad, G)


@_jit
def _to_lattice(x, lat, P):
    for n in range(lat.shape[0]):
        q = lat[n]
        P[0, q] = x[3 * n]
        P[1, q] = x[3 * n + 1]
        P[2, q] = x[3 * n + 2]


@_jit
def _from_lattice(P, lat, x):
    for n in range(lat.shape[0]):
        q = lat[n]
        x[3 * n] = P[0, q]
        x[3 * n + 1] = P[1, q]
        x[3 * n + 2] = P[2, q]


@_jit
def _cast(P, Pk):
    """Pk = P (elementwise conversion to the kernels' precision)."""
    for d in range(P.shape[0]):
        a, b = P[d], Pk[d]
        for q in range(a.shape[0]):
            b[q] = a[q]


@_jit
def _run(P, Vel, h, n_steps, save_every, alpha, mass, inv_m, fext,
         offs, nspan, K, L0, F, ncell, NX, S, kv, V0, W, pad, lat, out, Pk, G, copy):
    """Symplectic Euler: v += h (fext - g(x) - alpha m v) / m (free dofs: inv_m = 0 on fixed
    ones, whose velocity stays 0), x += h v.  Saves x (model layout) after every
    ``save_every``-th step into ``out``; returns the number saved.  The state ``P``, ``Vel`` and
    the update are double precision; the forces are evaluated on ``Pk``, a copy of ``P`` in the
    kernels' precision refreshed every step when ``copy`` (``Pk is P`` in double precision)."""
    N = P.shape[1]
    j = 0
    for step in range(n_steps):
        if copy:
            _cast(P, Pk)
        _gradient(Pk, offs, nspan, K, L0, F, ncell, NX, S, kv, V0, W, pad, G)
        for d in range(3):
            x, v, g, m, im, fe = P[d], Vel[d], G[d], mass[d], inv_m[d], fext[d]
            for q in range(N):
                v[q] += h * (fe[q] - g[q] - alpha * m[q] * v[q]) * im[q]
                x[q] += h * v[q]
        if (step + 1) % save_every == 0 and j < out.shape[0]:
            _from_lattice(P, lat, out[j])
            j += 1
    return j

"""Fast explicit dynamics of mass-spring models on structured hexahedral lattices.

:class:`LatticeExplicit` takes a :class:`msslib.model.Model` whose nodes form a full structured
lattice (``nx + 1`` by ``ny + 1`` by ``nz + 1`` points on a tensor-product grid; the spacing may
vary along each axis, the node numbering is free) and whose terms are

* 3D :class:`~msslib.terms.Springs` between lattice neighbours (the 26 neighbours of a node: edges,
  face and inner diagonals of the cells, any stiffness and rest length per spring),
* :class:`~msslib.terms.HexVolume` terms on lattice cells (corners in VTK order, any subset of
  the cells, one volume term per cell),
* constant external loads (:class:`~msslib.terms.ExternalForce`: gravity, nodal forces,
  tractions), scaled by the load factor,

and evaluates the same forces as ``model.force`` with loops that the compiler vectorises: the
state is stored structure-of-arrays (x, y, z in lattice order) and the springs are grouped by the
13 lattice directions, so that for a direction with flat offset ``o`` the springs are the node
pairs ``(p, p + o)``: contiguous shifted slices, no indirect indexing, no scattered writes.  A
pair that is not a spring (it wraps around the lattice, or the model has no spring there) has
``k = 0``.  The hexahedron volume term (Golec's averaged-edge volume
``V = ex . (ey x ez) / 64``) is evaluated the same way over the cell slots, and its nodal forces
are gathered from the neighbouring cells.

:meth:`LatticeExplicit.run` is the symplectic Euler loop of
``msslib.solvers.integrate(..., method="symplectic_euler")`` with mass-proportional damping,
entirely in numba: ``v += h (f(x) - alpha M v) / M`` on the free dofs, then ``x += h v``.
In double precision (the default) results agree with the model to round-off (summation order
differs); with ``precision="single"`` the force kernels run in single precision on a copy of
the positions (state and update stay double), about twice as fast, with forces within about
1e-5 of the double ones; see ``tests/test_fastexplicit.py``.
"""

from __future__ import annotations

import os

import numpy as np
from numba import njit
from numba.core import types as _types
from numba.extending import overload as _overload

from msslib.terms import ExternalForce, HexVolume, Springs, Term

__all__ = ["LatticeExplicit", "lattice_index"]

# fastmath as in msslib.terms (no reassociation: results stay deterministic and close to the
# generated kernels); nogil, cached on disk (MSSLIB_FASTEXPLICIT_NOCACHE=1 compiles in memory,
# e.g. to inspect the generated assembly).
_CACHE = os.environ.get("MSSLIB_FASTEXPLICIT_NOCACHE", "") == ""
_FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
_jit = njit(cache=_CACHE, error_model="numpy", nogil=True, fastmath=_FAST)

# corners of a hexahedron in VTK order, as lattice steps (di, dj, dk)
_HEX_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])


def _directions():
    """The 13 lattice directions (di, dj, dk) whose flat offset is positive (the most significant
    non-zero step, k then j then i, is +1)."""
    out = []
    for dk in (-1, 0, 1):
        for dj in (-1, 0, 1):
            for di in (-1, 0, 1):
                s = (dk, dj, di)
                first = next((c for c in s if c != 0), 0)
                if first > 0:
                    out.append((di, dj, dk))
    return np.array(out, dtype=np.int64)


_DIRS = _directions()  # (13, 3)
# direction index of a positive step (di, dj, dk) from its code (di + 1) + 3 (dj + 1) + 9 (dk + 1)
_DIR_OF_CODE = np.full(27, -1, dtype=np.int64)
_DIR_OF_CODE[(_DIRS[:, 0] + 1) + 3 * (_DIRS[:, 1] + 1) + 9 * (_DIRS[:, 2] + 1)] = np.arange(len(_DIRS))


def _axis_levels(c, tol):
    """Distinct coordinate levels of ``c`` (clusters closer than ``tol``) and the level of each."""
    order = np.argsort(c, kind="stable")
    cs = c[order]
    new = np.concatenate([[True], np.diff(cs) > tol])
    level_sorted = np.cumsum(new) - 1
    level = np.empty(len(c), dtype=np.int64)
    level[order] = level_sorted
    return int(level_sorted[-1]) + 1, level


def lattice_index(points, rtol: float = 1e-9):
    """Structured-lattice numbering of ``points`` (n, 3).

    Returns ``(shape, ijk)``: ``shape = (NX, NY, NZ)`` the numbers of coordinate levels per axis and
    ``ijk`` (n, 3) the level of every point.  Raises ValueError unless the points are exactly the
    ``NX NY NZ`` nodes of a tensor-product grid (coordinates equal within ``rtol`` times the
    bounding-box size)."""
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) == 0:
        raise ValueError(f"need 3D points (n, 3), got shape {p.shape}")
    size = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) or 1.0
    tol = rtol * size
    shape, ijk = [], []
    for d in range(3):
        n, lev = _axis_levels(p[:, d], tol)
        shape.append(n)
        ijk.append(lev)
    ijk = np.column_stack(ijk)
    NX, NY, NZ = shape
    if NX * NY * NZ != len(p):
        raise ValueError(f"the {len(p)} nodes are not a structured lattice: {NX} x {NY} x {NZ} coordinate "
                         f"levels would give {NX * NY * NZ} nodes")
    flat = ijk[:, 0] + NX * (ijk[:, 1] + NY * ijk[:, 2])
    if len(np.unique(flat)) != len(p):
        raise ValueError("the nodes are not a structured lattice: two nodes share a lattice position")
    # each level must be one coordinate value (tensor-product grid)
    for d in range(3):
        lo = np.full(shape[d], np.inf)
        hi = np.full(shape[d], -np.inf)
        np.minimum.at(lo, ijk[:, d], p[:, d])
        np.maximum.at(hi, ijk[:, d], p[:, d])
        if np.any(hi - lo > tol):
            raise ValueError("the nodes are not on a tensor-product grid")
    return (NX, NY, NZ), ijk


# --------------------------------------------------------------------------------------------
# numba kernels.  Node arrays are lattice ordered (q = i + NX (j + NY k)), length N.  The
# per-direction spring forces F and the per-cell hexahedron vectors W are stored with PAD
# leading zeros so that the gathers at q - offset never go below 0.
# --------------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------------
# the facility
# --------------------------------------------------------------------------------------------


class LatticeExplicit:
    """Vectorised force evaluation and explicit dynamics for a model on a structured hex lattice.

    Parameters
    ----------
    model : :class:`msslib.model.Model` (3D) whose nodes form a full tensor-product lattice and
        whose terms are Springs between lattice neighbours, HexVolume terms on lattice cells and
        constant external loads (anything else raises ValueError naming the term).  The lattice
        is detected from the rest positions ``model.mesh.points``.
    load : load factor of the external loads (constant during :meth:`run`).
    precision : ``"double"`` (default) or ``"single"``: the arithmetic of the force kernels.
        The state and the time update stay double precision either way.  Single precision
        halves the memory the kernels stream and doubles the SIMD width; its forces differ from
        the double ones by about 1e-5 of their size (rounding of positions to 24 bits: the
        cancellation in ``x_a - x_b`` and ``V - V0``), far below the time-discretisation
        error of an explicit run at the stability limit (``benchmarks/dynamics.py`` reports
        both).  Use double for anything compared with the model to round-off.

    The springs of the model are stored once (spring constants, rest lengths) per direction and
    base node, ``2 x 13 x N`` floats for ``N`` lattice nodes; several springs on the same node
    pair (from several Springs terms) are combined into one of summed stiffness and k-weighted
    rest length (exact up to round-off).  The object holds scratch buffers: use one object per
    thread.
    """

    def __init__(self, model, load: float = 1.0, precision: str = "double"):
        if precision not in ("double", "single"):
            raise ValueError(f"precision must be 'double' or 'single', got {precision!r}")
        self.precision = precision
        self.dtype = np.dtype(np.float64 if precision == "double" else np.float32)
        if getattr(model, "dim", None) != 3:
            raise ValueError("LatticeExplicit needs a 3D model")
        (NX, NY, NZ), ijk = lattice_index(model.mesh.points)
        self.shape = (NX, NY, NZ)
        self.NX, self.S = NX, NX * NY
        N = NX * NY * NZ
        self.N = N
        self.lat = np.ascontiguousarray(ijk[:, 0] + NX * (ijk[:, 1] + NY * ijk[:, 2]), dtype=np.int64)
        self._ijk = ijk
        self.offs = np.array([di + NX * (dj + NY * dk) for di, dj, dk in _DIRS], dtype=np.int64)
        self.pad = self.S + NX + 1  # largest offset (direction (1, 1, 1) and cell corner 6)
        self.load = float(load)

        springs, hexes, external, other = [], [], [], []
        for t in model.terms:
            if isinstance(t, Springs):
                springs.append(t)
            elif isinstance(t, HexVolume):
                hexes.append(t)
            elif isinstance(t, ExternalForce):
                external.append(t)
            elif isinstance(t, Term):
                other.append(t)
        if other:
            raise ValueError("LatticeExplicit supports Springs, HexVolume and constant external loads only; "
                             f"got {', '.join(type(t).__name__ for t in other)}")
        self._build_springs(springs)
        self._build_hexes(hexes)

        # constant external force at the load factor, lattice layout
        fext = np.zeros(model.n_dof)
        for t in external:
            fext += self.load * t.vector
        self.fext_flat = fext
        self.fext = self.to_lattice(fext)
        mass = np.asarray(model.mass, dtype=float).reshape(-1)
        free = np.asarray(model.free, dtype=bool).reshape(-1)
        if np.any(mass[free] <= 0):
            raise ValueError("masses of free dofs must be positive")
        self.free_flat = free
        self.mass = self.to_lattice(mass)
        inv = np.zeros(model.n_dof)
        inv[free] = 1.0 / mass[free]
        self.inv_m = self.to_lattice(inv)
        self.model = model
        # the kernels' copies of the constants, in their precision
        dt = self.dtype
        self._K, self._L0 = (np.ascontiguousarray(a, dtype=dt) for a in (self.K, self.L0))
        self._kv, self._V0 = (np.ascontiguousarray(a, dtype=dt) for a in (self.kv, self.V0))
        # scratch: separate allocations (the compiler then knows they do not overlap)
        self._F = tuple(np.zeros(self.pad + N, dtype=dt) for _ in range(3))
        self._W = tuple(np.zeros(self.pad + N, dtype=dt) for _ in range(12))

    # ---- construction ----------------------------------------------------------------------

    def _build_springs(self, springs):
        NX, NY, N = self.NX, self.shape[1], self.N
        K = np.zeros((13, N))
        KL = np.zeros((13, N))
        L0 = np.zeros((13, N))
        count = np.zeros((13, N), dtype=np.int64)
        ijk = self._ijk
        for t in springs:
            if t.dim != 3:
                raise ValueError("LatticeExplicit needs 3D springs")
            if len(t.conn) == 0:
                continue
            a, b = t.conn[:, 0], t.conn[:, 1]
            step = ijk[b] - ijk[a]
            if np.any(np.abs(step) > 1) or np.any(np.all(step == 0, axis=1)):
                bad = np.flatnonzero(np.any(np.abs(step) > 1, axis=1) | np.all(step == 0, axis=1))
                raise ValueError(f"{len(bad)} spring(s) do not join lattice neighbours, e.g. nodes "
                                 f"{tuple(int(v) for v in t.conn[bad[0]])}")
            # orient every spring so that its flat offset is positive
            off = step[:, 0] + NX * (step[:, 1] + NY * step[:, 2])
            flip = off < 0
            step = np.where(flip[:, None], -step, step)
            base = np.where(flip, self.lat[b], self.lat[a])
            d = _DIR_OF_CODE[(step[:, 0] + 1) + 3 * (step[:, 1] + 1) + 9 * (step[:, 2] + 1)]
            np.add.at(K, (d, base), t.k)
            np.add.at(KL, (d, base), t.k * t.rest_length)
            np.add.at(count, (d, base), 1)
            L0[d, base] = t.rest_length  # exact when the pair has one spring
        multi = count > 1
        L0[multi] = KL[multi] / K[multi]
        # spans: springs of direction d have base < nspan[d] (loop over 0..nspan-1, k = 0 elsewhere)
        nspan = np.zeros(13, dtype=np.int64)
        for d in range(13):
            nz = np.flatnonzero(count[d])
            nspan[d] = nz[-1] + 1 if len(nz) else 0
        self.K, self.L0, self.nspan = K, L0, nspan
        self.n_springs = int(sum(len(t.conn) for t in springs))

    def _build_hexes(self, hexes):
        NX, NY, NZ = self.shape
        N = self.N
        kap = np.zeros(N)
        V0 = np.ones(N)
        have = np.zeros(N, dtype=bool)
        ijk = self._ijk
        for t in hexes:
            if len(t.conn) == 0:
                continue
            c = t.conn
            rel = ijk[c] - ijk[c[:, :1]]  # (m, 8, 3)
            bad = np.flatnonzero(np.any(rel != _HEX_CORNERS[None], axis=(1, 2)))
            if len(bad):
                raise ValueError(f"{len(bad)} hexahedra of HexVolume are not lattice cells with corners in VTK order "
                                 f"(x, then y, then z), e.g. cell {int(bad[0])}: nodes {c[bad[0]].tolist()}")
            base = self.lat[c[:, 0]]
            if np.any(have[base]) or len(np.unique(base)) != len(base):
                raise ValueError("LatticeExplicit supports one HexVolume term per cell")
            have[base] = True
            kap[base] = t.kappa
            V0[base] = t.V0
        nz = np.flatnonzero(have)
        self.ncell = int(nz[-1] + 1) if len(nz) else 0
        self.kappa, self.V0 = kap, V0
        self.kv = kap / (64.0 * V0)  # the hexahedron kernel's scale: no division per step
        self.n_hexes = int(have.sum())

    # ---- layout ------------------------------------------------------------------------------

    def to_lattice(self, x) -> np.ndarray:
        """Flat model vector (n_dof,) -> (3, N) lattice-ordered components."""
        x = np.ascontiguousarray(x, dtype=float).reshape(-1)
        if x.size != 3 * self.N:
            raise ValueError(f"expected {3 * self.N} entries, got {x.size}")
        P = np.empty((3, self.N))
        _to_lattice(x, self.lat, P)
        return P

    def from_lattice(self, P) -> np.ndarray:
        """(3, N) lattice-ordered components -> flat model vector."""
        x = np.empty(3 * self.N)
        _from_lattice(np.ascontiguousarray(P, dtype=float), self.lat, x)
        return x

    # ---- forces --------------------------------------------------------------------------------

    def gradient_lattice(self, P, G=None) -> np.ndarray:
        """Gradient of the internal terms (springs + hex volume) at lattice positions ``P``
        (converted to the kernels' precision, as is ``G``, which is returned)."""
        P = np.ascontiguousarray(P, dtype=self.dtype)
        if G is None:
            G = np.empty((3, self.N), dtype=self.dtype)
        elif G.dtype != self.dtype or G.shape != (3, self.N) or not G.flags.c_contiguous:
            raise ValueError(f"G must be a C-contiguous (3, {self.N}) array of {self.dtype}")
        _gradient(P, self.offs, self.nspan, self._K, self._L0, self._F, self.ncell, self.NX, self.S,
                  self._kv, self._V0, self._W, self.pad, G)
        return G

    def internal_gradient(self, x) -> np.ndarray:
        """Sum of the gradients of the springs and volume terms (flat, model layout)."""
        return self.from_lattice(self.gradient_lattice(self.to_lattice(x)).astype(float))

    def force(self, x) -> np.ndarray:
        """``model.force(x, load)`` (flat, model layout)."""
        return self.fext_flat - self.internal_gradient(x)

    # ---- dynamics ------------------------------------------------------------------------------

    def stability_limit(self, x, alpha: float = 0.0) -> dict:
        """:func:`msslib.solvers.check_time_step` information (``stability_limit``, ...) of a run
        from ``x`` with damping ``alpha``, without a check; ``omega_max`` is computed once per
        starting state (kept for the next call from the same ``x``)."""
        from msslib.solvers import check_time_step

        return check_time_step(self.model, x, 0.0, method="symplectic_euler", damping=float(alpha),
                               load=self.load, omega_max=self._omega_max(x))

    def _omega_max(self, x):
        x = np.asarray(x, dtype=float).reshape(-1)
        cached = getattr(self, "_omega_cache", None)
        if cached is not None and cached[0].shape == x.shape and np.array_equal(cached[0], x):
            return cached[1]
        from msslib.solvers import _omega_max_squared

        omega = float(np.sqrt(_omega_max_squared(self.model, x, self.load)))
        self._omega_cache = (x.copy(), omega)
        return omega

    def run(self, x, v, h: float, n_steps: int, alpha: float | None = None, save_every: int = 1,
            allow_unstable: bool = False):
        """Symplectic Euler with mass-proportional damping ``C = alpha M`` for ``n_steps`` steps of
        ``h``; the scheme of ``solvers.integrate(method="symplectic_euler", damping=alpha)``.

        ``x``, ``v``: flat model-layout state (not modified; the velocity of fixed dofs is set to
        0 and fixed dofs keep their position).  ``alpha`` None takes ``model.damping`` (a scalar;
        Rayleigh ``beta`` is not supported).  Returns ``(x, v, saved)`` with ``saved`` the
        positions after steps ``save_every, 2 save_every, ...`` (``n_steps // save_every`` rows).

        As in :func:`msslib.solvers.integrate`, a step ``h`` above the stability limit of the model
        at ``x`` (:func:`msslib.solvers.check_time_step`, computed on the first call from a given
        ``x`` and kept) raises :class:`msslib.errors.StabilityError` unless ``allow_unstable``.
        The numba loop itself has no per-step divergence detector (it would cost the loop its
        vectorisation): a non-finite final state raises :class:`msslib.solvers.DivergenceError`."""
        if alpha is None:
            alpha = self.model.damping if self.model.damping is not None else 0.0
            if np.ndim(alpha) != 0:
                a, beta = alpha
                if beta:
                    raise ValueError("LatticeExplicit.run supports mass-proportional damping only (beta = 0)")
                alpha = a
        if not (h > 0) or n_steps < 0 or save_every < 1:
            raise ValueError("need h > 0, n_steps >= 0 and save_every >= 1")
        from msslib.solvers import DivergenceError, check_time_step

        limit = check_time_step(self.model, x, float(h), method="symplectic_euler", damping=float(alpha),
                                load=self.load, allow_unstable=allow_unstable,
                                omega_max=self._omega_max(x))["stability_limit"]
        P = self.to_lattice(x)
        vv = np.array(v, dtype=float).reshape(-1)
        vv[~self.free_flat] = 0.0
        Vel = self.to_lattice(vv)
        out = np.empty((n_steps // save_every, 3 * self.N))
        copy = self.dtype != P.dtype
        Pk = np.empty(P.shape, dtype=self.dtype) if copy else P
        G = np.zeros(P.shape, dtype=self.dtype)
        _run(P, Vel, float(h), int(n_steps), int(save_every), float(alpha), self.mass, self.inv_m, self.fext,
             self.offs, self.nspan, self._K, self._L0, self._F, self.ncell, self.NX, self.S, self._kv, self._V0,
             self._W, self.pad, self.lat, out, Pk, G, copy)
        if not (np.isfinite(P).all() and np.isfinite(Vel).all()):
            raise DivergenceError(
                f"LatticeExplicit.run diverged: non-finite state after {n_steps} steps of h = {h:.6g} s (the "
                f"stability limit of the model at the start is {limit:.6g} s; the loop does not check each step)",
                step=int(n_steps), time=float(n_steps * h), quantity="position", dof=-1, value=float("nan"),
                dt=float(h), stability_limit=limit)
        return self.from_lattice(P), self.from_lattice(Vel), out

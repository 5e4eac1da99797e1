"""Fast explicit dynamics of mass-spring models on structured hexahedral lattices.

:class:`LatticeExplicit` takes a :class:`msslib.system.Model` whose nodes form a full structured
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
``msslib.stepping.integrate(..., method="symplectic_euler")`` with mass-proportional damping,
entirely in numba: ``v += h (f(x) - alpha M v) / M`` on the free dofs, then ``x += h v``.
In double precision (the default) results agree with the model to round-off (summation order
differs); with ``precision="single"`` the force kernels run in single precision on a copy of
the positions (state and update stay double), about twice as fast, with forces within about
1e-5 of the double ones; see ``tests/test_fastexplicit.py``.

This module finds the lattice (:func:`lattice_index`) and holds the integrator; the numba
kernels are in :mod:`msslib.stepping.lattice_kernels`.
"""

from __future__ import annotations

import numpy as np

from msslib.stepping.lattice_kernels import _from_lattice, _gradient, _run, _to_lattice
from msslib.terms import ExternalForce, HexVolume, Springs, Term

__all__ = ["LatticeExplicit", "lattice_index"]

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
# the facility
# --------------------------------------------------------------------------------------------


class LatticeExplicit:
    """Vectorised force evaluation and explicit dynamics for a model on a structured hex lattice.

    Parameters
    ----------
    model : :class:`msslib.system.Model` (3D) whose nodes form a full tensor-product lattice and
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
        from msslib.solvers.stability import omega_max_squared

        omega = float(np.sqrt(omega_max_squared(self.model, x, self.load)))
        self._omega_cache = (x.copy(), omega)
        return omega

    def run(self, x, v, h: float, n_steps: int, alpha: float | None = None, save_every: int = 1,
            allow_unstable: bool = False):
        """Symplectic Euler with mass-proportional damping ``C = alpha M`` for ``n_steps`` steps of
        ``h``; the scheme of ``msslib.stepping.integrate(method="symplectic_euler", damping=alpha)``.

        ``x``, ``v``: flat model-layout state (not modified; the velocity of fixed dofs is set to
        0 and fixed dofs keep their position).  ``alpha`` None takes ``model.damping`` (a scalar;
        Rayleigh ``beta`` is not supported).  Returns ``(x, v, saved)`` with ``saved`` the
        positions after steps ``save_every, 2 save_every, ...`` (``n_steps // save_every`` rows).

        As in :func:`msslib.stepping.integrate`, a step ``h`` above the stability limit of the model
        at ``x`` (:func:`msslib.solvers.check_time_step`, computed on the first call from a given
        ``x`` and kept) raises :class:`msslib.errors.StabilityError` unless ``allow_unstable``.
        The numba loop itself has no per-step divergence detector (it would cost the loop its
        vectorisation): a non-finite final state raises :class:`msslib.solvers.DivergenceError`."""
        from msslib.solvers.stability import mass_proportional_alpha

        alpha = mass_proportional_alpha(self.model, alpha, "LatticeExplicit.run")
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


class LatticeStepper:
    """The stepper of ``engine="lattice"`` (a :class:`~msslib.stepping.protocol.Stepper`):
    :class:`LatticeExplicit`'s vectorised symplectic Euler behind the Simulator.

    For a model on a full structured hexahedral lattice (springs between lattice neighbours,
    Golec's hexahedron volume terms, constant external loads) with its own supports, constant loads
    and mass-proportional damping.  The state stays in lattice order between calls (reading ``x``
    or ``v`` converts it); the divergence check is the non-finite test at the end of each call, as
    on the JAX engine.  The stability check runs once, on the model (as the other engines')."""

    explicit = True

    def __init__(self, model, x0, v0, *, dt, damping=None, load=1.0, allow_unstable=False, blowup=1e3,
                 free=None, drive=None):
        from msslib.solvers import protocol
        from msslib.solvers.stability import check_time_step, mass_proportional_alpha
        from msslib.stepping.protocol import constant_loads_only

        constant_loads_only("lattice", model, free, drive)
        alpha = mass_proportional_alpha(model, damping, "engine='lattice'")
        try:
            self.lat = LatticeExplicit(model, load=float(load))
        except ValueError as exc:
            raise ValueError(f"engine='lattice' runs models on a full structured hexahedral lattice with springs, "
                             f"hexahedron volume terms and constant loads ({exc}); other models run on engine="
                             f"'network' or 'generic'") from None
        self.model, self.dt, self.load, self.alpha, self.extra = model, float(dt), float(load), float(alpha), None
        self.free = np.asarray(model.free, dtype=bool)
        self.mass = np.asarray(model.mass, dtype=float)
        x0 = np.array(x0, dtype=float).reshape(-1)
        check = check_time_step(model, x0, self.dt, method="symplectic_euler", damping=self.alpha, load=self.load,
                                allow_unstable=allow_unstable)
        self.limit = check["stability_limit"]
        self.conservative = protocol.is_conservative(model, x0, self.load)
        vv = np.array(v0, dtype=float).reshape(-1)
        vv[~self.free] = 0.0
        self._P, self._V = self.lat.to_lattice(x0), self.lat.to_lattice(vv)
        copy = self.lat.dtype != self._P.dtype
        self._Pk = np.empty(self._P.shape, dtype=self.lat.dtype) if copy else self._P
        self._G = np.zeros(self._P.shape, dtype=self.lat.dtype)
        self._copy = copy
        self._none = np.empty((0, 3 * self.lat.N))
        self.t, self.n_taken = 0.0, 0
        self.messages: list[str] = []
        self.stats = {"method": "symplectic_euler", "dt": self.dt, "n_steps": 0, "damping": (self.alpha, 0.0),
                      **check, "engine": "lattice", "n_force_evals": 0}

    @property
    def x(self) -> np.ndarray:
        return self.lat.from_lattice(self._P)

    @property
    def v(self) -> np.ndarray:
        return self.lat.from_lattice(self._V)

    def full_force(self) -> np.ndarray:
        return np.asarray(self.model.force(self.x, self.load), dtype=float)

    def reaction(self) -> np.ndarray:
        return np.where(self.free, 0.0, -self.full_force())

    def kinetic_energy(self) -> float:
        v = self.v
        return 0.5 * float(self.mass[self.free] @ (v[self.free] ** 2))

    def evaluate(self):
        """Nothing to keep: the loop computes the force at the start of every step."""

    def restart_detector(self):
        """Nothing to restart: the check is the non-finite test at the end of each call."""

    def steps(self, n: int, h=None, t_new=None):
        from msslib.errors import DivergenceError
        from msslib.stepping.lattice_kernels import _run

        if h is not None and abs(h - self.dt) > 1e-12 * self.dt:
            raise ValueError(f"engine='lattice' steps at dt = {self.dt:.6g} s only, got h = {h!r}")
        n = int(n)
        lat = self.lat
        P, V = self._P.copy(), self._V.copy()  # the state before the call stays until the call succeeded
        Pk = np.empty(P.shape, dtype=lat.dtype) if self._copy else P
        _run(P, V, self.dt, n, n + 1, self.alpha, lat.mass, lat.inv_m, lat.fext, lat.offs, lat.nspan, lat._K,
             lat._L0, lat._F, lat.ncell, lat.NX, lat.S, lat._kv, lat._V0, lat._W, lat.pad, lat.lat, self._none, Pk,
             self._G, self._copy)
        if not (np.isfinite(P).all() and np.isfinite(V).all()):
            raise DivergenceError(
                f"engine='lattice' diverged: non-finite state after {self.n_taken + n} steps of dt = {self.dt:.6g} s "
                f"(the stability limit at the start is {self.limit:.6g} s; the loop checks at the end of each call); "
                f"the state is that before the call", step=self.n_taken + n, time=self.t + n * self.dt,
                quantity="position", dof=-1, value=float("nan"), dt=self.dt, stability_limit=self.limit)
        self._P, self._V = P, V
        self.n_taken += n
        self.t = self.t + n * self.dt if t_new is None else float(t_new)
        self.stats["n_steps"] = self.n_taken
        self.stats["n_force_evals"] += n

    def step(self, h=None, t_new=None):
        self.steps(1, h, t_new)

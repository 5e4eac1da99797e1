"""Explicit steps of a model on a structured hexahedral lattice on JAX (:class:`JaxLattice`), the
scheme and the forces of :class:`msslib.stepping.LatticeExplicit` as a stencil.

The state is one array ``(3, NZ, NY, NX)`` per quantity (the lattice order of
:class:`~msslib.stepping.LatticeExplicit`, ``q = i + NX (j + NY k)``, reshaped).  The springs of
each of the 13 lattice directions ``(di, dj, dk)`` are the pairs of a slice of the lattice and the
same slice shifted by the direction (no wrap-around: the slices stop at the boundary); their
forces are added to both ends by padding them back to the lattice's shape, which the compiler
fuses into one pass.  The hexahedron volume term (Golec's averaged-edge volume
``V = ex . (ey x ez) / 64``) is evaluated on the ``(NZ-1, NY-1, NX-1)`` cells from the 8 shifted
corner slices and its corner forces are padded back the same way.  The tables (spring constants
and rest lengths per direction and base node, the volume constants per cell, masses, loads) and
the checks of the model are those of :class:`~msslib.stepping.LatticeExplicit`, which is built
once for them.

:meth:`JaxLattice.run` has the signature and the results of :meth:`LatticeExplicit.run`
(``v += h (f_ext - g(x) - alpha m v) / m`` on the free dofs, ``x += h v``), so either object can
run a caller's loop; :meth:`JaxLattice.reset`, :meth:`JaxLattice.steps`,
:meth:`JaxLattice.positions` and :meth:`JaxLattice.velocities` keep the state on the device
between calls.
"""

from __future__ import annotations

import numpy as np

from msslib.errors import DivergenceError
from msslib.stepping.lattice import _DIRS, _HEX_CORNERS, LatticeExplicit

from .device import check_precision, default_device, describe, use_jax, x64

__all__ = ["JaxLattice", "lattice_engine"]


def _axis_slices(s, n):
    """Base and partner slices along an axis of ``n`` points for a step ``s`` in {-1, 0, 1}, and
    the pad widths that put an array of the slice's length back at each."""
    lo, hi = max(0, -s), max(0, s)
    return slice(lo, n - hi), slice(hi, n - lo), (lo, hi), (hi, lo)


class JaxLattice:
    """Forces and symplectic Euler steps of a structured-lattice model on JAX.

    Parameters
    ----------
    model, load : as :class:`msslib.stepping.LatticeExplicit` (3D Springs between lattice
        neighbours, HexVolume terms on lattice cells, constant external loads; anything else
        raises its ValueError naming the term).
    precision : ``"double"`` (default; agrees with ``LatticeExplicit(model,
        precision="double")`` to round-off) or ``"single"``: the force stencil in fp32 on an fp32
        copy of the positions, state and update in fp64 (the meaning of ``"single"`` in
        :class:`~msslib.stepping.LatticeExplicit`).
    unroll : steps per iteration of the device loop (default 8 below 10^6 nodes, else 1).
    device : None (the first GPU JAX sees, else its CPU), ``"gpu"`` or ``"cpu"``.

    Double precision is scoped to the backend's calls (``jax.enable_x64`` contexts): JAX's global
    flag is not changed.
    """

    backend = "jax"

    def __init__(self, model, load: float = 1.0, precision: str = "double", *, unroll=None, device=None):
        import jax
        import jax.numpy as jnp

        self.dtype = check_precision(precision)
        self.precision = precision
        cpu = LatticeExplicit(model, load=load, precision="double")
        self._cpu = cpu
        self.model, self.load = model, float(load)
        self.shape = cpu.shape
        NX, NY, NZ = cpu.shape
        self._grid = (NZ, NY, NX)
        self.n_springs, self.n_hexes, self.N = cpu.n_springs, cpu.n_hexes, cpu.N
        self._jax_device = default_device(device)
        self.device = describe(self._jax_device)
        self.unroll = int(unroll) if unroll is not None else (8 if self.N < 10**6 else 1)
        if self.unroll < 1:
            raise ValueError(f"unroll must be >= 1, got {unroll!r}")
        grid = lambda a: np.asarray(a, dtype=float).reshape((-1,) + self._grid)  # noqa: E731
        self._dirs = []  # (direction index, base slices, partner slices, base pads, partner pads)
        K, L0 = [], []
        for d, step in enumerate(_DIRS):
            if cpu.nspan[d] == 0:
                continue
            axes = [_axis_slices(int(s), n) for s, n in zip(step[::-1], self._grid)]  # z, y, x
            base = tuple(a[0] for a in axes)
            self._dirs.append((base, tuple(a[1] for a in axes), tuple(a[2] for a in axes),
                               tuple(a[3] for a in axes)))
            K.append(grid(cpu.K[d])[0][base])
            L0.append(grid(cpu.L0[d])[0][base])
        cells = (slice(0, NZ - 1), slice(0, NY - 1), slice(0, NX - 1))
        dt = self.dtype
        with x64():
            put = lambda a, t=dt: jax.device_put(np.ascontiguousarray(a, dtype=t), self._jax_device)  # noqa: E731
            self._consts = dict(K=[put(k) for k in K], L0=[put(x) for x in L0],
                                mass=put(grid(cpu.mass), np.float64), inv_m=put(grid(cpu.inv_m), np.float64),
                                fext=put(grid(cpu.fext), np.float64))
            if cpu.n_hexes:
                self._consts["kv"] = put(grid(cpu.kv)[0][cells])
                self._consts["V0"] = put(grid(cpu.V0)[0][cells])
            self._gradient = jax.jit(lambda P, c: self._stencil(jnp, P, c))
            self._run = jax.jit(self._loop(jax, jnp))
        self._x = self._v = None
        self.n_steps = 0

    # ---- the stencil -------------------------------------------------------------------------

    def _stencil(self, jnp, P, c):
        """Gradient of the springs and volume terms (3, NZ, NY, NX) at positions ``P`` (computed
        in the backend's precision, returned in that of ``P``)."""
        X = P.astype(self.dtype)
        tiny = 1e-300 if self.dtype == np.float64 else 1e-30  # as the numba kernel: empty slots stay finite
        G = jnp.zeros_like(X)
        for (base, part, pb, pp), k, L0 in zip(self._dirs, c["K"], c["L0"]):
            D = X[(slice(None),) + base] - X[(slice(None),) + part]
            r = 1.0 / jnp.sqrt(D[0] * D[0] + D[1] * D[1] + D[2] * D[2] + tiny)
            f = D * (k * (L0 * r - 1.0))
            G = G - jnp.pad(f, ((0, 0),) + pb) + jnp.pad(f, ((0, 0),) + pp)
        if "kv" in c:
            G = G + self._hexes(jnp, X, c["kv"], c["V0"])
        return G.astype(P.dtype)

    def _hexes(self, jnp, X, kv, V0):
        NZ, NY, NX = self._grid
        x = [X[:, ck:ck + NZ - 1, cj:cj + NY - 1, ci:ci + NX - 1] for ci, cj, ck in _HEX_CORNERS]
        ex = (x[1] - x[0]) + (x[2] - x[3]) + (x[5] - x[4]) + (x[6] - x[7])
        ey = (x[3] - x[0]) + (x[2] - x[1]) + (x[7] - x[4]) + (x[6] - x[5])
        ez = (x[4] - x[0]) + (x[5] - x[1]) + (x[6] - x[2]) + (x[7] - x[3])

        def cross(p, q):
            return jnp.stack([p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]])

        a = cross(ey, ez)
        V = (ex[0] * a[0] + ex[1] * a[1] + ex[2] * a[2]) * (1.0 / 64.0)
        cs = kv * (V - V0)
        A, B, C = cs * a, cs * cross(ez, ex), cs * cross(ex, ey)
        G = jnp.zeros_like(X)
        for ci, cj, ck in _HEX_CORNERS:  # d V / d x_corner = sx A + sy B + sz C, s = +1 on the upper side
            g = (A if ci else -A) + (B if cj else -B) + (C if ck else -C)
            G = G + jnp.pad(g, ((0, 0), (ck, 1 - ck), (cj, 1 - cj), (ci, 1 - ci)))
        return G

    def _loop(self, jax, jnp):
        from jax import lax

        u = self.unroll

        def step(s, c, h, alpha):
            x, v = s
            g = self._stencil(jnp, x, c)
            v = v + h * (c["fext"] - g - alpha * c["mass"] * v) * c["inv_m"]
            return x + h * v, v

        def run(s, c, h, alpha, n):
            def chunk(_, s):
                for _ in range(u):
                    s = step(s, c, h, alpha)
                return s

            s = lax.fori_loop(0, n // u, chunk, s)
            s = lax.fori_loop(0, n % u, lambda _, s: step(s, c, h, alpha), s)
            return s, jnp.isfinite(s[0]).all() & jnp.isfinite(s[1]).all()

        return run

    # ---- layout and forces -------------------------------------------------------------------

    def _to_device(self, x):
        import jax

        return jax.device_put(self._cpu.to_lattice(x).reshape((3,) + self._grid), self._jax_device)

    def _to_model(self, P) -> np.ndarray:
        return self._cpu.from_lattice(np.asarray(P, dtype=float).reshape(3, -1))

    def force(self, x) -> np.ndarray:
        """``model.force(x, load)`` (flat, model layout) from the stencil."""
        with x64():
            G = self._gradient(self._to_device(x), self._consts)
            return self._cpu.fext_flat - self._to_model(G)

    # ---- dynamics ----------------------------------------------------------------------------

    def _alpha(self, alpha):
        from msslib.solvers.stability import mass_proportional_alpha

        return mass_proportional_alpha(self.model, alpha, "JaxLattice")

    def reset(self, x, v, h: float, alpha: float | None = None, allow_unstable: bool = False,
              omega_max: float | None = None):
        """Start from the flat model-layout state ``x``, ``v`` (velocities of fixed dofs set to
        0) with steps of ``h``; the stability check of :func:`msslib.solvers.check_time_step` (the
        cheap bound first, Lanczos only when ``h`` is above the bound's limit; StabilityError
        above the limit unless ``allow_unstable``; ``omega_max``: a value computed earlier for
        the same state, or an upper bound of it)."""
        from msslib.solvers import check_time_step

        alpha = self._alpha(alpha)
        if not (np.isfinite(h) and h > 0) or alpha < 0:
            raise ValueError(f"need h > 0 and alpha >= 0, got h = {h!r}, alpha = {alpha!r}")
        self.stability = check_time_step(self.model, x, float(h), method="symplectic_euler", damping=alpha,
                                         load=self.load, allow_unstable=allow_unstable, omega_max=omega_max)
        vv = np.array(v, dtype=float).reshape(-1)
        vv[~self._cpu.free_flat] = 0.0
        self.h, self.alpha = float(h), alpha
        with x64():
            self._x, self._v = self._to_device(x), self._to_device(vv)
        self.n_steps = 0
        return self

    def steps(self, n: int):
        """Advance ``n`` steps in one device call from the state of :meth:`reset`."""
        if self._x is None:
            raise ValueError("JaxLattice.steps: call reset(x, v, h) first")
        n = int(n)
        if n <= 0:
            return self
        with x64():
            s, finite = self._run((self._x, self._v), self._consts, self.h, self.alpha, np.int32(n))
            if not bool(finite):
                limit = self.stability["stability_limit"]
                raise DivergenceError(
                    f"JaxLattice diverged: non-finite state within the {n} steps of h = {self.h:.6g} s after step "
                    f"{self.n_steps} (the stability limit at the start is {limit:.6g} s); the state is left as it "
                    f"was before the call", step=self.n_steps + n, time=float((self.n_steps + n) * self.h),
                    quantity="position", dof=-1, value=float("nan"), dt=self.h, stability_limit=limit)
        self._x, self._v = s
        self.n_steps += n
        return self

    def block(self):
        """Wait for the device (for timings)."""
        self._x.block_until_ready()
        return self

    def positions(self) -> np.ndarray:
        return self._to_model(self._x)

    def velocities(self) -> np.ndarray:
        return self._to_model(self._v)

    def run(self, x, v, h: float, n_steps: int, alpha: float | None = None, save_every: int = 1,
            allow_unstable: bool = False):
        """:meth:`msslib.stepping.LatticeExplicit.run` on the device: returns ``(x, v, saved)``,
        ``saved`` the positions after steps ``save_every, 2 save_every, ...`` (one device call
        per saved state)."""
        if not (h > 0) or n_steps < 0 or save_every < 1:
            raise ValueError("need h > 0, n_steps >= 0 and save_every >= 1")
        self.reset(x, v, h, alpha, allow_unstable)
        out = np.empty((n_steps // save_every, 3 * self.N))
        for j in range(len(out)):
            out[j] = self.steps(save_every).positions()
        self.steps(n_steps - self.n_steps)
        return self.positions(), self.velocities(), out


def lattice_engine(model, load: float = 1.0, precision: str = "double", *, backend: str = "jax", **options):
    """A :class:`JaxLattice`, or, for ``backend="numba"`` or when JAX is not available (a
    :class:`msslib.errors.MsslibWarning` names the reason), a
    :class:`msslib.stepping.LatticeExplicit`: both run ``run(x, v, h, n_steps, alpha,
    save_every)`` with the same results."""
    if use_jax(backend):
        return JaxLattice(model, load, precision, **options)
    return LatticeExplicit(model, load=load, precision=precision)

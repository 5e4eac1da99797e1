"""Explicit steps of a general 3D spring network on JAX (:class:`JaxNetwork`), and the numba CPU
path behind the same interface (:class:`CpuNetwork`, the kernels of
:mod:`msslib.stepping.network_kernels`).

The scheme is that of :mod:`msslib.stepping.network_kernels`: symplectic Euler with mass-proportional
damping on the flat state ``x, v`` (``3 n_nodes``): ``F = f_springs(x) + f_ext``,
``v = damp v + w F``, ``x += h_free v`` with ``w = h / m`` and ``damp = 1 - h alpha`` on the free
dofs, ``w = 0``, ``damp = 1``, ``h_free = 0`` on the fixed ones (they keep their position and
velocity).  The force ``F`` is kept current: a call of ``steps(n)`` advances from the current
force, then evaluates the force at the new positions, so the state after ``n`` steps is the same
for any split of ``n`` into calls to round-off, not bitwise (37 steps in one call and as 20 + 17
differ in the last bits).

On JAX: a spring's force ``d k (l - L0) / l`` (``d = x_b - x_a``) is one gather of the two end
positions per spring; the nodal forces are two ``jax.ops.segment_sum`` (the springs are sorted by
their first node, so the first sum is over sorted segments); ``n`` steps are one jitted call of a
``lax.fori_loop`` whose body runs ``unroll`` steps, so a small network pays one launch per
``unroll`` steps and not one per step.  The jitted functions take every array as an argument
and are shared by all networks of the same node count, precision and unroll, so a rebuild with
arrays of the same shapes (a reset, a new load, a second network) compiles nothing.  The state stays on the device between calls;
:meth:`JaxNetwork.positions` and :meth:`JaxNetwork.velocities` copy it to NumPy.
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.sparse as sp

from msslib.errors import DivergenceError

from .device import check_precision, default_device, describe, use_jax, x64

__all__ = ["JaxNetwork", "CpuNetwork", "network_engine", "network_arrays", "spring_model"]


def network_arrays(model, load: float = 1.0):
    """``dict(x0, conn, k, rest_length, mass, free, fext)`` of a 3D model whose internal terms are
    :class:`msslib.terms.Springs` and whose other terms are dead external loads (at the load
    factor ``load``; fixed dofs at their prescribed positions); ValueError naming any other term."""
    from msslib.stepping.network_kernels import network_terms

    springs, other, why = network_terms(model)
    if why is None and other:
        why = f"the model has {', '.join(sorted({type(t).__name__ for t in other}))}"
    if why is not None:
        raise ValueError(f"the spring-network backend runs 3D Springs and dead external loads only: {why}")
    x0 = model.x0
    if hasattr(model, "apply_prescribed"):
        x0 = model.apply_prescribed(x0, load)
    return dict(x0=np.array(x0, dtype=float), conn=np.concatenate([t.conn for t in springs]),
                k=np.concatenate([t.k for t in springs]), rest_length=np.concatenate([t.rest_length for t in springs]),
                mass=np.asarray(model.mass, dtype=float).reshape(-1), free=np.asarray(model.free, dtype=bool),
                fext=np.asarray(model.external_force(load), dtype=float))


class _SpringProblem:
    """The springs of a network given as arrays, as a problem for
    :func:`msslib.solvers.check_time_step` (its cheap bound, and Lanczos when the step needs it)."""

    symmetric = True
    damping = None

    def __init__(self, springs, mass, free):
        self._springs = springs
        self.n_dof = mass.size
        self.mass = mass
        self.free = free

    def stiffness(self, x, load: float = 1.0):
        r, c, v = self._springs.hessian_coo(np.asarray(x, dtype=float))
        return sp.csr_matrix((v, (r, c)), shape=(self.n_dof, self.n_dof))

    def stiffness_row_bound(self, x, load, isq):
        out = np.zeros(self.n_dof)
        self._springs.abs_row_sums(np.asarray(x, dtype=float), 1.0, isq, out)
        return out


class _NetworkBase:
    """Validation of the arrays, the stability check, the step's weights: shared by the JAX and
    the numba network."""

    backend = ""

    def __init__(self, x0, conn, k, rest_length, mass, free, fext, h, alpha=0.0, *, v0=None,
                 allow_unstable=False, problem=None, load=1.0):
        from msslib.solvers import check_time_step
        from msslib.terms import Springs

        x0 = np.array(x0, dtype=float).reshape(-1)
        n = x0.size
        if n % 3:
            raise ValueError(f"x0 must hold 3 coordinates per node, got {n} entries")
        self.n_nodes = n // 3
        mass = np.asarray(mass, dtype=float).reshape(-1)
        free = np.asarray(free, dtype=bool).reshape(-1)
        fext = np.zeros(n) if fext is None else np.asarray(fext, dtype=float).reshape(-1)
        v0 = np.zeros(n) if v0 is None else np.array(v0, dtype=float).reshape(-1)
        for name, a in (("mass", mass), ("free", free), ("fext", fext), ("v0", v0)):
            if a.size != n:
                raise ValueError(f"{name} must have one entry per dof ({n}), got {a.size}")
        if np.any(~(mass[free] > 0)) or not np.all(np.isfinite(mass[free])):
            raise ValueError("masses of free dofs must be finite and > 0")
        if not (np.isfinite(h) and h > 0) or not np.isfinite(alpha) or alpha < 0:
            raise ValueError(f"need a step h > 0 and damping alpha >= 0, got h = {h!r}, alpha = {alpha!r}")
        self.h, self.alpha = float(h), float(alpha)
        conn = np.asarray(conn, dtype=np.int64).reshape(-1, 2)
        springs = Springs(conn, k, rest_length, 3, signed=True)  # checks finiteness and the node ids' shape
        if len(conn) and conn.max() >= self.n_nodes:
            raise ValueError(f"springs refer to node {int(conn.max())}; the network has {self.n_nodes} nodes")
        self.n_springs = len(conn)
        if problem is None:
            problem = self._array_problem(x0, conn, springs, mass, free, fext)
        self.stability = check_time_step(problem, x0, self.h, method="symplectic_euler", damping=self.alpha,
                                         load=load, allow_unstable=allow_unstable)
        self.free = free
        inv_m = np.where(free, 1.0 / np.where(free, mass, 1.0), 0.0)
        self.w = self.h * inv_m
        self.damp = np.where(free, 1.0 - self.h * self.alpha, 1.0)
        self.hfree = np.where(free, self.h, 0.0)
        v0[~free] = 0.0
        self.n_steps = 0
        self._problem, self._mass, self._load = problem, mass, load
        self._setup(x0, v0, conn, springs.k, springs.rest_length, fext)

    def _array_problem(self, x0, conn, springs, mass, free, fext):
        """The problem whose stability limit is checked, for a network given as arrays."""
        return _SpringProblem(springs, mass, free)

    @classmethod
    def from_model(cls, model, h, alpha=None, *, load: float = 1.0, x0=None, v0=None, **options):
        """From a :class:`msslib.system.Model` whose internal terms are 3D Springs (and dead
        external loads at the factor ``load``); ``alpha`` None takes ``model.damping`` (a scalar:
        Rayleigh ``beta`` is refused).  The stability check runs on the model itself."""
        arrays = network_arrays(model, load)
        from msslib.solvers.stability import mass_proportional_alpha

        alpha = mass_proportional_alpha(model, alpha, "the spring-network backend")
        if x0 is not None:
            arrays["x0"] = np.array(x0, dtype=float).reshape(-1)
        return cls(**arrays, h=h, alpha=float(alpha), v0=v0, problem=model, load=load, **options)

    def _diverged(self, n):
        limit = self.stability["stability_limit"]
        raise DivergenceError(
            f"{self.backend} spring network diverged: non-finite state within the {n} steps of h = {self.h:.6g} s "
            f"after step {self.n_steps} (the stability limit at the start is {limit:.6g} s); the state is "
            f"left as it was before the call",
            step=self.n_steps + n, time=float((self.n_steps + n) * self.h), quantity="position", dof=-1,
            value=float("nan"), dt=self.h, stability_limit=limit)

    def reactions(self) -> np.ndarray:
        """Support reactions ``-F`` on the fixed dofs, 0 on the free ones."""
        return np.where(self.free, 0.0, -self.forces())


class CpuNetwork(_NetworkBase):
    """The network engine of the Simulator (:class:`msslib.stepping.network.NetworkStepper`, the
    fused kernels of :mod:`msslib.stepping.network_kernels` on one CPU thread) behind the array
    interface of :class:`JaxNetwork`: ``steps(n)``, ``positions()``, ``velocities()``,
    ``forces()``, ``reactions()``; always double precision.  Not a second wrapper of the kernels:
    arrays without a model become a spring :class:`msslib.system.Model` (:func:`spring_model`),
    and the steps are the stepper's, with its divergence detector."""

    backend = "numba"
    device = "cpu (numba)"
    precision = "double"

    def _array_problem(self, x0, conn, springs, mass, free, fext):
        return spring_model(x0, conn, springs.k, springs.rest_length, mass, free, fext)

    def _setup(self, x0, v0, conn, k, L0, fext):
        from msslib.stepping.network import NetworkStepper

        # checked already, on the same model (the base class): the stepper's check reuses it
        self._st = NetworkStepper(self._problem, x0, v0, dt=self.h, damping=self.alpha, load=self._load,
                                  allow_unstable=True, free=self.free)
        self._st.messages.clear()

    def steps(self, n: int):
        """Advance ``n`` steps (the force is current after the call); a divergence leaves the
        state as it was before the call."""
        n = int(n)
        if n <= 0:
            return self
        st = self._st
        saved = st.snapshot()
        try:
            st.steps(n)
            ok = bool(np.isfinite(st.x).all() and np.isfinite(st.v).all())
        except DivergenceError:
            ok = False
        if not ok:
            st.restore(saved)
            self._diverged(n)
        self.n_steps += n
        return self

    def positions(self) -> np.ndarray:
        return np.array(self._st.x, dtype=float).reshape(-1)

    def velocities(self) -> np.ndarray:
        return np.array(self._st.v, dtype=float).reshape(-1)

    def forces(self) -> np.ndarray:
        return np.array(self._st.F, dtype=float)


def spring_model(x0, conn, k, rest_length, mass, free, fext):
    """A :class:`msslib.system.Model` of 3D springs given as arrays (no cells: a network has no
    elements), with dead loads ``fext`` (flat), masses ``mass`` (flat, one value per node
    repeated over its three dofs) and the supports ``~free``."""
    from msslib.mesh import Mesh
    from msslib.system import Model
    from msslib.terms import ExternalForce, Springs

    x0 = np.asarray(x0, dtype=float).reshape(-1, 3)
    mass = np.asarray(mass, dtype=float).reshape(-1, 3)
    if np.any(mass != mass[:, :1]):
        raise ValueError("mass must be one value per node, repeated over its three dofs")
    mesh = Mesh(x0, np.zeros((0, 4), dtype=np.int64), "tetra")
    springs = Springs(np.asarray(conn, dtype=np.int64).reshape(-1, 2), k, rest_length, 3, signed=True)
    terms = [springs, ExternalForce(np.asarray(fext, dtype=float).reshape(-1, 3), 3)]
    return Model(mesh, terms, masses=mass[:, 0], fixed=~np.asarray(free, dtype=bool).reshape(-1, 3))


def _spring_force(jnp, segment_sum, x, a, b, k, L0, n_nodes, dtype):
    """Nodal spring forces (flat) at flat positions ``x``, computed in ``dtype``."""
    p = x.reshape(-1, 3).astype(dtype)
    d = p[b] - p[a]
    l = jnp.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
    c = k * (l - L0) / l
    f = d * c[:, None]
    F = segment_sum(f, a, n_nodes, indices_are_sorted=True) - segment_sum(f, b, n_nodes)
    return F.reshape(-1)


@functools.lru_cache(maxsize=32)
def _compiled(n_nodes: int, dtype, unroll: int):
    """The jitted force and ``n``-step loop for ``n_nodes`` nodes, force precision ``dtype`` and
    ``unroll`` steps per loop iteration.  The arrays (springs, loads, weights, state) are
    arguments, not constants of the trace, so every network with the same options shares these
    functions and JAX's compilation cache: a rebuild with arrays of the same shapes (a reset, a
    new load, a second network on the same model) does not trace or compile again."""
    import jax
    import jax.numpy as jnp
    from jax import lax

    segment_sum = jax.ops.segment_sum
    u = unroll

    def force(x, c):
        return _spring_force(jnp, segment_sum, x, c["a"], c["b"], c["k"], c["L0"], n_nodes, dtype).astype(x.dtype) \
            + c["fext"]

    def step(s, c):
        x, v, F = s
        v = c["damp"] * v + c["w"] * F
        x = x + c["hfree"] * v
        return x, v, force(x, c)

    def run(s, c, n):
        def chunk(_, s):
            for _ in range(u):
                s = step(s, c)
            return s

        s = lax.fori_loop(0, n // u, chunk, s)
        s = lax.fori_loop(0, n % u, lambda _, s: step(s, c), s)
        finite = jnp.isfinite(s[0]).all() & jnp.isfinite(s[1]).all()
        return s, finite

    return jax.jit(force), jax.jit(run)


class JaxNetwork(_NetworkBase):
    """Symplectic Euler steps of a 3D spring network on JAX (GPU when JAX sees one, else CPU).

    Parameters
    ----------
    x0 : flat positions (3 n_nodes).
    conn, k, rest_length : springs (s, 2), their constants and rest lengths (those of the numba
        path, :func:`msslib.stepping.network_kernels.network_layout`).
    mass, free, fext : per dof: masses, the free mask (fixed dofs keep their position), the
        constant external force.
    h, alpha : the step (s) and the mass-proportional damping (1/s).
    v0 : initial velocities (0 on the fixed dofs).
    precision : ``"double"`` (default: agrees with the numba path to round-off) or ``"single"``:
        spring forces in fp32 on an fp32 copy of the positions, state and update in fp64 (as
        :class:`msslib.stepping.LatticeExplicit` ``precision="single"``).
    unroll : steps per iteration of the device loop (default 8 below 10^6 springs, else 1).
    device : None (the first GPU JAX sees, else its CPU), ``"gpu"`` or ``"cpu"``.
    allow_unstable : run a step above the stability limit (:func:`msslib.solvers.check_time_step`,
        checked at construction from ``x0``) instead of raising StabilityError.

    Double precision is scoped: every computation runs inside a ``jax.enable_x64`` context, so
    JAX's global ``jax_enable_x64`` flag is never changed (a JAX that has neither
    ``jax.enable_x64`` nor ``jax.experimental.enable_x64`` gets the global flag set when the
    backend runs).  A non-finite state after a call raises DivergenceError and leaves the
    state as it was before the call (the device loop does not check each step).
    """

    backend = "jax"

    def __init__(self, x0, conn, k, rest_length, mass, free, fext, h, alpha=0.0, *, v0=None, precision="double",
                 unroll=None, device=None, allow_unstable=False, problem=None, load=1.0):
        self.dtype = check_precision(precision)
        self.precision = precision
        self._device_kind = device
        self._unroll = unroll
        super().__init__(x0, conn, k, rest_length, mass, free, fext, h, alpha, v0=v0,
                         allow_unstable=allow_unstable, problem=problem, load=load)

    def _setup(self, x0, v0, conn, k, L0, fext):
        import jax
        import jax.numpy as jnp

        self._jax_device = default_device(self._device_kind)
        self.device = describe(self._jax_device)
        a = np.minimum(conn[:, 0], conn[:, 1])
        b = np.maximum(conn[:, 0], conn[:, 1])
        order = np.lexsort((b, a))
        idx = np.int32 if self.n_nodes < 2**31 else np.int64
        unroll = self._unroll if self._unroll is not None else (8 if self.n_springs < 10**6 else 1)
        if int(unroll) < 1:
            raise ValueError(f"unroll must be >= 1, got {unroll!r}")
        self.unroll = int(unroll)
        dt = self.dtype
        with x64():
            put = lambda arr: jax.device_put(arr, self._jax_device)  # noqa: E731
            self._consts = dict(a=put(a[order].astype(idx)), b=put(b[order].astype(idx)),
                                k=put(np.asarray(k, dtype=dt)[order]), L0=put(np.asarray(L0, dtype=dt)[order]),
                                fext=put(fext), w=put(self.w), damp=put(self.damp), hfree=put(self.hfree))
            self._force, self._run = self._compile(jax, jnp)
            x = put(x0)
            self._x, self._v = x, put(v0)
            self._F = self._force(x, self._consts)

    def _compile(self, jax, jnp):
        return _compiled(self.n_nodes, np.dtype(self.dtype), self.unroll)

    def steps(self, n: int):
        """Advance ``n`` steps in one device call (the force is current after the call)."""
        n = int(n)
        if n <= 0:
            return self
        with x64():
            s, finite = self._run((self._x, self._v, self._F), self._consts, np.int32(n) if n < 2**31 else n)
            if not bool(finite):
                self._diverged(n)
        self._x, self._v, self._F = s
        self.n_steps += n
        return self

    def block(self):
        """Wait for the device (for timings)."""
        self._x.block_until_ready()
        return self

    def positions(self) -> np.ndarray:
        return np.array(self._x)

    def velocities(self) -> np.ndarray:
        return np.array(self._v)

    def forces(self) -> np.ndarray:
        """The total force (springs + external) at the current positions."""
        return np.array(self._F)


def network_engine(model, h, alpha=None, *, backend: str = "jax", **options):
    """The spring network of ``model`` on ``backend``: a :class:`JaxNetwork`, or, for
    ``backend="numba"`` or when JAX is not available (a :class:`msslib.errors.MsslibWarning`
    names the reason), a :class:`CpuNetwork` with the same interface (the JAX-only options
    ``precision``, ``unroll`` and ``device`` are then dropped, and the run is double
    precision)."""
    if use_jax(backend):
        return JaxNetwork.from_model(model, h, alpha, **options)
    for key in ("precision", "unroll", "device"):
        options.pop(key, None)
    return CpuNetwork.from_model(model, h, alpha, **options)

"""The stepping API: :class:`Simulator`."""

from __future__ import annotations

import time

import numpy as np

from msslib.solvers.dynamics import Integrator

from .loads import time_function
from msslib.explicit.network import network_terms

from .network import NetworkStepper

ENGINES = ("auto", "network", "generic", "jax")


class Simulator:
    """Step a model in time, with loads that the caller changes between steps.

    ``Simulator(model, dt=...)`` takes a :class:`msslib.system.Model` (or what
    :func:`msslib.build_model` returns) at rest, with its own loads and supports, and integrates
    ``M dv/dt = f(x, load(t)) + f_user(t) - C v`` from ``x0`` (its prescribed displacements
    applied) at rest, with the schemes of :func:`msslib.solvers.integrate`: ``method`` is
    ``"symplectic_euler"`` (default), ``"velocity_verlet"`` or ``"implicit_euler"``, ``damping``
    ``alpha`` or ``(alpha, beta)`` (None: the model's).  The explicit schemes check ``dt`` against
    the stability limit once, when the simulator is built (a cheap safe bound first, Lanczos only
    when the step exceeds it, see :func:`msslib.solvers.check_time_step`), and every step runs
    the divergence checks of :func:`~msslib.solvers.integrate` (``allow_unstable``, ``blowup``).

    Loads, changeable between steps (each value a constant, a callable of time, or a table of
    ``[t, ...]`` rows read as a piecewise-linear curve, :mod:`msslib.simulator.loads`):

    * :meth:`set_load`: the load factor of the model's own loads (and prescribed displacements);
    * :meth:`apply_force`: nodal forces on a selection (per node, or a total shared equally);
    * :meth:`prescribe`: a displacement of a selection along a path (a tool); its dofs stop
      being free and their reactions are what the tool must push with.

    State, read without copies: :attr:`x` and :attr:`v` (``(n_nodes, dim)`` read-only views),
    :attr:`reaction` (``-f`` on every dof that does not move, 0 elsewhere: a view on the
    ``network`` engine), :attr:`t`, :attr:`n_steps`; :attr:`real_time_factor` is the simulated
    time over the wall time spent in :meth:`step`.  :meth:`reset` returns to the start.

    ``engine``: ``"network"`` runs symplectic Euler on 3D spring models with the fused kernel of
    :mod:`msslib.explicit.network` (other internal terms added before each pass; many steps in
    one call when nothing changes in between); ``"generic"`` runs
    :class:`msslib.solvers.dynamics.Integrator` on any model and scheme; ``"jax"`` runs 3D
    spring networks with constant loads on :mod:`msslib.explicit.jax_backend` (the first GPU
    JAX sees, else its CPU; without JAX a warning names the reason and ``network`` runs; the
    state lives on the device, so reading it copies, see :mod:`msslib.simulator.accelerated`);
    ``"auto"`` (default) takes ``network`` where it applies.  They run the same scheme and agree
    to round-off.
    """

    def __init__(self, model, *, dt: float, method: str = "symplectic_euler", damping=None, load=1.0,
                 allow_unstable: bool = False, blowup: float = 1e3, engine: str = "auto",
                 newton_tol: float = 1e-8, newton_max_iter: int = 30, linear_solver="auto"):
        model = getattr(model, "model", model)  # a ModelSetup
        if model is None or not hasattr(model, "force"):
            raise ValueError("Simulator needs a mass-spring model (a FEM reference has no time stepping)")
        if engine not in ENGINES:
            raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
        self.model = model
        self.dim = int(model.dim)
        self.n_nodes = int(model.n_nodes)
        self._options = dict(dt=float(dt), method=method, damping=damping, allow_unstable=allow_unstable,
                             blowup=blowup)
        self._implicit = dict(newton_tol=newton_tol, newton_max_iter=newton_max_iter, linear_solver=linear_solver)
        self._engine_request = engine
        self._load, self._load_varies = time_function(load, "load")
        self._forces: dict[int, tuple] = {}
        self._paths: dict[int, tuple] = {}
        self._next = 0
        self._omega = None
        self._wall = 0.0
        self._t0_sim = 0.0
        self._build(model.apply_prescribed(model.x0, self._load(0.0)), np.zeros(model.n_dof), 0.0, 0)

    # ---- set-up --------------------------------------------------------------------------

    def _engine(self):
        if self._engine_request == "generic":
            return "generic"
        if self._engine_request == "jax":
            from msslib.explicit.jax_backend import use_jax

            if self._varies() or self._forces or self._paths:
                raise ValueError("engine='jax' runs constant loads: a load curve, nodal forces or prescribed paths "
                                 "run on the network engine (engine='network')")
            if use_jax("jax"):  # else a warning names the reason and the network engine runs
                return "jax"
        _, _, why = network_terms(self.model)
        alpha_beta = self._options["damping"]
        if why is None and self._options["method"] != "symplectic_euler":
            why = f"it runs symplectic_euler only, not {self._options['method']}"
        if why is None and alpha_beta is not None and np.ndim(alpha_beta) and alpha_beta[1]:
            why = "it runs mass-proportional damping only (beta = 0)"
        if why is None:
            return "network"
        if self._engine_request == "network":
            raise ValueError(f"engine='network' cannot run this model: {why}")
        return "generic"

    def _free(self):
        free = np.array(self.model.free, dtype=bool)
        for dofs, _, _ in self._paths.values():
            free[dofs] = False
        return free

    def _varies(self) -> bool:
        return (self._load_varies or any(e[3] for e in self._forces.values())
                or any(e[2] for e in self._paths.values()))

    def _build(self, x, v, t, n_taken):
        self.engine = self._engine()
        free = self._free()
        varies = self._varies()
        holder = []  # the stepper, once built (it calls drive from its constructor already)
        drive = (lambda tt, xx: self._apply(tt, xx, holder[0] if holder else None)) if varies else None
        kw = dict(dt=self._options["dt"], damping=self._options["damping"], load=self._load(t),
                  blowup=self._options["blowup"], allow_unstable=self._options["allow_unstable"], free=free,
                  drive=drive)
        if self.engine == "network":
            stepper = NetworkStepper(self.model, x, v, **kw)
        elif self.engine == "jax":
            from .accelerated import JaxStepper

            stepper = JaxStepper(self.model, x, v, **kw)
        else:
            stepper = Integrator(self.model, x, v, method=self._options["method"], **kw, **self._implicit)
        stepper.t = t
        stepper.n_taken = n_taken
        holder.append(stepper)
        self._stepper = stepper
        self._apply(t, stepper.x, stepper)
        if self.engine in ("network", "jax"):
            stepper.evaluate()
        else:
            stepper.f = stepper.force(stepper.x) if stepper.explicit else None

    def _apply(self, t, x, st):
        """Loads at time ``t`` onto the stepper ``st`` (None: not built yet) and the driven
        positions onto ``x``."""
        lam = self._load(t)
        if st is not None:
            st.load = lam
        model = self.model
        x2 = x.reshape(-1, self.dim)  # a view of a flat array, or the network engine's (n, 3) view
        prescribed = getattr(model, "prescribed", None)
        if prescribed is not None:
            fixed = np.flatnonzero(~model.free)
            x2[fixed // self.dim, fixed % self.dim] = model.x0[fixed] + lam * prescribed[fixed]
        for dofs, fn, _ in self._paths.values():
            u = np.asarray(fn(t), dtype=float)
            x2[dofs // self.dim, dofs % self.dim] = model.x0[dofs] + np.resize(u, dofs.size)
        if st is None:
            return
        if self._forces:
            extra = np.zeros(model.n_dof)
            for dofs, fn, share, _ in self._forces.values():
                f = np.asarray(fn(t), dtype=float) * share
                np.add.at(extra, dofs, np.resize(f, dofs.size))
            st.extra = extra
        else:
            st.extra = None

    def _rebuild(self):
        st = self._stepper
        self._build(st.x.copy(), st.v.copy(), st.t, st.n_taken)

    def _nodes(self, selection) -> np.ndarray:
        mesh = getattr(self.model, "mesh", None)
        if isinstance(selection, dict):  # the scene's selection syntax (group, plane, box)
            from msslib.scene.selection import select_nodes

            size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if mesh.n_nodes else 1.0
            nodes = np.asarray(select_nodes("selection", mesh, selection, max(1e-8 * size, 1e-15)))
        else:
            a = np.asarray(selection)
            nodes = np.flatnonzero(a) if a.dtype == bool else a.astype(np.int64).reshape(-1)
        if nodes.size == 0:
            raise ValueError(f"the selection {selection!r} holds no node")
        if nodes.min() < 0 or nodes.max() >= self.n_nodes:
            raise ValueError(f"node ids must lie in 0..{self.n_nodes - 1}")
        return np.unique(nodes)

    def _dofs(self, nodes, axes=None):
        axes = range(self.dim) if axes is None else [int(a) for a in np.atleast_1d(axes)]
        return (self.dim * nodes[:, None] + np.asarray(list(axes))[None, :]).ravel()

    # ---- loads ---------------------------------------------------------------------------

    def set_load(self, load) -> None:
        """The load factor of the model's own loads: a number, a callable of time or a table."""
        self._load, self._load_varies = time_function(load, "load")
        self._rebuild()

    def apply_force(self, nodes, force, *, total: bool = False) -> int:
        """Add the force ``force`` (N, a vector, a callable of time or a table ``[[t, fx, fy, fz],
        ...]``) on each node of the selection ``nodes`` (node ids, a mask, ``{"box": ...}``,
        ``{"plane": ...}`` or ``{"group": name}``), or shared equally among them (``total``).
        Returns a handle for :meth:`remove`."""
        nodes = self._nodes(nodes)
        fn, varies = time_function(force, "force", self.dim)
        share = 1.0 / len(nodes) if total else 1.0
        return self._add(self._forces, (self._dofs(nodes), fn, share, varies))

    def prescribe(self, nodes, displacement, *, axes=None) -> int:
        """Move the nodes ``nodes`` by ``displacement`` (m; a vector, a callable of time or a table
        ``[[t, ux, uy, uz], ...]``) from their rest positions along ``axes`` (default all): a rigid
        tool.  Their dofs stop being free; :attr:`reaction` holds the force the tool applies.
        Returns a handle for :meth:`remove`."""
        nodes = self._nodes(nodes)
        fn, varies = time_function(displacement, "displacement", self.dim)
        dofs = self._dofs(nodes, axes)
        if axes is not None:
            ax = np.atleast_1d(axes)
            whole = fn
            fn = (lambda t, _f=whole, _a=ax: np.asarray(_f(t), dtype=float)[_a])
        return self._add(self._paths, (dofs, fn, varies))

    def _add(self, table, entry):
        handle = self._next
        self._next += 1
        table[handle] = entry
        self._rebuild()
        return handle

    def remove(self, handle: int) -> None:
        """Remove a force or a prescribed path (its nodes move freely again)."""
        for table in (self._forces, self._paths):
            if handle in table:
                del table[handle]
                self._rebuild()
                return
        raise KeyError(f"no force or path with handle {handle}")

    # ---- stepping ------------------------------------------------------------------------

    def step(self, n: int = 1, *, h: float | None = None, t_new: float | None = None) -> Simulator:
        """Advance ``n`` steps of ``h`` (default ``dt``; a shorter step ends a run at a given
        time, ``t_new`` the time after the last step)."""
        t0 = time.perf_counter()
        st = self._stepper
        if h is not None and not (0 < h <= self._options["dt"] * (1 + 1e-12)):
            raise ValueError(f"h must lie in (0, dt = {self._options['dt']:.6g} s], got {h!r}")
        if self.engine in ("network", "jax"):
            st.steps(n, h, t_new)
        else:
            for i in range(int(n)):
                st.step(h, t_new if i + 1 == n else None)
        self._wall += time.perf_counter() - t0
        return self

    def run(self, t_end: float, callback=None, every: int = 1) -> Simulator:
        """Step until ``t >= t_end`` (the last step is not shortened); ``callback(self)`` after
        every ``every`` steps."""
        dt = self._options["dt"]
        n = int(np.ceil((t_end - self.t) / dt - 1e-9))
        if callback is None:
            return self.step(max(n, 0))
        while n > 0:
            k = min(every, n)
            self.step(k)
            n -= k
            callback(self)
        return self

    def reset(self) -> None:
        """Back to ``t = 0`` at rest (loads and paths kept)."""
        self._wall = 0.0
        self._build(self.model.apply_prescribed(self.model.x0, self._load(0.0)), np.zeros(self.model.n_dof), 0.0, 0)

    # ---- state ---------------------------------------------------------------------------

    def _view(self, a):
        out = a.reshape(-1, self.dim).view()
        out.flags.writeable = False
        return out

    @property
    def x(self) -> np.ndarray:
        """Positions ``(n_nodes, dim)`` (a read-only view)."""
        return self._view(self._stepper.x)

    @property
    def v(self) -> np.ndarray:
        """Velocities ``(n_nodes, dim)`` (a read-only view)."""
        return self._view(self._stepper.v)

    @property
    def displacement(self) -> np.ndarray:
        return np.asarray(self._stepper.x).reshape(-1, self.dim) - self.model.x0.reshape(-1, self.dim)

    @property
    def reaction(self) -> np.ndarray:
        """Force the supports and the prescribed paths apply, ``(n_nodes, dim)`` (N): minus the
        total force of the terms on every dof that does not move, 0 elsewhere."""
        st = self._stepper
        if self.engine == "network":
            return self._view(st.react)
        f = st.full_force() if st.explicit else np.asarray(self.model.force(np.ravel(st.x), st.load), dtype=float)
        return np.where(st.free, 0.0, -f).reshape(-1, self.dim)

    @property
    def t(self) -> float:
        return float(self._stepper.t)

    @property
    def n_steps(self) -> int:
        return int(self._stepper.n_taken)

    @property
    def stats(self) -> dict:
        return self._stepper.stats

    @property
    def dt(self) -> float:
        """The time step (s)."""
        return self._options["dt"]

    @property
    def wall_time(self) -> float:
        """Wall time spent in :meth:`step` since the start or the last :meth:`reset` (s)."""
        return self._wall

    @property
    def messages(self) -> list[str]:
        """What the run noted (a step allowed over the limit, a solver fallback)."""
        return self._stepper.messages

    def kinetic_energy(self) -> float:
        """``1/2 v.M v`` over the free dofs (J)."""
        return self._stepper.kinetic_energy()

    def potential_energy(self) -> float | None:
        """Internal energy minus the work of the loads at the current load factor (J); None for a
        model with a non-conservative term."""
        st = self._stepper
        if not st.conservative:
            return None
        from msslib.solvers import protocol

        return protocol._energy_or_none(self.model, np.ravel(st.x), st.load)

    @property
    def real_time_factor(self) -> float:
        """Simulated time over the wall time spent in :meth:`step` (> 1: faster than real time)."""
        return self.t / self._wall if self._wall > 0 else float("inf")

    def __repr__(self) -> str:
        return (f"Simulator({type(self.model).__name__}, {self.n_nodes} nodes, {self._options['method']}, "
                f"dt={self._options['dt']:.4g} s, engine={self.engine}, t={self.t:.4g} s)")

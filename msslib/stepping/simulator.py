"""The stepping API: :class:`Simulator`."""

from __future__ import annotations

import numbers
import time

import numpy as np

from msslib.stepping.check import deferred_checks
from msslib.stepping.generic import Integrator

from msslib.terms.pressure import outward_facets, pressure_nodal_forces

from .loads import time_function
from msslib.stepping.network_kernels import network_terms

from .network import NetworkStepper

ENGINES = ("auto", "network", "generic", "jax", "lattice")
METHODS = ("symplectic_euler", "velocity_verlet", "implicit_euler")
# steps of one fused kernel call: the monitor rows it fills are held at most this many at a time
_CHUNK = 256


def _count(value, name: str) -> int:
    """``value`` as a positive whole number of steps, else a one-line refusal."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive whole number, got {value!r}")
    return int(value)


def _finite(value, name: str, allowed: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = float("nan")
    if isinstance(value, (bool, np.bool_)) or not np.isfinite(x):
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return x


def _checked_damping(damping):
    if damping is None:
        return None
    vals = np.atleast_1d(np.asarray(damping, dtype=object)).ravel()
    ok = vals.size in (1, 2)
    try:
        f = [float(v) for v in vals] if ok else []
    except (TypeError, ValueError):
        ok = False
    if not ok or not all(np.isfinite(v) and v >= 0 for v in f):
        raise ValueError(f"damping must be None, alpha or (alpha, beta), finite and >= 0, got {damping!r}")
    return damping


class Simulator:
    """Step a model in time, with loads that the caller changes between steps.

    ``Simulator(model, dt=...)`` takes a :class:`msslib.system.Model` (or what
    :func:`msslib.build_model` returns) at rest, with its own loads and supports, and integrates
    ``M dv/dt = f(x, load(t)) + f_user(t) - C v`` from ``x0`` (its prescribed displacements
    applied) at rest, with the schemes of :func:`msslib.stepping.integrate`: ``method`` is
    ``"symplectic_euler"`` (default), ``"velocity_verlet"`` or ``"implicit_euler"``, ``damping``
    ``alpha`` or ``(alpha, beta)`` (None: the model's).  The explicit schemes check ``dt`` against
    the stability limit once, when the simulator is built (a cheap safe bound first, then on
    spring models a few passes of a deterministic bound, a certified short Lanczos run or the
    Lanczos estimate only when the step exceeds them, see
    :func:`msslib.solvers.check_time_step`; on a model of 20 000 free dofs or more, a step that
    these cheap stages do not decide is checked on a second thread while the first call steps,
    and a refusal comes from that call, with the state as before it, and from every later one:
    :mod:`msslib.stepping.check`), and every step runs
    the divergence checks of :func:`~msslib.stepping.integrate` (``allow_unstable``, ``blowup``).

    Loads, changeable between steps (each value a constant, a callable of time, or a table of
    ``[t, ...]`` rows read as a piecewise-linear curve, :mod:`msslib.stepping.loads`):

    * :meth:`set_load`: the load factor of the model's own loads (and prescribed displacements);
    * :meth:`apply_force`: nodal forces on a selection (per node, or a total shared equally);
    * :meth:`prescribe`: a displacement of a selection along a path (a tool); its dofs stop
      being free and their reactions are what the tool must push with;
    * :meth:`apply_pressure`: a pressure on boundary facets, following the current surface (its
      forces evaluated every step on the current positions) or dead (constant forces).

    State, read as snapshots (read-only copies taken when read, on every engine; they do not
    follow later steps): :attr:`x` and :attr:`v` (``(n_nodes, dim)``), :attr:`reaction` (``-f``
    on every dof that does not move, 0 elsewhere), :attr:`t`, :attr:`n_steps`; :attr:`real_time_factor` is the simulated
    time over the wall time spent in :meth:`step`.  :meth:`reset` returns to the start.

    ``engine``: ``"network"`` runs symplectic Euler on 3D spring models with the fused kernel of
    :mod:`msslib.stepping.network_kernels` (other internal terms added before each pass; many steps in
    one call when nothing changes in between); ``"generic"`` runs
    :class:`msslib.stepping.generic.Integrator` on any model and scheme; ``"jax"`` runs 3D
    spring networks with constant loads on :mod:`msslib.stepping.jax_backend` (the first GPU
    JAX sees, else its CPU; without JAX a warning names the reason and ``network`` runs; the
    state lives on the device, so reading it copies, see :mod:`msslib.stepping.accelerated`);
    ``"lattice"`` runs a model on a full structured hexahedral lattice (Golec's cubes on a
    ``hex_grid``) with constant loads and its own supports on the vectorised loops of
    :class:`msslib.stepping.lattice.LatticeExplicit` (the state kept in lattice order; its
    divergence check is the non-finite test at the end of each call, as on ``jax``);
    ``"auto"`` (default) takes ``network`` where it applies (never ``lattice`` or ``jax``, whose
    divergence check is coarser: ask for them).  They run the same scheme and agree
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
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        dt = _finite(dt, "dt", "a finite time step > 0 (s)")
        if dt <= 0:
            raise ValueError(f"dt must be a finite time step > 0 (s), got {dt!r}")
        blowup = _finite(blowup, "blowup", "a finite number > 0")
        if blowup <= 0:
            raise ValueError(f"blowup must be a finite number > 0, got {blowup!r}")
        damping = _checked_damping(damping)
        if engine in ("jax", "lattice") and method != "symplectic_euler":
            raise ValueError(f"engine={engine!r} runs symplectic_euler only, got method={method!r} "
                             "(the other schemes run on engine='generic')")
        self.model = model
        self.dim = int(model.dim)
        self.n_nodes = int(model.n_nodes)
        self._options = dict(dt=float(dt), method=method, damping=damping, allow_unstable=allow_unstable,
                             blowup=blowup)
        self._implicit = dict(newton_tol=newton_tol, newton_max_iter=newton_max_iter, linear_solver=linear_solver)
        self._engine_request = engine
        self._load, self._load_varies = time_function(load, "load")
        self._value(self._load, 0.0, "load", ())
        self._forces: dict[int, tuple] = {}
        self._pressures: dict[int, tuple] = {}
        self._shift_cache: dict = {}
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
        if self._engine_request in ("lattice", "jax"):
            if self._varies() or self._forces or self._paths or self._pressures:
                raise ValueError(f"engine={self._engine_request!r} runs constant loads: a load curve, nodal forces, "
                                 "pressures or prescribed paths run on the network engine (engine='network')")
            if self._engine_request == "lattice":
                return "lattice"
            from msslib.stepping.jax_backend import use_jax

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
                or any(e[2] for e in self._paths.values()) or any(e[4] for e in self._pressures.values()))

    def _build(self, x, v, t, n_taken):
        self.engine = self._engine()
        free = self._free()
        varies = self._varies()
        holder = []  # the stepper, once built (it calls drive from its constructor already)
        plan = self._drive_plan()  # travels with the stepper: a refused change restores both
        drive = (lambda tt, xx: self._apply(tt, xx, holder[0] if holder else None, plan, False)) if varies else None
        kw = dict(dt=self._options["dt"], damping=self._options["damping"], load=self._load(t),
                  blowup=self._options["blowup"], allow_unstable=self._options["allow_unstable"], free=free,
                  drive=drive)
        if self.engine == "network":
            with deferred_checks():  # a long stability check runs while the first call steps
                stepper = NetworkStepper(self.model, x, v, **kw)
        elif self.engine == "jax":
            from .accelerated import JaxStepper

            stepper = JaxStepper(self.model, x, v, **kw)
        elif self.engine == "lattice":
            from .lattice import LatticeStepper

            stepper = LatticeStepper(self.model, x, v, **kw)
        else:
            with deferred_checks():
                stepper = Integrator(self.model, x, v, method=self._options["method"], **kw, **self._implicit)
        stepper.t = t
        stepper.n_taken = n_taken
        if self.engine == "network":  # a follower pressure reads the current positions
            stepper.drive_reads_state = any(e[2] for e in self._pressures.values())
        holder.append(stepper)
        self._stepper = stepper
        self._apply(t, stepper.x, stepper, plan, True)
        stepper.evaluate()
        stepper.restart_detector()  # its reference from the force with this call's loads

    def _drive_plan(self):
        """What :meth:`_apply` writes, indexed once per build instead of once per step: the
        model's prescribed dofs (rows, columns, rest positions, prescribed displacements, whether
        any is nonzero; None without prescribed dofs) and per path (rows, columns, rest positions,
        the rest positions as (nodes, axes), its function)."""
        model, dim = self.model, self.dim
        prescribed = getattr(model, "prescribed", None)
        presc = None
        if prescribed is not None:
            fixed = np.flatnonzero(~model.free)
            presc = (fixed // dim, fixed % dim, model.x0[fixed].copy(), prescribed[fixed].copy(),
                     bool(np.any(prescribed[fixed])))
        paths = []
        for dofs, fn, _ in self._paths.values():
            nodes = np.unique(dofs // dim)
            paths.append((dofs // dim, dofs % dim, model.x0[dofs].reshape(nodes.size, -1).copy(), fn))
        return presc, paths

    def _apply(self, t, x, st, plan, full):
        """Loads at time ``t`` onto the stepper ``st`` (None: not built yet) and the driven
        positions onto ``x`` (``plan``: :meth:`_drive_plan`).  Between steps (not ``full``) the
        supports that prescribe zero are not written again: they keep the rest positions the
        build gave them, which no step moves."""
        lam = self._load(t)
        if st is not None:
            st.load = lam
        model = self.model
        x2 = x.reshape(-1, self.dim)  # a view of a flat array, or the network engine's (n, 3) view
        presc, paths = plan
        if presc is not None and (full or presc[4]):
            rows, cols, x0, u, _ = presc
            x2[rows, cols] = x0 + lam * u
        for rows, cols, x0, fn in paths:
            x2[rows, cols] = (x0 + fn(t)).ravel()
        if st is None:
            return
        if self._forces or self._pressures:
            extra = np.zeros(model.n_dof)
            for dofs, fn, share, _ in self._forces.values():
                f = fn(t) * share
                np.add.at(extra, dofs, np.tile(f, dofs.size // f.size))
            for facets, fn, follow, thickness, _ in self._pressures.values():  # follower: at the current x
                on = x2 if follow else model.x0.reshape(-1, self.dim)
                extra += pressure_nodal_forces(on, facets, fn(t), thickness).ravel()
            st.extra = extra
        else:
            st.extra = None

    @staticmethod
    def _value(fn, t, name, shape):
        """``fn(t)`` as a float array of ``shape``, finite, else a one-line refusal."""
        raw = fn(t)
        try:
            a = np.asarray(raw, dtype=float)
        except (TypeError, ValueError):
            a = None
        if a is None or a.shape != shape or not np.all(np.isfinite(a)):
            want = "a finite number" if shape == () else f"{shape[0]} finite numbers"
            raise ValueError(f"{name} at t = {float(t):.6g} s must be {want}, got {raw!r}")
        return a

    def _checked(self, fn, name, shape, user=False):
        """``fn`` wrapped so that every value it returns is checked like a constant (``user``: a
        caller's callable, which may raise in the middle of a step call).  A constant or a table
        is returned as it is: :func:`time_function` checked its values (a table's curve
        interpolates finite rows of the right shape), and a step reads it without a check."""
        if not user:
            fn.user = False
            return fn

        def checked(t, _f=fn):
            return self._value(_f, t, name, shape)

        checked.user = user
        return checked

    def _rebuild(self):
        st = self._stepper
        self._build(st.x.copy(), st.v.copy(), st.t, st.n_taken)

    def _transaction(self, change):
        """Apply ``change()`` (which edits the load tables) and rebuild; on any error restore the
        tables and the stepper as they were, so a refused call changes nothing."""
        saved = (self._load, self._load_varies, dict(self._forces), dict(self._paths), self._next,
                 self._stepper, self.engine, dict(self._pressures))
        try:
            out = change()
            self._rebuild()
        except BaseException:
            (self._load, self._load_varies, self._forces, self._paths, self._next,
             self._stepper, self.engine, self._pressures) = saved
            raise
        return out

    def _nodes(self, selection) -> np.ndarray:
        mesh = getattr(self.model, "mesh", None)
        if isinstance(selection, dict):  # the scene's selection syntax (group, plane, box)
            from msslib.mesh.selection import select_nodes

            size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if mesh.n_nodes else 1.0
            nodes = np.asarray(select_nodes("selection", mesh, selection, max(1e-8 * size, 1e-15)))
        else:
            try:
                a = np.asarray(selection)
            except Exception:
                a = np.asarray([object()])
            if a.dtype == bool:
                if a.shape != (self.n_nodes,):
                    raise ValueError(f"nodes: a boolean mask must hold {self.n_nodes} entries (one per node), "
                                     f"got shape {a.shape}")
                nodes = np.flatnonzero(a)
            elif a.dtype.kind in "iu":
                nodes = a.astype(np.int64).reshape(-1)
            elif a.dtype.kind == "f" and np.all(np.isfinite(a)) and np.all(a == np.round(a)):
                nodes = a.astype(np.int64).reshape(-1)
            else:
                raise ValueError(f"nodes must be whole node ids in 0..{self.n_nodes - 1}, a boolean mask of "
                                 f"{self.n_nodes} entries or a selection dict, got {selection!r}")
        if nodes.size == 0:
            raise ValueError(f"nodes: the selection {selection!r} holds no node")
        if nodes.min() < 0 or nodes.max() >= self.n_nodes:
            bad = int(nodes[(nodes < 0) | (nodes >= self.n_nodes)][0])
            raise ValueError(f"nodes: node ids must lie in 0..{self.n_nodes - 1}, got {bad}")
        return np.unique(nodes)

    def _axes(self, axes):
        if axes is None:
            return np.arange(self.dim)
        a = np.atleast_1d(np.asarray(axes, dtype=object)).ravel()
        ok = a.size >= 1 and all(isinstance(v, (numbers.Integral, np.integer)) and not isinstance(v, (bool, np.bool_))
                                 and 0 <= v < self.dim for v in a)
        if not ok or len(set(int(v) for v in a)) != a.size:
            raise ValueError(f"axes must be distinct whole numbers in 0..{self.dim - 1}, got {axes!r}")
        return np.array([int(v) for v in a], dtype=np.int64)

    def _dofs(self, nodes, axes):
        return (self.dim * nodes[:, None] + axes[None, :]).ravel()

    # ---- loads ---------------------------------------------------------------------------

    def set_load(self, load) -> None:
        """The load factor of the model's own loads: a number, a callable of time or a table."""
        fn, varies = time_function(load, "load")
        fn = self._checked(fn, "load", (), callable(load))
        fn(self.t)

        def change():
            self._load, self._load_varies = fn, varies

        self._transaction(change)

    def apply_force(self, nodes, force, *, total: bool = False) -> int:
        """Add the force ``force`` (N, a vector, a callable of time or a table ``[[t, fx, fy, fz],
        ...]``) on each node of the selection ``nodes`` (node ids, a mask, ``{"box": ...}``,
        ``{"plane": ...}`` or ``{"group": name}``), or shared equally among them (``total``).
        Returns a handle for :meth:`remove`."""
        nodes = self._nodes(nodes)
        fn, varies = time_function(force, "force", self.dim)
        fn = self._checked(fn, "force", (self.dim,), callable(force))
        fn(self.t)  # a callable that fails or returns a wrong value is refused here
        share = 1.0 / len(nodes) if total else 1.0
        return self._add(self._forces, (self._dofs(nodes, np.arange(self.dim)), fn, share, varies))

    def prescribe(self, nodes, displacement, *, axes=None) -> int:
        """Move the nodes ``nodes`` by ``displacement`` (m; a vector, a callable of time or a table
        ``[[t, ux, uy, uz], ...]``) from their rest positions along ``axes`` (default all): a rigid
        tool.  Their dofs stop being free; :attr:`reaction` holds the force the tool applies.
        Returns a handle for :meth:`remove`."""
        nodes = self._nodes(nodes)
        ax = self._axes(axes)
        fn, varies = time_function(displacement, "displacement", self.dim)
        whole = self._checked(fn, "displacement", (self.dim,), callable(displacement))

        def fn(t, _f=whole, _a=ax):
            return _f(t)[_a]

        if np.array_equal(ax, np.arange(self.dim)):  # all axes in order: the vector itself
            fn = whole
        fn.user = whole.user
        fn(self.t)
        return self._add(self._paths, (self._dofs(nodes, ax), fn, varies))

    def apply_pressure(self, facets, pressure, *, follow: bool = True, thickness: float = 1.0) -> int:
        """Add a pressure ``pressure`` (Pa, positive into the body; a number, a callable of time or
        a table ``[[t, p], ...]``) on boundary facets: ``facets`` node ids ``(k, 2)`` (2D) or
        ``(k, 3|4)`` (3D) of boundary facets in any node order, or a selection dict as the scene's
        ``select`` of a pressure load.  ``follow`` (default): the consistent forces of the current
        surface, evaluated every step on the current positions; else dead, constant forces normal
        to the rest surface (:func:`msslib.terms.pressure_nodal_forces`); 2D: ``thickness`` (m).
        Not scaled by the load factor.  Returns a handle for :meth:`remove`."""
        from msslib.mesh.selection import loaded_facets

        mesh = self.model.mesh
        if not isinstance(follow, (bool, np.bool_)):
            raise ValueError(f"follow must be True or False, got {follow!r}")
        if isinstance(facets, dict):
            size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if mesh.n_nodes else 1.0
            facets = loaded_facets("facets", mesh, facets, max(1e-8 * size, 1e-15), {}, "pressure")
        found = outward_facets(mesh, facets)
        t = _finite(thickness, "thickness", "a finite thickness > 0 (m)")
        if t <= 0 or (self.dim == 3 and t != 1.0):
            raise ValueError(f"thickness must be a finite thickness > 0 (m), on a 2D mesh only, got {thickness!r}")
        fn, varies = time_function(pressure, "pressure")
        fn = self._checked(fn, "pressure", (), callable(pressure))
        fn(self.t)
        return self._add(self._pressures, (found, fn, bool(follow), t, varies or bool(follow)))

    def _add(self, table, entry):
        def change():
            handle = self._next
            self._next += 1
            table[handle] = entry
            return handle

        return self._transaction(change)

    def remove(self, handle: int) -> None:
        """Remove a force or a prescribed path (its nodes move freely again)."""
        for table in (self._forces, self._paths, self._pressures):
            if isinstance(handle, (numbers.Integral, np.integer)) and not isinstance(handle, bool) and handle in table:
                self._transaction(lambda: table.pop(handle))
                return
        raise KeyError(f"handle: no force, path or pressure with handle {handle!r} (handles: "
                       f"{sorted([*self._forces, *self._paths, *self._pressures])})")

    # ---- stepping ------------------------------------------------------------------------

    def step(self, n: int = 1, *, h: float | None = None, t_new: float | None = None) -> Simulator:
        """Advance ``n`` steps (a positive whole number) of ``h`` (default ``dt``; a shorter step
        ends a run at a given time, ``t_new`` the time after the last step, later than ``t``).
        A wrong argument is refused before anything moves."""
        n = _count(n, "n")
        dt = self._options["dt"]
        if h is not None:
            hv = _finite(h, "h", f"a step in (0, dt = {dt:.6g} s]")
            if not (0 < hv <= dt * (1 + 1e-12)):
                raise ValueError(f"h must be a step in (0, dt = {dt:.6g} s], got {h!r}")
            h = hv
        if t_new is not None:
            tn = _finite(t_new, "t_new", f"a finite time later than t = {self.t:.6g} s")
            if not tn > self.t:
                raise ValueError(f"t_new must be a finite time later than t = {self.t:.6g} s (time never runs "
                                 f"backwards), got {t_new!r}")
            t_new = tn
        t0 = time.perf_counter()
        st = self._stepper
        user = (getattr(self._load, "user", False) or any(e[1].user for e in self._forces.values())
                or any(e[1].user for e in self._paths.values()) or any(e[1].user for e in self._pressures.values()))
        saved = (st.x.copy(), st.v.copy(), st.t, st.n_taken) if user else None  # a callable may raise
        try:
            st.steps(n, h, t_new)
        except Exception as exc:
            from msslib.errors import DivergenceError

            if saved is not None and not isinstance(exc, DivergenceError):
                # a load or path callable failed in the middle of the call: back to the state before it
                self._build(*saved)
            raise
        finally:
            self._wall += time.perf_counter() - t0
        return self

    def run(self, t_end: float, callback=None, every: int = 1) -> Simulator:
        """Step until ``t >= t_end`` (a finite time; the last step is not shortened);
        ``callback(self)`` after every ``every`` steps (a positive whole number)."""
        t_end = _finite(t_end, "t_end", "a finite time (s)")
        every = _count(every, "every")
        if callback is not None and not callable(callback):
            raise ValueError(f"callback must be callable or None, got {callback!r}")
        dt = self._options["dt"]
        n = int(np.ceil((t_end - self.t) / dt - 1e-9))
        if n < 1:
            return self
        if callback is None:
            return self.step(n)
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
        """A snapshot of ``a`` as ``(n_nodes, dim)``: a read-only copy taken when read (it does
        not follow later steps, on any engine)."""
        out = np.array(a, dtype=float).reshape(-1, self.dim)
        out.flags.writeable = False
        return out

    @property
    def x(self) -> np.ndarray:
        """Positions ``(n_nodes, dim)``: a read-only snapshot (a copy taken when read)."""
        return self._view(self._stepper.x)

    @property
    def v(self) -> np.ndarray:
        """Velocities ``(n_nodes, dim)``: a read-only snapshot (a copy taken when read)."""
        return self._view(self._stepper.v)

    @property
    def displacement(self) -> np.ndarray:
        """``x - x0`` ``(n_nodes, dim)`` (m), a snapshot."""
        return np.asarray(self._stepper.x).reshape(-1, self.dim) - self.model.x0.reshape(-1, self.dim)

    @property
    def reaction(self) -> np.ndarray:
        """Force the supports and the prescribed paths apply, ``(n_nodes, dim)`` (N): minus the
        total force of the terms on every dof that does not move, 0 elsewhere."""
        return self._view(self._stepper.reaction())

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
        """Internal energy minus the work of the loads on the displacement from the rest
        positions, at the current load factor (J): it does not depend on where the mesh sits
        (:func:`msslib.stepping.generic.relative_potential_energy`); None for a model with a
        non-conservative term."""
        st = self._stepper
        if not st.conservative:
            return None
        from msslib.stepping.generic import relative_potential_energy

        x = np.ravel(np.asarray(st.x))
        if self._forces:  # the extra nodal forces do work on the displacement too
            extra = np.zeros(self.model.n_dof)
            for dofs, fn, share, _ in self._forces.values():
                np.add.at(extra, dofs, np.tile(fn(self.t) * share, dofs.size // self.dim))
            work = float(extra @ (x - self.model.x0))
        else:
            work = 0.0
        return relative_potential_energy(self.model, x, st.load, self._shift_cache) - work

    @property
    def real_time_factor(self) -> float:
        """Simulated time over the wall time spent in :meth:`step` (> 1: faster than real time)."""
        return self.t / self._wall if self._wall > 0 else float("inf")

    def __repr__(self) -> str:
        return (f"Simulator({type(self.model).__name__}, {self.n_nodes} nodes, {self._options['method']}, "
                f"dt={self._options['dt']:.4g} s, engine={self.engine}, t={self.t:.4g} s)")

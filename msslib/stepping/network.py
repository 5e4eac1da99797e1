"""The fused spring-network engine of the stepping API: :class:`NetworkStepper` runs the steps of
:class:`msslib.stepping.generic.Integrator` (symplectic Euler, mass-proportional damping) with
the kernels of :mod:`msslib.stepping.network_kernels`, and the same stability check and divergence
detector.

A large network whose numbering scatters its springs is stepped in an internal numbering
(reverse Cuthill-McKee, :func:`~msslib.stepping.network_kernels.cache_order`), chosen once when
the stepper is built: the pass then reads and writes nodes that are near in memory.  It is
invisible: ``x``, ``v``, the force and the reactions are arrays in the model's numbering, written
in place after every call, and what the Simulator writes into
``x`` between steps (paths, prescribed displacements) is read back before the next pass."""

from __future__ import annotations

import math

import numpy as np

from msslib.errors import DivergenceError
from msslib.stepping.network_kernels import (N_MONITOR, cache_order, fused_advance, fused_pass, fused_steps,
                                             fused_steps_lean, gather_state, network_layout, network_terms, records,
                                             scatter_state)
from msslib.stepping.generic import Integrator, _check_state


class NetworkStepper(Integrator):
    """:class:`Integrator` for ``symplectic_euler`` on a 3D spring model, with the fused kernel.

    The state arrays ``x``, ``v`` (flat), the total force ``F`` at ``x`` and the reactions
    ``react`` (``-F`` on the dofs that do not move, 0 elsewhere) are updated in place and stay
    current after every step."""

    def __init__(self, model, x0, v0, *, dt, damping=None, load=1.0, blowup=1e3, allow_unstable=False,
                 free=None, drive=None):
        springs, others, why = network_terms(model)
        if why is not None:
            raise ValueError(f"network engine: {why}")
        super().__init__(model, x0, v0, dt=dt, method="symplectic_euler", damping=damping, load=load,
                         blowup=blowup, allow_unstable=allow_unstable, free=free, drive=drive)
        if self.beta:
            raise ValueError("network engine: mass-proportional damping only (beta = 0)")
        n = model.n_dof
        conn = np.concatenate([s.conn for s in springs])
        k = np.concatenate([s.k for s in springs])
        rest = np.concatenate([s.rest_length for s in springs])
        # internal node i is node order[i] of the model (None: the model's numbering)
        self.order = order = cache_order(conn, model.n_nodes)
        if order is not None:
            new = np.empty(model.n_nodes, dtype=np.int64)
            new[order] = np.arange(model.n_nodes)
            conn = new[conn]
            self._dofs = (3 * order[:, None] + np.arange(3)).reshape(-1)  # internal dof j is dof _dofs[j]
        self.layout = network_layout(conn, k, rest, model.n_nodes)
        self.n_springs = len(conn)
        self.others = others
        self._external = model.external_force(1.0) if hasattr(model, "external_force") else np.zeros(n)
        self.R = records(self._internal(self.x))  # positions and force accumulators, one record per node
        self.v = np.ascontiguousarray(self.v)
        self.F = np.zeros(n)
        self.react = np.zeros(n)
        if order is None:  # the kernels' arrays are the state's
            self.x = self.R[:, :3]  # a view: the state lives in the records
            self._v, self._F, self._react = self.v, self.F, self.react
        else:
            self.x = np.array(self.x, dtype=float).reshape(-1, 3)  # written after every call
            self._v, self._F, self._react = self.v[self._dofs], np.zeros(n), np.zeros(n)
        self._external_i = self._internal(self._external)
        self._x_ref = self._internal(self.x_ref)
        self.fext = np.zeros(n)  # internal numbering
        self.inv_m_all = np.where(self.free, 1.0 / np.where(self.mass > 0, self.mass, 1.0), 0.0)
        self._h = None
        self._set_step(self.dt)
        self.mon = np.zeros((1, N_MONITOR))
        self._fixed_at = 6 * (self._fixed // 3) + self._fixed % 3  # in the flat records (used without renumbering)
        self._fext_of = None  # (load, extra) that fext holds
        self.evaluate()

    def _internal(self, a):
        """A flat dof array of the model's numbering in the internal one (a copy)."""
        a = np.asarray(a, dtype=float).reshape(-1)
        return a.copy() if self.order is None else a[self._dofs]

    def _sync_in(self):
        """Positions and velocities of the model's numbering into the kernels' arrays."""
        if self.order is not None:
            gather_state(self.R, self._v, self.x, self.v, self.order)

    def _sync_out(self):
        """The kernels' state, force and reactions into the model's numbering (in place)."""
        if self.order is not None:
            scatter_state(self.R, self._v, self._F, self._react, self.x, self.v, self.F, self.react, self.order)

    def snapshot(self):
        """The state (positions, velocities, force, reactions, time, steps taken) to :meth:`restore`."""
        return (self.x.copy(), self.v.copy(), self.F.copy(), self.react.copy(), self.t, self.n_taken)

    def restore(self, snap):
        """Back to a :meth:`snapshot` (the force and reactions as they were, no evaluation)."""
        self.x[:], self.v[:], self.F[:], self.react[:] = snap[:4]
        self.t, self.n_taken = snap[4], snap[5]
        if self.order is not None:
            self._sync_in()
            self._F[:] = self.F[self._dofs]
            self._react[:] = self.react[self._dofs]
        self._dmax_ub = self._dmax_exact()

    def _dmax_exact(self):
        """``max |x - x_ref|`` of the current state (nan if not finite)."""
        with np.errstate(invalid="ignore"):
            d = np.abs(self.x.reshape(-1) - self.x_ref)
        return float(d.max()) if np.isfinite(d).all() else float("nan")

    def _set_step(self, h):
        if h != self._h:
            self._h = float(h)
            self.w = self._internal(np.where(self.free, self._h * self.inv_m_all, 0.0))
            self.damp = 1.0 - self._h * self.alpha

    def _update_external(self):
        of = self._fext_of
        if of is not None and of[0] == self.load and of[1] is self.extra:
            return  # unchanged since the last pass (the reference keeps the array alive)
        np.multiply(self._external_i, self.load, out=self.fext)
        if self.extra is not None:
            self.fext += self.extra if self.order is None else self.extra[self._dofs]
        self._fext_of = (self.load, self.extra)

    def _preload(self):
        if not self.others:
            return
        flat = self.x.reshape(-1)  # a copy (the records interleave the accumulators)
        g = np.zeros(flat.size)
        for t in self.others:
            g += t.gradient(flat)
        g = g.reshape(-1, 3)
        self.R[:, 3:] = -(g if self.order is None else g[self.order])

    def _flat_x(self):
        return self.x.reshape(-1)

    def _fixed_positions(self):
        if self.drive is None or not self._fixed.size:
            return None
        if self.order is None:
            return self.R.reshape(-1)[self._fixed_at]
        return self.x.reshape(-1)[self._fixed]

    def evaluate(self):
        """The force, reactions and monitor at the current state (no step): after a change of the
        loads or of the driven dofs' positions made outside :meth:`step`."""
        self._sync_in()
        self._update_external()
        self._preload()
        rowptr, ia, ib, kl = self.layout
        fused_pass(self.R, self._v, self._F, rowptr, ia, ib, kl, self.w, self.damp, self._h, self.fext, self._x_ref,
                   self._react, self.mon, 0, False, True)
        self._dmax_ub = float(self.mon[0, 4])  # an upper bound of max |x - x_ref| now (here exact)
        self._sync_out()
        self.stats["n_force_evals"] += 1

    def reaction(self):
        """The reactions the fused kernel keeps current (flat, N)."""
        return self.react

    def full_force(self):
        return self.F

    def _free_force(self):
        return self.F[self.free]

    def step(self, h=None, t_new=None):
        self.steps(1, h, t_new)

    # A divergence is reported with the state before the failing step.  Instead of copying the
    # state before every step, a checkpoint (state, time, detector) is kept at most every
    # _CHECKPOINT_EVERY steps with the steps taken since; a failure replays them (the scheme is
    # deterministic: the same loads, the same driven positions at the same times).
    _CHECKPOINT_EVERY = 64

    def _checkpoint(self):
        self._ckpt = (self.x.copy(), self.v.copy(), self.t, self.n_taken, self.j_min, self.flips, self.a_in)
        self._since = []  # (n, h, end) of the calls since the checkpoint

    # steps of one fused kernel call: the monitor rows are held for at most this many steps, so
    # that the memory of a call does not grow with its number of steps
    _CHUNK = 256
    # from this many steps a call leaves the exact max |x - x_ref| out of the kernel (see
    # _bound_displacements); below, the bound's bookkeeping costs more than it saves
    _LEAN_MIN_STEPS = 16

    def steps(self, n: int, h=None, t_new=None):
        """``n`` steps of ``h`` (default ``dt``); ``t_new`` the time after the last one.  Runs them
        in fused kernel calls of at most ``_CHUNK`` steps when nothing changes in between (no
        ``drive``, no other terms)."""
        n = int(n)
        if n < 1:
            return
        h = self.dt if h is None else float(h)
        end = self.t + n * h if t_new is None else float(t_new)
        done = 0
        while done < n:
            k = min(self._CHUNK, n - done)
            done += k
            self._steps(k, h, end if done == n else self.t + k * h)

    def _steps(self, n, h, end):
        self._set_step(h)
        if getattr(self, "_ckpt", None) is None or self.n_taken - self._ckpt[3] >= self._CHECKPOINT_EVERY:
            self._checkpoint()
        self._since.append((n, h, end))
        rowptr, ia, ib, kl = self.layout
        failed = False
        if self.drive is None and not self.others:
            if self.mon.shape[0] < n:
                self.mon = np.zeros((n, N_MONITOR))
            lean = n >= self._LEAN_MIN_STEPS
            (fused_steps_lean if lean else fused_steps)(self.R, self._v, self._F, rowptr, ia, ib, kl, self.w,
                                                        self.damp, h, self.fext, self._x_ref, self._react, self.mon, n)
            self._sync_out()
            self.stats["n_force_evals"] += n
            t0 = self.t
            try:
                if lean:
                    self._bound_displacements(n, h)
                else:
                    self._dmax_ub = float(self.mon[n - 1, 4])
                for i in range(n):
                    self._observe_row(i, h, self.n_taken + i + 1, t0 + (i + 1) * h if i + 1 < n else end,
                                      None, None)
            except DivergenceError:
                failed = True
            self.n_taken += n
            self.t = end
        else:
            try:
                for i in range(n):
                    self._one(h, self.t + h if i + 1 < n else end)
                    self._observe_row(0, h, self.n_taken, self.t, None, None)
            except DivergenceError:
                failed = True
        if failed:  # raised again by the replay, with the states around the failing step
            self._replay()
        self.stats["n_steps"] = max(self.stats["n_steps"], self.n_taken)

    # whether the drive reads positions of free dofs (a follower pressure does): then it must run
    # after the update; the Simulator says so when it builds the stepper
    drive_reads_state = True

    def _one(self, h, t_step):
        """One step without the detector: advance, move the driven dofs, evaluate."""
        if self.drive is not None and not self.drive_reads_state and not self.others:
            # the drive writes only dofs that no update moves (w = 0) and reads none that it does:
            # it runs first, and the update and the force pass run in one kernel call
            before = (self._fixed_positions(), self.load, self.extra)
            self.drive(t_step, self.x)
            self.note_input(before[0], self._fixed_positions(), before[1], before[2])
            self._sync_in()
            self._update_external()
            rowptr, ia, ib, kl = self.layout
            fused_steps(self.R, self._v, self._F, rowptr, ia, ib, kl, self.w, self.damp, h, self.fext, self._x_ref,
                        self._react, self.mon, 1)
            self._dmax_ub = float(self.mon[0, 4])
            self._sync_out()
            self.stats["n_force_evals"] += 1
            self.n_taken += 1
            self.t = t_step
            return
        fused_advance(self.R, self._v, self._F, self.w, self.damp, h)
        self._sync_out()
        if self.drive is not None:
            before = (self._fixed_positions(), self.load, self.extra)
            self.drive(t_step, self.x)
            self.note_input(before[0], self._fixed_positions(), before[1], before[2])
        self.evaluate()
        self.n_taken += 1
        self.t = t_step

    def _bound_displacements(self, n, h):
        """The monitor's ``max |x - x_ref|`` column of a call of :func:`fused_steps_lean` (which
        leaves it out): only the update moved nodes, so step ``p + 1`` is at most
        ``h max|v_{p+1}| <= h sqrt(v.v)`` farther than step ``p``, from the bound of the state
        before the call.  Where that bound passes the divergence bound, the detector checks the
        state after the call (:func:`msslib.stepping.generic._check_state`), as it does when the
        exact value passes it: whether it raises depends on that state alone, so the outcome is
        that of the exact column (and a divergence is replayed step by step, exactly).  Once that
        check has passed, the rest of the call is not checked again, and the bound restarts from
        the exact value after the call."""
        d = self._dmax_ub
        bounds = np.zeros(n)  # 0 after the check passed
        for i, q in enumerate(self.mon[:n, 0].tolist()):
            d = d + h * math.sqrt(q) if q >= 0.0 else float("nan")
            if not d <= self.bound:
                _check_state(self.problem, self._flat_x(), self.v, self.x_ref, self.bound, self.n_taken + i + 1,
                             self.t + (i + 1) * h, self.dt, self.method, None, None, self.limit)
                self._dmax_ub = self._dmax_exact()
                break
            bounds[i] = d
        else:
            self._dmax_ub = d
        self.mon[:n, 4] = bounds

    def _observe_row(self, i, h, step, t, x_prev, v_prev):
        q, pf, ku, r, dmax = self.mon[i]
        self.observe(q, pf, ku, r, dmax, h, step, t, x_prev, v_prev, True)

    def _replay(self):
        """Rerun the steps since the checkpoint one by one, keeping the state before each, until
        the detector raises again (with that state)."""
        x, v, t, n_taken, j_min, flips, a_in = self._ckpt
        self.x[:] = x
        self.v[:] = v
        self.t, self.n_taken, self.j_min, self.flips, self.a_in = t, n_taken, j_min, flips, a_in
        if self.drive is not None:
            self.drive(t, self.x)
        self.evaluate()
        for n, h, end in self._since:
            self._set_step(h)
            for i in range(n):
                x_prev, v_prev = np.array(self.x).reshape(-1), self.v.copy()
                self._one(h, self.t + h if i + 1 < n else end)
                self._observe_row(0, h, self.n_taken, self.t, x_prev, v_prev)
        raise RuntimeError("the replay did not find the divergence again")  # pragma: no cover

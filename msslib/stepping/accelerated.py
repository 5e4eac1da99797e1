"""The JAX engine of the stepping API: :class:`JaxStepper` runs a spring network on
:class:`msslib.stepping.jax_backend.JaxNetwork` (the first GPU JAX sees, else its CPU) behind the
interface the :class:`~msslib.stepping.Simulator` steps.

The state lives on the device: reading ``x``, ``v`` or the reactions copies it to the host, so a
loop that reads every step pays a transfer; many steps per call are what the device is for.
Constant loads only (the device runs the steps of a call without the host); the divergence check
is the device's non-finite test at the end of each call (no per-step detector).
"""

from __future__ import annotations

import numpy as np

from msslib.solvers.stability import mass_proportional_alpha
from msslib.stepping.protocol import constant_loads_only


class JaxStepper:
    """The stepper of ``engine="jax"`` (see the module docstring)."""

    explicit = True
    conservative = True

    def __init__(self, model, x0, v0, *, dt, damping=None, load=1.0, allow_unstable=False, blowup=1e3,
                 free=None, drive=None):
        from msslib.stepping.jax_backend import JaxNetwork

        constant_loads_only("jax", model, free, drive)
        alpha = mass_proportional_alpha(model, damping, "engine='jax'")
        self.net = JaxNetwork.from_model(model, dt, alpha, load=load, x0=x0, v0=v0, allow_unstable=allow_unstable)
        self.model, self.dt, self.load, self.extra = model, float(dt), load, None
        self.free = np.asarray(model.free, dtype=bool)
        self.mass = np.asarray(model.mass, dtype=float)
        self.t, self.n_taken = 0.0, 0
        self.messages: list[str] = []
        self.stats = {"method": "symplectic_euler", "dt": self.dt, "n_steps": 0, "damping": (alpha, 0.0),
                      **self.net.stability, "engine": "jax", "device": str(getattr(self.net, "device", ""))}

    @property
    def x(self) -> np.ndarray:
        return self.net.positions()

    @property
    def v(self) -> np.ndarray:
        return self.net.velocities()

    def full_force(self) -> np.ndarray:
        return self.net.forces()

    def kinetic_energy(self) -> float:
        v = self.v
        return 0.5 * float(self.mass[self.free] @ (v[self.free] ** 2))

    def evaluate(self):
        """Nothing to do: the device keeps the force current."""

    def restart_detector(self):
        """Nothing to restart: the device's divergence check is its non-finite test at the end
        of each call."""

    def reaction(self):
        """Minus the total force on the dofs that do not move, 0 on the free ones (flat, N)."""
        return np.where(self.free, 0.0, -self.full_force())

    def steps(self, n: int, h=None, t_new=None):
        if h is not None and abs(h - self.dt) > 1e-12 * self.dt:
            raise ValueError(f"engine='jax' steps at dt = {self.dt:.6g} s only, got h = {h!r}")
        self.net.steps(int(n))
        self.n_taken += int(n)
        self.t = self.n_taken * self.dt if t_new is None else float(t_new)
        self.stats["n_steps"] = self.n_taken

    def step(self, h=None, t_new=None):
        self.steps(1, h, t_new)

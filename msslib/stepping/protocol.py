"""The one interface between the :class:`~msslib.stepping.Simulator` and its engines.

An engine (a *stepper*) owns the state of one run between two changes of its inputs: the
Simulator builds a new one with the current state whenever a load, a path or a support changes
(``_build``), and talks to it only through :class:`Stepper`.  Each engine --
:class:`~msslib.stepping.generic.Integrator` (``generic``),
:class:`~msslib.stepping.network.NetworkStepper` (``network``) and
:class:`~msslib.stepping.accelerated.JaxStepper` (``jax``) -- implements all of it;
``tests/test_stepping_protocol.py`` checks each against this class, so a new engine that misses a
member is found before a Simulator calls it.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Stepper(Protocol):
    """What an engine of the Simulator provides.

    State, read by the Simulator after any call: ``x`` and ``v`` (flat, ``n_dof``), ``t`` (s) and
    ``n_taken`` (steps since the start; the Simulator sets both on a rebuilt stepper), ``stats``
    (a dict of the run: scheme, dt, stability limit, ...) and ``messages`` (notes of the run).
    Fixed at construction: ``explicit`` (an explicit scheme: the force of the state is kept),
    ``conservative`` (the model has an energy), ``free`` (bool mask of the dofs that move) and
    ``load`` (the load factor).  Set by the Simulator between calls: ``extra``, the extra nodal
    forces of ``apply_force`` (flat, N) or None."""

    explicit: bool
    conservative: bool
    free: np.ndarray
    load: object
    extra: object
    t: float
    n_taken: int
    stats: dict
    messages: list

    @property
    def x(self) -> np.ndarray: ...

    @property
    def v(self) -> np.ndarray: ...

    def steps(self, n: int, h: float | None = None, t_new: float | None = None) -> None:
        """``n`` steps of ``h`` (None: the stepper's dt); ``t_new``: the time after the last one."""

    def evaluate(self) -> None:
        """Recompute what the next step needs from the state (after the loads were changed)."""

    def restart_detector(self) -> None:
        """Restart the divergence detector from the current state and loads."""

    def full_force(self) -> np.ndarray:
        """The total force on every dof at the current state and load (N)."""

    def reaction(self) -> np.ndarray:
        """The force the supports and paths apply: minus the total force on every dof that does
        not move, 0 on the free dofs (flat, N)."""

    def kinetic_energy(self) -> float:
        """``1/2 v.M v`` over the free dofs (J)."""


def constant_loads_only(engine: str, model, free, drive) -> None:
    """Refuse, in one line naming ``engine``, what an engine that runs the steps of a call without
    the host cannot: a driven load (``drive``, a load curve or a path) or supports other than the
    model's (``free``, prescribed paths)."""
    if drive is not None:
        raise ValueError(f"engine={engine!r} runs constant loads: a load curve, time-varying forces or a moving "
                         "path run on the network engine (engine='network')")
    if free is not None and np.any(np.asarray(free) != np.asarray(model.free)):
        raise ValueError(f"engine={engine!r} keeps the model's supports: prescribed paths run on the network engine")


__all__ = ["Stepper", "constant_loads_only"]

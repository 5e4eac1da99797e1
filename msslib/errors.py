"""The errors and warnings msslib reports to its users.

Every error a run can end with is one of these (or a ValueError / OSError for bad input); the
command line prints each as one line, ``msslib: error: ...``, and each warning as
``msslib: warning: ...``.  The solver failures :class:`ConvergenceError` and
:class:`DivergenceError` are defined here and raised by :mod:`msslib.solvers` (which re-exports
them).
"""

from __future__ import annotations

__all__ = [
    "ConvergenceError",
    "DivergenceError",
    "MsslibWarning",
    "ResourceError",
    "StabilityError",
    "UnphysicalStateError",
]


class MsslibWarning(UserWarning):
    """A result msslib stands behind, with something the user must know (inverted cells, merged
    nodes, ...).  Shown by the command line as one ``msslib: warning:`` line."""


class UnphysicalStateError(RuntimeError):
    """A solution contains inverted or collapsed cells and the scene asked for an error
    (``checks: {inverted: error}``)."""


class ResourceError(ValueError):
    """A run would need more memory than allowed (the estimate and a hint are in the message)."""


class StabilityError(ValueError):
    """An explicit time step above the stability limit of the model at rest was refused."""


class ConvergenceError(RuntimeError):
    """Newton's method failed (static load step or implicit time step).

    Attributes ``load_step``, ``load``, ``iteration``, ``residual`` (absolute free-dof residual
    norm), ``x_last`` (the last converged state, finite) and, for dynamics, ``step`` and ``time``.
    """

    def __init__(self, message, *, load_step=None, load=None, iteration=None, residual=None,
                 x_last=None, step=None, time=None):
        super().__init__(message)
        self.load_step = load_step
        self.load = load
        self.iteration = iteration
        self.residual = residual
        self.x_last = x_last
        self.step = step
        self.time = time


class DivergenceError(RuntimeError):
    """A time integration blew up.

    Attributes ``step`` (index of the offending step, 1-based), ``time``, ``quantity``
    (``"position"``, ``"velocity"``, ``"displacement"`` or ``"growth"``: the explicit
    instability, ``value`` then the growth factor), ``dof``, ``value``, the last finite state
    ``x_last``, ``v_last`` (the state before the offending step), ``dt``, ``stability_limit`` (the
    limit of the model at rest computed before an explicit run; None for implicit Euler) and
    ``max_displacement`` (``max |x - x0|`` when it was stopped).
    """

    def __init__(self, message, *, step, time, quantity, dof, value, x_last=None, v_last=None, dt=None,
                 stability_limit=None, max_displacement=None):
        super().__init__(message)
        self.step = step
        self.time = time
        self.quantity = quantity
        self.dof = dof
        self.value = value
        self.x_last = x_last
        self.v_last = v_last
        self.dt = dt
        self.stability_limit = stability_limit
        self.max_displacement = max_displacement

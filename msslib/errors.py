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


class _SolverFailure(RuntimeError):
    """A solver failure with the circumstances it happened in as attributes: ``FIELDS`` names
    them (each None unless given as a keyword), ``REQUIRED`` those that must be given."""

    FIELDS: tuple[str, ...] = ()
    REQUIRED: tuple[str, ...] = ()

    def __init__(self, message, **details):
        unknown = [name for name in details if name not in self.FIELDS]
        if unknown:
            raise TypeError(f"{type(self).__name__}() got an unexpected keyword argument {unknown[0]!r}")
        missing = [name for name in self.REQUIRED if name not in details]
        if missing:
            raise TypeError(f"{type(self).__name__}() missing required keyword argument(s): {', '.join(missing)}")
        super().__init__(message)
        for name in self.FIELDS:
            setattr(self, name, details.get(name))


class ConvergenceError(_SolverFailure):
    """Newton's method failed (static load step or implicit time step).

    Attributes ``load_step``, ``load``, ``iteration``, ``residual`` (absolute free-dof residual
    norm), ``x_last`` (the last converged state, finite) and, for dynamics, ``step`` and ``time``.
    """

    FIELDS = ("load_step", "load", "iteration", "residual", "x_last", "step", "time")


class DivergenceError(_SolverFailure):
    """A time integration blew up.

    Attributes ``step`` (index of the offending step, 1-based), ``time``, ``quantity``
    (``"position"``, ``"velocity"``, ``"displacement"`` or ``"growth"``: the explicit
    instability, ``value`` then the growth factor), ``dof``, ``value``, the last finite state
    ``x_last``, ``v_last`` (the state before the offending step), ``dt``, ``stability_limit`` (the
    limit of the model at rest computed before an explicit run; None for implicit Euler) and
    ``max_displacement`` (``max |x - x0|`` when it was stopped); the first five are required.
    """

    FIELDS = ("step", "time", "quantity", "dof", "value", "x_last", "v_last", "dt", "stability_limit",
              "max_displacement")
    REQUIRED = FIELDS[:5]

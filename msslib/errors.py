"""The errors and warnings msslib reports to its users.

Every error a run can end with is one of these (or a ValueError / OSError for bad input); the
command line prints each as one line, ``msslib: error: ...``, and each warning as
``msslib: warning: ...``.  Solver failures keep their home in :mod:`msslib.solvers`
(:class:`~msslib.solvers.ConvergenceError`, :class:`~msslib.solvers.DivergenceError`) and are
re-exported here.
"""

from __future__ import annotations

__all__ = ["MsslibWarning", "UnphysicalStateError", "ResourceError", "StabilityError",
           "ConvergenceError", "DivergenceError"]


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


def __getattr__(name):  # re-export without importing numba-heavy modules at import time
    if name in ("ConvergenceError", "DivergenceError"):
        from msslib import solvers

        return getattr(solvers, name)
    raise AttributeError(name)

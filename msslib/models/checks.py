"""Checks shared by the parameter functions of the model families (:mod:`msslib.models`).

Every parameter function takes SI inputs and returns a frozen dataclass of per-element values;
the helpers here refuse non-real input, out-of-domain values and results that overflow, each with
a ``ValueError`` naming the value, and warn (:class:`FormulaValidityWarning`) where a formula is
used outside the conditions it was derived under.
"""

from __future__ import annotations

import numbers
import warnings
from dataclasses import fields

import numpy as np


class FormulaValidityWarning(UserWarning):
    """A formula is used outside the conditions under which it was derived."""


def brief(value) -> str:
    """A value for a message: arrays by shape and dtype, long reprs cut."""
    if isinstance(value, np.ndarray) and value.ndim:
        return f"array of shape {value.shape} ({value.dtype})"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def real(name, value):
    """``value`` if it is a real number or a numpy array of real numbers, else ValueError."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf":
            raise ValueError(f"{name} must be a real number or a numpy array of real numbers, "
                             f"got an array of dtype {value.dtype}: {brief(value)}")
        return value
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.integer, np.floating)):
        raise ValueError(f"{name} must be a real number or a numpy array of real numbers, "
                         f"got {type(value).__name__} {brief(value)}")
    try:
        float(value)
    except OverflowError:
        raise ValueError(f"{name} is too large for double precision, got {brief(value)}") from None
    return value


def flag(name, value):
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {type(value).__name__} {brief(value)}")
    return bool(value)


def same_shape(function, **args):
    """All array arguments of one call have the same shape (scalars go with any)."""
    shapes = {k: np.shape(v) for k, v in args.items() if isinstance(v, np.ndarray) and v.ndim}
    if len(set(shapes.values())) > 1:
        shown = ", ".join(f"{k} {s}" for k, s in shapes.items())
        raise ValueError(f"{function}: array arguments must all have the same shape (no broadcasting), got {shown}")


def evaluate(function, formula, cls, **args):
    """``cls(*formula(*args))``; a field that overflows to inf or comes out NaN is refused."""
    shown = ", ".join(f"{k}={brief(v)}" for k, v in args.items())
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        try:
            values = formula(*args.values())
        except (OverflowError, ZeroDivisionError):
            raise ValueError(f"{function}({shown}): the result overflows double precision; the inputs are "
                             f"out of its range") from None
    values = values if isinstance(values, tuple) else (values,)
    for f, v in zip(fields(cls), values):
        bad = ~np.isfinite(np.asarray(v, dtype=float))
        if np.any(bad):
            what = "is infinite" if np.any(np.isinf(np.asarray(v, dtype=float))) else "is NaN"
            raise ValueError(f"{function}({shown}): {f.name} {what}; the inputs are out of the range "
                             f"of double precision")
    return cls(*values)


def offending(value, bad):
    """The value itself (scalars) or the first offending entry and where it is (arrays)."""
    v = np.asarray(value, dtype=float)
    if v.ndim == 0:
        return repr(value)
    i = int(np.flatnonzero(bad.ravel())[0])
    return f"{float(v.ravel()[i])!r} (entry {i} of {v.size})"


def positive(name, value):
    real(name, value)
    v = np.asarray(value, dtype=float)
    bad = ~np.isfinite(v) | (v <= 0)
    if np.any(bad):
        raise ValueError(f"{name} must be finite and > 0, got {offending(value, bad)}")
    return value


def poisson(nu, low=-1.0, high=0.5):
    real("Poisson's ratio nu", nu)
    v = np.asarray(nu, dtype=float)
    bad = ~np.isfinite(v) | (v <= low) | (v >= high)
    if np.any(bad):
        raise ValueError(f"Poisson's ratio nu must lie in ({low:g}, {high:g}), got {offending(nu, bad)}")
    return nu


def warn_nu(nu, exact, model):
    if nu is None:
        return
    off = np.abs(np.asarray(nu, dtype=float) - exact) > 1e-9
    if np.any(off):
        warnings.warn(f"{model} is exact only for nu = {exact:.6g}; got nu = {offending(nu, off)}",
                      FormulaValidityWarning, stacklevel=3)

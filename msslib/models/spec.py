"""What a model family declares: :class:`ModelSpec` and its parts.

A family module of :mod:`msslib.models` (``lloyd``, ``baudet``, ...) lists its models in a
module-level ``SPECS`` tuple; the registry (:func:`msslib.models.registry`) finds them.  A spec says
which cells the model runs on, which force terms it can build (and which it builds by default),
which scene options it takes and how each is checked, which generated derivation module its
constants come from, the paper it implements, the function that turns material and geometry into
constants, the builder that turns a mesh into force terms, and where its derivation claims it is
exact (what the registry tests check).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from typing import Any, Callable

__all__ = ["BuildContext", "Exactness", "ModelSpec", "Option", "OptionError", "choice", "positive_number",
           "boolean"]


class OptionError(ValueError):
    """A bad model option; the message is the part after the key path."""


def choice(*choices: str, what: str = "value"):
    """A parser accepting one of ``choices``."""

    def parse(value):
        if not isinstance(value, str) or value not in choices:
            hint = difflib.get_close_matches(str(value), list(choices), n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise OptionError(f"unknown {what} {value!r}; expected one of {', '.join(choices)}{did}")
        return value

    parse.choices = choices
    return parse


def positive_number(value):
    """A finite number > 0 (numbers written as strings such as ``1e6`` too)."""
    import math

    if isinstance(value, bool) or value is None:
        raise OptionError(f"expected a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise OptionError(f"expected a number, got {value!r}") from None
    if not math.isfinite(number):
        raise OptionError(f"expected a finite number, got {value!r}")
    if number <= 0:
        raise OptionError(f"must be > 0, got {value!r}")
    return number


def boolean(value):
    if not isinstance(value, bool):
        raise OptionError(f"expected true or false, got {value!r}")
    return value


@dataclass(frozen=True)
class Option:
    """A scene option of a model: ``{type: NAME, <name>: value}``.

    ``parse(value)`` returns the normalised value or raises :class:`OptionError`; ``default`` is
    used when the scene does not give it."""

    name: str
    parse: Callable[[Any], Any]
    default: Any
    doc: str


@dataclass(frozen=True)
class Exactness:
    """Where a model's derivation claims it reproduces linear elasticity exactly.

    ``level``: ``"element"`` (its stiffness at rest equals the linear FEM element's, so the assembled
    matrices are equal) or ``"lattice"`` (a homogeneous strain of a mesh of such cells gives the
    continuum's stress: the virial of the forces equals ``V D eps``).  ``mesh``: the cells it
    holds on (``"equilateral"`` triangles, ``"square"`` quads, ``"cube"`` hexahedra); ``nu`` the
    Poisson's ratio it needs (None: any); ``options`` the option values it needs."""

    level: str
    mesh: str
    nu: float | None = None
    options: dict = field(default_factory=dict)
    source: str = ""


@dataclass
class BuildContext:
    """What a builder receives: the mesh, ``materials`` as ``(E, nu)`` pairs indexed by
    ``mesh.material``, the parsed ``options`` (with ``terms``, the terms to build), the membrane
    ``thickness`` (2D) and ``surface_forces`` (n, dim) N, the traction and nodal loads at unit load
    factor (Baudet's correction is computed from them)."""

    mesh: Any
    materials: list
    options: dict
    thickness: float = 1.0
    surface_forces: Any = None


@dataclass(frozen=True)
class ModelSpec:
    """One simulator model, as scenes name it.

    ``kind`` is ``"mss"`` (a builder of force terms) or ``"fem"`` (a reference solved by
    :mod:`msslib.fem` with material law ``law``, None for linear).  ``terms`` the internal force
    terms an MSS model can build, ``default_terms`` those built when a scene does not list them;
    ``nonconservative`` the terms that are not the gradient of an energy.  ``element``: the module
    of :mod:`msslib.generated` its constants come from.  ``parameters``: the function from
    material and geometry to per-element constants; ``build(ctx)`` returns ``{term: [Term, ...]}``
    for the terms in ``ctx.options["terms"]``."""

    name: str
    family: str
    kind: str
    cells: tuple[str, ...]
    dim: int
    title: str
    reference: str
    doi: str | None = None
    hal: str | None = None
    element: str | None = None
    terms: tuple[str, ...] = ()
    default_terms: tuple[str, ...] | None = None
    nonconservative: tuple[str, ...] = ()
    options: tuple[Option, ...] = ()
    parameters: Callable | None = None
    build: Callable[[BuildContext], dict] | None = None
    law: str | None = None
    exact: tuple[Exactness, ...] = ()
    published_variant: bool = False
    equilibrium_at_rest: Callable[[dict], bool] | None = None

    def __post_init__(self):
        if self.kind not in ("mss", "fem"):
            raise ValueError(f"model {self.name}: kind must be 'mss' or 'fem', got {self.kind!r}")
        if self.kind == "mss" and (self.build is None or not self.terms):
            raise ValueError(f"model {self.name}: an MSS model needs a builder and its terms")
        if self.default_terms is not None and not set(self.default_terms) <= set(self.terms):
            raise ValueError(f"model {self.name}: default terms {self.default_terms} not among {self.terms}")

    @property
    def cell_type(self) -> str:
        """The cell type (every model runs on one)."""
        return self.cells[0]

    @property
    def defaults(self) -> tuple[str, ...]:
        return self.terms if self.default_terms is None else self.default_terms

    def option(self, name: str) -> Option | None:
        return next((o for o in self.options if o.name == name), None)

    def in_equilibrium_at_rest(self, options: dict) -> bool:
        """Whether the built terms exert no force at the rest positions with these options."""
        return True if self.equilibrium_at_rest is None else bool(self.equilibrium_at_rest(options))


def split_terms(terms, wanted) -> dict:
    """``{term name: [Term, ...]}`` of the ``wanted`` internal terms among ``terms`` (a builder's
    list): springs are ``"springs"``, volume terms ``"volume"``."""
    out: dict = {}
    for t in terms:
        kind = t.kind if t.kind in ("springs", "volume") else None  # each term declares its kind
        if kind is None:
            raise TypeError(f"unexpected internal term {type(t).__name__}")
        if kind in wanted:
            out.setdefault(kind, []).append(t)
    return out

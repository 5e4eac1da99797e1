"""What a derivation module hands on: formulas to generate code from, published formulas, errata."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class Formula:
    """A generated function ``name(*args) -> outputs`` (outputs: ordered name -> expression)."""

    name: str
    args: tuple  # sympy symbols, in call order
    outputs: dict
    doc: str


@dataclass(frozen=True)
class Erratum:
    paper: str  # short citation
    where: str  # equation / section
    printed: str  # LaTeX of the printed formula
    correct: str  # LaTeX of the derived formula
    explanation: str
    proof: str  # the test proving it (pytest node id)


@dataclass
class Derivation:
    module: str
    title: str
    formulas: list = field(default_factory=list)  # derived; code generated into msslib.generated
    published: list = field(default_factory=list)  # as printed (where they differ)
    errata: list = field(default_factory=list)
    findings: list = field(default_factory=list)  # (label, LaTeX or text) for the paper
    data: dict = field(default_factory=dict)  # anything tests want to look at
    checks: dict = field(default_factory=dict)  # name -> number (1/0 for a property that holds or not) the paper reads


def latex(e) -> str:
    return sp.latex(e)


@dataclass(frozen=True)
class Element:
    """What an element module (``derivations/elements/<name>.py``) declares at module level as
    ``ELEMENT``: the registry finds the module, codegen writes ``msslib/generated/<name>.py``.

    ``cell`` is the :mod:`derivations.element_stiffness` cell type it derives (``triangle``, ``quad``, ``tetra``,
    ``hexahedron``); ``models`` the simulator models (scene model names) whose parameters come from
    the generated code; ``source`` the paper and section it derives; ``extends`` the element it
    generalises, if any (its derivation is listed after that one)."""

    name: str
    cell: str
    models: tuple = ()
    source: str = ""
    extends: str | None = None

"""The export formats: one :class:`Format` per format, declared in the modules of this package.

Every module here that defines ``FORMATS`` (a tuple of :class:`Format`) adds its formats; the table
(:func:`table`) is read from the package's folder when first asked for, so a new format is one new
module (its writer and its entry) and its test, with no other edit. The built-in six are in
:mod:`msslib.export.formats.builtin`.

Which terms of a model a format carries: a term names the formats that carry it
(:attr:`msslib.terms.Term.export_formats`), and a format may also take terms by its own rule
(:attr:`Format.takes`, e.g. every term for a format of tables). A format that leaves a term out
says so in its file and on the command line, naming the model and the term
(:func:`msslib.export.model.not_carried`).
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable


@dataclass(frozen=True)
class Format:
    """One export format.

    ``name``
        as ``msslib export --format`` takes it.
    ``order``
        where it stands in the table (outputs are written and listed in this order).
    ``files(exp, stem)``
        ``[(what, path, table)]``: the files it writes for the model ``exp`` at the path prefix
        ``stem`` (``table``: which part a file holds, passed back to ``writer``; None for one file).
    ``writer(exp, table)``
        ``write(path)`` that writes one of them.
    ``carries``, ``help``
        a phrase saying what it carries; the help text of ``msslib export --format``.
    ``whole_only``
        written by default only when it carries every term of the model (MuJoCo and SOFA).
    ``takes(term)``
        its own rule for the terms it carries, besides the terms that name it.
    """

    name: str
    order: int
    files: Callable
    writer: Callable
    carries: str
    help: str
    whole_only: bool = False
    takes: Callable | None = None

    def carries_term(self, term) -> bool:
        """Whether the format carries ``term`` whole."""
        return self.name in term.export_formats or (self.takes is not None and bool(self.takes(term)))


def text_writer(make: Callable[[], str]):
    """``write(path)`` that writes the text ``make()`` returns (UTF-8)."""
    def write(path):
        Path(path).write_text(make(), encoding="utf-8")
    return write


def one_file(what: str, suffix: str):
    """``files(exp, stem)`` of a format that writes one file ``STEM<suffix>``."""
    return lambda exp, stem: [(what, stem.with_name(f"{stem.name}{suffix}"), None)]


@functools.cache
def table() -> tuple[Format, ...]:
    """Every format, in order: the ``FORMATS`` of every module of this package. ValueError naming a
    format given twice."""
    found: dict[str, tuple[Format, str]] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        for fmt in getattr(module, "FORMATS", ()):
            if fmt.name in found:
                raise ValueError(f"export format {fmt.name!r} is declared twice: in {found[fmt.name][1]} and "
                                 f"{module.__name__}")
            found[fmt.name] = (fmt, module.__name__)
    return tuple(sorted((f for f, _ in found.values()), key=lambda f: (f.order, f.name)))


def names() -> tuple[str, ...]:
    """The names of every format, in order."""
    return tuple(f.name for f in table())


def get(name: str) -> Format:
    """The format called ``name``; ValueError if there is none."""
    for f in table():
        if f.name == name:
            return f
    raise ValueError(f"unknown format {name!r}; expected one of {', '.join(names())}")


def whole_only() -> tuple[str, ...]:
    """The formats written by default only for models they carry whole (the springs-only ones)."""
    return tuple(f.name for f in table() if f.whole_only)


__all__ = ["Format", "get", "names", "one_file", "table", "text_writer", "whole_only"]

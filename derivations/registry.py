"""The derivation modules, found by scanning their folders (there is no list of them anywhere).

    derivations/elements/<name>.py   an element family: declares ``ELEMENT`` (:class:`records.Element`)
                                     and ``derive()``; codegen writes ``msslib/generated/<name>.py``
    derivations/terms/<name>.py      energy-term kernels: declares ``derive()``; generated the same way
    derivations/analyses/<name>.py   an analysis that uses the engine and generates no code
    derivations/*.py                 the engine (every generated file is hashed on it and on its own
                                     module only, so adding a module leaves the others up to date)

Names are file stems and unique across the folders (a generated module is named after its
source). Elements are listed by dimension, then number of nodes, then name, an element that
``extends`` another right after it; terms after the elements, by name. The order fixes the order
of the paper's derivation results and the numbering of its errata.
"""

from __future__ import annotations

import importlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
KINDS = ("elements", "terms", "analyses")
#: the kinds whose modules codegen turns into msslib/generated/<name>.py
GENERATED_KINDS = ("elements", "terms")


def _stems(kind: str) -> list[str]:
    return sorted(p.stem for p in (HERE / kind).glob("*.py") if not p.stem.startswith("_"))


def names(kind: str) -> list[str]:
    """The module names of one folder, by file name (nothing imported)."""
    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}, expected one of {', '.join(KINDS)}")
    return _stems(kind)


def _index() -> dict[str, str]:
    """name -> kind; a name in two folders is an error."""
    out = {}
    for kind in KINDS:
        for name in _stems(kind):
            if name in out:
                raise ValueError(f"derivation module {name!r} is in both derivations/{out[name]}/ and "
                                 f"derivations/{kind}/; names must be unique")
            out[name] = kind
    return out


def kind(name: str) -> str:
    """``elements``, ``terms`` or ``analyses``; KeyError for an unknown module."""
    index = _index()
    if name not in index:
        raise KeyError(f"no derivation module {name!r} in derivations/{{{','.join(KINDS)}}}/")
    return index[name]


def resolve(name: str) -> str:
    """The bare module name of ``name``, given as ``triangle``, ``elements.triangle``,
    ``elements/triangle``, ``derivations/elements/triangle.py`` or ``derivations.elements.triangle``."""
    stem = name.replace("\\", "/").removesuffix(".py").replace(".", "/").rstrip("/").rsplit("/", 1)[-1]
    kind(stem)
    return stem


def qualified(name: str) -> str:
    """The importable name, e.g. ``derivations.elements.triangle``."""
    name = resolve(name)
    return f"derivations.{kind(name)}.{name}"


def path(name: str) -> Path:
    """The source file of a derivation module."""
    name = resolve(name)
    return HERE / kind(name) / f"{name}.py"


def relpath(name: str) -> str:
    """The source file relative to the repository, e.g. ``derivations/elements/triangle.py``."""
    return path(name).relative_to(ROOT).as_posix()


def module(name: str):
    """The imported module (importing derives nothing: ``derive()`` is called by the user)."""
    return importlib.import_module(qualified(name))


def element(name: str):
    """The ``ELEMENT`` declaration of an element module."""
    mod = module(name)
    decl = getattr(mod, "ELEMENT", None)
    if decl is None or decl.name != resolve(name):
        raise ValueError(f"{relpath(name)} must declare ELEMENT = records.Element({resolve(name)!r}, ...)")
    return decl


def _element_order(decls: dict) -> list[str]:
    from derivations.element_stiffness import _REF

    def key(name):
        d = decls[name]
        base = decls.get(d.extends) if d.extends else None
        if d.extends and base is None:
            raise ValueError(f"element {name!r} extends {d.extends!r}, which is not an element module")
        ref = _REF[(base or d).cell]
        return (len(ref[0]), len(ref), (base or d).name, 1 if base else 0, name)

    return sorted(decls, key=key)


def elements() -> list[str]:
    """The element modules, in their listing order (imports each module to read ``ELEMENT``)."""
    return _element_order({n: element(n) for n in names("elements")})


def terms() -> list[str]:
    """The term-kernel modules, by name."""
    return names("terms")


def generated() -> list[str]:
    """Every module codegen turns into ``msslib/generated/<name>.py``: the elements, then the terms."""
    _index()  # unique names
    return elements() + terms()


def engine_files() -> list[Path]:
    """The engine: every Python file directly in ``derivations/`` (this one included), by name."""
    return sorted(HERE.glob("*.py"))

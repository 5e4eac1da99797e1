"""The simulator models, one module per family, found by scanning this package.

Each family module (``lloyd``, ``baudet``, ``golec``, ``delingette``, ``lsq``; ``references``, the
FEM references) holds its parameter dataclasses and functions (constants from :mod:`msslib.generated`, with their checks), its builders, and a
module-level ``SPECS`` tuple of :class:`ModelSpec`.  :func:`registry` imports every module of the
package and collects the specs: adding a model is adding a module (or a spec to one); scenes,
:mod:`msslib.parameters`, :mod:`msslib.planning` and the tests read the registry.

``registry()`` maps model names (as scenes write them) to specs in a fixed order: by the families'
``RANK`` (FEM references first, then the papers in order), then in declaration order.
"""

from __future__ import annotations

import importlib
import pkgutil
from functools import lru_cache
from types import ModuleType

from msslib.models.spec import BuildContext, Exactness, ModelSpec, Option, OptionError

__all__ = ["BuildContext", "Exactness", "ModelSpec", "Option", "OptionError", "families", "registry", "get",
           "names", "for_cells", "option_names"]



@lru_cache(maxsize=None)
def families() -> tuple[ModuleType, ...]:
    """The family modules of this package (those declaring ``SPECS``), ordered by their ``RANK``
    (FEM references first), then by name."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.ispkg:
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(module, "SPECS"):
            found.append(module)
    return tuple(sorted(found, key=lambda m: (getattr(m, "RANK", 100), m.__name__)))


@lru_cache(maxsize=None)
def _registry() -> tuple[tuple[str, ModelSpec], ...]:
    out: dict[str, ModelSpec] = {}
    for module in families():
        for spec in module.SPECS:
            if not isinstance(spec, ModelSpec):
                raise TypeError(f"{module.__name__}.SPECS holds {spec!r}, not a ModelSpec")
            if spec.name in out:
                raise ValueError(f"model {spec.name!r} declared twice ({out[spec.name].family} and {spec.family})")
            out[spec.name] = spec
    return tuple(out.items())


def registry() -> dict[str, ModelSpec]:
    """Model name -> :class:`ModelSpec`, every model of every family."""
    return dict(_registry())


def get(name: str) -> ModelSpec:
    """The spec of model ``name``; KeyError naming the known models."""
    reg = registry()
    if name not in reg:
        raise KeyError(f"unknown model {name!r}; expected one of {', '.join(reg)}")
    return reg[name]


def names(kind: str | None = None) -> tuple[str, ...]:
    """Model names, all or of one ``kind`` (``"mss"`` or ``"fem"``)."""
    return tuple(n for n, s in _registry() if kind is None or s.kind == kind)


def for_cells(cell_type: str, kind: str | None = None) -> tuple[str, ...]:
    """The models that run on ``cell_type`` cells (FEM references run on every cell type)."""
    return tuple(n for n, s in _registry() if (kind is None or s.kind == kind)
                 and (s.kind == "fem" or cell_type in s.cells))


def option_names() -> tuple[str, ...]:
    """Every model-specific option any model takes."""
    return tuple(dict.fromkeys(o.name for _, s in _registry() for o in s.options))

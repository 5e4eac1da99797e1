"""Small meshes of every cell type for the registry-wide tests, read from the cell registry
(``CellType.example`` of :mod:`msslib.mesh.cells`): a new cell type is picked up with no edit."""

from __future__ import annotations

from msslib import mesh as M
from msslib.mesh import cells


def _scaled(args: dict, scale: float) -> dict:
    """The generator's arguments with every length (a float) times ``scale``; counts (ints) kept."""
    return {k: v * scale if isinstance(v, float) else v for k, v in args.items()}


def example_mesh(cell_type: str, scale: float = 1.0) -> M.Mesh:
    """The example mesh of ``cell_type`` (about 1 m across), its lengths times ``scale``."""
    generator, args = cells.get(cell_type).example
    make = generator if callable(generator) else getattr(M, generator)  # a function of its cell module, or a name
    return make(**_scaled(args, scale))


def example_geometry(cell_type: str, scale: float = 0.01) -> dict:
    """A scene's ``geometry`` of the example mesh of ``cell_type``, lengths times ``scale`` (a
    body of about 1 cm by default): a generator of msslib.mesh by name, or the mesh itself in
    memory when the cell module makes it."""
    generator, args = cells.get(cell_type).example
    if callable(generator):
        return {"mesh": example_mesh(cell_type, scale)}
    return {"generator": generator, "args": _scaled(args, scale)}

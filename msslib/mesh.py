"""Meshes: node positions, cells of one type, a material index per cell.

Conventions (shared by every module of msslib):

* ``points`` has shape ``(n_nodes, dim)`` in metres, ``dim`` is 2 or 3.
* ``cells`` has shape ``(n_cells, nodes_per_cell)``; node order is meshio's/VTK's:
  ``triangle`` and ``quad`` counter-clockwise; ``tetra`` positively oriented
  (``det[p1-p0, p2-p0, p3-p0] > 0``); ``hexahedron`` nodes 0-3 the bottom face counter-clockwise
  seen from above, 4-7 the top face, node ``i + 4`` above node ``i``.
* ``material`` has shape ``(n_cells,)``: an index into the list of materials of a model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CELL_TYPES = {"triangle": (2, 3), "quad": (2, 4), "tetra": (3, 4), "hexahedron": (3, 8)}


@dataclass(frozen=True)
class Mesh:
    points: np.ndarray
    cells: np.ndarray
    cell_type: str
    material: np.ndarray = field(default=None)

    def __post_init__(self):
        if self.cell_type not in CELL_TYPES:
            raise ValueError(f"unknown cell_type {self.cell_type!r}; expected one of {sorted(CELL_TYPES)}")
        dim, nv = CELL_TYPES[self.cell_type]
        points = np.ascontiguousarray(self.points, dtype=float)
        cells = np.ascontiguousarray(self.cells, dtype=np.int64)
        if points.ndim != 2 or points.shape[1] != dim:
            raise ValueError(f"points must have shape (n, {dim}) for {self.cell_type}, got {points.shape}")
        if cells.ndim != 2 or cells.shape[1] != nv:
            raise ValueError(f"cells must have shape (m, {nv}) for {self.cell_type}, got {cells.shape}")
        if cells.size and (cells.min() < 0 or cells.max() >= len(points)):
            raise ValueError("cells refer to nodes that do not exist")
        material = np.zeros(len(cells), dtype=np.int64) if self.material is None else np.asarray(self.material, dtype=np.int64)
        if material.shape != (len(cells),):
            raise ValueError(f"material must have shape ({len(cells)},), got {material.shape}")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "material", material)

    @property
    def dim(self) -> int:
        return self.points.shape[1]

    @property
    def n_nodes(self) -> int:
        return len(self.points)

    @property
    def n_cells(self) -> int:
        return len(self.cells)

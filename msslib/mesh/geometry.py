"""Geometry of a mesh: signed cell measures (:func:`cell_measures`), the check for inverted and
degenerate cells (:func:`check_cells`), orientation (:func:`orient`), facet lengths and areas
(:func:`facet_areas`) and lumped nodal masses (:func:`lumped_masses`).  Lengths in metres, areas
in m^2, volumes in m^3, masses in kg.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import cells as _cells
from .core import Mesh


def cell_measures(mesh: Mesh) -> np.ndarray:
    """Signed area (2D, m^2) or volume (3D, m^3) of each cell; positive for the conventional
    orientation.

    Triangles and tetrahedra: exact.  Quads: exact area of the bilinear quad (shoelace formula).
    Hexahedra: exact volume of the trilinear hexahedron (2 x 2 x 2 Gauss quadrature of det J).
    Wedges: exact volume of the wedge (det J integrated exactly).  The formula of each type is
    its cell module's (:mod:`msslib.mesh.cells`).
    """
    return _cells.get(mesh.cell_type).measure(mesh.points[mesh.cells])


def check_cells(mesh: Mesh, rtol: float = 1e-12, max_report: int = 5) -> np.ndarray:
    """Raise ValueError if a cell is inverted (negative measure) or degenerate
    (``|measure| <= rtol * mean |measure|``); otherwise return the measures.

    The message names the first ``max_report`` offending cell indices with their measure.
    """
    measures = cell_measures(mesh)
    if measures.size == 0:
        return measures
    mean = np.abs(measures).mean()
    degenerate = np.abs(measures) <= rtol * mean
    inverted = (measures < 0) & ~degenerate
    problems = []
    for label, mask in (("inverted", inverted), ("degenerate", degenerate)):
        bad = np.flatnonzero(mask)
        if len(bad):
            shown = ", ".join(f"cell {i} (measure {measures[i]:.3e})" for i in bad[:max_report])
            more = f" and {len(bad) - max_report} more" if len(bad) > max_report else ""
            problems.append(f"{len(bad)} {label} {mesh.cell_type} cell(s): {shown}{more}")
    if problems:
        raise ValueError("; ".join(problems) + f" (mean |measure| {mean:.3e})")
    return measures


def orient(mesh: Mesh) -> Mesh:
    """Return a mesh whose cells with negative measure are flipped: triangles and tetrahedra swap
    nodes 1 and 2, quads reverse their order, hexahedra swap their bottom and top faces, wedges
    swap nodes 1 and 2 and nodes 4 and 5 (each type's ``flip``, :mod:`msslib.mesh.cells`)."""
    flip = cell_measures(mesh) < 0
    if not flip.any():
        return mesh
    cells = mesh.cells.copy()
    cells[flip] = cells[flip][:, np.array(_cells.get(mesh.cell_type).flip)]
    return replace(mesh, cells=cells)  # material and groups unchanged (cell and node numbers are kept)


def facet_areas(mesh: Mesh, facets: np.ndarray) -> np.ndarray:
    """Length (2D, metres) or area (3D, m^2) of each facet of ``facets`` (node ids).

    Quads use the area of the bilinear surface they span (2 x 2 Gauss quadrature; exact for
    planar quads).
    """
    facets = np.asarray(facets, dtype=np.int64)
    x = mesh.points[facets]
    if facets.shape[1] == 2:
        return np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
    if facets.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    if facets.shape[1] == 4:
        g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
        area = np.zeros(len(facets))
        for u in g:
            for v in g:
                # bilinear map on [-1, 1]^2, corners counter-clockwise
                du = 0.25 * ((x[:, 1] - x[:, 0]) * (1 - v) + (x[:, 2] - x[:, 3]) * (1 + v))
                dv = 0.25 * ((x[:, 3] - x[:, 0]) * (1 - u) + (x[:, 2] - x[:, 1]) * (1 + u))
                area += np.linalg.norm(np.cross(du, dv), axis=1)
        return area
    raise ValueError(f"facets must have 2, 3 or 4 nodes, got {facets.shape[1]}")


def lumped_masses(mesh: Mesh, density, thickness: float = 1.0) -> np.ndarray:
    """Lumped nodal masses (kg): each cell's mass split equally among its nodes.

    ``density`` in kg/m^3, a scalar or one value per cell.  For 2D meshes the cell mass is
    ``density * area * thickness`` (thickness in metres); for 3D meshes ``density * volume``
    and ``thickness`` must be left at 1.
    """
    density = np.broadcast_to(np.asarray(density, dtype=float), (mesh.n_cells,))
    if mesh.dim == 3 and thickness != 1.0:
        raise ValueError("thickness applies to 2D meshes only")
    cell_mass = density * np.abs(cell_measures(mesh)) * (thickness if mesh.dim == 2 else 1.0)
    per_node = np.repeat(cell_mass / mesh.nodes_per_cell, mesh.nodes_per_cell)
    return np.bincount(mesh.cells.ravel(), weights=per_node, minlength=mesh.n_nodes)

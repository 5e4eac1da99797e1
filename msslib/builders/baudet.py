"""Baudet et al.'s cube model: springs on the edges and inner diagonals of every cube, and the
orthogonal correction forces from the surface loads."""

from __future__ import annotations

from functools import partial

import numpy as np

from msslib.terms import BaudetCorrection, Term, sum_external_forces

from .common import (
    _cube_edges,
    _merge_springs,
    _parameters,
    _per_cell,
    _require,
    assemble_springs,
    material_arrays,
)


def baudet_cube_springs(mesh, materials, published: bool = False) -> list[Term]:
    """Baudet et al.'s springs on a mesh of cubes: per cube ``k_edge`` on its 12 edges (summed over
    the cubes sharing an edge) and ``k_diagonal`` on its 4 inner diagonals
    (``parameters.baudet_cube(E, nu, a)``, ``a`` the cube's edge).  Add :func:`baudet_correction`
    for the Poisson effect under load. (The printed and derived spring constants agree;
    ``published`` is accepted for symmetry with the other builders.)"""
    _require(mesh, "hexahedron")
    a = _cube_edges(mesh)
    E, nu = material_arrays(mesh, materials)
    k_e, k_d = _per_cell(partial(_parameters().baudet_cube, published=published), ("k_edge", "k_diagonal"), E, nu, a)
    edges = assemble_springs(mesh, "edges", lambda c, _p: k_e[c])
    inner = assemble_springs(mesh, "inner_diagonals", lambda c, _p: k_d[c])
    return [_merge_springs([edges, inner])]


def baudet_correction(mesh, materials, loads, published: bool = False) -> BaudetCorrection:
    """:class:`msslib.terms.BaudetCorrection` for a mesh of cubes with the per-cube factor
    ``parameters.baudet_cube(E, nu, a).correction_factor``; ``loads`` (n, 3) nodal surface forces
    at unit load, or a list of terms whose external forces are summed (leave gravity out).
    ``published=True`` uses the printed factor -(4 nu - 1)/16 (see the errata)."""
    _require(mesh, "hexahedron")
    a = _cube_edges(mesh)
    E, nu = material_arrays(mesh, materials)
    (c,) = _per_cell(partial(_parameters().baudet_cube, published=published), ("correction_factor",), E, nu, a)
    if not isinstance(loads, np.ndarray):
        try:
            loads = np.asarray(loads, dtype=float)
        except (TypeError, ValueError):
            loads = sum_external_forces(loads, mesh.n_nodes, 3)
    return BaudetCorrection(mesh, loads, c)

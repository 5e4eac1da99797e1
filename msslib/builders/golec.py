"""Golec et al.'s cube model: springs on the edges, face diagonals and inner diagonals of every
cube, and a volume correction per cube."""

from __future__ import annotations

from functools import partial

import numpy as np

from msslib.generated import kernels as _K
from msslib.terms import HexVolume, Term

from .common import (
    _cube_edges,
    _merge_springs,
    _parameters,
    _per_cell,
    _require,
    assemble_springs,
    material_arrays,
)


def _hex_rest_volumes(mesh):
    p = mesh.points[mesh.cells]  # (m, 8, 3)
    return np.asarray(_K.hex_averaged_volume(*[p[:, a, d] for a in range(8) for d in range(3)]), dtype=float)


def golec_cube_springs(mesh, materials, A, published: bool = False) -> list[Term]:
    """Golec et al.'s cube model: per cube ``parameters.golec_cube(E, nu, a, A)`` gives ``k_edge``
    (12 edges), ``k_face`` (12 face diagonals) and ``k_inner`` (4 inner diagonals), each summed over
    the cubes sharing the pair, and ``kappa`` for a :class:`HexVolume` term per cube with ``V0``
    the averaged-edge volume at rest.  ``A`` (a scalar or one value per cell) is passed through to
    ``golec_cube``. ``published=True`` uses the printed constants, per element (see the errata);
    the volume term keeps the dimensionally consistent energy kappa/(2 V0) (V - V0)^2."""
    _require(mesh, "hexahedron")
    a = _cube_edges(mesh)
    E, nu = material_arrays(mesh, materials)
    k_e, k_f, k_i, kappa = _per_cell(partial(_parameters().golec_cube, published=published), ("k_edge", "k_face", "k_inner", "kappa"),
                                     E, nu, a, A)
    springs = _merge_springs([
        assemble_springs(mesh, "edges", lambda c, _p: k_e[c]),
        assemble_springs(mesh, "face_diagonals", lambda c, _p: k_f[c]),
        assemble_springs(mesh, "inner_diagonals", lambda c, _p: k_i[c]),
    ])
    return [springs, HexVolume(mesh.cells, kappa, _hex_rest_volumes(mesh))]

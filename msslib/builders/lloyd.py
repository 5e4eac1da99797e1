"""Lloyd et al.'s models: springs on triangles (and Van Gelder's triangle springs, which Lloyd et
al. compare with), on squares, and on tetrahedra with an optional volume term."""

from __future__ import annotations

from functools import partial

import numpy as np

from msslib.generated import kernels as _K
from msslib.terms import Term, TetVolume

from .common import (
    _merge_springs,
    _pair_lengths,
    _parameters,
    _per_cell,
    _require,
    assemble_springs,
    material_arrays,
)


def lloyd_triangle_springs(mesh, materials, t: float) -> list[Term]:
    """Lloyd et al.'s springs on the edges of a triangle mesh (plane stress, thickness ``t`` m):
    per triangle ``parameters.lloyd_triangle(E, t).k`` on each of its edges, summed over the
    triangles sharing an edge; rest lengths are the mesh distances."""
    _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    _parameters().check_material(E, nu, "lloyd_triangle")
    (k,) = _per_cell(_parameters().lloyd_triangle, ("k",), E, t)
    return [assemble_springs(mesh, "edges", lambda cells, _p: k[cells])]


def van_gelder_springs(mesh, materials, t: float) -> list[Term]:
    """Van Gelder's springs: per triangle ``parameters.van_gelder_triangle(E, t, A_e, l).k`` on each
    edge of length ``l`` (``A_e`` the triangle's area), summed over the adjacent triangles."""
    area = _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    _parameters().check_material(E, nu, "van_gelder_triangle")
    fn = _parameters().van_gelder_triangle

    def k_fn(cells, node_pairs):
        (k,) = _per_cell(fn, ("k",), E[cells], t, area[cells], _pair_lengths(mesh, node_pairs))
        return k

    return [assemble_springs(mesh, "edges", k_fn)]


def lloyd_square_springs(mesh, materials, t: float) -> list[Term]:
    """Lloyd et al.'s springs on a mesh of squares (quads): per element ``k_edge`` on its four
    edges and ``k_diagonal`` on both diagonals (``parameters.lloyd_square(E, t)``), summed over
    the elements sharing them; rest lengths are ``rest_factor_edge`` and ``rest_factor_diagonal``
    times the mesh distances (prestrained springs)."""
    _require(mesh, "quad")
    E, nu = material_arrays(mesh, materials)
    _parameters().check_material(E, nu, "lloyd_square")
    k_e, k_d, f_e, f_d = _per_cell(_parameters().lloyd_square,
                                   ("k_edge", "k_diagonal", "rest_factor_edge", "rest_factor_diagonal"), E, t)
    edges = assemble_springs(mesh, "edges", lambda c, p: (k_e[c], f_e[c] * _pair_lengths(mesh, p)))
    diags = assemble_springs(mesh, "face_diagonals", lambda c, p: (k_d[c], f_d[c] * _pair_lengths(mesh, p)))
    return [_merge_springs([edges, diags])]


def _tet_rest_volumes(mesh):
    p = mesh.points[mesh.cells]  # (m, 4, 3)
    return np.asarray(_K.tet_signed_volume(*[p[:, a, d] for a in range(4) for d in range(3)]), dtype=float)


def lloyd_tet_springs(mesh, materials, volume: bool = False, published: bool = False) -> list[Term]:
    """Lloyd et al.'s springs on the edges of a tetrahedral mesh.

    Each tetrahedron of volume ``V`` is treated as a regular one of the same volume, edge
    ``l_hat = (6 sqrt(2) V)^(1/3)``; its constant ``parameters.lloyd_tetrahedron(E, l_hat).k`` is
    added to each of its edges.  With ``volume=True`` the constants come from
    ``parameters.lloyd_tetrahedron_volume(E, l_hat, nu)`` (``k``, ``k_volume``) and a
    :class:`TetVolume` term with ``k_v = k_volume`` and ``V0 = V`` is added; ``published=True`` uses
    eq. 14 as printed (its values at nu = 1/4) instead of the optimum for each nu.
    """
    V = _require(mesh, "tetra")
    E, nu = material_arrays(mesh, materials)
    _parameters().check_material(E, nu, None if volume else "lloyd_tetrahedron")
    l_hat = np.cbrt(6.0 * np.sqrt(2.0) * V)
    P = _parameters()
    if volume:
        k, k_vol = _per_cell(partial(P.lloyd_tetrahedron_volume, published=published), ("k", "k_volume"), E, l_hat, nu)
    else:
        (k,) = _per_cell(P.lloyd_tetrahedron, ("k",), E, l_hat)
    terms: list[Term] = [assemble_springs(mesh, "edges", lambda c, _p: k[c])]
    if volume:
        terms.append(TetVolume(mesh.cells, k_vol, _tet_rest_volumes(mesh)))
    return terms

"""Lloyd et al. (2007) and the models derived beside them: triangles (eq. 8, van Gelder's eq. 9),
squares with prestrain (eqs. 10-11), rectangles of any aspect ratio (the square's derivation
extended), tetrahedra (eqs. 12-13, with the volume term eq. 14).

Parameter functions take SI inputs (E in Pa, lengths and thickness in m) and return frozen
dataclasses of per-element values: a spring shared by several elements gets the sum of their
values.  The formulas come from :mod:`msslib.generated` (``python -m derivations.codegen``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

from msslib.generated import kernels as _K
from msslib.generated import rectangle as _rect
from msslib.generated import square as _square
from msslib.generated import tetrahedron as _tet
from msslib.generated import triangle as _tri
from msslib.models.checks import (
    evaluate,
    flag,
    offending,
    poisson,
    positive,
    same_shape,
    warn_nu,
)
from msslib.models.common import (
    _merge_springs,
    _pair_lengths,
    _per_cell,
    _require,
    assemble_springs,
    check_material,
    material_arrays,
)
from msslib.models.spec import Exactness, ModelSpec, Option, choice, split_terms
from msslib.terms import Term, TetVolume

__all__ = [
    "TriangleSprings", "SquareSprings", "RectangleSprings", "TetrahedronSprings", "TetrahedronVolumeSprings",
    "lloyd_triangle", "van_gelder_triangle", "lloyd_square", "lloyd_rectangle", "equivalent_edge_length",
    "lloyd_tetrahedron", "lloyd_tetrahedron_volume",
]  # the parameters (gathered by msslib.parameters); the builders are found through SPECS

#: place in the registry's order
RANK = 1

#: parameter function -> the Poisson's ratio at which it is exact (or optimal)
VALID_NU = {"lloyd_triangle": 1 / 3, "van_gelder_triangle": 1 / 3, "lloyd_square": 1 / 3, "lloyd_rectangle": 1 / 3,
            "lloyd_tetrahedron": 1 / 4}

REFERENCE = ("B. A. Lloyd, G. Szekely, M. Harders, Identification of Spring Parameters for Deformable Object "
             "Simulation, IEEE TVCG 13(5), 2007")
# no DOI: none is printed in the available text, and an identifier is not written from memory
DOI = None


# --------------------------------------------------------------------------------------------
# parameters
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TriangleSprings:
    k: float  # N/m, per element


@dataclass(frozen=True)
class SquareSprings:
    k_edge: float
    k_diagonal: float
    rest_factor_edge: float
    rest_factor_diagonal: float


@dataclass(frozen=True)
class RectangleSprings:
    k_h: float  # N/m: the 2 edges along the first side (nodes 0-1, 3-2), length a
    k_v: float  # N/m: the 2 edges along the second side (nodes 1-2, 0-3), length b = r a
    k_d: float  # N/m: the 2 diagonals
    c_h: float  # rest length = c x rest distance
    c_v: float
    c_d: float


@dataclass(frozen=True)
class TetrahedronSprings:
    k: float


@dataclass(frozen=True)
class TetrahedronVolumeSprings:
    k: float  # N/m
    k_volume: float  # J: coefficient of k_V/(2 V0^2) (V - V0)^2


def _nu_optional(nu):
    if nu is not None:
        poisson(nu)


def _plate(function, formula, cls, E, t, nu, **sizes):
    """The parameters ``cls`` of the plate element ``function`` from ``formula(E, t, *sizes)``:
    ``E``, the thickness ``t`` and the ``sizes`` must be positive; ``nu`` (optional) is only checked
    and warned about where it differs from the one at which the element is exact
    (``VALID_NU[function]``)."""
    positive("E", E), positive("thickness t", t)
    for name, value in sizes.items():
        positive(name, value)
    _nu_optional(nu)
    same_shape(function, E=E, t=t, **sizes, nu=nu)
    warn_nu(nu, VALID_NU[function], function)
    return evaluate(function, formula, cls, E=E, t=t, **sizes)


def lloyd_triangle(E, *, t, nu=None) -> TriangleSprings:
    """Lloyd et al. eq. 8: k = sqrt(3)/4 E t per equilateral triangle (exact for nu = 1/3)."""
    return _plate("lloyd_triangle", _tri.lloyd_triangle, TriangleSprings, E, t, nu)


def van_gelder_triangle(E, *, t, area, length, nu=None) -> TriangleSprings:
    """Van Gelder: k = E t A_e / l^2 per triangle of area A_e, for its edge of length l (Lloyd eq. 9)."""
    return _plate("van_gelder_triangle", _tri.van_gelder_triangle, TriangleSprings, E, t, nu, area=area,
                  length=length)


def lloyd_square(E, *, t, nu=None) -> SquareSprings:
    """Lloyd et al. eqs. 10-11: prestrained square (exact for nu = 1/3)."""
    return _plate("lloyd_square", _square.lloyd_square, SquareSprings, E, t, nu)


RECTANGLE_FITS = ("equilibrium", "least_squares")


def lloyd_rectangle(E, *, t, r, nu=None, fit="equilibrium") -> RectangleSprings:
    """Six prestrained springs of an a x b rectangle, aspect ratio ``r = b / a`` (the square of
    Lloyd et al. Sec. 4.1 extended; ``derivations/elements/rectangle.py``).

    No set of springs matches the bilinear element unless r = 1 and nu = 1/3 (there it is eqs.
    10-11); otherwise the constants minimise the Frobenius distance of the stiffness matrices.
    ``fit="equilibrium"`` (default): the optimum among elements in equilibrium at rest, nu = 1/3,
    positive for every r.  ``fit="least_squares"``: the free optimum for ``nu`` (default 1/3),
    closer to the FEM matrix but not in equilibrium at rest for r != 1 (a mesh of them deforms
    without load) and with positive constants only in an interval around r = 1 (0.4920 < r <
    2.0324 at nu = 1/3); a non-positive constant is a ValueError naming r."""
    positive("E", E), positive("thickness t", t), positive("aspect ratio r", r)
    _nu_optional(nu)
    if fit not in RECTANGLE_FITS:
        raise ValueError(f"lloyd_rectangle: fit must be one of {', '.join(RECTANGLE_FITS)}, got {fit!r}")
    same_shape("lloyd_rectangle", E=E, t=t, r=r, nu=nu)
    if fit == "equilibrium":
        warn_nu(nu, 1 / 3, "lloyd_rectangle")
        return evaluate("lloyd_rectangle", _rect.rectangle_least_squares_equilibrium, RectangleSprings, E=E, t=t, r=r)
    if nu is None:
        out = evaluate("lloyd_rectangle", _rect.rectangle_least_squares, RectangleSprings, E=E, t=t, r=r)
    else:
        out = evaluate("lloyd_rectangle", _rect.rectangle_least_squares_nu, RectangleSprings, E=E, nu=nu, t=t, r=r)
    for name in ("k_h", "k_v", "k_d", "c_h", "c_v", "c_d"):
        bad = np.asarray(getattr(out, name), dtype=float) <= 0
        if np.any(bad):
            where = f"r = {r!r}" if np.ndim(r) == 0 else f"r = {offending(r, np.broadcast_to(bad, np.shape(r)))}"
            raise ValueError(f"lloyd_rectangle (fit least_squares): {name} <= 0 at {where}; the free least-squares "
                             f"fit has positive constants only near r = 1 (0.4920 < r < 2.0324 at nu = 1/3); "
                             f"fit: equilibrium is positive for every r")
    return out


def equivalent_edge_length(volume):
    """Lloyd et al. eq. 13: edge of the regular tetrahedron of the given volume [m]."""
    positive("volume", volume)
    return _tet.equivalent_edge_length(volume)


def lloyd_tetrahedron(E, *, l, nu=None) -> TetrahedronSprings:
    """Lloyd et al. eq. 12: least-squares k = 2 sqrt(2)/25 E l (nu = 1/4); with ``nu`` given, the
    least-squares optimum for that nu (derived; eq. 12 is its value at 1/4)."""
    positive("E", E), positive("edge length l", l)
    if nu is None:
        same_shape("lloyd_tetrahedron", E=E, l=l)
        return evaluate("lloyd_tetrahedron", _tet.lloyd_tetrahedron, TetrahedronSprings, E=E, l=l)
    poisson(nu)
    same_shape("lloyd_tetrahedron", E=E, l=l, nu=nu)
    return evaluate("lloyd_tetrahedron", _tet.lloyd_tetrahedron_general_nu, TetrahedronSprings, E=E, nu=nu, l=l)


def lloyd_tetrahedron_volume(E, *, l, nu=0.25, published=False) -> TetrahedronVolumeSprings:
    """Lloyd et al. eq. 14 with the volume energy: the least-squares optimum for ``nu`` (derived);
    ``published=True`` gives eq. 14 as printed (its value at nu = 1/4, whatever ``nu``)."""
    positive("E", E), positive("edge length l", l), poisson(nu)
    same_shape("lloyd_tetrahedron_volume", E=E, l=l, nu=nu)
    if flag("published", published):
        return evaluate("lloyd_tetrahedron_volume", _tet.lloyd_tetrahedron_volume_published, TetrahedronVolumeSprings,
                        E=E, l=l)
    return evaluate("lloyd_tetrahedron_volume", _tet.lloyd_tetrahedron_volume, TetrahedronVolumeSprings,
                    E=E, nu=nu, l=l)


# --------------------------------------------------------------------------------------------
# the rectangle's builder (the other builders are those of msslib.system)
# --------------------------------------------------------------------------------------------


def rectangle_sides(mesh, rtol=1e-6):
    """``(a, b)`` per quad: the lengths of its sides 0-1 and 1-2; ValueError unless every quad is
    a rectangle (opposite sides equal and parallel, a right angle, within ``rtol``)."""
    x = mesh.points[mesh.cells]
    e01, e12, e32, e03 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 1], x[:, 2] - x[:, 3], x[:, 3] - x[:, 0]
    a, b = np.linalg.norm(e01, axis=1), np.linalg.norm(e12, axis=1)
    size = np.maximum(a, b)
    bad = np.flatnonzero((np.linalg.norm(e32 - e01, axis=1) > rtol * size)
                         | (np.linalg.norm(e03 - e12, axis=1) > rtol * size)
                         | (np.abs(np.einsum("ij,ij->i", e01, e12)) > rtol * size**2))
    if len(bad):
        shown = ", ".join(f"cell {i} (nodes {mesh.cells[i].tolist()})" for i in bad[:5])
        raise ValueError(f"{len(bad)} quads are not rectangles (rtol {rtol}): {shown}")
    return a, b


# local node pairs of a quad by spring family (VTK order 0-1-2-3 around the quad)
_FAMILY_OF_PAIR = {(0, 1): 0, (2, 3): 0, (1, 2): 1, (0, 3): 1, (0, 2): 2, (1, 3): 2}


def _family(mesh, cells, node_pairs):
    """Spring family (0 h, 1 v, 2 d) of each (cell, node pair) incidence, from the local positions."""
    local = mesh.cells[cells]
    i = np.argmax(local == node_pairs[:, :1], axis=1)
    j = np.argmax(local == node_pairs[:, 1:], axis=1)
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    table = np.full((4, 4), -1)
    for (p, q), f in _FAMILY_OF_PAIR.items():
        table[p, q] = f
    fam = table[lo, hi]
    assert (fam >= 0).all()
    return fam


def lloyd_rectangle_springs(mesh, materials, t: float, fit: str = "equilibrium") -> list:
    """Springs of :func:`lloyd_rectangle` on a mesh of rectangles (quads of any aspect ratio, each
    with its own ``r = b / a``): per quad ``k_h``/``k_v`` on its sides 0-1, 3-2 / 1-2, 0-3 and
    ``k_d`` on both diagonals, rest lengths ``c`` times the mesh distances; constants summed and
    rest lengths k-weighted over the quads sharing a pair (as for the square)."""
    from msslib import mesh as _mesh
    from msslib.terms import Springs

    if mesh.cell_type != "quad":
        raise ValueError(f"this model needs quad cells, got {mesh.cell_type}")
    _mesh.check_cells(mesh)
    a, b = rectangle_sides(mesh)
    E, nu = material_arrays(mesh, materials)
    p = lloyd_rectangle(E, t=t, r=b / a, nu=None if fit == "equilibrium" else nu, fit=fit)
    k = np.stack([np.broadcast_to(np.asarray(getattr(p, f"k_{s}"), dtype=float), a.shape) for s in "hvd"])
    c = np.stack([np.broadcast_to(np.asarray(getattr(p, f"c_{s}"), dtype=float), a.shape) for s in "hvd"])

    def per_incidence(cells, node_pairs):
        fam = _family(mesh, cells, node_pairs)
        dist = np.linalg.norm(mesh.points[node_pairs[:, 1]] - mesh.points[node_pairs[:, 0]], axis=1)
        return k[fam, cells], c[fam, cells] * dist

    parts = [assemble_springs(mesh, kind, per_incidence) for kind in ("edges", "face_diagonals")]
    return [Springs(np.concatenate([s.pairs for s in parts]), np.concatenate([s.k for s in parts]),
                    np.concatenate([s.rest_length for s in parts]), mesh.dim)]


# --------------------------------------------------------------------------------------------
# builders: a mesh and its materials turned into terms
# --------------------------------------------------------------------------------------------


def lloyd_triangle_springs(mesh, materials, t: float) -> list[Term]:
    """Lloyd et al.'s springs on the edges of a triangle mesh (plane stress, thickness ``t`` m):
    per triangle ``parameters.lloyd_triangle(E, t=t).k`` on each of its edges, summed over the
    triangles sharing an edge; rest lengths are the mesh distances."""
    _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    check_material(E, nu, "lloyd_triangle", VALID_NU)
    (k,) = _per_cell(lloyd_triangle, ("k",), E, t=t)
    return [assemble_springs(mesh, "edges", lambda cells, _p: k[cells])]


def van_gelder_springs(mesh, materials, t: float) -> list[Term]:
    """Van Gelder's springs: per triangle ``parameters.van_gelder_triangle(E, t=t, area=A_e, length=l).k`` on each
    edge of length ``l`` (``A_e`` the triangle's area), summed over the adjacent triangles."""
    area = _require(mesh, "triangle")
    E, nu = material_arrays(mesh, materials)
    check_material(E, nu, "van_gelder_triangle", VALID_NU)
    fn = van_gelder_triangle

    def k_fn(cells, node_pairs):
        (k,) = _per_cell(fn, ("k",), E[cells], t=t, area=area[cells], length=_pair_lengths(mesh, node_pairs))
        return k

    return [assemble_springs(mesh, "edges", k_fn)]


def lloyd_square_springs(mesh, materials, t: float) -> list[Term]:
    """Lloyd et al.'s springs on a mesh of squares (quads): per element ``k_edge`` on its four
    edges and ``k_diagonal`` on both diagonals (``parameters.lloyd_square(E, t=t)``), summed over
    the elements sharing them; rest lengths are ``rest_factor_edge`` and ``rest_factor_diagonal``
    times the mesh distances (prestrained springs)."""
    _require(mesh, "quad")
    E, nu = material_arrays(mesh, materials)
    check_material(E, nu, "lloyd_square", VALID_NU)
    k_e, k_d, f_e, f_d = _per_cell(lloyd_square,
                                   ("k_edge", "k_diagonal", "rest_factor_edge", "rest_factor_diagonal"), E, t=t)
    edges = assemble_springs(mesh, "edges", lambda c, p: (k_e[c], f_e[c] * _pair_lengths(mesh, p)))
    diags = assemble_springs(mesh, "face_diagonals", lambda c, p: (k_d[c], f_d[c] * _pair_lengths(mesh, p)))
    return [_merge_springs([edges, diags])]


def _tet_rest_volumes(mesh):
    p = mesh.points[mesh.cells]  # (m, 4, 3)
    return np.asarray(_K.tet_signed_volume(*[p[:, a, d] for a in range(4) for d in range(3)]), dtype=float)


def lloyd_tet_springs(mesh, materials, volume: bool = False, published: bool = False) -> list[Term]:
    """Lloyd et al.'s springs on the edges of a tetrahedral mesh.

    Each tetrahedron of volume ``V`` is treated as a regular one of the same volume, edge
    ``l_hat = (6 sqrt(2) V)^(1/3)``; its constant ``parameters.lloyd_tetrahedron(E, l=l_hat).k`` is
    added to each of its edges.  With ``volume=True`` the constants come from
    ``parameters.lloyd_tetrahedron_volume(E, l=l_hat, nu=nu)`` (``k``, ``k_volume``) and a
    :class:`TetVolume` term with ``k_v = k_volume`` and ``V0 = V`` is added; ``published=True`` uses
    eq. 14 as printed (its values at nu = 1/4) instead of the optimum for each nu.
    """
    V = _require(mesh, "tetra")
    E, nu = material_arrays(mesh, materials)
    check_material(E, nu, None if volume else "lloyd_tetrahedron", VALID_NU)
    l_hat = np.cbrt(6.0 * np.sqrt(2.0) * V)
    if volume:
        k, k_vol = _per_cell(partial(lloyd_tetrahedron_volume, published=published), ("k", "k_volume"), E, l=l_hat, nu=nu)
    else:
        (k,) = _per_cell(lloyd_tetrahedron, ("k",), E, l=l_hat)
    terms: list[Term] = [assemble_springs(mesh, "edges", lambda c, _p: k[c])]
    if volume:
        terms.append(TetVolume(mesh.cells, k_vol, _tet_rest_volumes(mesh)))
    return terms


# --------------------------------------------------------------------------------------------
# specs
# --------------------------------------------------------------------------------------------


def _build_triangle(ctx):
    return split_terms(lloyd_triangle_springs(ctx.mesh, ctx.materials, ctx.thickness), ctx.options["terms"])


def _build_van_gelder(ctx):
    return split_terms(van_gelder_springs(ctx.mesh, ctx.materials, ctx.thickness), ctx.options["terms"])


def _build_square(ctx):
    return split_terms(lloyd_square_springs(ctx.mesh, ctx.materials, ctx.thickness), ctx.options["terms"])


def _build_rectangle(ctx):
    terms = lloyd_rectangle_springs(ctx.mesh, ctx.materials, ctx.thickness, fit=ctx.options["fit"])
    return split_terms(terms, ctx.options["terms"])


def _build_tet(ctx, volume):
    terms = lloyd_tet_springs(ctx.mesh, ctx.materials, volume=volume, published=ctx.options["published"])
    return split_terms(terms, ctx.options["terms"])


_EQUILATERAL = Exactness("element", "equilateral", nu=1 / 3,
                         source="the equilateral triangle's springs reproduce its linear element at nu = 1/3 "
                                "(derivations/elements/triangle.py)")
_SQUARE = Exactness("element", "square", nu=1 / 3,
                    source="the prestrained square reproduces the bilinear element at nu = 1/3 "
                           "(derivations/elements/square.py; the rectangle's Groebner basis: only r = 1)")

SPECS = (
    ModelSpec("lloyd_triangle", "lloyd", "mss", ("triangle",), 2, "Lloyd's triangle springs (eq. 8)",
              REFERENCE + ", eq. 8", doi=DOI, element="triangle", terms=("springs",), parameters=lloyd_triangle,
              build=_build_triangle, exact=(_EQUILATERAL,)),
    ModelSpec("van_gelder", "lloyd", "mss", ("triangle",), 2, "van Gelder's triangle springs (Lloyd eq. 9)",
              REFERENCE + ", eq. 9 (A. van Gelder, J. Graphics Tools 3(2), 1998)", doi=DOI, element="triangle",
              terms=("springs",), parameters=van_gelder_triangle, build=_build_van_gelder, exact=(_EQUILATERAL,)),
    ModelSpec("lloyd_square", "lloyd", "mss", ("quad",), 2, "Lloyd's prestrained square (eqs. 10-11)",
              REFERENCE + ", eqs. 10-11", doi=DOI, element="square", terms=("springs",), parameters=lloyd_square,
              build=_build_square, exact=(_SQUARE,)),
    ModelSpec("lloyd_rectangle", "lloyd", "mss", ("quad",), 2,
              "prestrained rectangle of any aspect ratio (Lloyd's square extended, least squares)",
              REFERENCE + ", Sec. 4.1 extended to rectangles", doi=DOI, element="rectangle", terms=("springs",),
              options=(Option("fit", choice(*RECTANGLE_FITS, what="rectangle fit"), "equilibrium",
                              "equilibrium: least squares among elements in equilibrium at rest (any r); "
                              "least_squares: the free optimum for the material's nu (0.49 < r < 2.03 at nu = 1/3)"),),
              parameters=lloyd_rectangle, build=_build_rectangle,
              exact=(Exactness("element", "square", nu=1 / 3, options={"fit": "equilibrium"}, source=_SQUARE.source),
                     Exactness("element", "square", nu=1 / 3, options={"fit": "least_squares"}, source=_SQUARE.source)),
              equilibrium_at_rest=lambda options: options.get("fit") != "least_squares"),
    ModelSpec("lloyd_tetrahedron", "lloyd", "mss", ("tetra",), 3, "Lloyd's tetrahedron springs (eqs. 12-13)",
              REFERENCE + ", eqs. 12-13", doi=DOI, element="tetrahedron", terms=("springs",),
              parameters=lloyd_tetrahedron, build=partial(_build_tet, volume=False)),
    ModelSpec("lloyd_tetrahedron_volume", "lloyd", "mss", ("tetra",), 3,
              "Lloyd's tetrahedron springs with the volume term (eq. 14)", REFERENCE + ", eq. 14", doi=DOI,
              element="tetrahedron", terms=("springs", "volume"), parameters=lloyd_tetrahedron_volume,
              build=partial(_build_tet, volume=True), published_variant=True),
)

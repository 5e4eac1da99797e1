"""Baudet et al. (2007): the cube with edge and inner-diagonal springs (configuration M2, eqs. 7-8)
and its correction force for the Poisson effect, in two readings (:mod:`msslib.terms.baudet`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from msslib.terms.baudet import READINGS, ElementBaudetCorrection
from msslib.generated import cube_baudet as _baudet
from msslib.models.checks import evaluate, flag, poisson, positive, same_shape
from msslib.models.common import cube_constants, cube_springs
from msslib.models.spec import Exactness, ModelSpec, Option, choice, split_terms
from msslib.terms import BaudetCorrection, Term, sum_external_forces

__all__ = ["BaudetCube", "baudet_cube"]  # the parameters (gathered by msslib.parameters)

#: place in the registry's order
RANK = 2

VALID_NU: dict = {}

#: readings of the correction force (scene option ``correction``)
CORRECTION_READINGS = READINGS


@dataclass(frozen=True)
class BaudetCube:
    k_edge: float
    k_diagonal: float
    correction_factor: float  # F_perp = factor x F_i, resultants per face


def baudet_cube(E, *, nu, a, published=False) -> BaudetCube:
    """Baudet et al. eqs. 7-8 for a cube of edge a; the correction factor is for resultants per face
    (derived: -(4 nu - 1)/2); ``published=True`` gives the printed -(4 nu - 1)/16."""
    positive("E", E), poisson(nu), positive("cube edge a", a)
    same_shape("baudet_cube", E=E, nu=nu, a=a)
    f = _baudet.baudet_cube_published if flag("published", published) else _baudet.baudet_cube
    return evaluate("baudet_cube", f, BaudetCube, E=E, nu=nu, a=a)



# --------------------------------------------------------------------------------------------
# builders: a mesh and its materials turned into terms
# --------------------------------------------------------------------------------------------


def baudet_cube_springs(mesh, materials, published: bool = False) -> list[Term]:
    """Baudet et al.'s springs on a mesh of cubes: per cube ``k_edge`` on its 12 edges (summed over
    the cubes sharing an edge) and ``k_diagonal`` on its 4 inner diagonals
    (``parameters.baudet_cube(E, nu=nu, a=a)``, ``a`` the cube's edge).  Add :func:`baudet_correction`
    for the Poisson effect under load. (The printed and derived spring constants agree;
    ``published`` is accepted for symmetry with the other builders.)"""
    k_e, k_d = cube_constants(mesh, materials, baudet_cube, ("k_edge", "k_diagonal"), published=published)
    return [cube_springs(mesh, [("edges", k_e), ("inner_diagonals", k_d)])]


def baudet_correction(mesh, materials, loads, published: bool = False) -> BaudetCorrection:
    """:class:`msslib.terms.BaudetCorrection` for a mesh of cubes with the per-cube factor
    ``parameters.baudet_cube(E, nu=nu, a=a).correction_factor``; ``loads`` (n, 3) nodal surface forces
    at unit load, or a list of terms whose external forces are summed (leave gravity out).
    ``published=True`` uses the printed factor -(4 nu - 1)/16 (see the errata)."""
    (c,) = cube_constants(mesh, materials, baudet_cube, ("correction_factor",), published=published)
    if not isinstance(loads, np.ndarray):
        try:
            loads = np.asarray(loads, dtype=float)
        except (TypeError, ValueError):
            loads = sum_external_forces(loads, mesh.n_nodes, 3)
    return BaudetCorrection(mesh, loads, c)


def element_correction(mesh, materials, published: bool = False) -> ElementBaudetCorrection:
    """:class:`ElementBaudetCorrection` for a mesh of cubes with each cube's ``k_edge``,
    ``k_diagonal`` and ``correction_factor`` from ``parameters.baudet_cube(E, nu=nu, a=a)``
    (``published=True``: the printed factor -(4 nu - 1)/16)."""
    k_e, k_d, c = cube_constants(mesh, materials, baudet_cube, ("k_edge", "k_diagonal", "correction_factor"),
                                 published=published)
    return ElementBaudetCorrection(mesh, k_e, k_d, c)


def correction_term(reading, mesh, materials, loads, published: bool = False) -> Term:
    """The correction term of ``reading`` (``boundary``: from the nodal surface ``loads``;
    ``element``: from the forces on each cube, ``loads`` unused)."""
    if reading == "element":
        return element_correction(mesh, materials, published=published)
    if reading == "boundary":
        return baudet_correction(mesh, materials, loads, published=published)
    raise ValueError(f"unknown Baudet correction reading {reading!r}; expected one of {', '.join(CORRECTION_READINGS)}")


def _build(ctx):
    opts, wanted = ctx.options, ctx.options["terms"]
    out = split_terms(baudet_cube_springs(ctx.mesh, ctx.materials, published=opts["published"]), wanted) \
        if "springs" in wanted else {}
    if "correction" in wanted:
        out["correction"] = [correction_term(opts["correction"], ctx.mesh, ctx.materials, ctx.surface_forces,
                                             published=opts["published"])]
    return out


SPECS = (
    ModelSpec("baudet_cube", "baudet", "mss", ("hexahedron",), 3,
              "Baudet's cube with inner diagonals and the correction force (eqs. 7-8)",
              "V. Baudet, M. Beuve, F. Jaillet, B. Shariat, F. Zara, Integrating Tensile Parameters in 3D "
              "Mass-Spring System, 2007, eqs. 7-8", hal="hal-01493738", element="cube_baudet",
              terms=("springs", "correction"), nonconservative=("correction",),
              options=(Option("correction", choice(*CORRECTION_READINGS, what="Baudet correction reading"), "boundary",
                              "boundary: from the surface loads; element: each cube's correction from the forces "
                              "acting on it from outside (msslib.terms.baudet)"),),
              parameters=baudet_cube, build=_build, published_variant=True,
              exact=(Exactness("lattice", "cube", nu=0.25, options={"terms": ("springs",)},
                               source="without the correction the lattice is isotropic only at nu = 1/4, "
                                      "nu_lattice = 1/(4 nu + 3) (derivations/elements/cube_baudet.py)"),)),
)

"""Baudet et al. (2007): the cube with edge and inner-diagonal springs (configuration M2, eqs. 7-8)
and its correction force for the Poisson effect, in two readings (:mod:`msslib.baudet_correction`).
"""

from __future__ import annotations

from dataclasses import dataclass

from msslib.generated import cube_baudet as _baudet
from msslib.models.checks import evaluate, flag, poisson, positive, same_shape
from msslib.models.spec import Exactness, ModelSpec, Option, choice, split_terms

__all__ = ["BaudetCube", "baudet_cube"]

#: place in the registry's order
RANK = 2

VALID_NU: dict = {}

#: readings of the correction force (scene option ``correction``; msslib.baudet_correction.READINGS)
CORRECTION_READINGS = ("boundary", "element")


@dataclass(frozen=True)
class BaudetCube:
    k_edge: float
    k_diagonal: float
    correction_factor: float  # F_perp = factor x F_i, resultants per face


def baudet_cube(E, nu, a, *, published=False) -> BaudetCube:
    """Baudet et al. eqs. 7-8 for a cube of edge a; the correction factor is for resultants per face
    (derived: -(4 nu - 1)/2); ``published=True`` gives the printed -(4 nu - 1)/16."""
    positive("E", E), poisson(nu), positive("cube edge a", a)
    same_shape("baudet_cube", E=E, nu=nu, a=a)
    f = _baudet.baudet_cube_published if flag("published", published) else _baudet.baudet_cube
    return evaluate("baudet_cube", f, BaudetCube, E=E, nu=nu, a=a)


def _build(ctx):
    from msslib.model import baudet_cube_springs

    opts, wanted = ctx.options, ctx.options["terms"]
    out = split_terms(baudet_cube_springs(ctx.mesh, ctx.materials, published=opts["published"]), wanted) \
        if "springs" in wanted else {}
    if "correction" in wanted:
        from msslib.baudet_correction import correction_term

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
                              "acting on it from outside (msslib.baudet_correction)"),),
              parameters=baudet_cube, build=_build, published_variant=True,
              exact=(Exactness("lattice", "cube", nu=0.25, options={"terms": ("springs",)},
                               source="without the correction the lattice is isotropic only at nu = 1/4, "
                                      "nu_lattice = 1/(4 nu + 3) (derivations/elements/cube_baudet.py)"),)),
)

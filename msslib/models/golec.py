"""Golec et al. (2017): the hybrid cube with edge, face-diagonal and inner-diagonal springs (ratio
``A = k_inner / k_face``) and the volume correction ``kappa``."""

from __future__ import annotations

from dataclasses import dataclass

from msslib.generated import cube_golec as _golec
from msslib.models.checks import evaluate, flag, poisson, positive, same_shape
from msslib.models.spec import Exactness, ModelSpec, Option, positive_number, split_terms

__all__ = ["GolecCube", "golec_cube"]

#: place in the registry's order
RANK = 3

VALID_NU: dict = {}


@dataclass(frozen=True)
class GolecCube:
    k_edge: float
    k_face: float
    k_inner: float
    kappa: float  # Pa: coefficient of kappa/(2 V0) (V - V0)^2


def golec_cube(E, nu, a, A, *, published=False) -> GolecCube:
    """Golec et al.'s hybrid cube with ratio A = k_inner/k_face (derived per-element constants that
    make the lattice exactly isotropic with E and nu); ``published=True`` gives the printed values
    (k_edge and k_face there are interior totals, see the errata)."""
    positive("E", E), poisson(nu), positive("cube edge a", a), positive("ratio A", A)
    same_shape("golec_cube", E=E, nu=nu, a=a, A=A)
    f = _golec.golec_cube_published if flag("published", published) else _golec.golec_cube
    return evaluate("golec_cube", f, GolecCube, E=E, nu=nu, a=a, A=A)


def _build(ctx):
    from msslib.model import golec_cube_springs

    opts = ctx.options
    terms = golec_cube_springs(ctx.mesh, ctx.materials, A=opts["A"], published=opts["published"])
    return split_terms(terms, opts["terms"])


SPECS = (
    ModelSpec("golec_cube", "golec", "mss", ("hexahedron",), 3,
              "Golec's hybrid cube: edge, face and inner springs with a volume correction",
              "K. Golec, J.-F. Palierne, F. Zara, S. Nicolle, G. Damiand, Hybrid 3D Mass-Spring System to "
              "simulate isotropic materials, 2017", hal="hal-01504413", element="cube_golec",
              terms=("springs", "volume"),
              options=(Option("A", positive_number, 1.0, "the ratio k_inner / k_face"),),
              parameters=golec_cube, build=_build, published_variant=True,
              exact=(Exactness("lattice", "cube", nu=None, options={"published": False},
                               source="per-element constants that make the lattice of cubes isotropic with E and "
                                      "nu (derivations/elements/cube_golec.py)"),)),
)

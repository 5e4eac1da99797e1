"""Golec et al. (2017): the hybrid cube with edge, face-diagonal and inner-diagonal springs (ratio
``A = k_inner / k_face``) and the volume correction ``kappa``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from msslib.generated import cube_golec as _golec
from msslib.generated import kernels as _K
from msslib.models.checks import evaluate, flag, poisson, positive, same_shape
from msslib.models.common import cube_constants, cube_springs
from msslib.models.spec import (
    Exactness,
    ModelSpec,
    Option,
    positive_number,
    split_terms,
)
from msslib.terms import HexVolume, Term

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


def golec_cube(E, *, nu, a, A, published=False) -> GolecCube:
    """Golec et al.'s hybrid cube with ratio A = k_inner/k_face (derived per-element constants that
    make the lattice exactly isotropic with E and nu); ``published=True`` gives the printed values
    (k_edge and k_face there are interior totals, see the errata)."""
    positive("E", E), poisson(nu), positive("cube edge a", a), positive("ratio A", A)
    same_shape("golec_cube", E=E, nu=nu, a=a, A=A)
    f = _golec.golec_cube_published if flag("published", published) else _golec.golec_cube
    return evaluate("golec_cube", f, GolecCube, E=E, nu=nu, a=a, A=A)



# --------------------------------------------------------------------------------------------
# builders: a mesh and its materials turned into terms
# --------------------------------------------------------------------------------------------


def _hex_rest_volumes(mesh):
    p = mesh.points[mesh.cells]  # (m, 8, 3)
    return np.asarray(_K.hex_averaged_volume(*[p[:, a, d] for a in range(8) for d in range(3)]), dtype=float)


def golec_cube_springs(mesh, materials, A, published: bool = False) -> list[Term]:
    """Golec et al.'s cube model: per cube ``parameters.golec_cube(E, nu=nu, a=a, A=A)`` gives ``k_edge``
    (12 edges), ``k_face`` (12 face diagonals) and ``k_inner`` (4 inner diagonals), each summed over
    the cubes sharing the pair, and ``kappa`` for a :class:`HexVolume` term per cube with ``V0``
    the averaged-edge volume at rest.  ``A`` (a scalar or one value per cell) is passed through to
    ``golec_cube``. ``published=True`` uses the printed constants, per element (see the errata);
    the volume term keeps the dimensionally consistent energy kappa/(2 V0) (V - V0)^2."""
    k_e, k_f, k_i, kappa = cube_constants(mesh, materials, golec_cube, ("k_edge", "k_face", "k_inner", "kappa"),
                                          A=A, published=published)
    springs = cube_springs(mesh, [("edges", k_e), ("face_diagonals", k_f), ("inner_diagonals", k_i)])
    return [springs, HexVolume(mesh.cells, kappa, _hex_rest_volumes(mesh))]


def _build(ctx):
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

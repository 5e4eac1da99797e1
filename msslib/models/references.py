"""Finite-element references (scikit-fem, :mod:`msslib.fem`): linear elasticity, St Venant-Kirchhoff
and neo-Hookean, on every cell type.  They build no force terms: scenes solve them with
:func:`msslib.fem.solve_linear` / :func:`msslib.fem.solve_nonlinear` (material law ``law``)."""

from __future__ import annotations

import warnings

import numpy as np

from msslib.mesh import cells as _cells
from msslib.models.spec import ModelSpec, Option, choice

__all__: list = []  # no spring-constant formulas (msslib.parameters gathers the families' __all__)

#: place in the registry's order
RANK = 0

VALID_NU: dict = {}

#: every cell type of the registry (msslib.mesh.cells): each has a linear scikit-fem element
CELLS = _cells.names()

_PLANE = Option("plane", choice("stress", "strain", what="plane"), "stress",
                "2D meshes: plane stress (default) or plane strain")


def _spec(name, law, title):
    return ModelSpec(name, "fem", "fem", CELLS, 0, title, "finite elements (scikit-fem), msslib.fem",
                     options=(_PLANE,), law=law)


SPECS = (
    _spec("fem_linear", None, "linear elasticity (small strain)"),
    _spec("fem_svk", "svk", "St Venant-Kirchhoff"),
    _spec("fem_neohookean", "neohookean", "compressible neo-Hookean"),
)


#: at and above this Poisson's ratio a FEM solve warns that its linear elements lock
LOCKING_NU = 0.45


def warn_locking(mesh, nu_c, plane) -> None:
    """One :class:`msslib.errors.MsslibWarning` (called once per solve of :mod:`msslib.fem`) when a
    cell's nu ``nu_c`` is at least :data:`LOCKING_NU`: the displacement-only linear elements lock
    as nu -> 1/2 (volumetric locking; not in 2D plane stress, ``plane="stress"``, whose in-plane
    response stays compressible)."""
    from msslib.errors import MsslibWarning

    nu_max = float(np.max(nu_c)) if np.size(nu_c) else 0.0
    if nu_max < LOCKING_NU or (mesh.dim == 2 and plane == "stress"):
        return
    element = _cells.get(mesh.cell_type).linear.title
    warnings.warn(f"linear-element FEM locks near nu = 1/2 (nu = {nu_max:.6g}, {element}): "
                  f"its displacements are too small, by a factor that depends on the mesh (a clamped cube of "
                  f"3^3 hexahedra at nu = 0.4999 settles 3.7 times less than one of 6^3); use quadratic elements with "
                  f"the volumetric part reduced (msslib.fem: order=2, volumetric='reduced'), or nu < {LOCKING_NU} "
                  f"where the material allows, and check that refining the mesh no longer changes the result",
                  MsslibWarning, stacklevel=3)

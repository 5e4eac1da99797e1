"""Finite-element references (scikit-fem, :mod:`msslib.fem`): linear elasticity, St Venant-Kirchhoff
and neo-Hookean, on every cell type.  They build no force terms: scenes solve them with
:func:`msslib.fem.solve_linear` / :func:`msslib.fem.solve_nonlinear` (material law ``law``)."""

from __future__ import annotations

from msslib.models.spec import ModelSpec, Option, choice

__all__: list = []

#: place in the registry's order
RANK = 0

VALID_NU: dict = {}

CELLS = ("triangle", "quad", "tetra", "hexahedron")

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

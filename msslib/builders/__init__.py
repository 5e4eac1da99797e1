"""Model builders: a mesh and its materials turned into the terms of a mass-spring model, grouped
by model family.

The spring constants come from :mod:`msslib.parameters` (per element, then summed over the
elements sharing a node pair):

* :mod:`msslib.builders.common`: :func:`assemble_springs` (generic: per (pair, cell) constant,
  summed per pair), :func:`material_arrays`, and the helpers of the families below;
* :mod:`msslib.builders.lloyd`: :func:`lloyd_triangle_springs`, :func:`van_gelder_springs`
  (triangles, plane stress, thickness t), :func:`lloyd_square_springs` (quads; prestrained edges
  and diagonals), :func:`lloyd_tet_springs` (tetrahedra, optionally with Lloyd's volume term);
* :mod:`msslib.builders.baudet`: :func:`baudet_cube_springs`, :func:`baudet_correction` (cubes);
* :mod:`msslib.builders.golec`: :func:`golec_cube_springs` (cubes: springs plus the volume
  correction).

``materials`` is a list of ``(E, nu)`` pairs (Pa, -) indexed by ``mesh.material``.  Every builder
first runs :func:`msslib.mesh.check_cells` (ValueError on inverted or degenerate cells) and
returns a list of terms, to be combined with loads into a :class:`msslib.model.Model`.  Every
name is also importable from ``msslib.builders`` and ``msslib.model``.

The modules import one another in one direction: ``common`` <- ``lloyd``, ``baudet``, ``golec``;
they use :mod:`msslib.terms` and :mod:`msslib.mesh`, never :mod:`msslib.model`.
"""

from __future__ import annotations

from .baudet import baudet_correction, baudet_cube_springs
from .common import assemble_springs, material_arrays
from .golec import golec_cube_springs
from .lloyd import (
    lloyd_square_springs,
    lloyd_tet_springs,
    lloyd_triangle_springs,
    van_gelder_springs,
)

__all__ = [
    "material_arrays",
    "assemble_springs",
    "lloyd_triangle_springs",
    "van_gelder_springs",
    "lloyd_square_springs",
    "lloyd_tet_springs",
    "baudet_cube_springs",
    "baudet_correction",
    "golec_cube_springs",
]

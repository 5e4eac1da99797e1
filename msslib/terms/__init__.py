"""Force terms of a mass-spring system: springs, volume energies, external loads, corrections.

Every term works on the flat state ``x`` (node positions, ``n_nodes * dim`` long, interleaved by
node, see :mod:`msslib.solvers`) and shares one interface:

``energy(x) -> float or None``
    Potential energy of the term (J) at unit load; ``None`` for a non-conservative term.
``gradient(x) -> ndarray (n_dof,)``
    ``dW/dx`` (N): the force of the term is minus this.  For a non-conservative term it is simply
    minus its force (there is no ``W``).
``hessian_pattern() -> (rows, cols)``
    Dof indices of the term's Hessian entries, element by element (each element contributes a
    dense ``n_local x n_local`` row-major block).  The pattern depends only on the topology: it
    is computed once and cached.
``hessian_values(x) -> ndarray``
    Values of the entries of ``hessian_pattern()`` at ``x`` (N/m), filled by a numba loop.
``hessian_coo(x) -> (rows, cols, vals)``
    Convenience: the pattern and the values together (duplicates are to be summed).

Class attributes describe how a :class:`msslib.system.Model` combines the terms:
``conservative`` (False: the model's energy is ``None``), ``scales_with_load`` (True: external
terms whose contribution is multiplied by the load factor) and ``symmetric`` (Hessian symmetry).

Internal terms use the generated kernels of :mod:`msslib.generated.kernels` (energy, gradient and
Hessian of the exact energies the derivations linearise), compiled by numba on first use with
``cache=True``.  The first call of a kernel family compiles it (seconds; the hexahedron Hessian
about ten seconds); later processes load it from ``msslib/terms/__pycache__``, which is dropped
when the generated kernels change (:mod:`msslib.terms.jit`).

Terms with no elements never call numba (cheap when absent).

Contents of this package, one concern per module; every name below is importable from
``msslib.terms``:

* :mod:`msslib.terms.jit`: the numba decorators and the on-disk cache of the compiled loops;
* :mod:`msslib.terms.loops`: numba loops of the internal terms (energy, gradient and Hessian
  blocks of springs, tetrahedron and hexahedron volumes; the fast 3D spring force);
* :mod:`msslib.terms.assembly`: element block patterns and the loops that add Hessian values into
  CSR and BSR matrices with a node-blocked pattern (used by :class:`msslib.system.Model`);
* :mod:`msslib.terms.base`: :class:`Term` and the element-term base class;
* :mod:`msslib.terms.internal`: :class:`Springs`, :class:`TetVolume`, :class:`HexVolume`;
* :mod:`msslib.terms.external`: :class:`ExternalForce`, :class:`NodalForces`, :class:`Gravity`,
  :class:`Traction`, :func:`sum_external_forces`;
* :mod:`msslib.terms.pressure`: :class:`Pressure` (dead or follower pressure on boundary facets)
  and :func:`pressure_nodal_forces`;
* :mod:`msslib.terms.baudet`: Baudet's correction in its two readings, :class:`BaudetCorrection`
  (from the surface loads) and :class:`ElementBaudetCorrection` (every cube from the forces acting
  on it from outside).

The modules import one another in one direction: ``jit`` <- ``loops``, ``assembly``;
``assembly`` <- ``base``; ``base``, ``loops`` <- ``internal``; ``assembly``, ``base`` <-
``external`` <- ``baudet``; ``base``, ``external`` <- ``pressure``.
"""

from __future__ import annotations

from .base import Term
from .baudet import BaudetCorrection, ElementBaudetCorrection
from .external import ExternalForce, Gravity, NodalForces, Traction, sum_external_forces
from .internal import HexVolume, Springs, TetVolume
from .pressure import Pressure, pressure_nodal_forces

__all__ = [
    "Term",
    "ElementBaudetCorrection",
    "Springs",
    "TetVolume",
    "HexVolume",
    "ExternalForce",
    "Gravity",
    "NodalForces",
    "Traction",
    "Pressure",
    "pressure_nodal_forces",
    "BaudetCorrection",
    "sum_external_forces",
]

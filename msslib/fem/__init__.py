"""FEM references (scikit-fem) on the same :class:`~msslib.mesh.Mesh` objects the mass-spring models use.

Public functions
----------------
* :func:`solve_linear` -- small-strain isotropic linear elasticity (2D plane stress/strain, 3D).
* :func:`solve_nonlinear` -- total-Lagrangian finite-strain reference (St Venant-Kirchhoff or
  compressible neo-Hookean), dead loads and pressures (dead or follower), Newton with load
  stepping and step halving.
* :func:`element_stiffness` -- numeric stiffness matrix of one element, dofs interleaved by node
  ``(n0_x, n0_y, [n0_z], n1_x, ...)`` in the VTK node order of the given coordinates.

Conventions
-----------
Displacements, forces and reactions are ``(n_nodes, dim)`` arrays. Internally the global dof of
node ``a``, component ``i`` is ``a * dim + i`` (interleaved by node).

Elements: triangle P1 (``ElementTriP1``), quad Q1 (``ElementQuad1``), tetra P1 (``ElementTetP1``),
hexahedron Q1 (``ElementHex1``), wedge (``ElementWedge1``); each cell type's elements, node
permutation and quadrature are its cell module's (:mod:`msslib.mesh.cells`). Quadrature: one point
for simplices (exact for the constant strains and for the linear load integrands), 2x2 / 2x2x2
Gauss for Q1, and for the wedge a 6-point rule of msslib's own (scikit-fem 12.0.2's wedge
weights sum to half the reference volume).

Assembly: scikit-fem provides the meshes, reference mappings, quadrature and basis functions.
:func:`element_stiffness` and ``solve_linear(..., assembly="skfem")`` assemble with a scikit-fem
``BilinearForm`` on ``ElementVector``; the default ``assembly="fast"`` and the non-linear solver
build the element matrices with vectorised ``numpy.einsum`` from the scalar basis gradients (about
10x faster on large meshes; the two agree to round-off, see the tests). Linear systems are solved
by the linear-solver policy of the mass-spring models (:mod:`msslib.fem.newton`: banded
Cholesky, SuperLU or AMG-preconditioned CG, :func:`msslib.solvers.choose_linear_solver`), the
finite-strain ones by their Newton iteration (:func:`msslib.solvers.static_solve`).

Element order: ``order=1`` (the elements above) or ``order=2``: quadratic Lagrange elements
(``ElementTriP2``, ``ElementTetP2``, ``ElementQuad2``, ``ElementHex2``; degree-2
rules on simplices, 3x3(x3) Gauss on Q2), the references of the speed-against-error studies (:mod:`msslib.planning`).  Near
nu = 1/2 displacement-only elements lock (linear ones by a factor of 10 on a clamped cube at
nu = 0.4999; quadratic ones by a few per cent that shrink slowly under refinement);
``volumetric="reduced"`` integrates the volumetric part of the energy (the ``lambda`` terms) with
one point on quadratic simplices (the cell mean of the displacement gradient) and 2x2(x2) points
on Q2: on simplices the penalty form of the inf-sup stable P2-P0 pair, on Q2 the classical
selective reduced integration, so it does not lock.
It is chosen over a mixed u-p formulation because it keeps one displacement field (the same
Newton, solver and laws) and over reduced integration of linear elements because that leaves P1
simplices locked.

Node orders (checked against the volumes of a unit square/box in the tests):

* triangle, tetra, quad: scikit-fem accepts the VTK order as is (``MeshTri`` sorts the node
  indices of each triangle, which does not change P1 results; ``MeshQuad1`` numbers its corners
  counter-clockwise 0-1-2-3 like VTK).
* wedge: ``MeshWedge1``'s reference triangle turns the other way than VTK's (whose first
  triangle's normal points out of the cell): ``skfem_cells = vtk_cells[:, [0, 2, 1, 3, 5, 4]]``.
* hexahedron: ``MeshHex1`` numbers the corners of the unit cube
  (0,0,0), (0,0,1), (0,1,0), (1,0,0), (0,1,1), (1,0,1), (1,1,0), (1,1,1); the VTK order is
  (0,0,0), (1,0,0), (1,1,0), (0,1,0), (0,0,1), (1,0,1), (1,1,1), (0,1,1). Hence
  ``skfem_cells = vtk_cells[:, [0, 4, 3, 1, 7, 5, 2, 6]]`` (:data:`HEX_VTK_TO_SKFEM`).

2D finite strain: ``plane="strain"`` keeps ``F33 = 1``. ``plane="stress"`` is the exact plane
stress of the 3D law: at every quadrature point the out-of-plane stretch ``F33`` is solved from
``P33 = 0`` (closed form for St Venant-Kirchhoff, a local Newton iteration for neo-Hookean) and the
tangent is statically condensed. For St Venant-Kirchhoff this is identical to the 2D SVK law with
the plane-stress Lame constant ``lambda* = 2 lambda mu / (lambda + 2 mu)``. Integrals are taken
over the reference thickness (nominal quantities), so thickness changes are accounted for exactly.
Pressures (``pressures=((facets, p, follow), ...)`` of both solves): integrated with scikit-fem
facet forms on the element's own facets (quadratic ones with ``order=2``); a follower pressure
adds its non-symmetric load stiffness to Newton's tangent (:mod:`~msslib.fem.pressure`). The
closed-form solutions they are verified against (thick-walled cylinder and sphere) are in
:mod:`~msslib.fem.exact`.
Curved boundaries (``curved=((facets, project), ...)`` of both solves, ``order=2`` only): the
quadratic nodes of boundary facets known to lie on a surface are placed on it by ``project``
(isoparametric elements, :func:`~msslib.fem.space.curved_mesh`), so the quadratic element keeps
its third order in L2 on a curved body; by default every side is straight (a mesh does not say
which surface its facets approximate), which caps that order at 2 there.
Every converged increment of a finite-strain solve is checked for inverted elements
(``det F > 0`` at every quadrature point, for every law), else
:class:`msslib.errors.UnphysicalStateError` names the load factor, the element and ``det F``.

Modules: :mod:`~msslib.fem.materials` (Lame constants, per-cell materials, the finite-strain
laws), :mod:`~msslib.fem.space` (scikit-fem conversion, the element basis of either order,
assembly, boundary conditions and loads), :mod:`~msslib.fem.pressure` (pressure loads),
:mod:`~msslib.fem.newton` (the solves on :mod:`msslib.solvers`), :mod:`~msslib.fem.solve` (the
solves), :mod:`~msslib.fem.exact` (exact solutions under pressure).
"""

from msslib.fem.materials import lame
from msslib.fem.solve import FemResult, element_stiffness, solve_linear, solve_nonlinear, solve_sparse
from msslib.fem.space import HEX_VTK_TO_SKFEM, to_skfem

__all__ = [
    "FemResult",
    "HEX_VTK_TO_SKFEM",
    "element_stiffness",
    "lame",
    "solve_linear",
    "solve_nonlinear",
    "solve_sparse",
    "to_skfem",
]

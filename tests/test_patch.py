"""Patch tests and cross-checks between the derivations, the simulator and the FEM references.

* The symbolic FEM element matrices equal scikit-fem's numerically (two independent computations).
* The linearised MSS stiffness of every derived element model, assembled on a mesh by msslib,
  equals the symbolic MSS matrix, and where the derivation claims an exact match it equals the FEM
  stiffness on the whole mesh.
* Patch tests: where the derivation says the lattice is exactly the continuum, a homogeneous strain
  imposed on the boundary is reproduced in the interior (linearised, to round-off).
"""

import numpy as np
import pytest
import sympy as sp

from derivations import element_stiffness as sfem
from derivations.elasticity import E as sE
from derivations.elasticity import nu as snu
from derivations.elasticity import t as st
from msslib.models.golec import golec_cube_springs
from msslib.models.lloyd import lloyd_square_springs, lloyd_triangle_springs
from msslib import fem, mesh as M
from msslib.system import Model

E0, T0 = 1234.0, 0.01


@pytest.mark.parametrize("cell_type, coords, kind", [
    ("triangle", [(0, 0), (2, 0), (sp.Rational(1, 2), 1)], "plane_stress"),
    ("quad", [(0, 0), (2, 0), (2, 1), (0, 1)], "plane_stress"),
    ("tetra", [(0, 0, 0), (1, 0, 0), (0, 2, 0), (sp.Rational(1, 3), sp.Rational(1, 2), 1)], "3d"),
    ("hexahedron", [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0), (0, 0, 3), (2, 0, 3), (2, 1, 3), (0, 1, 3)], "3d"),
])
def test_symbolic_element_stiffness_equals_scikit_fem(cell_type, coords, kind):
    K = sfem.element_stiffness(cell_type, coords, kind)
    vals = {sE: E0, snu: 0.3, st: T0}
    Ks = np.array(K.subs(vals).evalf(), dtype=float)
    Kn = fem.element_stiffness(cell_type, np.array(coords, dtype=float), E0, 0.3, thickness=T0)
    assert np.allclose(Ks, Kn, rtol=1e-10, atol=1e-10 * np.abs(Kn).max())


def _fem_global(mesh, nu, t=T0):
    """Global linear-FEM stiffness assembled from the element matrices (dofs interleaved)."""
    dim = mesh.dim
    K = np.zeros((mesh.n_nodes * dim,) * 2)
    for cell in mesh.cells:
        Ke = fem.element_stiffness(mesh.cell_type, mesh.points[cell], E0, nu, thickness=t)
        dofs = (dim * cell[:, None] + np.arange(dim)).ravel()
        K[np.ix_(dofs, dofs)] += Ke
    return K


@pytest.mark.parametrize("name", ["triangle", "square"])
def test_exact_models_equal_fem_on_a_whole_mesh(name):
    """Lloyd's triangle (equilateral, nu = 1/3) and prestrained square: the assembled MSS stiffness
    at rest equals the assembled FEM stiffness, entry by entry."""
    if name == "triangle":
        mesh = M.hexagon_equilateral(1.0, 2)
        terms = lloyd_triangle_springs(mesh, [(E0, 1 / 3)], T0)
    else:
        mesh = M.quad_grid(1.0, 1.0, 3, 3)
        terms = lloyd_square_springs(mesh, [(E0, 1 / 3)], T0)
    model = Model(mesh, terms)
    K_mss = model.stiffness(model.x0).toarray()
    assert np.allclose(model.force(model.x0), 0.0, atol=1e-12 * E0)  # in equilibrium at rest
    assert np.allclose(K_mss, _fem_global(mesh, 1 / 3), rtol=1e-10, atol=1e-10 * E0 * T0)


def _patch(model, mesh, eps):
    """Impose u = eps X on the boundary, solve the linearised MSS, return the max interior error."""
    dim = mesh.dim
    X = mesh.points
    u_exact = X @ eps.T
    facets = M.boundary_facets(mesh)
    boundary = np.unique(facets)
    fixed = np.zeros(mesh.n_nodes * dim, bool)
    for n in boundary:
        fixed[dim * n:dim * n + dim] = True
    K = model.stiffness(model.x0).toarray()
    f = model.force(model.x0)  # zero at rest
    u = np.zeros(mesh.n_nodes * dim)
    u[fixed] = u_exact.ravel()[fixed]
    free = ~fixed
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free] - K[np.ix_(free, fixed)] @ u[fixed])
    return np.abs(u - u_exact.ravel()).max() / np.abs(u_exact).max(), free.sum()


def test_patch_triangle_lattice():
    mesh = M.hexagon_equilateral(1.0, 3)
    model = Model(mesh, lloyd_triangle_springs(mesh, [(E0, 1 / 3)], T0))
    err, n_free = _patch(model, mesh, np.array([[1e-3, 4e-4], [2e-4, -5e-4]]))
    assert n_free > 0 and err < 1e-10


def test_patch_prestrained_square_lattice():
    mesh = M.quad_grid(1.0, 1.0, 4, 4)
    model = Model(mesh, lloyd_square_springs(mesh, [(E0, 1 / 3)], T0))
    err, n_free = _patch(model, mesh, np.array([[1e-3, 4e-4], [2e-4, -5e-4]]))
    assert n_free > 0 and err < 1e-10


@pytest.mark.parametrize("nu, A", [(0.3, 1.0), (0.45, 0.5), (0.1, 2.0)])
def test_patch_golec_lattice(nu, A):
    """Golec's cube lattice with the derived constants (and the volume term) passes the patch test
    for any nu and A, and its interior stress matches the continuum's (lambda, mu)."""
    mesh = M.hex_grid(1.0, 1.0, 1.0, 3, 3, 3)
    model = Model(mesh, golec_cube_springs(mesh, [(E0, nu)], A))
    eps = np.array([[1e-3, 2e-4, 0.0], [2e-4, -5e-4, 3e-4], [0.0, 3e-4, 2e-4]])
    err, n_free = _patch(model, mesh, eps)
    assert n_free > 0 and err < 1e-9
    # energy of the homogeneous strain = continuum energy density x volume (linearised)
    K = model.stiffness(model.x0).toarray()
    u = (mesh.points @ eps.T).ravel()
    lam, mu = E0 * nu / ((1 + nu) * (1 - 2 * nu)), E0 / (2 * (1 + nu))
    w = lam / 2 * np.trace(eps) ** 2 + mu * np.sum(eps * eps)
    assert 0.5 * u @ K @ u == pytest.approx(w * 1.0, rel=1e-9)


def test_published_golec_constants_miss_the_continuum_energy():
    """The printed Golec constants, used per element, do not give the continuum's energy under a
    homogeneous shear (erratum: interior totals and E instead of 5E/(4(1+nu))); the derived ones do."""
    mesh = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2)
    nu = 0.45
    eps = np.array([[0.0, 1e-3, 0.0], [1e-3, 0.0, 0.0], [0.0, 0.0, 0.0]])
    u = (mesh.points @ eps.T).ravel()
    mu = E0 / (2 * (1 + nu))
    w = mu * np.sum(eps * eps)
    energies = {}
    for published in (False, True):
        model = Model(mesh, golec_cube_springs(mesh, [(E0, nu)], 1.0, published=published))
        K = model.stiffness(model.x0).toarray()
        energies[published] = 0.5 * u @ K @ u
    assert energies[False] == pytest.approx(w, rel=1e-9)
    assert abs(energies[True] / w - 1) > 0.5

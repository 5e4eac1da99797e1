"""Delingette's triangle (tensile and angular springs): the derivation's exactness for every triangle
and every Poisson's ratio, the simulated model against the CST on an irregular mesh, and its large
deformation against St Venant-Kirchhoff FEM (which it equals, element by element)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from derivations.elasticity import E, nu, t
from derivations.elements import triangle_angular as D
from msslib import fem
from msslib import mesh as M
from msslib.system import Model
from msslib.models.delingette import (
    delingette_springs,
    delingette_triangle,
    local_coordinates,
)
from msslib.scene import load_scene, run_scene

T = 0.01  # thickness (m)


def test_derived_constants_match_the_cst_symbolically():
    (s,) = D.exact().solutions
    assert (D.K_fem() - D.K_mss().subs(s)).applyfunc(sp.simplify) == sp.zeros(6, 6)
    assert D.derive().formulas[0].args == (E, nu, t, D.a, D.x2, D.y2)


def test_equilateral_at_one_third_is_lloyds_triangle():
    eq = D.equilateral()
    assert all(eq[c] == 0 for c in D.c)
    assert all(sp.simplify(eq[k] - sp.sqrt(3) / 8 * E * t) == 0 for k in D.k)


def _irregular_mesh(seed=0):
    """A triangulated unit square with jittered interior nodes (irregular, obtuse triangles too)."""
    mesh = M.triangle_grid_right(1.0, 1.0, 5, 5)
    rng = np.random.default_rng(seed)
    p = mesh.points.copy()
    inner = (p[:, 0] > 1e-9) & (p[:, 0] < 1 - 1e-9) & (p[:, 1] > 1e-9) & (p[:, 1] < 1 - 1e-9)
    p[inner] += 0.08 * rng.uniform(-1, 1, (inner.sum(), 2))
    return M.Mesh(p, mesh.cells, mesh.cell_type)


def _cst_stiffness(mesh, young, poisson):
    n = 2 * mesh.n_nodes
    K = np.zeros((n, n))
    for cell in mesh.cells:
        dofs = np.ravel([[2 * v, 2 * v + 1] for v in cell])
        K[np.ix_(dofs, dofs)] += fem.element_stiffness("triangle", mesh.points[cell], young, poisson, thickness=T)
    return K


@pytest.mark.parametrize("poisson", [-0.5, 0.0, 0.25, 0.3, 0.45, 0.49])
def test_stiffness_at_rest_is_the_cst_on_an_irregular_mesh(poisson):
    mesh = _irregular_mesh()
    model = Model(mesh, delingette_springs(mesh, [(2.0e3, poisson)], T))
    K = model.stiffness(model.x0).toarray()
    K_fem = _cst_stiffness(mesh, 2.0e3, poisson)
    assert np.abs(K - K_fem).max() <= 1e-9 * np.abs(K_fem).max()
    assert np.abs(model.force(model.x0, 0.0)).max() <= 1e-12 * np.abs(K_fem).max()


def test_constants_are_those_of_the_generated_formula_for_random_triangles():
    rng = np.random.default_rng(1)
    (s,) = D.exact().solutions
    for _ in range(5):
        a, x2, y2, n = rng.uniform(0.5, 2), rng.uniform(-1, 2), rng.uniform(0.2, 2), rng.uniform(-0.9, 0.49)
        p = delingette_triangle(3.0, nu=n, t=0.1, a=a, x2=x2, y2=y2)
        at = {E: 3, nu: sp.Float(n, 30), t: sp.Rational(1, 10), D.a: sp.Float(a, 30), D.x2: sp.Float(x2, 30),
              D.y2: sp.Float(y2, 30)}
        for name, sym in zip(("k_01", "k_12", "k_02", "c_01_12", "c_12_02", "c_01_02"), list(D.k) + list(D.c)):
            assert getattr(p, name) == pytest.approx(float(s[sym].subs(at)), rel=1e-12)


def test_local_coordinates_of_a_rotated_and_mirrored_triangle():
    X = np.array([[0.0, 0.0], [2.0, 0.0], [0.5, 1.5]])
    R = np.array([[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]])
    for P in (X @ R.T, (X @ R.T) * np.array([1.0, -1.0])):
        a, x2, y2 = local_coordinates(P, np.array([[0, 1, 2]]))
        assert (a[0], x2[0], y2[0]) == pytest.approx((2.0, 0.5, 1.5))


def test_large_stretch_equals_st_venant_kirchhoff_fem():
    """The Green strain of a triangle is linear in the squared edge lengths, so the energy is the
    St Venant-Kirchhoff membrane's: a 30 % stretch of a plate agrees with svk FEM to solver tolerance."""
    scene = {
        "name": "plate", "model": "delingette_triangle",
        "geometry": {"generator": "triangle_grid_right", "args": {"lx": 0.04, "ly": 0.02, "nx": 6, "ny": 3}},
        "materials": [{"E": 1.0e4, "nu": 0.3}], "thickness": T,
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["x", 0.04]}, "traction": [3000.0, 0.0]}],
        "solver": {"type": "static", "load_steps": 4, "tol": 1.0e-10},
    }
    mss = run_scene(load_scene(scene), progress=False)
    ref = run_scene(load_scene({**scene, "model": "fem_svk"}), progress=False)
    u, u_ref = mss["displacement"].values, ref["displacement"].values
    assert np.abs(u_ref).max() > 0.2 * 0.04  # a large deformation
    assert np.abs(u - u_ref).max() <= 1e-6 * np.abs(u_ref).max()

"""Springs fitted per element by least squares (triangles and tetrahedra of any shape): the
generated formulas against the engine's least squares, the fit against Lloyd's constants where
they coincide, its optimality, and its stiffness at rest against the FEM on irregular meshes
(closer than Lloyd's constants), and where a constant turns negative (tests/test_lsq_stability.py:
what is then simulated and what refused)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp

from derivations import element_stiffness as sfem
from derivations import match, mss
from derivations.elasticity import E, nu, t
from derivations.elements import tetrahedron_lsq as DT
from derivations.elements import triangle_lsq as D
from fem_helpers import fem_stiffness, jittered
from msslib import mesh as M
from msslib.system import Model
from msslib.models.checks import FormulaValidityWarning
from msslib.models.lloyd import (
    lloyd_tet_springs,
    lloyd_tetrahedron,
    lloyd_triangle,
    lloyd_triangle_springs,
)
from msslib.models.lsq import (
    lsq_tetrahedron,
    lsq_tetrahedron_springs,
    lsq_triangle,
    lsq_triangle_springs,
    tetra_frame,
)
from msslib.terms import Springs

T = 0.01  # thickness (m)
R = sp.Rational


# ---- the derivation against the engine's least squares -------------------------------------------


@pytest.mark.parametrize("shape", [(2, R(1, 2), R(3, 2)), (1, R(-1, 2), R(1, 3)), (3, 2, 1)])
def test_triangle_closed_form_is_the_engines_least_squares(shape):
    """At rational shapes (acute, obtuse), match.least_squares in the plain unknowns gives the
    generated closed form exactly, for symbolic E, nu, t; its gradient vanishes, its Hessian is
    positive definite."""
    at = dict(zip((D.a, D.x2, D.y2), shape))
    coords = [tuple(sp.sympify(c).subs(at) for c in p) for p in D.COORDS]
    K_fem = sfem.element_stiffness("triangle", coords, "plane_stress")
    K_mss = mss.stiffness_at_rest([mss.spring(i, j, kk) for (i, j), kk in zip(D.EDGES, D.k)], coords)
    ls = match.least_squares(K_fem, K_mss, D.k)
    for kk in D.k:
        assert sp.cancel(ls.solution[kk] - D.solution()[kk].subs(at)) == 0
    assert all(sp.simplify(g) == 0 for g in ls.gradient)
    assert match.is_positive_definite(ls.hessian)


def test_tetrahedron_normal_equations_are_the_engines_least_squares():
    """At a rational irregular tetrahedron, nu = 3/10: the simulator's solve of the generated normal
    equations equals match.least_squares (exact rationals) to 1e-12."""
    coords = [(0, 0, 0), (2, 0, 0), (R(1, 2), 1, 0), (R(1, 3), R(1, 4), R(3, 2))]
    K_fem = sfem.element_stiffness("tetra", coords, "3d").subs({nu: R(3, 10), E: 1})
    K_mss = mss.stiffness_at_rest([mss.spring(i, j, kk) for (i, j), kk in zip(DT.EDGES, DT.k)], coords)
    ls = match.least_squares(K_fem, K_mss, DT.k)
    want = np.array([float(ls.solution[kk]) for kk in DT.k])
    got = lsq_tetrahedron(1.0, nu=0.3, points=np.array(coords, dtype=float)).k
    assert got == pytest.approx(want, rel=1e-12)
    assert np.ptp(want) > 0.4  # six different constants


def test_tetra_frame_of_a_rotated_tetrahedron():
    X = np.array([[0.0, 0, 0], [2, 0, 0], [0.5, 1, 0], [1 / 3, 0.25, 1.5]])
    q, _ = np.linalg.qr(np.random.default_rng(2).standard_normal((3, 3)))
    q *= np.sign(np.linalg.det(q))  # a rotation
    frame = tetra_frame(X @ q.T + np.array([1.0, -2.0, 0.5]))
    assert np.array(frame) == pytest.approx([2, 0.5, 1, 1 / 3, 0.25, 1.5], abs=1e-12)


# ---- where the fit is Lloyd's ----------------------------------------------------------------------


def test_equilateral_fit_is_lloyds_eq8_at_one_third():
    """Equilateral: k = 2 sqrt(3)/9 E t / (1 - nu^2) for every nu (derived), sqrt(3)/4 E t at nu = 1/3."""
    for kk, v in D.equilateral().items():
        assert sp.simplify(v - 2 * sp.sqrt(3) / 9 * E * t / (1 - nu**2)) == 0
    p = lsq_triangle(2.0, nu=1 / 3, t=0.1, a=1.5, x2=0.75, y2=1.5 * np.sqrt(3) / 2)
    assert (p.k_01, p.k_12, p.k_02) == pytest.approx([lloyd_triangle(2.0, t=0.1).k] * 3, rel=1e-13)
    assert lsq_triangle(2.0, nu=0.2, t=0.1, a=1.5, x2=0.75, y2=1.5 * np.sqrt(3) / 2).k_01 != pytest.approx(lloyd_triangle(2.0, t=0.1).k)


@pytest.mark.parametrize("n", [0.1, 0.25, 0.4])
def test_regular_tetrahedron_fit_is_lloyds_least_squares(n):
    """Regular tetrahedron of edge l: the six constants equal tetrahedron.py's least squares for
    that nu, sqrt(2) E l (1 - nu) / (15 (1 + nu)(1 - 2 nu)); eq. 12 (2 sqrt(2)/25 E l) at nu = 1/4."""
    assert sp.simplify(DT.regular()[0] - sp.sqrt(2) * E * (1 - nu) / (15 * (1 + nu) * (1 - 2 * nu))) == 0
    l = 0.7
    X = l * np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, np.sqrt(3) / 6, np.sqrt(2 / 3)]])
    k = lsq_tetrahedron(3.0, nu=n, points=X).k
    assert k == pytest.approx([lloyd_tetrahedron(3.0, l=l, nu=n).k] * 6, rel=1e-12)
    if n == 0.25:
        assert k == pytest.approx([lloyd_tetrahedron(3.0, l=l).k] * 6, rel=1e-12)


# ---- optimality of the simulated constants ---------------------------------------------------------


@pytest.mark.parametrize("cell", ["triangle", "tetra"])
def test_each_constant_sits_at_the_optimum(cell):
    """One irregular element: scaling any one spring by 0.99 or 1.01 increases ||K - K_FEM||_F."""
    if cell == "triangle":
        mesh = M.Mesh(np.array([[0.0, 0], [2, 0], [0.4, 1.1]]), np.array([[0, 1, 2]]), "triangle")
        model = Model(mesh, lsq_triangle_springs(mesh, [(5.0, 0.3)], T))
    else:
        mesh = M.Mesh(np.array([[0.0, 0, 0], [2, 0, 0], [0.5, 1, 0], [1 / 3, 0.25, 1.5]]), np.array([[0, 1, 2, 3]]),
                      "tetra")
        model = Model(mesh, lsq_tetrahedron_springs(mesh, [(5.0, 0.3)]))
    K_fem = fem_stiffness(mesh, 5.0, 0.3, T)

    springs = model.terms[0]

    def residual(k):
        m = Model(mesh, [Springs(springs.pairs, k, springs.rest_length, mesh.dim)])
        return np.linalg.norm(m.stiffness(m.x0).toarray() - K_fem)

    best = residual(springs.k)
    assert best > 1e-3 * np.linalg.norm(K_fem)  # not exact: the perturbations below can fail
    for s in range(len(springs.k)):
        for factor in (0.99, 1.01):
            k = springs.k.copy()
            k[s] *= factor
            assert residual(k) > best


# ---- irregular meshes: closer to the FEM than Lloyd's constants --------------------------------------


def _relative(terms, mesh, K_fem):
    model = Model(mesh, terms)
    return np.linalg.norm(model.stiffness(model.x0).toarray() - K_fem) / np.linalg.norm(K_fem)


@pytest.mark.parametrize("base, amount, lsq, lloyd", [
    ("equilateral", 0.05, 0.2020, 0.3102),  # 0.3 x the edge 1/6; largest angle 100.8 degrees
    ("right", 0.02, 0.4118, 0.5661),  # 0.1 x the leg 0.2; largest angle 99.4 degrees
])
def test_triangle_mesh_closer_to_the_cst_than_lloyd(base, amount, lsq, lloyd):
    """||K - K_CST||_F / ||K_CST||_F at nu = 1/3 on a jittered unit square (66 or 50 triangles)."""
    mesh = jittered(M.triangle_grid_equilateral(1.0, 1.0, 6) if base == "equilateral"
                     else M.triangle_grid_right(1.0, 1.0, 5, 5), amount)
    K_fem = fem_stiffness(mesh, 1.0, 1 / 3, T)
    ours = _relative(lsq_triangle_springs(mesh, [(1.0, 1 / 3)], T), mesh, K_fem)
    theirs = _relative(lloyd_triangle_springs(mesh, [(1.0, 1 / 3)], T), mesh, K_fem)
    assert (ours, theirs) == pytest.approx((lsq, lloyd), abs=1e-4)


@pytest.mark.parametrize("n, lsq, lloyd", [(0.25, 0.4694, 0.6342), (1 / 3, 0.4860, 0.6666), (0.45, 0.5733, 0.8307)])
def test_tetrahedron_mesh_closer_to_the_fem_than_lloyd(n, lsq, lloyd):
    """Unit cube, 3 x 3 x 3 x 6 = 162 tetrahedra, interior nodes moved by up to 0.05 (0.15 x the
    spacing): some per-element constants are negative (warned), every summed one positive."""
    mesh = jittered(M.tet_grid(1.0, 1.0, 1.0, 3, 3, 3), 0.05)
    K_fem = fem_stiffness(mesh, 1.0, n, T)
    with pytest.warns(FormulaValidityWarning, match=r"lsq_tetrahedron: \d+ of 972 per-element spring constants"):
        ours = _relative(lsq_tetrahedron_springs(mesh, [(1.0, n)]), mesh, K_fem)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FormulaValidityWarning)  # Lloyd's eq. 12 is for nu = 1/4
        theirs = _relative(lloyd_tet_springs(mesh, [(1.0, n)]), mesh, K_fem)
    assert (ours, theirs) == pytest.approx((lsq, lloyd), abs=1e-4)


# ---- negative constants ----------------------------------------------------------------------------


@pytest.mark.parametrize("n, angle", [(0.0, 104.4775), (0.25, 106.1919), (1 / 3, 106.8576), (0.45, 107.8956)])
def test_isosceles_constant_opposite_an_obtuse_apex_turns_negative(n, angle):
    """Isosceles triangle (legs 1): the constant of the base changes sign at the apex angle given."""
    def k_base(deg):
        th = np.radians(deg)
        return lsq_triangle(1.0, nu=n, t=1.0, a=1.0, x2=np.cos(th), y2=np.sin(th)).k_12

    assert k_base(angle - 1e-3) > 0 > k_base(angle + 1e-3)

"""Baudet's correction at element level (msslib.terms.baudet) against the boundary reading,
eqs. 7-8, the paper's fixed-point loop and dynamic relaxation."""

from __future__ import annotations

import numpy as np
import pytest

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib import mesh as M
from msslib import system as MD
from msslib import terms as T
from msslib.terms.baudet import (
    ElementBaudetCorrection,
    FrozenForce,
    fixed_point_solve,
    outside_pair_forces,
)
from msslib.metrics import mean_displacement_gradient
from msslib.models.baudet import element_correction
from msslib.scene import load_scene, prepare
from msslib.solvers import static_solve
from msslib.stepping import integrate

E0, A0 = 1.0e3, 0.1


def _face(mesh, axis, value):
    facets = M.boundary_facets(mesh)
    nodes = M.select_nodes(mesh, plane=(axis, value))
    return facets[np.all(np.isin(facets, nodes), axis=1)]


def _tension(n, nu, reading, P=1.0, published=False):
    """Octant of a box (symmetry planes x = y = z = 0) pulled along z by a dead traction P."""
    mesh = M.hex_grid(A0 * n[0], A0 * n[1], A0 * n[2], *n)
    terms = list(baudet_cube_springs(mesh, [(E0, nu)]))
    load = T.Traction(mesh, _face(mesh, "z", A0 * n[2]), [0.0, 0.0, P])
    terms.append(load)
    if reading == "boundary":
        terms.append(baudet_correction(mesh, [(E0, nu)], [load], published=published))
    elif reading == "element":
        terms.append(element_correction(mesh, [(E0, nu)], published=published))
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    for d, ax in enumerate("xyz"):
        fixed[M.select_nodes(mesh, plane=(ax, 0.0)), d] = True
    return mesh, MD.Model(mesh, terms, fixed=fixed)


def _moduli(mesh, x, P):
    H = mean_displacement_gradient(mesh.points, x.reshape(-1, 3))
    return P / H[2, 2], -(H[0, 0] + H[1, 1]) / 2 / H[2, 2]


def _beam(n, nu, reading, density=1.0):
    """Beam along x clamped at x = 0 under gravity (the boundary reading has no correction)."""
    mesh = M.hex_grid(A0 * n[0], A0 * n[1], A0 * n[2], *n)
    terms = list(baudet_cube_springs(mesh, [(E0, nu)]))
    terms.append(T.Gravity(M.lumped_masses(mesh, density), [0.0, 0.0, -9.81]))
    if reading == "element":
        terms.append(element_correction(mesh, [(E0, nu)]))
    elif reading == "frozen":
        terms.append(FrozenForce(mesh.n_nodes))
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[M.select_nodes(mesh, plane=("x", 0.0)), :] = True
    return mesh, MD.Model(mesh, terms, fixed=fixed, masses=M.lumped_masses(mesh, density))


@pytest.mark.parametrize("nu", [0.1, 0.3, 0.45])
@pytest.mark.parametrize("published", [False, True])
def test_single_cube_equals_boundary_reading(nu, published):
    """One cube: the outside forces are the load and the support reactions, so both readings
    give the same equilibrium at any load (here 30 % of E, large strain)."""
    _, mb = _tension((1, 1, 1), nu, "boundary", P=300.0, published=published)
    _, me = _tension((1, 1, 1), nu, "element", P=300.0, published=published)
    xb = static_solve(mb, mb.x0, load_steps=4, tol=1e-12).x
    xe = static_solve(me, me.x0, load_steps=4, tol=1e-12).x
    assert np.abs(xe - xb).max() < 1e-12 * A0


@pytest.mark.parametrize("nu", [0.1, 0.25, 0.3, 0.45])
def test_single_cube_reproduces_eqs_7_8(nu):
    """Small strain: E and nu of one cube equal the input values (eqs. 7-8, derived factor)."""
    P = 1e-6 * E0
    mesh, model = _tension((1, 1, 1), nu, "element", P=P)
    x = static_solve(model, model.x0, tol=1e-13).x
    E, nu_m = _moduli(mesh, x, P)
    assert E == pytest.approx(E0, rel=1e-6)
    assert nu_m == pytest.approx(nu, rel=1e-6)


@pytest.mark.parametrize("nu", [0.2, 0.3, 0.499])
def test_composite_in_tension_equals_one_cube(nu):
    """Uniform tension: every cube of a composite holds the single cube's state (the outside
    forces on each cube are its own share of the load), so E and nu equal the cube's exactly,
    here at 5 % strain; the boundary reading (only the loaded top cubes corrected) does not."""
    P = 0.05 * E0
    m1, c1 = _tension((1, 1, 1), nu, "element", P=P)
    E1, nu1 = _moduli(m1, static_solve(c1, c1.x0, load_steps=2, tol=1e-12).x, P)
    mn, cn = _tension((2, 2, 3), nu, "element", P=P)
    En, nun = _moduli(mn, static_solve(cn, cn.x0, load_steps=2, tol=1e-12).x, P)
    assert En == pytest.approx(E1, rel=1e-9)
    assert nun == pytest.approx(nu1, rel=1e-9)
    mb, cb = _tension((2, 2, 3), nu, "boundary", P=P)
    _, nub = _moduli(mb, static_solve(cb, cb.x0, load_steps=2, tol=1e-12).x, P)
    assert abs(nub / nu1 - 1.0) > 0.05


def test_jacobian_matches_finite_differences():
    _, model = _beam((3, 2, 2), 0.35, "element")
    assert not model.symmetric and model.energy(model.x0) is None
    x = model.x0 + 0.01 * np.random.default_rng(1).standard_normal(model.n_dof)
    K = model.stiffness(x).toarray()
    h = 1e-7
    J = np.empty_like(K)
    for i in range(model.n_dof):
        e = np.zeros(model.n_dof)
        e[i] = h
        J[:, i] = -(model.force(x + e) - model.force(x - e)) / (2 * h)
    assert np.abs(K - J).max() < 1e-7 * np.abs(J).max()
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()  # genuinely non-symmetric


def test_correction_has_zero_resultant_and_moment_per_cube():
    mesh, model = _beam((3, 2, 2), 0.4, "element")
    term = model.terms[-1]
    x = model.x0 + 0.02 * np.random.default_rng(2).standard_normal(model.n_dof)
    s = term.element_spring_forces(x).reshape(len(term.cells), 24)
    ke = np.einsum("mij,mj->mi", term.map, s).reshape(-1, 8, 3)
    X = mesh.points[term.cells]
    assert np.abs(ke.sum(axis=1)).max() < 1e-12 * np.abs(ke).max()
    assert np.abs(np.cross(X, ke).sum(axis=1)).max() < 1e-12 * np.abs(ke).max() * A0


@pytest.mark.parametrize("nu", [0.1, 0.3, 0.4])
def test_paper_fixed_point_loop_converges_to_the_equilibrium_form(nu):
    """The paper's algorithm (freeze the corrections, solve, recompute them from the forces of the
    neighbours, loads and supports) converges, and to the equilibrium-form solution; the pair
    forces built from the neighbours equal those from the cube's own springs there."""
    _, me = _beam((6, 2, 2), nu, "element")
    xe = static_solve(me, me.x0, tol=1e-12).x
    term = me.terms[-1]
    _, mf = _beam((6, 2, 2), nu, "frozen")
    xf, _, hist = fixed_point_solve(mf, term, tol=1e-11)
    assert hist[-1] < 1e-11 and len(hist) < 60
    scale = np.abs(xe - me.x0).max()
    assert np.abs(xf - xe).max() < 1e-9 * scale
    F_local = term.pair_forces(xe)
    F_out = outside_pair_forces(term, xe, me.force(xe), me.free, F_local)
    assert np.abs(F_out - F_local).max() < 1e-8 * np.abs(F_local).max()
    # gravity alone drives the element reading: the beam is not the bare lattice
    _, m0 = _beam((6, 2, 2), nu, "none")
    x0 = static_solve(m0, m0.x0, tol=1e-12).x
    assert np.abs(x0 - xe).max() > 1e-3 * scale


def test_springs_only_variant_differs_in_a_composite_only():
    """Leaving the neighbours' corrections out of the outside forces changes nothing for one cube
    and changes a composite."""
    _, me1 = _tension((1, 1, 1), 0.4, "element", P=10.0)
    x1 = static_solve(me1, me1.x0, tol=1e-12).x
    mesh1 = M.hex_grid(A0, A0, A0, 1, 1, 1)
    terms = [*baudet_cube_springs(mesh1, [(E0, 0.4)]), T.Traction(mesh1, _face(mesh1, "z", A0), [0, 0, 10.0]),
             FrozenForce(mesh1.n_nodes)]
    mf1 = MD.Model(mesh1, terms, fixed=me1.fixed)
    xs1, _, _ = fixed_point_solve(mf1, me1.terms[-1], tol=1e-12, neighbour_corrections=False)
    assert np.abs(xs1 - x1).max() < 1e-12 * A0
    _, me = _beam((6, 2, 2), 0.4, "element")
    xe = static_solve(me, me.x0, tol=1e-12).x
    _, mf = _beam((6, 2, 2), 0.4, "frozen")
    xs, _, _ = fixed_point_solve(mf, me.terms[-1], tol=1e-11, neighbour_corrections=False)
    assert np.abs(xs - xe).max() > 1e-3 * np.abs(xe - me.x0).max()


def test_dynamic_relaxation_reaches_the_static_state():
    """Evaluated at every step, the correction lets damped implicit Euler relax to the static
    solution (the inertial difference to the paper's outside force vanishes at rest)."""
    _, model = _beam((4, 2, 2), 0.3, "element", density=1.0)
    xs = static_solve(model, model.x0, tol=1e-12).x
    res = integrate(model, model.x0, np.zeros(model.n_dof), dt=0.02, t_end=6.0, method="implicit_euler",
                    damping=20.0, newton_tol=1e-12)
    assert np.abs(res.x_final - xs).max() < 1e-6 * np.abs(xs - model.x0).max()


def test_singular_factor_is_refused():
    mesh = M.hex_grid(A0, A0, A0, 1, 1, 1)
    with pytest.raises(ValueError, match="c = 1 or -1/2"):
        ElementBaudetCorrection(mesh, 1.0, 1.0, -0.5)


def _scene(**model):
    return {
        "name": "cube",
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.2, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 1, "nz": 1}},
        "materials": [{"E": 1.0e3, "nu": 0.3}],
        "model": {"type": "baudet_cube", **model},
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["x", 0.2]}, "traction": [1.0, 0.0, 0.0]}],
        "solver": {"type": "static"},
    }


def test_scene_option():
    assert isinstance(prepare(load_scene(_scene(correction="element"))).model.terms[1], ElementBaudetCorrection)
    assert isinstance(prepare(load_scene(_scene())).model.terms[1], T.BaudetCorrection)
    assert isinstance(prepare(load_scene(_scene(correction="boundary"))).model.terms[1], T.BaudetCorrection)
    with pytest.raises(ValueError, match=r"scene\.model\.correction: unknown Baudet correction reading 'elements'"):
        load_scene(_scene(correction="elements"))
    bad = _scene(correction="element")
    bad["model"]["type"] = "golec_cube"
    with pytest.raises(ValueError, match=r"scene\.model\.correction: only baudet_cube"):
        load_scene(bad)

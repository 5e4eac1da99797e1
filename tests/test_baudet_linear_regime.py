"""Baudet's cube with its correction (readings ``boundary`` and ``element``) statically solved from
1e-3 Pa to large deformation and from 0.1 to 100 m/s^2 of gravity: every case converges in one load
step without halving (or, beyond what the model can carry, stops with one line), and its result is
checked against numbers that do not come from the Newton iteration: the exact uniaxial-tension
solution (which the element reading reproduces), linear FEM on the same mesh, the model's own
linearisation at rest (one sparse solve), the springs alone (solved under the energy line search),
linear scaling with the load and the balance of support reactions and applied loads.

The non-conservative correction puts the Newton iteration under the residual line search.  A
full Newton step of a bending problem raises the residual (its rotation leaves a stretching
residual far larger than the bending residual it removes) although it is right to within a small
correction; judged by the residual norm alone, such steps were halved again and again (hundreds of
iterations and repeated load-step halvings on a two-material bar under 1 m/s^2).  The steps are
now also judged by the size of the next Newton correction (natural monotonicity test)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib import mesh as M
from msslib import system as MD
from msslib import terms as T
from msslib.errors import ConvergenceError
from msslib.fem import solve_linear
from msslib.models.baudet import element_correction
from msslib.solvers import static_solve

E0, A0, RHO = 1.0e6, 0.01, 1000.0  # Pa, cube edge (m), kg/m^3


def _face(mesh, axis, value):
    facets = M.boundary_facets(mesh)
    nodes = M.select_nodes(mesh, plane=(axis, value))
    return facets[np.all(np.isin(facets, nodes), axis=1)]


def _model(mesh, materials, reading, fixed, traction=None, facets=None, g=0.0):
    """Baudet's springs, a dead traction on ``facets`` and/or gravity, and the correction of
    ``reading`` (``boundary``, ``element`` or ``springs``: none)."""
    terms = list(baudet_cube_springs(mesh, materials))
    surface = [T.Traction(mesh, facets, traction)] if traction is not None else []
    terms += surface
    if g:
        terms.append(T.Gravity(M.lumped_masses(mesh, RHO), [0.0, 0.0, -g]))
    if reading == "boundary" and surface:
        terms.append(baudet_correction(mesh, materials, surface))
    elif reading == "element":
        terms.append(element_correction(mesh, materials))
    return MD.Model(mesh, terms, fixed=fixed)


def _solve(model, max_iterations):
    """Converged in one load step, no halving, at most ``max_iterations`` Newton iterations; the
    residual recomputed here is within the threshold the solver reports."""
    res = static_solve(model, model.x0)
    assert res.n_cuts == 0 and res.n_load_steps == 1, res.messages
    assert res.total_iterations <= max_iterations, res.residuals
    assert np.linalg.norm(model.force(res.x)[model.free]) <= res.threshold
    return res


def _check_balance(model, res, applied):
    """Support reactions balance the applied load ``applied`` (3,) (N): the sum of the reactions
    and the loads is the sum of the free residuals, at most ``sqrt(n_free) * threshold``, and at
    most 1e-5 of the load (at 1e-3 Pa the threshold is the round-off floor of the forces, about
    1e-5 of the load on 2 x 2 cubes of 1 cm)."""
    total = model.reaction(res.x).sum(axis=0) + np.asarray(applied)
    assert np.abs(total).max() <= np.sqrt(model.free.sum()) * res.threshold
    assert np.abs(total).max() <= 1e-5 * np.abs(applied).max()


def _linearised(model):
    """Displacement of the model linearised at rest: one sparse solve ``K(x0) u = f(x0)``."""
    f = model.free
    K = model.stiffness(model.x0).tocsc()[f][:, f]
    u = np.zeros(model.n_dof)
    u[f] = spla.spsolve(K, model.force(model.x0)[f])
    return u


def _bar(n):
    """Bar of ``n`` cubes clamped at x = 0 (all dofs)."""
    mesh = M.hex_grid(A0 * n[0], A0 * n[1], A0 * n[2], *n)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[M.select_nodes(mesh, plane=("x", 0.0)), :] = True
    return mesh, fixed


def _octant(n):
    """Box of ``n`` cubes on the symmetry planes x = y = z = 0 (normal dofs fixed): free to contract."""
    mesh = M.hex_grid(A0 * n[0], A0 * n[1], A0 * n[2], *n)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    for d, axis in enumerate("xyz"):
        fixed[M.select_nodes(mesh, plane=(axis, 0.0)), d] = True
    return mesh, fixed


# --------------------------------------------------------------------------------------------
# uniaxial tension: the exact solution
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("nu", [0.3, 0.45])
@pytest.mark.parametrize("P", [1e-3, 1.0, 10.0])
def test_element_reading_reproduces_uniaxial_tension(nu, P):
    """Every cube of a box in uniform tension holds E and nu of eqs. 7-8: the end moves by
    P L / E and the sides by -nu P W / E (exact elasticity; the geometric non-linearity is of
    the order of the strain, at most 1e-5 here)."""
    n = (2, 2, 8)
    mesh, fixed = _octant(n)
    L, W = A0 * n[2], A0 * n[0]
    model = _model(mesh, [(E0, nu)], "element", fixed, [0.0, 0.0, P], _face(mesh, "z", L))
    res = _solve(model, 3)
    u = (res.x - model.x0).reshape(-1, 3)
    assert u[np.isclose(mesh.points[:, 2], L), 2].mean() == pytest.approx(P * L / E0, rel=1e-5)
    assert u[np.isclose(mesh.points[:, 0], W), 0].mean() == pytest.approx(-nu * P * W / E0, rel=1e-5)
    _check_balance(model, res, [0.0, 0.0, P * W * A0 * n[1]])


@pytest.mark.parametrize("reading", ["boundary", "element"])
def test_two_material_bar_in_tension(reading):
    """Soft (E) and stiff (10 E) halves in series under 1 and 2 Pa: the displacement doubles with
    the load, equals the model linearised at rest, and the end displacement agrees with Q1 FEM
    on the same mesh (which is 2.5 % below the series-spring value P L/2 (1/E + 1/(10 E)): the
    lateral contraction is restrained at the interface): to 0.5 % under the element reading,
    5 % under the boundary reading (only the loaded top cubes are corrected; the others contract
    as the bare lattice, nu_lattice = 1/(4 nu + 3))."""
    n = (2, 2, 8)
    mesh, fixed = _octant(n)
    centre_z = mesh.points[mesh.cells].mean(axis=1)[:, 2]
    mesh = dataclasses.replace(mesh, material=(centre_z > A0 * n[2] / 2).astype(np.int64))
    materials = [(E0, 0.3), (10 * E0, 0.3)]
    L = A0 * n[2]
    top = np.isclose(mesh.points[:, 2], L)
    u = {}
    for P in (1.0, 2.0):
        model = _model(mesh, materials, reading, fixed, [0.0, 0.0, P], _face(mesh, "z", L))
        res = _solve(model, 3)
        u[P] = res.x - model.x0
        _check_balance(model, res, [0.0, 0.0, P * A0 * A0 * n[0] * n[1]])
        lin = _linearised(model)
        assert np.abs(u[P] - lin).max() <= 1e-5 * np.abs(lin).max()
    assert np.abs(u[2.0] - 2.0 * u[1.0]).max() <= 1e-5 * np.abs(u[2.0]).max()
    surface = T.sum_external_forces([T.Traction(mesh, _face(mesh, "z", L), [0.0, 0.0, 1.0])], mesh.n_nodes, 3)
    fem = solve_linear(mesh, [E0, 10 * E0], [0.3, 0.3], fixed=fixed, nodal_forces=surface).displacement
    fem_end = fem[top, 2].mean()
    assert fem_end == pytest.approx(0.5 * L * (1 / E0 + 1 / (10 * E0)), rel=0.05)  # FEM itself: the series value
    end = u[1.0].reshape(-1, 3)[top, 2].mean()
    assert end == pytest.approx(fem_end, rel=5e-3 if reading == "element" else 0.05)


# --------------------------------------------------------------------------------------------
# cantilever: tip traction and gravity in the linear regime
# --------------------------------------------------------------------------------------------

CANTILEVER = (8, 2, 2)
# (the boundary reading has no correction under gravity: tip tractions only)
TIP_LOADS = [("traction", 1e-3), ("traction", 0.1), ("traction", 10.0), ("gravity", 0.1), ("gravity", 1.0)]


def _cantilever(reading, nu, kind, value, n=CANTILEVER):
    mesh, fixed = _bar(n)
    L = A0 * n[0]
    area = A0 * A0 * n[1] * n[2]
    if kind == "traction":
        model = _model(mesh, [(E0, nu)], reading, fixed, [0.0, 0.0, -value], _face(mesh, "x", L))
        applied = [0.0, 0.0, -value * area]
    else:
        model = _model(mesh, [(E0, nu)], reading, fixed, g=value)
        applied = [0.0, 0.0, -RHO * value * area * L]
    return mesh, model, applied


def _tip(mesh, u):
    return -u.reshape(-1, 3)[np.isclose(mesh.points[:, 0], mesh.points[:, 0].max()), 2].mean()


@pytest.mark.parametrize("nu", [0.3, 0.45])
@pytest.mark.parametrize("reading,kind,value", [("element", k, v) for k, v in TIP_LOADS]
                         + [("boundary", k, v) for k, v in TIP_LOADS if k == "traction"])
def test_cantilever_linear_regime(reading, nu, kind, value):
    """Clamped 8 x 2 x 2 cubes of 1 cm: converged in at most 3 iterations; u(2F) = 2 u(F) and
    the Newton solution equals the model linearised at rest, both to 1e-6 plus the rotation
    theta = max|u| / L (the geometric non-linearity; measured 0.5 theta); reactions balance
    the load; the tip deflection is within 5 % of the springs alone (solved under the energy
    line search; the correction changes the bending by 0.5-2.5 %) and, at nu = 0.3, within 25 %
    of Q1 FEM on the same mesh (a two-cube-thick cube lattice is stiffer in bending: Baudet
    0.82 and Golec's exactly isotropic lattice 0.89 of Q1)."""
    mesh, model, applied = _cantilever(reading, nu, kind, value)
    res = _solve(model, 3)
    _check_balance(model, res, applied)
    u = res.x - model.x0
    theta = np.abs(u).max() / (A0 * CANTILEVER[0])
    _, model2, _ = _cantilever(reading, nu, kind, 2 * value)
    u2 = _solve(model2, 3).x - model2.x0
    assert np.abs(u2 - 2 * u).max() <= (1e-6 + theta) * np.abs(2 * u).max()
    lin = _linearised(model)
    assert np.abs(u - lin).max() <= (1e-6 + theta) * np.abs(lin).max()
    _, springs, _ = _cantilever("springs", nu, kind, value)
    s = static_solve(springs, springs.x0)
    assert s.line_search_merit == "energy"
    assert _tip(mesh, u) == pytest.approx(_tip(mesh, s.x - springs.x0), rel=0.05)
    if nu == 0.3:
        _, fixed = _bar(CANTILEVER)
        if kind == "traction":
            f = T.sum_external_forces([T.Traction(mesh, _face(mesh, "x", A0 * CANTILEVER[0]), [0.0, 0.0, -value])],
                                      mesh.n_nodes, 3)
            fem = solve_linear(mesh, E0, nu, fixed=fixed, nodal_forces=f)
        else:
            fem = solve_linear(mesh, E0, nu, fixed=fixed, body_force=(0.0, 0.0, -RHO * value))
        assert _tip(mesh, u) == pytest.approx(_tip(mesh, fem.displacement), rel=0.25)


# --------------------------------------------------------------------------------------------
# where the residual line search used to creep
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("g", [0.1, 1.0, 5.0, 9.58, 9.81, 20.0, 100.0])
def test_slender_two_material_bar_under_gravity(g):
    """20 cm bar of 20 x 2 x 2 cubes, soft (E) and stiff (10 E) halves, element reading, nu = 0.3:
    one load step, no halving (at 1 m/s^2 the residual line search alone took 312 iterations and
    9 halvings; at 5 m/s^2, 35 halvings); reactions balance the weight; at 0.1 m/s^2 the result
    is the linearised one to 1e-6 plus the rotation."""
    n = (20, 2, 2)
    mesh, fixed = _bar(n)
    centre_x = mesh.points[mesh.cells].mean(axis=1)[:, 0]
    mesh = dataclasses.replace(mesh, material=(centre_x > A0 * n[0] / 2).astype(np.int64))
    model = _model(mesh, [(E0, 0.3), (10 * E0, 0.3)], "element", fixed, g=g)
    res = _solve(model, 30)
    _check_balance(model, res, [0.0, 0.0, -RHO * g * A0**3 * np.prod(n)])
    if g <= 0.1:
        u, lin = res.x - model.x0, _linearised(model)
        theta = np.abs(u).max() / (A0 * n[0])
        assert np.abs(u - lin).max() <= (1e-6 + theta) * np.abs(lin).max()


@pytest.mark.parametrize("nu", [0.1, 0.3, 0.45])
@pytest.mark.parametrize("kind,value", [("traction", 10.0), ("gravity", 5.0), ("gravity", 100.0)])
def test_single_cube(nu, kind, value):
    """One clamped cube (its free face held by four edges and four diagonals: nearly a mechanism
    at rest): a few iterations (38 under the residual line search alone at nu = 0.1), reactions
    balance the load."""
    mesh, model, applied = _cantilever("element", nu, kind, value, n=(1, 1, 1))
    res = _solve(model, 10)
    _check_balance(model, res, applied)


# --------------------------------------------------------------------------------------------
# large deformation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("nu", [0.3, 0.45])
@pytest.mark.parametrize("reading,kind,value", [("boundary", "traction", 1e4), ("boundary", "traction", 1e5),
                                                 ("element", "traction", 1e4), ("element", "traction", 1e5),
                                                 ("element", "gravity", 100.0), ("element", "gravity", 1000.0)])
def test_large_deformation_converges_or_stops_in_one_line(reading, nu, kind, value):
    """Up to tip deflections of the order of the length: converged (residual within the threshold,
    reactions balancing the load), or one line that says so."""
    mesh, model, applied = _cantilever(reading, nu, kind, value)
    try:
        res = static_solve(model, model.x0)
    except ConvergenceError as exc:
        text = str(exc)
        assert "\n" not in text and text.startswith("static_solve did not converge")
        return
    assert np.linalg.norm(model.force(res.x)[model.free]) <= res.threshold
    _check_balance(model, res, applied)
    assert np.abs(res.x - model.x0).max() > 0.03 * A0 * CANTILEVER[0]  # large indeed

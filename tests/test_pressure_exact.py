"""The FEM references under pressure against closed-form linear-elastic solutions
(msslib.fem.exact): the thick-walled cylinder in plane strain on a quarter annulus and the
thick-walled sphere on an octant, internal pressure, symmetry supports.

Measured orders (errors relative; L2 over the mesh, max over the nodes):

* linear elements at nu = 0.3: 2 in L2 and about 1.8-2 at the nodes; at nu = 0.49 they approach 2
  only on the finest meshes, at nu = 0.4999 they lock (35-95 % error, no convergence).
* quadratic elements with the reduced volumetric rule of the references: order 2 at every nu
  (the walls are straight-sided facets between nodes on the circle or sphere, an O(h^2)
  approximation of the geometry, which caps the order of the quadratic element at 2 here), with
  errors at nu = 0.4999 within 1.25 times those at nu = 0.3 on the cylinder, 1.12 on the sphere:
  no locking.
* the same with the walls' quadratic nodes on the circles and spheres (``curved``,
  isoparametric elements): order 3 in L2 at nu = 0.3 and at nu = 0.4999 (2.8-3.1), with errors
  at 0.4999 within 1.25 times those at 0.3 on the cylinder, 1.8 on the sphere.
"""

from __future__ import annotations

from functools import lru_cache, partial

import numpy as np
import pytest

from msslib.fem import exact, solve_linear
from msslib.fem.space import _Geometry
from msslib.mesh import boundary_facets

A, B, P, E = 1.0, 2.0, 1.0, 1.0
RULES = {1: "full", 2: "reduced"}


def _slopes(errors):
    e = np.asarray(errors)
    return np.log2(e[:-1] / e[1:])


def _cylinder_errors(cell_type, order, nu, levels=(4, 8, 16)):
    l2, nodal = [], []
    for n in levels:
        mesh = exact.quarter_annulus(A, B, n, cell_type)
        r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), plane="strain", order=order,
                         volumetric=RULES[order], linear_solver="direct",
                         pressures=[(exact.inner_wall(mesh, A), P, True)])
        u = partial(exact.cylinder_displacement, a=A, b=B, p=P, E=E, nu=nu)
        l2.append(exact.l2_error(r, mesh, order, u))
        nodal.append(exact.max_nodal_error(r, mesh, u))
    return np.array(l2), np.array(nodal)


def test_exact_solutions_are_those_of_lame():
    """The closed forms satisfy their boundary conditions: radial stress -p at r = a, 0 at r = b
    (from finite differences of u_r), and the plane-strain one solves equilibrium."""
    nu = 0.3
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    for dim, u in ((2, partial(exact.cylinder_displacement, a=A, b=B, p=P, E=E, nu=nu)),
                   (3, partial(exact.sphere_displacement, a=A, b=B, p=P, E=E, nu=nu))):
        def ur(r):
            x = np.zeros(dim)
            x[0] = r
            return u(x)[0]

        for r, want in ((A, -P), (B, 0.0), (1.5, None)):
            h = 1e-5
            dur = (ur(r + h) - ur(r - h)) / (2 * h)
            hoop = ur(r) / r
            srr = lam * (dur + (dim - 1) * hoop) + 2 * mu * dur
            if want is not None:
                assert srr == pytest.approx(want, abs=1e-8)
    x = np.array([[1.2, 0.7]])  # equilibrium of the plane-strain field: div sigma = 0
    u = partial(exact.cylinder_displacement, a=A, b=B, p=P, E=E, nu=nu)
    h = 1e-3

    def sigma(y):
        g = np.stack([(u(y + h * e) - u(y - h * e)) / (2 * h) for e in np.eye(2)], axis=-1)[0]
        eps = 0.5 * (g + g.T)
        return lam * np.trace(eps) * np.eye(2) + 2 * mu * eps

    div = sum((sigma(x + h * e)[:, j] - sigma(x - h * e)[:, j]) / (2 * h) for j, e in enumerate(np.eye(2)))
    assert np.abs(div).max() < 1e-5


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
def test_cylinder_linear_elements_converge_at_order_two_and_lock_near_incompressibility(cell_type):
    l2, nodal = _cylinder_errors(cell_type, 1, 0.3)
    assert np.all(_slopes(l2) > 1.6) and _slopes(l2)[-1] > 1.9  # measured 1.71, 1.98 (triangles)
    assert _slopes(nodal)[-1] > 1.6  # measured 1.77 (triangles), 1.99 (quads)
    l2_49, _ = _cylinder_errors(cell_type, 1, 0.49)
    assert _slopes(l2_49)[-1] > 1.5  # measured 1.67 (triangles), 1.95 (quads)
    l2_locked, _ = _cylinder_errors(cell_type, 1, 0.4999)
    assert l2_locked[-1] > 0.3 and l2_locked[-1] > 100 * l2[-1]  # locked: 35 % (triangles), 50 % (quads)


@pytest.mark.parametrize("nu", [0.3, 0.49, 0.4999])
@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
def test_cylinder_quadratic_reduced_converges_and_does_not_lock(cell_type, nu):
    l2, nodal = _cylinder_errors(cell_type, 2, nu)
    assert np.all(_slopes(l2) > 1.9)  # measured 2.00-2.03
    assert np.all(_slopes(nodal) > 1.8)  # measured 2.02-2.09
    reference, _ = _cylinder_errors(cell_type, 2, 0.3)
    assert np.all(l2 < 1.3 * reference)  # measured at most 1.22 (nu = 0.4999; 1.51 on triangles fully integrated)
    assert l2[-1] < 6e-4


@lru_cache(maxsize=None)
def _octant(h):
    return exact.sphere_octant(A, B, h)


@lru_cache(maxsize=None)
def _sphere_errors(order, nu, sizes):
    l2, nodal = [], []
    u = partial(exact.sphere_displacement, a=A, b=B, p=P, E=E, nu=nu)
    for h in sizes:
        mesh = _octant(h)
        r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), order=order, volumetric=RULES[order],
                         linear_solver="direct", pressures=[(exact.inner_wall(mesh, A), P, False)])
        l2.append(exact.l2_error(r, mesh, order, u))
        nodal.append(exact.max_nodal_error(r, mesh, u))
    return np.array(l2), np.array(nodal)


def test_sphere_octant_mesh_and_supports():
    mesh = exact.sphere_octant(A, B, 0.4)
    radius = np.linalg.norm(mesh.points, axis=1)
    assert radius.min() == pytest.approx(A, rel=1e-9) and radius.max() == pytest.approx(B, rel=1e-9)
    assert mesh.points.min() >= -1e-12
    wall = exact.inner_wall(mesh, A)
    area = 0.0
    for f in wall:  # the inner wall's facets cover an eighth of the sphere, to O(h^2)
        x = mesh.points[f]
        area += 0.5 * np.linalg.norm(np.cross(x[1] - x[0], x[2] - x[0]))
    assert area == pytest.approx(np.pi * A**2 / 2, rel=0.03)
    assert exact.symmetry_supports(mesh).sum() > 0


SIZES = (0.4, 0.2)


def test_sphere_linear_tetrahedra_converge_at_order_two_and_lock_near_incompressibility():
    l2, nodal = _sphere_errors(1, 0.3, SIZES)
    assert _slopes(l2)[0] > 1.6  # measured 1.84
    assert _slopes(nodal)[0] > 1.0  # measured 1.37 (unstructured meshes: the node of largest error moves)
    locked, _ = _sphere_errors(1, 0.4999, SIZES)
    assert locked.min() > 0.8  # linear tetrahedra lock (measured 95-99 %)


@pytest.mark.parametrize("nu", [0.3, pytest.param(0.49, marks=pytest.mark.slow), 0.4999])
def test_sphere_quadratic_reduced_converges_and_does_not_lock(nu):
    e, _ = _sphere_errors(2, nu, SIZES)
    assert _slopes(e)[0] > 1.8  # measured 2.06
    assert np.all(e < 1.2 * _sphere_errors(2, 0.3, SIZES)[0])  # measured at most 1.12
    assert e[-1] < 0.4 * _sphere_errors(1, 0.3, SIZES)[0][-1]  # measured 1.4-1.5 % against linear's 4.6 %


@pytest.mark.slow
def test_sphere_orders_on_a_third_mesh():
    sizes = (0.4, 0.2, 0.1)
    l2, _ = _sphere_errors(1, 0.3, sizes)
    assert np.all(_slopes(l2) > 1.7)  # measured 1.84, 1.89
    for nu in (0.3, 0.4999):
        e, _ = _sphere_errors(2, nu, sizes)
        assert np.all(_slopes(e) > 1.8)  # measured 2.06, 1.97 (0.3)
        assert e[-1] < 5e-3  # measured 3.7e-3 (0.3), 3.9e-3 (0.4999)


def test_study_models_exact_on_their_elements_agree_with_linear_fem_under_pressure():
    """The study's two paths meet: Delingette's triangle and Kikuuwe's tetrahedron reproduce the
    linear element's stiffness, so their scene runs under the dead pressure (the mass-spring
    pressure load on a facet group) give linear FEM's displacements (msslib.fem pressures on the
    same facets) to round-off, with the same errors against the exact solution."""
    from experiments.performance.studies import pressure_exact as study

    for mesh, model, u_exact in (
            (exact.quarter_annulus(A, B, 4), "delingette_triangle", partial(study.plane_stress_cylinder, nu=0.3)),
            (exact.sphere_octant(A, B, 0.4), "kikuuwe_tetrahedron",
             partial(exact.sphere_displacement, a=A, b=B, p=study.P, E=study.E, nu=0.3))):
        inner = exact.inner_wall(mesh, A)
        u_mss = study.mss_run(model, mesh, inner, 0.3)
        u_fem = study.fem_run(1, mesh, inner, 0.3)
        assert np.abs(u_mss - u_fem).max() < 1e-9 * np.abs(u_fem).max()
        err, _ = study.errors(u_fem, mesh, u_exact)
        err_q, _ = study.errors(study.fem_run(2, mesh, inner, 0.3), mesh, u_exact)
        assert 0.01 < err < 0.5 and err_q < 0.5 * err  # measured 7.3 % / 0.65 % (cylinder), 24 % / 7.8 % (sphere)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("body", ["triangle", "quad", "tetra"])
def test_equal_pressure_inside_and_outside_compresses_uniformly_to_round_off(body, order):
    """The same pressure on the inner and outer walls (the faceted ones of the mesh) and symmetry
    supports: the exact solution of the discrete body is the uniform compression
    u = -p (1 + nu)(1 - 2 nu) / E x (plane strain) or -p (1 - 2 nu) / E x (3D), which linear and
    quadratic elements represent: every node's displacement to round-off, whatever the mesh."""
    nu = 0.3
    mesh = exact.sphere_octant(A, B, 0.5) if body == "tetra" else exact.quarter_annulus(A, B, 3, body)
    walls = [(exact.inner_wall(mesh, A), P, False), (exact.inner_wall(mesh, B), P, True)]
    r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), plane="strain", order=order,
                     volumetric=RULES[order], pressures=walls)
    factor = (1 + nu) * (1 - 2 * nu) if mesh.dim == 2 else (1 - 2 * nu)
    want = -P * factor / E * mesh.points
    assert np.abs(r.displacement - want).max() < 1e-12 * np.abs(want).max()
    assert np.abs(r.dof_displacement + P * factor / E * r.dof_points).max() < 1e-12 * np.abs(want).max()


def test_study_summary_reads_the_finest_level_and_the_order_from_synthetic_errors():
    """The study's summary on made-up rows whose rms error is C h^2 (cylinder: h = 1 / n; sphere: h
    the size): the order read is 2, the finest level's error is the finest mesh's, and a model that
    does not run on a case is NaN there."""
    from experiments.performance.studies import pressure_exact as study

    rows = []
    for n, nodes in ((4, 50), (8, 170), (16, 600)):
        rows.append({"problem": "cylinder", "cells": "quad", "level": float(n), "model": "a", "nu": 0.3,
                     "n_nodes": nodes, "error_max": 3.0 / n ** 2, "error_rms": 1.0 / n ** 2,
                     "error_max_vs_fem": 0.0, "outcome": "ok"})
    for h, nodes in ((0.4, 80), (0.2, 400)):
        rows.append({"problem": "sphere", "cells": "tetra", "level": h, "model": "b", "nu": 0.3, "n_nodes": nodes,
                     "error_max": 5 * h, "error_rms": h ** 3, "error_max_vs_fem": 0.0, "outcome": "ok"})
    s = study.summary(rows)
    cases, models = s["coords"]["case"], s["coords"]["model"]
    rate = s["data"]["rate"][1]
    finest = s["data"]["finest_error_max"][1]
    i, j = cases.index("cylinder_quad"), models.index("a")
    assert rate[i, j, 0] == pytest.approx(2.0) and finest[i, j, 0] == pytest.approx(3.0 / 256)
    i, j = cases.index("sphere_tetra"), models.index("b")
    assert rate[i, j, 0] == pytest.approx(3.0) and finest[i, j, 0] == pytest.approx(1.0)
    assert np.isnan(rate[i, models.index("a"), 0])


# --------------------------------------------------------------------------------------------
# isoparametric quadratic elements: the walls' quadratic nodes on the circles and spheres
# --------------------------------------------------------------------------------------------


def _curved_cylinder_errors(cell_type, nu, levels=(4, 8, 16)):
    l2 = []
    for n in levels:
        mesh = exact.quarter_annulus(A, B, n, cell_type)
        walls = exact.curved_walls(mesh, A, B)
        r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), plane="strain", order=2,
                         volumetric="reduced", linear_solver="direct", pressures=[(exact.inner_wall(mesh, A), P, True)],
                         curved=walls)
        l2.append(exact.l2_error(r, mesh, 2, partial(exact.cylinder_displacement, a=A, b=B, p=P, E=E, nu=nu),
                                 curved=walls))
    return np.array(l2)


@pytest.mark.parametrize("cell_type", ["triangle", "quad"])
def test_cylinder_isoparametric_quadratic_converges_at_order_three_and_does_not_lock(cell_type):
    """With straight sides the order is 2 (above); with the walls' mid-side nodes on the circles it
    is the element's 3, at nu = 0.3 and, with the reduced volumetric rule (one point on P2
    triangles, 2x2 Gauss on Q2), at nu = 0.4999 too."""
    l2 = _curved_cylinder_errors(cell_type, 0.3)
    near = _curved_cylinder_errors(cell_type, 0.4999)
    assert np.all(_slopes(l2) > 2.8)  # measured 3.07, 3.03 (triangles), 2.92, 2.95 (quads)
    assert np.all(_slopes(near) > 2.8)  # measured 3.08, 3.03 (triangles), 2.93, 2.96 (quads)
    assert np.all(near < 1.5 * l2)  # measured at most 1.24 (triangles and quads)
    straight, _ = _cylinder_errors(cell_type, 2, 0.3)
    assert l2[-1] < 0.1 * straight[-1]  # measured 8.1e-6 against 3.3e-4 (triangles), 3.8e-6 against 3.3e-4 (quads)


@lru_cache(maxsize=None)
def _curved_sphere_errors(nu, sizes):
    l2 = []
    for h in sizes:
        mesh = _octant(h)
        walls = exact.curved_walls(mesh, A, B)
        r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), order=2, volumetric="reduced",
                         linear_solver="direct", pressures=[(exact.inner_wall(mesh, A), P, False)], curved=walls)
        l2.append(exact.l2_error(r, mesh, 2, partial(exact.sphere_displacement, a=A, b=B, p=P, E=E, nu=nu),
                                 curved=walls))
    return np.array(l2)


def test_sphere_isoparametric_quadratic_converges_at_order_three_and_does_not_lock():
    e = _curved_sphere_errors(0.3, SIZES)
    near = _curved_sphere_errors(0.4999, SIZES)
    assert _slopes(e)[0] > 2.7 and _slopes(near)[0] > 2.7  # measured 2.84 and 3.02
    assert np.all(near < 2.2 * e)  # measured 1.78, 1.57
    assert e[-1] < 0.1 * _sphere_errors(2, 0.3, SIZES)[0][-1]  # measured 7.9e-4 against 1.4e-2 (straight sides)


@pytest.mark.parametrize("body", ["triangle", "quad", "tetra"])
def test_curved_walls_carry_equal_pressures_to_uniform_compression_to_round_off(body):
    """Isoparametric elements represent a field linear in the physical coordinates, and the
    pressure is integrated on the curved facets: the same pressure on both curved walls gives the
    uniform compression at every dof, which now lies on the circles or spheres."""
    nu = 0.3
    mesh = exact.sphere_octant(A, B, 0.5) if body == "tetra" else exact.quarter_annulus(A, B, 3, body)
    walls = exact.curved_walls(mesh, A, B)
    loads = [(exact.inner_wall(mesh, A), P, False), (exact.inner_wall(mesh, B), P, True)]
    r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), plane="strain", order=2, volumetric="reduced",
                     pressures=loads, curved=walls)
    factor = (1 + nu) * (1 - 2 * nu) if mesh.dim == 2 else (1 - 2 * nu)
    want = -P * factor / E * r.dof_points
    assert np.abs(r.dof_displacement - want).max() < 1e-12 * np.abs(want).max()
    geo = _Geometry(mesh, 2)  # straight sides: the same dofs
    for radius in (A, B):  # every dof of a wall's facets lies on its circle or sphere
        wall = exact.inner_wall(mesh, radius)
        dofs = geo._sk_to_ours[np.asarray(geo.basis.get_dofs(facets=geo.facet_ids(wall)).all()).ravel()]
        assert dofs.size > 2 * len(wall)  # the nodes and the mid-side nodes (and more, on a sphere)
        assert np.abs(np.linalg.norm(r.dof_points[dofs], axis=1) - radius).max() < 1e-14 * radius
        assert np.abs(np.linalg.norm(geo.points[dofs], axis=1) - radius).max() > 1e-3 * radius  # straight: inside


def test_curved_with_the_identity_is_the_straight_sided_solution():
    mesh = exact.quarter_annulus(A, B, 3, "quad")
    kw = dict(fixed=exact.symmetry_supports(mesh), plane="strain", order=2, volumetric="reduced",
              pressures=[(exact.inner_wall(mesh, A), P, False)])
    straight = solve_linear(mesh, E, 0.3, **kw)
    same = solve_linear(mesh, E, 0.3, curved=[(exact.inner_wall(mesh, A), lambda X: X)], **kw)
    assert np.abs(same.dof_displacement - straight.dof_displacement).max() < 1e-12 * np.abs(straight.displacement).max()


def test_curved_is_refused_in_one_line_before_any_solve():
    mesh = exact.quarter_annulus(A, B, 2, "triangle")
    kw = dict(fixed=exact.symmetry_supports(mesh), plane="strain")
    wall = exact.inner_wall(mesh, A)
    boundary = {tuple(sorted(f)) for f in boundary_facets(mesh).tolist()}
    inside = next([a, b] for c in mesh.cells.tolist() for a, b in ((c[0], c[1]), (c[1], c[2]), (c[2], c[0]))
                  if tuple(sorted((a, b))) not in boundary)
    cases = [
        (dict(order=1, curved=[(wall, exact.onto_radius(A))]), r"^curved: only quadratic elements \(order=2\).*order=1$"),
        (dict(order=2, curved=[(wall, 1.0)]), r"^curved\[0\] must be a pair \(facets, project\) with project a "
                                               r"function of points \(k, dim\) -> \(k, dim\), got project of type float$"),
        (dict(order=2, curved=[wall]), r"^curved\[0\] must be a pair .*got a ndarray$"),
        (dict(order=2, curved=[(np.array([inside]), exact.onto_radius(A))]),
         r"^curved\[0\]: facet of nodes \[\d+, \d+\] is not a boundary facet"),
        (dict(order=2, curved=[(wall, lambda X: X[:1])]),
         r"^curved\[0\]: project must map points \(k, 2\) to finite points of the same shape, got shape \(1, 2\)$"),
        (dict(order=2, curved=[(wall, lambda X: X * np.nan)]), r"with non-finite values$"),
    ]
    for extra, message in cases:
        with pytest.raises(ValueError, match=message):
            solve_linear(mesh, E, 0.3, **kw, **extra)


@pytest.mark.parametrize("body", ["triangle", "tetra"])
def test_reduced_volumetric_rule_of_p2_simplices_is_one_point_on_straight_sides(body):
    """On straight-sided P2 simplices the reduced volumetric term is the one-point rule at the
    centroid (weight: the reference simplex's measure), the penalty form of P2-P0; on triangles
    it was scikit-fem's 3-point rule (its triangle rules have 3 points at every degree below 3),
    i.e. not reduced at all."""
    from msslib.fem.solve import _reduced_geometry
    from msslib.fem.space import _linear_stiffness

    mesh = exact.sphere_octant(A, B, 0.6) if body == "tetra" else exact.quarter_annulus(A, B, 3, "triangle")
    d, m = mesh.dim, len(mesh.cells)
    lam, zero = np.ones(m), np.zeros(m)
    one_point = _Geometry(mesh, 2, quadrature=(np.full((d, 1), 1.0 / (d + 1)), np.array([1.0 / (2 if d == 2 else 6)])))
    reduced = _reduced_geometry(mesh)
    K = _linear_stiffness(reduced, lam, zero)
    K1 = _linear_stiffness(one_point, lam, zero)
    assert reduced.dx.shape == (m, 1)
    assert abs(K - K1).max() < 1e-12 * abs(K1).max()
    assert abs(K - _linear_stiffness(_Geometry(mesh, 2), lam, zero)).max() > 1e-3 * abs(K1).max()


def test_finite_strain_solve_on_curved_walls_tends_to_the_linear_one_at_small_pressure():
    """solve_nonlinear takes the same curved walls: at a pressure of 1e-6 E its solution is the
    linear one to O(p^2) (relative 1e-6), and the inversion check passes."""
    from msslib.fem import solve_nonlinear

    mesh = exact.quarter_annulus(A, B, 3, "triangle")
    walls = exact.curved_walls(mesh, A, B)
    p = 1e-6 * E
    kw = dict(fixed=exact.symmetry_supports(mesh), plane="strain", order=2, volumetric="reduced", curved=walls,
              pressures=[(exact.inner_wall(mesh, A), p, True)])
    lin = solve_linear(mesh, E, 0.3, **kw)
    for law in ("svk", "neohookean"):
        r = solve_nonlinear(mesh, E, 0.3, law=law, steps=1, **kw)
        scale = np.abs(lin.dof_displacement).max()
        assert np.abs(r.dof_displacement - lin.dof_displacement).max() < 1e-5 * scale
        assert np.array_equal(r.dof_points, lin.dof_points)

"""Pressure loads of the FEM references (msslib.fem.pressure): the consistent forces against the
mass-spring term's and closed forms, the follower's load stiffness by finite differences, the
guards, a stall, the work of a follower pressure against p times the volume change, and a free
body under pressure on all sides."""

from __future__ import annotations

import numpy as np
import pytest

from msslib.errors import ConvergenceError
from msslib.fem import solve_linear, solve_nonlinear
from msslib.fem.newton import _problem_class
from msslib.fem.pressure import FacetPressure
from msslib.fem.space import _Geometry
from msslib.mesh import Mesh, boundary_facets, hex_grid, quad_grid, tet_grid
from msslib.mesh.structured import triangle_grid_right
from msslib.terms.pressure import pressure_nodal_forces


def _meshes():
    rng = np.random.default_rng(3)
    out = []
    for mesh in (quad_grid(1.0, 1.0, 3, 2), triangle_grid_right(1.0, 1.0, 2, 3), tet_grid(1.0, 1.0, 1.0, 2, 2, 2),
                 hex_grid(1.0, 1.0, 1.0, 2, 2, 1)):
        p = mesh.points + 0.03 * rng.standard_normal(mesh.points.shape)
        out.append(Mesh(p, mesh.cells, mesh.cell_type))
    return out


MESHES = _meshes()
IDS = [m.cell_type for m in MESHES]


@pytest.mark.parametrize("mesh", MESHES, ids=IDS)
def test_linear_elements_give_the_nodal_forces_of_the_pressure_term(mesh):
    """Order 1: dead forces at rest and follower forces at a displaced state are those of
    msslib.terms.pressure.pressure_nodal_forces on the reference and the current positions."""
    t = 0.7 if mesh.dim == 2 else 1.0
    facets = boundary_facets(mesh)[::2]
    geo = _Geometry(mesh, 1)
    u = 0.05 * np.random.default_rng(1).standard_normal(geo.n_dofs)
    dead = FacetPressure(geo, facets, 3.0, False, t)
    follow = FacetPressure(geo, facets, 3.0, True, t)
    at_rest = pressure_nodal_forces(mesh.points, facets, 3.0, t).ravel()
    moved = pressure_nodal_forces(mesh.points + u.reshape(-1, mesh.dim), facets, 3.0, t).ravel()
    assert np.abs(dead.forces(u) - at_rest).max() < 1e-13 * np.abs(at_rest).max()
    assert np.abs(follow.forces() - at_rest).max() < 1e-13 * np.abs(at_rest).max()
    assert np.abs(follow.forces(u) - moved).max() < 1e-13 * np.abs(moved).max()
    assert np.abs(moved - at_rest).max() > 1e-3  # the follower reading differs from the dead one


def test_quadratic_edge_forces_are_one_sixth_two_thirds_one_sixth():
    """A P2 or Q2 edge of length L under p carries p L / 6 at each end and 2 p L / 3 at its middle
    node, normal to the edge (per unit thickness times the thickness)."""
    for mesh in (quad_grid(2.0, 1.0, 2, 1), triangle_grid_right(2.0, 1.0, 2, 1)):
        bf = boundary_facets(mesh)
        top = bf[np.isclose(mesh.points[bf][:, :, 1], 1.0).all(1)]
        geo = _Geometry(mesh, 2)
        f = FacetPressure(geo, top, 5.0, False, 0.5).forces().reshape(-1, 2)
        assert np.abs(f[:, 0]).max() < 1e-14
        fy = {tuple(np.round(geo.points[i], 12)): f[i, 1] for i in np.flatnonzero(np.abs(f[:, 1]) > 1e-14)}
        L, q = 1.0, -5.0 * 0.5  # each top edge is 1 m long; force per length times thickness, downwards
        want = {(0.0, 1.0): q * L / 6, (0.5, 1.0): 2 * q * L / 3, (1.0, 1.0): q * L / 3, (1.5, 1.0): 2 * q * L / 3,
                (2.0, 1.0): q * L / 6}
        assert set(fy) == set(want)
        for key, value in want.items():
            assert fy[key] == pytest.approx(value, rel=1e-13)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("mesh", MESHES, ids=IDS)
def test_follower_load_stiffness_matches_finite_differences(mesh, order):
    geo = _Geometry(mesh, order)
    load = FacetPressure(geo, boundary_facets(mesh)[1::2], 2.5, True, 0.8)
    u = 0.05 * np.random.default_rng(2).standard_normal(geo.n_dofs)
    K = load.stiffness(u).toarray()
    h = 1e-6
    fd = np.empty_like(K)
    for j in range(geo.n_dofs):
        e = np.zeros(geo.n_dofs)
        e[j] = h
        fd[:, j] = (load.forces(u + e) - load.forces(u - e)) / (2 * h)
    assert np.abs(K - fd).max() < 1e-8 * np.abs(K).max()
    assert np.abs(K - K.T).max() > 1e-3 * np.abs(K).max()  # not symmetric on an open surface
    assert FacetPressure(geo, boundary_facets(mesh)[:2], 2.5, False).stiffness(u).nnz == 0


def test_follower_makes_the_newton_problem_non_symmetric():
    mesh = quad_grid(1.0, 1.0, 2, 2)
    geo = _Geometry(mesh, 1)
    n = geo.n_dofs
    args = (lambda u, t: None, np.zeros(n), np.zeros(n, bool), np.zeros(n), geo.points)
    assert _problem_class()(*args).symmetric is True
    assert _problem_class()(*args, [FacetPressure(geo, boundary_facets(mesh)[:1], 1.0, True)]).symmetric is False


def _block():
    mesh = quad_grid(1.0, 1.0, 3, 3)
    bf = boundary_facets(mesh)
    top = bf[np.isclose(mesh.points[bf][:, :, 1], 1.0).all(1)]
    fixed = np.zeros((mesh.n_nodes, 2), bool)
    fixed[np.isclose(mesh.points[:, 1], 0.0), 1] = True
    fixed[0, 0] = True
    return mesh, top, fixed


def test_linear_solve_of_a_pressed_block_is_uniaxial_compression():
    """A block on rollers under p on its top: sigma_yy = -p, u_y = -p y (1 - nu^2) / E in plane
    strain, u_x = p x nu (1 + nu) / E; exact for linear and quadratic elements."""
    mesh, top, fixed = _block()
    E, nu, p = 200.0, 0.3, 2.0
    for order in (1, 2):
        for follow in (False, True):  # follow has no effect in small strain
            r = solve_linear(mesh, E, nu, fixed=fixed, plane="strain", order=order, pressures=[(top, p, follow)])
            x, y = mesh.points.T
            assert np.allclose(r.displacement[:, 1], -p * y * (1 - nu**2) / E, rtol=0, atol=1e-13)
            assert np.allclose(r.displacement[:, 0], p * x * nu * (1 + nu) / E, rtol=0, atol=1e-13)
            assert r.reaction[:, 1].sum() == pytest.approx(p * 1.0, rel=1e-12)


@pytest.mark.parametrize("bad, message", [
    ("nan", "pressures[0]: pressure must be a finite number (Pa), got nan"),
    ("empty", "pressures[0]: facets is empty"),
    ("inner", "is not a boundary facet of the mesh"),
    ("follow", "pressures[0]: follow must be True (follower) or False (dead), got 'yes'"),
    ("shape", "pressures[0]: facets must be node ids of shape (k, 2)"),
    ("ids", "pressures[0]: facets: node ids must lie in 0..15, got 16"),
    ("twice", "pressures[0]: facet of nodes [12, 13] is listed twice; give each loaded facet once"),
])
def test_bad_pressures_are_refused_in_one_line(bad, message):
    mesh, top, fixed = _block()
    entry = {"nan": (top, float("nan"), True), "empty": (np.zeros((0, 2), int), 1.0, True),
             "inner": (np.array([[5, 6]]), 1.0, True), "follow": (top, 1.0, "yes"),
             "shape": (top.ravel(), 1.0, True), "ids": (np.array([[15, 16]]), 1.0, True),
             "twice": (np.vstack([top, top[:1][:, ::-1]]), 1.0, False)}[bad]
    for solve in (solve_linear, solve_nonlinear):
        with pytest.raises(ValueError) as info:
            solve(mesh, 1.0, 0.3, fixed=fixed, pressures=[entry])
        assert message in str(info.value)
        assert "\n" not in str(info.value)


def test_pressure_on_wedges_is_refused_in_one_line():
    from msslib.mesh import boundary_facets_by_type, wedge_grid

    mesh = wedge_grid(1.0, 1.0, 1.0, 2, 2, 2)
    top = boundary_facets_by_type(mesh)["triangle"][0][:1]
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    with pytest.raises(ValueError, match=r"^pressures: the FEM references take pressures on meshes whose facets are "
                                         r"of one type \(triangle, quad, tetra or hexahedron cells\), got wedge cells$"):
        solve_linear(mesh, 1.0, 0.3, fixed=fixed, pressures=[(top, 1.0, False)])


def test_follower_inflation_past_its_limit_stops_with_the_load_factor_reached():
    """A thin neo-Hookean ring (radius 1, wall 0.1, plane strain) inflated by a follower pressure:
    its hoop force saturates, so the pressure it holds is bounded (about mu t / R = 0.038 E); a
    pressure of 0.1 E has no equilibrium. The solve stops with ConvergenceError naming the last
    converged load factor, there p lambda lies near the bound; the dead reading of the same
    pressure (fixed nodal forces) has a solution."""
    base = quad_grid(1.0, 1.0, 2, 8)
    x, y = base.points.T
    r, t = 1.0 + 0.1 * x, 0.5 * np.pi * y
    mesh = Mesh(np.column_stack([r * np.cos(t), r * np.sin(t)]), base.cells, "quad")
    bf = boundary_facets(mesh)
    inner = bf[np.isclose(np.hypot(*mesh.points[bf].transpose(2, 0, 1)), 1.0).all(1)]
    fixed = np.zeros((mesh.n_nodes, 2), bool)
    fixed[np.isclose(mesh.points[:, 1], 0.0, atol=1e-12), 1] = True
    fixed[np.isclose(mesh.points[:, 0], 0.0, atol=1e-12), 0] = True
    kw = dict(fixed=fixed, plane="strain", law="neohookean", steps=5, max_halvings=6)
    dead = solve_nonlinear(mesh, 1.0, 0.3, pressures=[(inner, 0.1, False)], **kw)
    assert dead.stats["load_factors"][-1] == 1.0
    with pytest.raises(ConvergenceError) as info:
        solve_nonlinear(mesh, 1.0, 0.3, pressures=[(inner, 0.1, True)], **kw)
    msg = str(info.value)
    assert "last converged load factor" in msg
    reached = float(msg.split("last converged load factor ")[1].split(",")[0])
    assert 0.025 < 0.1 * reached < 0.045


def _cavity_area(points):
    """Area enclosed by the axes and the polygon of ``points`` (ordered from the x axis to the y axis)."""
    x, y = np.vstack([[0.0, 0.0], points]).T
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def _annulus(n):
    base = quad_grid(1.0, 1.0, n, 2 * n)
    x, y = base.points.T
    r, t = 1.0 + x, 0.5 * np.pi * y
    return Mesh(np.column_stack([r * np.cos(t), r * np.sin(t)]), base.cells, "quad")


@pytest.mark.parametrize("order", [1, 2])
def test_follower_work_equals_pressure_times_cavity_volume_change(order):
    """Inflating a neo-Hookean quarter ring (plane strain, 10 % radial growth of the cavity): the
    work of the follower pressure along the load path, sum over increments of the trapezoid of
    lambda f(u) . du, equals the trapezoid of lambda p dV of the cavity (per thickness t), to the
    integration error (second order: halving the increments divides the difference by 4)."""
    mesh = _annulus(3)
    bf = boundary_facets(mesh)
    inner = bf[np.isclose(np.hypot(*mesh.points[bf].transpose(2, 0, 1)), 1.0).all(1)]
    fixed = np.zeros((mesh.n_nodes, 2), bool)
    fixed[np.isclose(mesh.points[:, 1], 0.0, atol=1e-12), 1] = True
    fixed[np.isclose(mesh.points[:, 0], 0.0, atol=1e-12), 0] = True
    ring = np.flatnonzero(np.isclose(np.hypot(*mesh.points.T), 1.0))
    ring = ring[np.argsort(np.arctan2(mesh.points[ring, 1], mesh.points[ring, 0]))]
    p, t = 0.15, 0.5
    gaps = []
    for n in (8, 16):
        geo = _Geometry(mesh, order)
        load = FacetPressure(geo, inner, p, True, t)
        us, works, volumes = [np.zeros(geo.n_dofs)], [0.0], [0.0]
        for k in range(1, n + 1):
            lam = k / n
            r = solve_nonlinear(mesh, 1.0, 0.3, fixed=fixed, plane="strain", law="neohookean", order=order,
                                steps=k, thickness=t, pressures=[(inner, lam * p, True)])
            u = r.dof_displacement.ravel()
            f0, f1 = (k - 1) / n * load.forces(us[-1]), lam * load.forces(u)
            works.append(works[-1] + 0.5 * (f0 + f1) @ (u - us[-1]))
            us.append(u)
            V = t * _cavity_area(mesh.points[ring] + r.displacement[ring])
            if order == 2:  # the quadratic arcs add 2/3 of the area between each chord and its mid-side node
                V = t * _cavity_area(_inner_polygon(geo, u, ring))
            V0 = t * _cavity_area(mesh.points[ring]) if order == 1 else t * _cavity_area(
                _inner_polygon(geo, np.zeros(geo.n_dofs), ring))
            volumes.append(V - V0)
        pdV = sum(0.5 * ((k - 1) / n + k / n) * p * (volumes[k] - volumes[k - 1]) for k in range(1, n + 1))
        assert volumes[-1] > 0.05 * t * _cavity_area(mesh.points[ring])  # a large deformation
        gaps.append(abs(works[-1] - pdV) / pdV)
    assert gaps[0] < 5e-3
    assert gaps[1] < 0.3 * gaps[0]  # second order in the increment (measured: 0.25)


def _inner_polygon(geo, u, ring):
    """Points of the current inner wall: the nodes of ``ring`` and, between each pair, a point
    that makes the polygon's shoelace area the exact area under the quadratic arcs."""
    X = geo.points + u.reshape(-1, 2)
    pts = [X[ring[0]]]
    for a, b in zip(ring[:-1], ring[1:]):
        mid_ref = 0.5 * (geo.points[a] + geo.points[b])
        m = int(np.argmin(np.linalg.norm(geo.points - mid_ref, axis=1)))
        xa, xb, xm = X[a], X[b], X[m]
        # the parabola through xa, xm, xb encloses with its chord 4/3 of the triangle (xa, xm, xb);
        # the polygon point c = c0 + 4/3 (xm - c0), c0 the chord's middle, gives a triangle
        # (xa, c, xb) of that area
        c0 = 0.5 * (xa + xb)
        pts.append(c0 + 4.0 / 3.0 * (xm - c0))
        pts.append(xb)
    return np.array(pts)


@pytest.mark.parametrize("mesh, order", [(quad_grid(1.0, 0.5, 2, 2), 1), (triangle_grid_right(1.0, 0.5, 2, 2), 2),
                                         (hex_grid(1.0, 0.5, 0.5, 2, 1, 1), 1), (tet_grid(1.0, 0.5, 0.5, 2, 1, 1), 2)],
                         ids=["quad-1", "triangle-2", "hexahedron-1", "tetra-2"])
def test_free_body_under_pressure_on_all_sides_has_zero_resultant_and_torque(mesh, order):
    """A body held by statically determinate supports (no force but against rigid motion) under a
    follower pressure on its whole surface: at every load level the pressure forces have zero
    resultant and zero torque about the origin (closed surface), so the supports react nothing,
    while the body is compressed."""
    d = mesh.dim
    bf = boundary_facets(mesh)
    fixed = np.zeros((mesh.n_nodes, d), bool)
    corner = np.flatnonzero(np.all(np.isclose(mesh.points, 0.0), axis=1))[0]
    fixed[corner] = True
    ex = np.flatnonzero(np.isclose(mesh.points[:, 0], 1.0) & np.all(np.isclose(mesh.points[:, 1:], 0.0), axis=1))[0]
    fixed[ex, 1:] = True
    if d == 3:
        ey = np.flatnonzero(np.isclose(mesh.points[:, 1], 0.5) & np.isclose(mesh.points[:, 0], 0.0)
                            & np.isclose(mesh.points[:, 2], 0.0))[0]
        fixed[ey, 2] = True
    p, E = 0.3, 1.0
    geo = _Geometry(mesh, order)
    load = FacetPressure(geo, bf, p, True)
    for lam in (1 / 3, 2 / 3, 1.0):
        r = solve_nonlinear(mesh, E, 0.3, fixed=fixed, law="neohookean", order=order, steps=3,
                            plane="strain", pressures=[(bf, lam * p, True)])
        x = geo.points + r.dof_displacement
        f = lam * load.forces(r.dof_displacement.ravel()).reshape(-1, d)
        scale = np.abs(f).sum()
        assert np.abs(f.sum(axis=0)).max() < 1e-13 * scale
        torque = np.cross(x, f).sum(axis=0)
        assert np.abs(torque).max() < 1e-13 * scale
        assert np.abs(r.reaction).max() < 1e-8 * scale
        assert r.displacement[ex, 0] < -0.02  # compressed: the far corner moved towards the held one


def test_follower_work_equals_pressure_times_cavity_volume_change_in_3d():
    """The same on an octant of a thick neo-Hookean sphere (linear tetrahedra, radii 1 and 2):
    the cavity's volume is the cone of the inner wall's facets from the centre (the symmetry planes
    pass through it), ``V = -sum x0 . (x1 x x2) / 6`` over the outward facets."""
    from msslib.fem import exact

    mesh = exact.sphere_octant(1.0, 2.0, 0.5)
    inner = exact.inner_wall(mesh, 1.0)
    fixed = exact.symmetry_supports(mesh)
    p = 0.2

    def volume(x):
        a, b, c = x[inner[:, 0]], x[inner[:, 1]], x[inner[:, 2]]
        return -np.einsum("ki,ki->", a, np.cross(b, c)) / 6.0

    assert 0.85 * np.pi / 6 < volume(mesh.points) < np.pi / 6  # an eighth of the unit ball, faceted inside it
    geo = _Geometry(mesh, 1)
    load = FacetPressure(geo, inner, p, True)
    gaps = []
    for n in (4, 8):
        u_prev, work, pdv = np.zeros(geo.n_dofs), 0.0, 0.0
        for k in range(1, n + 1):
            r = solve_nonlinear(mesh, 1.0, 0.3, fixed=fixed, law="neohookean", steps=k,
                                pressures=[(inner, k / n * p, True)])
            u = r.dof_displacement.ravel()
            work += 0.5 * ((k - 1) / n * load.forces(u_prev) + k / n * load.forces(u)) @ (u - u_prev)
            dv = volume(mesh.points + u.reshape(-1, 3)) - volume(mesh.points + u_prev.reshape(-1, 3))
            pdv += 0.5 * (2 * k - 1) / n * p * dv
            u_prev = u
        assert volume(mesh.points + u_prev.reshape(-1, 3)) > 1.1 * volume(mesh.points)  # a large inflation
        gaps.append(abs(work - pdv) / pdv)
    assert gaps[0] < 2e-2
    assert gaps[1] < 0.3 * gaps[0]  # second order in the increment


@pytest.mark.parametrize("order", [1, 2])
def test_newton_converges_quadratically_with_the_follower_load_stiffness(order):
    """A block pressed by a follower pressure, one load step: with the load stiffness in the
    tangent, Newton's residuals fall quadratically (r_k+1 <= r_k^2 in units of the load, measured
    0.16 r_k^2 with quadratic elements)."""
    mesh, top, fixed = _block()
    r = solve_nonlinear(mesh, 1.0, 0.3, fixed=fixed, plane="strain", law="neohookean", steps=1, tol=1e-13,
                        order=order, pressures=[(top, 0.2, True)])
    res = r.stats["residuals"][0]
    pairs = [(a, b) for a, b in zip(res[:-1], res[1:]) if 1e-7 < a < 0.5]
    assert len(pairs) >= 2
    assert all(b < a**2 for a, b in pairs), res

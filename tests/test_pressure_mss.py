"""The pressure term of the mass-spring models (msslib.terms.pressure): consistent nodal forces,
the follower's load stiffness against finite differences, the closed-surface identity
f = -p grad V, the free-body balance, and Newton's quadratic convergence on the non-symmetric
tangent."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from msslib import mesh as M
from msslib.scene import load_scene, prepare
from msslib.solvers import static_solve
from msslib.solvers.policy import choose_linear_solver
from msslib.terms import Pressure, pressure_nodal_forces

MESHES = {
    "tetra": lambda: M.tet_grid(1.0, 1.2, 0.8, 2, 2, 2),
    "hexahedron": lambda: M.hex_grid(1.0, 1.2, 0.8, 2, 2, 2),
    "quad": lambda: M.quad_grid(1.0, 1.2, 3, 2),
    "triangle": lambda: M.triangle_grid_right(1.0, 1.2, 2, 3),
}


def _moved(mesh, seed=0, amount=0.07):
    return mesh.points + amount * np.random.default_rng(seed).standard_normal(mesh.points.shape)


def _volume(mesh, x):
    """The volume (area in 2D) of the mesh's cells at positions x: exact for tetrahedra, triangles,
    and for the trilinear hexahedra and bilinear quads whose boundary the pressure term integrates."""
    return float(M.cell_measures(dataclasses.replace(mesh, points=x.reshape(mesh.points.shape))).sum())


def _fd_gradient(fun, x, h=1e-6):
    g = np.zeros(x.size)
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        g[i] = (fun(x + e) - fun(x - e)) / (2 * h)
    return g


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_closed_surface_follower_force_is_minus_p_grad_volume(kind):
    # independent check: the enclosed volume from the cells' measures, differentiated numerically
    mesh = MESHES[kind]()
    facets = M.boundary_facets(mesh)
    x = _moved(mesh)
    p = 2.5e3
    f = pressure_nodal_forces(x, facets, p)
    grad = _fd_gradient(lambda y: _volume(mesh, y), x.ravel())
    assert np.abs(f.ravel() + p * grad).max() < 1e-6 * p


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_free_body_zero_resultant_and_torque_at_deformed_states(kind):
    mesh = MESHES[kind]()
    facets = M.boundary_facets(mesh)
    for seed in range(3):
        x = _moved(mesh, seed, 0.1)
        f = pressure_nodal_forces(x, facets, 1.0e4)
        scale = 1.0e4 * np.abs(x).max() ** 2
        assert np.abs(f.sum(axis=0)).max() < 1e-12 * scale
        if mesh.dim == 3:
            torque = np.cross(x, f).sum(axis=0)
        else:
            torque = np.array([(x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0]).sum()])
        assert np.abs(torque).max() < 1e-12 * scale * np.abs(x).max()


def test_dead_pressure_resultant_on_flat_faces_is_p_times_area():
    p = 700.0
    # 3D hexahedra: the top face z = 0.8 has area 1.0 x 1.2, outward normal +z
    hexes = M.hex_grid(1.0, 1.2, 0.8, 2, 3, 2)
    top = M.boundary_facets(hexes)
    top = top[np.all(np.isclose(hexes.points[top][:, :, 2], 0.8), axis=1)]
    np.testing.assert_allclose(pressure_nodal_forces(hexes.points, top, p).sum(axis=0), [0, 0, -p * 1.2], atol=1e-9)
    # tetrahedra: the face x = 1, area 1.2 x 0.8, normal +x
    tets = M.tet_grid(1.0, 1.2, 0.8, 2, 2, 2)
    side = M.boundary_facets(tets)
    side = side[np.all(np.isclose(tets.points[side][:, :, 0], 1.0), axis=1)]
    np.testing.assert_allclose(pressure_nodal_forces(tets.points, side, p).sum(axis=0), [-p * 0.96, 0, 0], atol=1e-9)
    # 2D edges per thickness: the edge y = 1.2 of length 1.0, 0.01 m thick, normal +y
    quads = M.quad_grid(1.0, 1.2, 4, 3)
    edge = M.boundary_facets(quads)
    edge = edge[np.all(np.isclose(quads.points[edge][:, :, 1], 1.2), axis=1)]
    f = pressure_nodal_forces(quads.points, edge, p, thickness=0.01)
    np.testing.assert_allclose(f.sum(axis=0), [0, -p * 0.01], atol=1e-12)
    # consistent split: each interior node of the edge takes a quarter of p t L, the two ends an eighth
    loaded = np.sort(f[np.abs(f[:, 1]) > 0, 1])
    np.testing.assert_allclose(loaded, np.sort([-p * 0.01 / 8] * 2 + [-p * 0.01 / 4] * 3))


def test_bilinear_quad_forces_are_the_exact_integral_on_a_warped_facet():
    # a warped quad: its consistent force on corner a is -p int N_a (x_u x x_v) du dv, integrated here
    # with a 6 x 6 Gauss rule (the integrand is a polynomial of degree 2 in each variable)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.2], [1.1, 0.9, -0.1], [-0.1, 1.2, 0.3]])
    su = np.array([-1.0, 1.0, 1.0, -1.0])
    sv = np.array([-1.0, -1.0, 1.0, 1.0])
    g, w = np.polynomial.legendre.leggauss(6)
    want = np.zeros((4, 3))
    for u, wu in zip(g, w):
        for v, wv in zip(g, w):
            n = 0.25 * (1 + su * u) * (1 + sv * v)
            xu = (0.25 * su * (1 + sv * v)) @ x
            xv = (0.25 * sv * (1 + su * u)) @ x
            want -= 3.0 * wu * wv * n[:, None] * np.cross(xu, xv)[None, :]
    np.testing.assert_allclose(pressure_nodal_forces(x, np.array([[0, 1, 2, 3]]), 3.0), want, rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_follower_load_stiffness_matches_finite_differences_on_an_open_surface(kind):
    mesh = MESHES[kind]()
    facets = M.boundary_facets(mesh)
    top = facets[np.all(np.isclose(mesh.points[facets][:, :, -1], mesh.points[:, -1].max()), axis=1)]
    term = Pressure(mesh, top, 3.0e3, thickness=0.05 if mesh.dim == 2 else 1.0)
    x = _moved(mesh, 4).ravel()
    rows, cols = term.hessian_pattern()
    H = sp.coo_matrix((term.hessian_values(x), (rows, cols)), shape=(x.size, x.size)).toarray()
    h = 1e-6
    fd = np.column_stack([(term.gradient(x + h * e) - term.gradient(x - h * e)) / (2 * h) for e in np.eye(x.size)])
    assert np.abs(H - fd).max() < 1e-6 * np.abs(H).max()
    if mesh.dim == 3:  # an open surface's load stiffness is not symmetric
        assert np.abs(H - H.T).max() > 1e-3 * np.abs(H).max()


def test_dead_reading_is_constant_and_the_follower_is_not():
    mesh = MESHES["hexahedron"]()
    facets = M.boundary_facets(mesh)[:5]
    dead = Pressure(mesh, facets, 100.0, follow=False)
    follower = Pressure(mesh, facets, 100.0)
    x = _moved(mesh).ravel()
    np.testing.assert_array_equal(dead.gradient(x), -pressure_nodal_forces(mesh.points, facets, 100.0).ravel())
    np.testing.assert_array_equal(follower.gradient(x), -pressure_nodal_forces(x.reshape(-1, 3), facets, 100.0).ravel())
    np.testing.assert_array_equal(follower.gradient(mesh.points), dead.gradient(x))
    assert dead.symmetric and dead.energy(x) is not None and len(dead.hessian_pattern()[0]) == 0
    assert not follower.symmetric and not follower.conservative and follower.energy(x) is None


def _scene(pressure, follow=True, n=3, model="golec_cube"):
    return load_scene({
        "name": "pressure", "geometry": {"generator": "hex_grid", "args": {"lx": 1.0, "ly": 1.0, "lz": 1.0,
                                                                          "nx": n, "ny": n, "nz": n}},
        "materials": [{"E": 1.0e4, "nu": 0.3}], "model": model,
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
        "loads": [{"type": "pressure", "select": {"plane": ["x", 1.0]}, "pressure": pressure, "follow": follow}]})


def test_model_with_a_follower_pressure_tells_the_solvers_its_tangent_is_not_symmetric():
    follower = prepare(_scene(1.0e3)).model
    dead = prepare(_scene(1.0e3, follow=False)).model
    assert dead.symmetric and not follower.symmetric
    K = follower.stiffness(follower.x0 + 0.01, 1.0).toarray()
    assert np.abs(K - K.T).max() > 0
    # "auto" never takes CG (nor a Cholesky) for a non-symmetric tangent, however large
    assert choose_linear_solver("auto", 10**6, follower.symmetric) != "cg"


@pytest.mark.parametrize("n, pressure", [(3, 1.5e3), (9, 500.0)])
def test_follower_newton_converges_quadratically(n, pressure):
    # 9^3 cells: 2700 free dofs, beyond the size where "auto" takes CG for a symmetric tangent
    model = prepare(_scene(pressure, n=n)).model
    res = static_solve(model, model.x0, load_steps=1, tol=1e-12, max_iter=30)
    r = np.array(res.residuals[-1])
    assert r[-1] <= 1e-12 * r[0] * 10
    rel = r / r[0]
    tail = [(a, b) for a, b in zip(rel[:-1], rel[1:]) if a < 1e-2]
    assert len(tail) >= 2
    for a, b in tail:  # quadratic: the next residual within a constant of the square of this one
        assert b <= 10.0 * a * a + 1e-13
    # the solution is the follower's equilibrium: its forces on the deformed face, not at rest
    f = model.force(res.x, 1.0)[model.free]
    assert np.abs(f).max() < 1e-9 * r[0]


def test_pressure_refusals_name_the_argument():
    mesh = MESHES["hexahedron"]()
    facets = M.boundary_facets(mesh)
    with pytest.raises(ValueError, match=r"^pressure must be finite \(Pa\), got nan"):
        pressure_nodal_forces(mesh.points, facets, float("nan"))
    with pytest.raises(ValueError, match=r"^facets must be whole node ids of shape \(k, 3\) or \(k, 4\)"):
        pressure_nodal_forces(mesh.points, facets[:, :2], 1.0)
    with pytest.raises(ValueError, match=r"^facets: node ids must lie in 0\.\.26, got 27"):
        pressure_nodal_forces(mesh.points, facets + 27 - facets.max(), 1.0)
    with pytest.raises(ValueError, match=r"^thickness applies to 2D meshes only, got 2\.0"):
        Pressure(mesh, facets, 1.0, thickness=2.0)
    with pytest.raises(ValueError, match=r"^facets: a pressure needs at least one facet"):
        Pressure(mesh, facets[:0], 1.0)
    with pytest.raises(ValueError, match=r"^follow must be true or false, got 'yes'"):
        Pressure(mesh, facets, 1.0, follow="yes")


def _square_ring(pressure, follow=True, k=100.0, R=1.0):
    """Four springs (k, rest length sqrt(2) R) joining the nodes (R, 0), (0, R), (-R, 0), (0, -R), each
    node free along its radius only, and a pressure pulling the ring outward (negative on the
    outward edges).  Exact radius: follower r = 2 k R / (2 k - |p|) (no equilibrium from |p| = 2 k,
    where the radial stiffness 2 k - |p| vanishes), dead r = R (1 + |p| / (2 k))."""
    from msslib.mesh import Mesh
    from msslib.system import Model
    from msslib.terms import Springs

    pts = np.array([[R, 0.0], [0.0, R], [-R, 0.0], [0.0, -R], [0.0, 0.0]])
    mesh = Mesh(pts, np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]), "triangle")
    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    fixed = np.zeros((5, 2), dtype=bool)
    fixed[4] = True
    fixed[[0, 2], 1] = True
    fixed[[1, 3], 0] = True
    terms = [Springs(edges, k, np.full(4, np.sqrt(2.0) * R), 2), Pressure(mesh, edges, -pressure, follow=follow)]
    return Model(mesh, terms, fixed=fixed, masses=np.ones(5))


@pytest.mark.parametrize("follow, radius", [(True, 2.0), (False, 1.5)])
def test_pressurised_ring_reaches_the_exact_radius(follow, radius):
    model = _square_ring(100.0, follow)
    res = static_solve(model, model.x0, load_steps=2, tol=1e-12)
    r = np.linalg.norm(res.x.reshape(-1, 2)[:4], axis=1)
    np.testing.assert_allclose(r, radius, rtol=1e-12)


def test_a_follower_load_past_its_limit_stops_at_the_load_factor_reached_and_says_so():
    from msslib.solvers import ConvergenceError

    # |p| = 4 k: the tangent's radial stiffness 2 k - lambda |p| vanishes at lambda = 1/2
    model = _square_ring(400.0)
    with pytest.raises(ConvergenceError) as info:
        static_solve(model, model.x0, load_steps=4, tol=1e-10)
    message = str(info.value)
    reached = float(message.split("last converged load factor ")[1].split(",")[0])
    assert 0.49 < reached < 0.5 and info.value.load <= 0.5 + 1e-12
    assert "\n" not in message


def test_copies_keep_the_reading():
    import copy
    import pickle

    mesh = MESHES["hexahedron"]()
    facets = M.boundary_facets(mesh)[:3]
    x = _moved(mesh).ravel()
    for term in (Pressure(mesh, facets, 50.0, follow=False), Pressure(mesh, facets, 50.0)):
        for other in (copy.deepcopy(term), pickle.loads(pickle.dumps(term))):
            assert type(other) is type(term) and other.follow == term.follow
            np.testing.assert_array_equal(other.gradient(x), term.gradient(x))


@pytest.mark.parametrize("kind", ["tetra", "hexahedron"])
def test_follower_work_on_a_closed_surface_is_minus_p_times_the_volume_change(kind):
    # along the straight path x0 -> x1 the forces are quadratic in the path parameter, so two Gauss
    # points integrate their work exactly; the volumes come from the cells (exact for both cell types)
    mesh = MESHES[kind]()
    facets = M.boundary_facets(mesh)
    x0, x1 = mesh.points, _moved(mesh, 7, 0.1)
    p = 1.7e3
    work = 0.0
    for s, w in zip(*np.polynomial.legendre.leggauss(2)):
        x = x0 + 0.5 * (1 + s) * (x1 - x0)
        work += 0.5 * w * float(np.sum(pressure_nodal_forces(x, facets, p) * (x1 - x0)))
    dv = _volume(mesh, x1.ravel()) - _volume(mesh, x0.ravel())
    assert abs(dv) > 1e-3
    assert work == pytest.approx(-p * dv, rel=1e-12)

"""Tests of the FEM references in :mod:`msslib.fem` against closed-form solutions."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from msslib import fem
from msslib.mesh import Mesh

# ---------------------------------------------------------------------------------------------
# small structured meshes (VTK node order), built here so the tests do not depend on generators
# ---------------------------------------------------------------------------------------------


def quad_grid(L, H, nx, ny, *, jitter=0.0, seed=0):
    x, y = np.linspace(0, L, nx + 1), np.linspace(0, H, ny + 1)
    X, Y = np.meshgrid(x, y, indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel()]
    idx = lambda i, j: i * (ny + 1) + j  # noqa: E731
    cells = [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)] for i in range(nx) for j in range(ny)]
    if jitter:
        rng = np.random.default_rng(seed)
        inner = (pts[:, 0] > 1e-12) & (pts[:, 0] < L - 1e-12) & (pts[:, 1] > 1e-12) & (pts[:, 1] < H - 1e-12)
        pts[inner] += jitter * rng.uniform(-1, 1, (inner.sum(), 2)) * [L / nx, H / ny]
    return Mesh(pts, np.array(cells), "quad")


def tri_grid(L, H, nx, ny, **kw):
    q = quad_grid(L, H, nx, ny, **kw)
    c = q.cells
    return Mesh(q.points, np.r_[c[:, [0, 1, 2]], c[:, [0, 2, 3]]], "triangle")


def hex_grid(L, W, H, nx, ny, nz, material=None):
    x, y, z = np.linspace(0, L, nx + 1), np.linspace(0, W, ny + 1), np.linspace(0, H, nz + 1)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    pts = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k  # noqa: E731
    cells = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        b = [idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k), idx(i, j + 1, k)]
        t = [idx(i, j, k + 1), idx(i + 1, j, k + 1), idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)]
        cells.append(b + t)
    cells = np.array(cells)
    mat = None if material is None else material(pts[cells].mean(axis=1))
    return Mesh(pts, cells, "hexahedron", mat)


def tet_grid(L, W, H, nx, ny, nz):
    """Kuhn split of every hexahedron into 6 positively oriented tetrahedra (conforming)."""
    h = hex_grid(L, W, H, nx, ny, nz)
    corner = {(0, 0, 0): 0, (1, 0, 0): 1, (1, 1, 0): 2, (0, 1, 0): 3, (0, 0, 1): 4, (1, 0, 1): 5, (1, 1, 1): 6, (0, 1, 1): 7}
    local = []
    for perm in itertools.permutations(range(3)):
        v = np.zeros(3, int)
        path = [corner[tuple(v)]]
        for ax in perm:
            v[ax] = 1
            path.append(corner[tuple(v)])
        local.append(path)
    cells = h.cells[:, np.array(local)].reshape(-1, 4)
    p = h.points[cells]
    det = np.linalg.det(np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=1))
    cells[det < 0] = cells[det < 0][:, [0, 2, 1, 3]]
    return Mesh(h.points, cells, "tetra")


def tributary(coord):
    """Trapezoid weights of the nodes of a (possibly irregular) 1D grid, per node."""
    u = np.unique(np.round(coord, 12))
    w = np.zeros(len(u))
    w[:-1] += np.diff(u) / 2
    w[1:] += np.diff(u) / 2
    return w[np.searchsorted(u, np.round(coord, 12))]


def face_load(mesh, axis, value, traction):
    """Consistent nodal loads of a uniform traction on the axis-aligned face ``x_axis == value``
    of a structured quad/hex grid (exact for bilinear faces and linear edges)."""
    pts = mesh.points
    on = np.isclose(pts[:, axis], value)
    w = np.ones(on.sum())
    for other in range(mesh.dim):
        if other != axis:
            w = w * tributary(pts[on, other])
    f = np.zeros_like(pts)
    f[on] = w[:, None] * np.asarray(traction, float)[None, :]
    return f


def symmetry_bc(mesh):
    """Roller supports on the coordinate planes x=0, y=0 (, z=0)."""
    fixed = np.zeros(mesh.points.shape, bool)
    for ax in range(mesh.dim):
        fixed[np.isclose(mesh.points[:, ax], 0.0), ax] = True
    return fixed


# ---------------------------------------------------------------------------------------------
# node orders and element matrices
# ---------------------------------------------------------------------------------------------

UNIT = {
    "triangle": np.array([[0, 0], [1, 0], [0, 1.0]]),
    "quad": np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]),
    "tetra": np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]),
    "hexahedron": np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]]),
}


@pytest.mark.parametrize("cell_type, volume", [("triangle", 3.0), ("quad", 6.0), ("tetra", 1.0), ("hexahedron", 6.0)])
def test_skfem_conversion_volume(cell_type, volume):
    """Scaled unit element (3 x 2 x 1): the converted mesh integrates the right volume/area and
    the isoparametric map sends the quadrature points inside the element."""
    import skfem

    scale = np.array([3.0, 2.0, 1.0])[: UNIT[cell_type].shape[1]]
    mesh = Mesh(UNIT[cell_type] * scale, np.arange(len(UNIT[cell_type]))[None], cell_type)
    skm, elem = fem.to_skfem(mesh)
    basis = skfem.Basis(skm, elem, intorder=2)
    assert np.sum(basis.dx) == pytest.approx(volume, rel=1e-12)
    # constant Jacobian (affine) on a box: |det DF| equal at all quadrature points
    det = np.abs(basis.mapping.detDF(basis.X))
    assert np.allclose(det, det.flat[0])
    x = basis.mapping.F(basis.X)
    assert np.all(x >= -1e-12) and np.all(x <= scale[:, None, None] + 1e-12)


def test_hex_permutation_is_the_skfem_order():
    """The VTK -> MeshHex1 permutation puts the unit cube's corners at MeshHex1's default doflocs."""
    import skfem

    sk = skfem.MeshHex1()
    assert np.array_equal(UNIT["hexahedron"][fem.HEX_VTK_TO_SKFEM], sk.p[:, sk.t[:, 0]].T)


def _rigid_modes(coords):
    n, d = coords.shape
    modes = [np.tile(np.eye(d)[i], n) for i in range(d)]
    rots = [(0, 1)] if d == 2 else [(0, 1), (1, 2), (2, 0)]
    for a, b in rots:
        r = np.zeros((n, d))
        r[:, a], r[:, b] = -coords[:, b], coords[:, a]
        modes.append(r.ravel())
    return np.array(modes)


@pytest.mark.parametrize("cell_type", list(UNIT))
def test_element_stiffness_symmetric_rigid_modes(cell_type):
    coords = UNIT[cell_type] * 1.3 + 0.2
    K = fem.element_stiffness(cell_type, coords, 7.0, 0.3)
    n, d = coords.shape
    assert K.shape == (n * d, n * d)
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    R = _rigid_modes(coords)
    assert np.abs(K @ R.T).max() < 1e-12 * np.abs(K).max()
    n_rigid = 3 if d == 2 else 6
    eig = np.linalg.eigvalsh(K)
    assert np.sum(eig < 1e-10 * eig.max()) == n_rigid  # exactly the rigid modes (full integration)
    assert eig.min() > -1e-10 * eig.max()


def test_element_stiffness_known_entries():
    E, nu = 1.0, 0.3
    lam, mu = fem.lame(E, nu)
    lam_s, _ = fem.lame(E, nu, "stress")
    # quad, unit square: K00 = int (lam*+2mu) N0,x^2 + mu N0,y^2 = (lam*+3mu)/3, K01 = (lam*+mu)/4
    K = fem.element_stiffness("quad", UNIT["quad"], E, nu)
    assert K[0, 0] == pytest.approx((lam_s + 3 * mu) / 3, rel=1e-12)
    assert K[0, 1] == pytest.approx((lam_s + mu) / 4, rel=1e-12)
    assert K[0, 0] == pytest.approx(E / (1 - nu**2) * (0.5 - nu / 6), rel=1e-12)  # textbook form
    Ks = fem.element_stiffness("quad", UNIT["quad"], E, nu, plane="strain", thickness=0.1)
    assert Ks[0, 0] == pytest.approx(0.1 * (lam + 3 * mu) / 3, rel=1e-12)
    # triangle (0,0),(1,0),(0,1): grad N0 = (-1,-1), area 1/2
    K = fem.element_stiffness("triangle", UNIT["triangle"], E, nu)
    assert K[0, 0] == pytest.approx((lam_s + 3 * mu) / 2, rel=1e-12)
    assert K[0, 1] == pytest.approx((lam_s + mu) / 2, rel=1e-12)
    assert K[2, 2] == pytest.approx((lam_s + 2 * mu) / 2, rel=1e-12)  # N1 = x
    # hexahedron, unit cube: int N0,x^2 = 1/9, int N0,x N0,y = 1/12
    K = fem.element_stiffness("hexahedron", UNIT["hexahedron"], E, nu)
    assert K[0, 0] == pytest.approx((lam + 4 * mu) / 9, rel=1e-12)
    assert K[0, 1] == pytest.approx((lam + mu) / 12, rel=1e-12)
    # tetra, unit corner: grad N0 = (-1,-1,-1), volume 1/6
    K = fem.element_stiffness("tetra", UNIT["tetra"], E, nu)
    assert K[0, 0] == pytest.approx((lam + 4 * mu) / 6, rel=1e-12)
    assert K[0, 1] == pytest.approx((lam + mu) / 6, rel=1e-12)


def test_element_stiffness_follows_vtk_node_order():
    """Relabelling the nodes of a box (another valid VTK order) permutes K accordingly."""
    coords = UNIT["hexahedron"] * [2.0, 1.0, 0.5]
    K = fem.element_stiffness("hexahedron", coords, 3.0, 0.25)
    perm = np.array([1, 2, 3, 0, 5, 6, 7, 4])  # rotate the bottom/top faces
    Kp = fem.element_stiffness("hexahedron", coords[perm], 3.0, 0.25)
    dofs = (perm[:, None] * 3 + np.arange(3)).ravel()
    assert np.allclose(Kp, K[np.ix_(dofs, dofs)], atol=1e-12)
    coords = UNIT["quad"] * [2.0, 1.0]
    K = fem.element_stiffness("quad", coords, 3.0, 0.25)
    perm = np.array([2, 3, 0, 1])
    Kp = fem.element_stiffness("quad", coords[perm], 3.0, 0.25)
    dofs = (perm[:, None] * 2 + np.arange(2)).ravel()
    assert np.allclose(Kp, K[np.ix_(dofs, dofs)], atol=1e-12)


# ---------------------------------------------------------------------------------------------
# linear solutions
# ---------------------------------------------------------------------------------------------


def test_uniaxial_bar_hex_traction():
    L, W, H, E, nu, F = 4.0, 1.0, 0.5, 200.0, 0.3, 3.0
    mesh = hex_grid(L, W, H, 4, 2, 2)
    A = W * H
    f = face_load(mesh, 0, L, [F / A, 0, 0])
    assert f[:, 0].sum() == pytest.approx(F)
    res = fem.solve_linear(mesh, E, nu, fixed=symmetry_bc(mesh), nodal_forces=f)
    x, y, z = mesh.points.T
    eps = F / (E * A)
    u = res.displacement
    assert np.allclose(u[:, 0], eps * x, atol=1e-12)
    assert np.allclose(u[:, 1], -nu * eps * y, atol=1e-12)
    assert np.allclose(u[:, 2], -nu * eps * z, atol=1e-12)
    assert u[np.isclose(x, L), 0] == pytest.approx(F * L / (E * A), rel=1e-10)
    assert res.strain_energy == pytest.approx(0.5 * F**2 * L / (E * A), rel=1e-10)
    # reactions balance the load and live only on constrained dofs
    assert res.reaction[:, 0].sum() == pytest.approx(-F, rel=1e-10)
    assert np.all(res.reaction[~symmetry_bc(mesh)] == 0)
    assert res.stats["n_dofs"] == 3 * mesh.n_nodes and res.stats["wall_time"] > 0 and res.stats["solver"]


def test_uniaxial_bar_tet_prescribed_displacement():
    L, W, H, E, nu, d = 2.0, 1.0, 1.0, 50.0, 0.25, 0.01
    mesh = tet_grid(L, W, H, 2, 1, 1)
    fixed = symmetry_bc(mesh)
    end = np.isclose(mesh.points[:, 0], L)
    fixed[end, 0] = True
    presc = np.zeros_like(mesh.points)
    presc[end, 0] = d
    res = fem.solve_linear(mesh, E, nu, fixed=fixed, prescribed=presc)
    eps = d / L
    assert np.allclose(res.displacement[:, 0], eps * mesh.points[:, 0], atol=1e-13)
    assert np.allclose(res.displacement[:, 1], -nu * eps * mesh.points[:, 1], atol=1e-13)
    assert res.reaction[end, 0].sum() == pytest.approx(E * W * H * eps, rel=1e-10)


@pytest.mark.parametrize("make", [quad_grid, tri_grid])
def test_uniaxial_bar_2d_thickness(make):
    L, H, E, nu, F, t = 3.0, 1.0, 10.0, 0.3, 0.2, 0.05
    mesh = make(L, H, 3, 2)
    f = face_load(mesh, 0, L, [F / (H * t), 0]) * t
    res = fem.solve_linear(mesh, E, nu, fixed=symmetry_bc(mesh), nodal_forces=f, thickness=t)
    eps = F / (E * H * t)
    assert np.allclose(res.displacement[:, 0], eps * mesh.points[:, 0], atol=1e-12)
    assert np.allclose(res.displacement[:, 1], -nu * eps * mesh.points[:, 1], atol=1e-12)


def test_simple_shear_block():
    """Shear tractions tau on the four faces normal to x and y; with the rigid modes removed by
    u(0)=0, u_x(0,W,0)=u_z(0,W,0)=0, u_z(L,0,0)=0 the exact field is u = (0, gamma x, 0)."""
    L, W, H, E, nu, tau = 2.0, 1.5, 1.0, 26.0, 0.3, 0.4
    G = E / (2 * (1 + nu))
    mesh = hex_grid(L, W, H, 2, 2, 2)
    f = (
        face_load(mesh, 1, W, [tau, 0, 0]) + face_load(mesh, 1, 0.0, [-tau, 0, 0])
        + face_load(mesh, 0, L, [0, tau, 0]) + face_load(mesh, 0, 0.0, [0, -tau, 0])
    )
    p = mesh.points
    fixed = np.zeros(p.shape, bool)
    fixed[np.all(np.isclose(p, 0), axis=1)] = True
    fixed[np.all(np.isclose(p, [0, W, 0]), axis=1), 0::2] = True
    fixed[np.all(np.isclose(p, [L, 0, 0]), axis=1), 2] = True
    res = fem.solve_linear(mesh, E, nu, fixed=fixed, nodal_forces=f)
    gamma = tau / G
    assert np.allclose(res.displacement[:, 1], gamma * p[:, 0], atol=1e-12)
    assert np.allclose(res.displacement[:, [0, 2]], 0, atol=1e-12)
    assert res.strain_energy == pytest.approx(0.5 * tau * gamma * L * W * H, rel=1e-10)
    assert np.abs(res.reaction).max() < 1e-10  # self-equilibrated load


@pytest.mark.parametrize("load", ["tip", "gravity"])
def test_cantilever_hex_euler_bernoulli(load):
    L, B, E, rho_g = 10.0, 1.0, 1000.0, 2.0
    mesh = hex_grid(L, B, B, 40, 4, 4)
    fixed = np.zeros(mesh.points.shape, bool)
    fixed[np.isclose(mesh.points[:, 0], 0)] = True
    I = B**4 / 12
    tip = np.isclose(mesh.points[:, 0], L)
    if load == "tip":
        P = 0.5
        res = fem.solve_linear(mesh, E, 0.0, fixed=fixed, nodal_forces=face_load(mesh, 0, L, [0, 0, -P / B**2]))
        expected = P * L**3 / (3 * E * I)
        total = P
    else:
        res = fem.solve_linear(mesh, E, 0.0, fixed=fixed, body_force=[0, 0, -rho_g])
        q = rho_g * B**2
        expected = q * L**4 / (8 * E * I)
        total = q * L
    deflection = -res.displacement[tip, 2].mean()
    assert deflection == pytest.approx(expected, rel=0.035)
    assert res.reaction[:, 2].sum() == pytest.approx(total, rel=1e-10)


@pytest.mark.parametrize(
    "mesh",
    [tri_grid(2.0, 1.0, 3, 2, jitter=0.3), quad_grid(2.0, 1.0, 3, 2, jitter=0.3), tet_grid(1.0, 1.0, 1.0, 2, 1, 1),
     hex_grid(2.0, 1.0, 1.0, 2, 1, 2, material=lambda c: (c[:, 2] > 0.5).astype(int))],
    ids=["triangle", "quad", "tetra", "hexahedron"],
)
def test_fast_assembly_equals_skfem_forms(mesh):
    """The vectorised stiffness equals scikit-fem's BilinearForm on ElementVector (two materials)."""
    f = np.zeros(mesh.points.shape)
    f[:, -1] = np.linspace(-1, 1, mesh.n_nodes)
    fixed = symmetry_bc(mesh)
    a = fem.solve_linear(mesh, [2.0, 5.0], [0.3, 0.1], fixed=fixed, nodal_forces=f, thickness=0.2, assembly="fast")
    b = fem.solve_linear(mesh, [2.0, 5.0], [0.3, 0.1], fixed=fixed, nodal_forces=f, thickness=0.2, assembly="skfem")
    assert np.allclose(a.displacement, b.displacement, rtol=1e-10, atol=1e-12 * np.abs(a.displacement).max())
    assert a.strain_energy == pytest.approx(b.strain_energy, rel=1e-10)


@pytest.mark.parametrize("position", ["first", "last"])
def test_unused_node_is_held(position):
    """A node used by no cell (e.g. left over from meshing) neither breaks the solve nor moves."""
    q = quad_grid(2.0, 1.0, 2, 1)
    extra = np.array([[7.0, 7.0]])
    pts, cells = (np.r_[extra, q.points], q.cells + 1) if position == "first" else (np.r_[q.points, extra], q.cells)
    mesh = Mesh(pts, cells, "quad")
    orphan = 0 if position == "first" else mesh.n_nodes - 1
    f = face_load(mesh, 0, 2.0, [0.5, 0])
    for assembly in ("fast", "skfem"):
        res = fem.solve_linear(mesh, 1.0, 0.25, fixed=symmetry_bc(mesh), nodal_forces=f, assembly=assembly)
        assert np.allclose(res.displacement[:, 0], np.where(np.isclose(pts[:, 0], 7.0), 0.0, 0.5 * pts[:, 0]))
        assert np.all(res.displacement[orphan] == 0)


def test_body_force_per_cell_matches_uniform():
    mesh = hex_grid(2.0, 1.0, 1.0, 2, 1, 1)
    fixed = np.zeros(mesh.points.shape, bool)
    fixed[np.isclose(mesh.points[:, 0], 0)] = True
    a = fem.solve_linear(mesh, 5.0, 0.2, fixed=fixed, body_force=[0, 1.0, -2.0])
    b = fem.solve_linear(mesh, 5.0, 0.2, fixed=fixed, body_force=np.tile([0, 1.0, -2.0], (mesh.n_cells, 1)))
    assert np.allclose(a.displacement, b.displacement, rtol=1e-12, atol=0)
    # consistent load: total force = body force x volume
    assert a.reaction.sum(axis=0) == pytest.approx([0, -2.0, 4.0], abs=1e-12)


def test_two_material_bar_in_series():
    """E and nu differ per material with nu/E equal, so lateral strains match: the solution is exact."""
    L1, L2, A, F = 1.0, 2.0, 1.0, 1.5
    E, nu = [4.0, 1.0], [0.2, 0.05]
    mesh = hex_grid(L1 + L2, 1.0, 1.0, 3, 1, 1, material=lambda c: (c[:, 0] > L1).astype(int))
    assert set(mesh.material) == {0, 1}
    res = fem.solve_linear(mesh, E, nu, fixed=symmetry_bc(mesh), nodal_forces=face_load(mesh, 0, L1 + L2, [F, 0, 0]))
    x = mesh.points[:, 0]
    expected = np.where(x <= L1, F * x / (E[0] * A), F * L1 / (E[0] * A) + F * (x - L1) / (E[1] * A))
    assert np.allclose(res.displacement[:, 0], expected, atol=1e-12)
    assert res.displacement[np.isclose(x, 3.0), 0] == pytest.approx(F * (L1 / E[0] + L2 / E[1]) / A, rel=1e-10)


@pytest.mark.parametrize("make", [quad_grid, tri_grid])
@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_patch_test_plane_stress_strain(make, plane):
    """Distorted interior nodes, uniform traction sigma on x=L: homogeneous strain reproduced
    exactly, with the effective modulus/Poisson ratio of plane stress or plane strain."""
    L, H, E, nu, s = 2.0, 1.0, 3.0, 0.3, 0.6
    mesh = make(L, H, 4, 3, jitter=0.3)
    res = fem.solve_linear(mesh, E, nu, fixed=symmetry_bc(mesh), nodal_forces=face_load(mesh, 0, L, [s, 0]), plane=plane)
    Ee, nue = (E, nu) if plane == "stress" else (E / (1 - nu**2), nu / (1 - nu))
    x, y = mesh.points.T
    assert np.allclose(res.displacement[:, 0], s / Ee * x, atol=1e-12)
    assert np.allclose(res.displacement[:, 1], -nue * s / Ee * y, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# non-linear solutions
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("law", ["svk", "neohookean"])
@pytest.mark.parametrize(
    "make, plane",
    [(lambda: hex_grid(4.0, 1.0, 1.0, 4, 1, 1), None), (lambda: quad_grid(4.0, 1.0, 4, 2), "stress"),
     (lambda: tri_grid(4.0, 1.0, 4, 2), "strain")],
)
def test_nonlinear_small_load_equals_linear(make, plane, law):
    mesh = make()
    fixed = np.zeros(mesh.points.shape, bool)
    fixed[np.isclose(mesh.points[:, 0], 0)] = True
    f = np.zeros(mesh.points.shape)
    f[np.isclose(mesh.points[:, 0], 4.0), -1] = -1e-7
    kw = {} if plane is None else {"plane": plane}
    lin = fem.solve_linear(mesh, 100.0, 0.3, fixed=fixed, nodal_forces=f, **kw)
    nl = fem.solve_nonlinear(mesh, 100.0, 0.3, fixed=fixed, nodal_forces=f, law=law, steps=1, **kw)
    scale = np.abs(lin.displacement).max()
    assert np.abs(nl.displacement - lin.displacement).max() < 1e-6 * scale
    assert nl.strain_energy == pytest.approx(lin.strain_energy, rel=1e-5)


@pytest.mark.parametrize("law", ["svk", "neohookean"])
def test_uniaxial_stretch_nu0_analytic(law):
    """nu = 0: lateral stretch stays 1; nominal stress SVK P = E (l^3 - l)/2, neo-Hookean P = mu (l - 1/l)."""
    E, lam_target = 10.0, 1.4
    P = E * (lam_target**3 - lam_target) / 2 if law == "svk" else E / 2 * (lam_target - 1 / lam_target)
    L = 3.0
    mesh = hex_grid(L, 1.0, 1.0, 3, 1, 1)
    res = fem.solve_nonlinear(mesh, E, 0.0, fixed=symmetry_bc(mesh), nodal_forces=face_load(mesh, 0, L, [P, 0, 0]), law=law, steps=4, tol=1e-12)
    x = mesh.points[:, 0]
    assert np.allclose(res.displacement[:, 0], (lam_target - 1) * x, rtol=0, atol=1e-9)
    assert np.allclose(res.displacement[:, 1:], 0, atol=1e-9)
    W = E / 8 * (lam_target**2 - 1) ** 2 if law == "svk" else E / 4 * (lam_target**2 - 1) - E / 2 * np.log(lam_target)
    assert res.strain_energy == pytest.approx(W * L, rel=1e-8)


@pytest.mark.parametrize("law", ["svk", "neohookean"])
def test_plane_stress_matches_3d_uniaxial(law):
    """A homogeneous uniaxial stretch with free lateral faces is a plane-stress state: the 2D
    plane-stress solution must equal the 3D one (nu != 0); plane strain must differ."""
    E, nu, P, L = 10.0, 0.3, 3.0, 2.0
    bar = hex_grid(L, 1.0, 1.0, 2, 1, 1)
    r3 = fem.solve_nonlinear(bar, E, nu, fixed=symmetry_bc(bar), nodal_forces=face_load(bar, 0, L, [P, 0, 0]), law=law, steps=3, tol=1e-12)
    sq = quad_grid(L, 1.0, 2, 1)
    r2 = fem.solve_nonlinear(sq, E, nu, fixed=symmetry_bc(sq), nodal_forces=face_load(sq, 0, L, [P, 0]), law=law, steps=3, plane="stress", tol=1e-12)
    rs = fem.solve_nonlinear(sq, E, nu, fixed=symmetry_bc(sq), nodal_forces=face_load(sq, 0, L, [P, 0]), law=law, steps=3, plane="strain")
    end3 = np.all(np.isclose(bar.points, [L, 1.0, 0.0]), axis=1)
    end2 = np.all(np.isclose(sq.points, [L, 1.0]), axis=1)
    assert np.allclose(r2.displacement[end2], r3.displacement[end3][:, :2], rtol=1e-9, atol=1e-12)
    assert r2.strain_energy == pytest.approx(r3.strain_energy, rel=1e-9)
    assert abs(rs.displacement[end2, 0] - r2.displacement[end2, 0]) > 1e-3


@pytest.mark.parametrize("plane", ["strain", "stress"])
@pytest.mark.parametrize("law", ["svk", "neohookean"])
def test_newton_converges_quadratically(law, plane):
    """Unit block, bottom clamped, top pulled and sheared (40-50 % displacements) in one load
    step: in the asymptotic range the relative residuals satisfy r_{k+1} <= C r_k^2 with C ~ 1
    (a linear rate would not)."""
    mesh = quad_grid(1.0, 1.0, 3, 3)
    fixed = np.zeros(mesh.points.shape, bool)
    fixed[np.isclose(mesh.points[:, 1], 0)] = True
    f = face_load(mesh, 1, 1.0, [0.1, 0.1])
    res = fem.solve_nonlinear(mesh, 1.0, 0.3, fixed=fixed, nodal_forces=f, steps=1, tol=1e-13, plane=plane, law=law)
    assert np.abs(res.displacement).max() > 0.3  # a truly non-linear problem
    (hist,) = res.stats["residuals"]
    assert len(hist) == res.stats["iterations"][0] + 1 and hist[-1] <= 1e-13
    checked = 0
    for r0, r1 in zip(hist, hist[1:]):
        if r0 < 0.1 and r1 > 1e-13:  # asymptotic range, above round-off
            assert r1 <= 5 * r0**2
            checked += 1
    assert checked >= 2


def test_step_halving_recovers():
    """One increment with too few iterations allowed fails; halving it lets Newton converge to the
    same solution as a run with several nominal steps."""
    mesh = quad_grid(1.0, 1.0, 3, 3)
    fixed = np.zeros(mesh.points.shape, bool)
    fixed[np.isclose(mesh.points[:, 1], 0)] = True
    f = face_load(mesh, 1, 1.0, [0.1, 0.1])
    kw = dict(fixed=fixed, nodal_forces=f, law="neohookean", tol=1e-12, plane="strain")
    a = fem.solve_nonlinear(mesh, 1.0, 0.3, steps=1, max_iter=5, **kw)
    b = fem.solve_nonlinear(mesh, 1.0, 0.3, steps=4, **kw)
    assert a.stats["n_halvings"] >= 1 and len(a.stats["load_factors"]) > 1
    assert max(a.stats["iterations"]) <= 5
    assert np.allclose(a.displacement, b.displacement, atol=1e-10)


@pytest.mark.parametrize("law", ["svk", "neohookean"])
def test_displacement_driven_stretch_tets(law):
    """Prescribed end displacement (no external force), nu = 0: reaction = nominal stress x area."""
    E, L, stretch = 6.0, 2.0, 1.3
    mesh = tet_grid(L, 1.0, 1.0, 2, 1, 1)
    fixed = symmetry_bc(mesh)
    end = np.isclose(mesh.points[:, 0], L)
    fixed[end, 0] = True
    presc = np.zeros(mesh.points.shape)
    presc[end, 0] = (stretch - 1) * L
    res = fem.solve_nonlinear(mesh, E, 0.0, fixed=fixed, prescribed=presc, law=law, steps=2, tol=1e-12)
    P = E * (stretch**3 - stretch) / 2 if law == "svk" else E / 2 * (stretch - 1 / stretch)
    assert res.reaction[end, 0].sum() == pytest.approx(P, rel=1e-9)
    assert np.allclose(res.displacement[:, 0], (stretch - 1) * mesh.points[:, 0], atol=1e-10)


def test_progress_and_stats():
    mesh = quad_grid(2.0, 1.0, 2, 1)
    calls = []
    f = face_load(mesh, 0, 2.0, [0.1, 0])
    res = fem.solve_nonlinear(mesh, 1.0, 0.2, fixed=symmetry_bc(mesh), nodal_forces=f, steps=3, progress=lambda s, n: calls.append((s, n)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    assert len(res.stats["iterations"]) == 3 and res.stats["load_factors"][-1] == pytest.approx(1.0)
    assert res.stats["n_dofs"] == 2 * mesh.n_nodes and res.stats["wall_time"] > 0


def test_nonconvergence_raises_runtime_error():
    mesh = hex_grid(2.0, 1.0, 1.0, 2, 1, 1)
    f = face_load(mesh, 0, 2.0, [50.0, 0, 0])
    with pytest.raises(RuntimeError, match=r"step 1 of 1.*residual"):
        fem.solve_nonlinear(mesh, 1.0, 0.3, fixed=symmetry_bc(mesh), nodal_forces=f, steps=1, max_iter=2, max_halvings=1)


@pytest.mark.parametrize(
    "E, nu, match",
    [(-1.0, 0.3, r"E=-1\.0 of material 0"), (1.0, 0.5, r"nu=0\.5 of material 0"), (1.0, -1.0, r"nu=-1\.0"),
     ([1.0, 0.0], 0.3, r"E=0\.0 of material 1"), (1.0, [0.3, 0.7], r"nu=0\.7 of material 1"), ([1.0], 0.3, "material indices")],
)
def test_bad_material_raises(E, nu, match):
    mesh = hex_grid(2.0, 1.0, 1.0, 2, 1, 1, material=lambda c: (c[:, 0] > 1).astype(int))
    fixed = symmetry_bc(mesh)
    with pytest.raises(ValueError, match=match):
        fem.solve_linear(mesh, E, nu, fixed=fixed)
    with pytest.raises(ValueError, match=match):
        fem.solve_nonlinear(mesh, E, nu, fixed=fixed)
    if np.ndim(E) == 0 and np.ndim(nu) == 0:
        with pytest.raises(ValueError, match=match):
            fem.element_stiffness("hexahedron", UNIT["hexahedron"], E, nu)

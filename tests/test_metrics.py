import numpy as np
import pytest

from msslib.mesh import Mesh
from msslib.metrics import (
    DisplacementError,
    bulk_modulus,
    cell_volumes,
    displacement_error,
    mean_displacement_gradient,
    mesh_volume,
    shear_modulus,
    youngs_modulus_poisson,
)


def box_hex(nx=2, ny=3, nz=2, size=(1.0, 2.0, 0.5), origin=(0.3, -0.2, 1.0)):
    xs = [np.linspace(o, o + s, k + 1) for o, s, k in zip(origin, size, (nx, ny, nz))]
    X, Y, Z = np.meshgrid(*xs, indexing="ij")
    points = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = np.arange(len(points)).reshape(nx + 1, ny + 1, nz + 1)
    cells = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                bottom = [idx[i, j, k], idx[i + 1, j, k], idx[i + 1, j + 1, k], idx[i, j + 1, k]]
                top = [idx[i, j, k + 1], idx[i + 1, j, k + 1], idx[i + 1, j + 1, k + 1], idx[i, j + 1, k + 1]]
                cells.append(bottom + top)
    return Mesh(points=points, cells=np.array(cells), cell_type="hexahedron")


def box_quad(nx=3, ny=2, size=(2.0, 1.0)):
    xs = [np.linspace(0, s, k + 1) for s, k in zip(size, (nx, ny))]
    X, Y = np.meshgrid(*xs, indexing="ij")
    points = np.column_stack([X.ravel(), Y.ravel()])
    idx = np.arange(len(points)).reshape(nx + 1, ny + 1)
    cells = [[idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]] for i in range(nx) for j in range(ny)]
    return Mesh(points=points, cells=np.array(cells), cell_type="quad")


# ---------------------------------------------------------------------------- displacement error


def test_displacement_error_known_field():
    u_ref = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [3.0, 4.0]])
    e = np.array([[0.0, 0.0], [0.3, 0.4], [0.0, 1.0], [0.6, 0.8]])  # norms 0, 0.5, 1, 1
    res = displacement_error(u_ref + e, u_ref)
    assert isinstance(res, DisplacementError)
    np.testing.assert_allclose(res.per_node, [0.0, 0.5, 1.0, 1.0])
    assert res.mean == pytest.approx(0.625)
    assert res.std == pytest.approx(np.std([0.0, 0.5, 1.0, 1.0]))
    assert res.max == pytest.approx(1.0)
    assert res.scale == pytest.approx(5.0)  # max |u_ref|
    assert res.rel_mean == pytest.approx(0.625 / 5)
    assert res.rel_std == pytest.approx(res.std / 5)
    assert res.rel_max == pytest.approx(0.2)
    with pytest.raises(Exception):
        res.mean = 0.0  # frozen


def test_displacement_error_relative_variants():
    u_ref = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [3.0, 4.0]])
    u = u_ref + np.array([[0.0, 0.0], [0.3, 0.4], [0.0, 1.0], [0.6, 0.8]])
    fixed_scale = displacement_error(u, u_ref, relative_to=10.0)
    assert fixed_scale.scale == 10.0 and fixed_scale.rel_max == pytest.approx(0.1)
    node = displacement_error(u, u_ref, relative_to="node")
    assert node.scale is None
    assert np.isnan(node.per_node_relative[0])  # zero reference displacement: left out
    np.testing.assert_allclose(node.per_node_relative[1:], [0.5, 0.5, 0.2])
    assert node.rel_mean == pytest.approx(0.4)
    assert node.rel_max == pytest.approx(0.5)
    exact = displacement_error(u_ref, u_ref)
    assert exact.mean == exact.max == exact.rel_max == 0.0
    still = displacement_error(u, np.zeros_like(u))
    assert np.isnan(still.rel_mean) and still.max == pytest.approx(5.0 + 1.0)
    with pytest.raises(ValueError):
        displacement_error(u, u_ref[:3])
    with pytest.raises(ValueError):
        displacement_error(u, u_ref, relative_to=-1.0)
    with pytest.raises(ValueError):
        displacement_error(u, u_ref, relative_to="mean")


# ---------------------------------------------------------------------------- effective moduli


@pytest.mark.parametrize("method", ["fit", "extent"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_youngs_modulus_poisson_uniaxial_affine_3d(method, axis):
    E, nu, sigma = 2.5e6, 0.3, -1.2e4  # compression
    rest = box_hex().points
    eps = np.full(3, -nu * sigma / E)
    eps[axis] = sigma / E
    displaced = rest + (rest - rest.mean(axis=0) + 0.1) * eps + np.array([1e-3, -2e-3, 5e-4])  # + rigid shift
    E_fit, nu_fit = youngs_modulus_poisson(rest, displaced, sigma, axis, method=method)
    assert E_fit == pytest.approx(E, rel=1e-10)
    assert nu_fit == pytest.approx(nu, rel=1e-10)


def test_youngs_modulus_poisson_2d_and_mask():
    E, nu, sigma = 1e5, 0.45, 300.0
    rest = box_quad().points
    u = rest * np.array([sigma / E, -nu * sigma / E])
    res = youngs_modulus_poisson(rest, rest + u, sigma, 0)
    assert res.E == pytest.approx(E, rel=1e-10) and res.nu == pytest.approx(nu, rel=1e-10)
    # a perturbation on masked-out nodes does not change the fit
    displaced = rest + u
    displaced[0] += 0.1
    mask = np.ones(len(rest), bool)
    mask[0] = False
    assert youngs_modulus_poisson(rest, displaced, sigma, 0, mask=mask).E == pytest.approx(E, rel=1e-10)
    with pytest.raises(ValueError):
        youngs_modulus_poisson(rest, rest, sigma, 0)  # no strain
    with pytest.raises(ValueError):
        youngs_modulus_poisson(rest, rest + u, sigma, 2)


@pytest.mark.parametrize("method", ["fit", "extent"])
def test_shear_modulus_simple_shear(method):
    G, tau = 8e5, 4e4
    gamma = tau / G  # tan(theta)
    rest = box_hex().points
    displaced = rest.copy()
    displaced[:, 0] += gamma * (rest[:, 2] - rest[:, 2].min())  # load along x, faces normal to z
    assert shear_modulus(rest, displaced, tau, 0, 2, method=method) == pytest.approx(G, rel=1e-10)
    small = shear_modulus(rest, displaced, tau, 0, 2, method=method, small_angle=True)
    assert small == pytest.approx(tau / np.arctan(gamma), rel=1e-10)
    assert small == pytest.approx(G, rel=1e-3) and small != pytest.approx(G, rel=1e-12)


def test_shear_modulus_2d_large_angle():
    rest = box_quad().points
    displaced = rest.copy()
    displaced[:, 1] += 1.0 * rest[:, 0]  # theta = 45 degrees, load along y, normal x
    assert shear_modulus(rest, displaced, 2.0, 1, 0) == pytest.approx(2.0)
    assert shear_modulus(rest, displaced, 2.0, 1, 0, small_angle=True) == pytest.approx(2.0 / (np.pi / 4))
    with pytest.raises(ValueError):
        shear_modulus(rest, displaced, 2.0, 1, 1)


def test_bulk_modulus_uniform_dilation():
    B, p = 3e6, 2e4  # compression: the volume shrinks by p / B
    mesh = box_hex()
    s = (1.0 - p / B) ** (1.0 / 3.0)
    center = mesh.points.mean(axis=0)
    u = (s - 1.0) * (mesh.points - center)
    V0, V = mesh_volume(mesh), mesh_volume(mesh, u)
    assert V == pytest.approx(V0 * s**3, rel=1e-12)
    assert bulk_modulus(V0, V, p) == pytest.approx(B, rel=1e-9)
    assert bulk_modulus(1.0, 1.01, -1.0) == pytest.approx(100.0)  # tension expands
    np.testing.assert_allclose(bulk_modulus(np.array([1.0, 2.0]), np.array([0.9, 1.9]), 1.0), [10.0, 20.0])
    with pytest.raises(ValueError):
        bulk_modulus(1.0, 1.0, 5.0)


def test_mean_displacement_gradient_affine():
    rng = np.random.default_rng(0)
    rest = rng.random((20, 3))
    H = rng.normal(size=(3, 3)) * 1e-2
    np.testing.assert_allclose(mean_displacement_gradient(rest, rest + rest @ H.T + 0.5), H, atol=1e-13)


# ---------------------------------------------------------------------------- volumes


def test_hex_volume_after_affine_map():
    mesh = box_hex()
    V0 = mesh_volume(mesh)
    assert V0 == pytest.approx(1.0 * 2.0 * 0.5, rel=1e-14)
    np.testing.assert_allclose(cell_volumes(mesh), V0 / mesh.n_cells, rtol=1e-13)
    F = np.array([[1.2, 0.3, -0.1], [0.05, 0.9, 0.2], [0.1, -0.25, 1.1]])
    u = mesh.points @ F.T + np.array([1.0, 2.0, 3.0]) - mesh.points
    assert mesh_volume(mesh, u) == pytest.approx(np.linalg.det(F) * V0, rel=1e-12)
    # a reflection inverts every cell: the signed volume changes sign
    R = np.diag([1.0, 1.0, -1.0])
    assert mesh_volume(mesh, mesh.points @ R.T - mesh.points) == pytest.approx(-V0, rel=1e-12)


def test_hex_volume_trilinear_warped_face():
    # unit cube with the top corner (1, 1, 1) raised by h: z = zeta * (1 + h x y), volume 1 + h/4
    h = 0.6
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1 + h], [0, 1, 1]], float)
    mesh = Mesh(points=pts, cells=np.arange(8)[None, :], cell_type="hexahedron")
    assert mesh_volume(mesh) == pytest.approx(1.0 + h / 4, rel=1e-14)
    # a general trilinear map: the cubic in the coordinates agrees with a fine midpoint rule
    rng = np.random.default_rng(1)
    pts2 = pts + rng.normal(scale=0.1, size=pts.shape)
    mesh2 = Mesh(points=pts2, cells=np.arange(8)[None, :], cell_type="hexahedron")
    n = 40
    xi = (np.arange(n) + 0.5) / n * 2 - 1
    g = np.array(np.meshgrid(xi, xi, xi, indexing="ij")).reshape(3, -1).T
    ref = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    dN = np.empty((len(g), 8, 3))
    for k in range(3):
        o = [j for j in range(3) if j != k]
        dN[:, :, k] = ref[:, k] * (1 + g[:, None, o[0]] * ref[:, o[0]]) * (1 + g[:, None, o[1]] * ref[:, o[1]]) / 8
    J = np.einsum("ni,qnj->qij", pts2, dN)
    midpoint = np.linalg.det(J).sum() * (2.0 / n) ** 3
    assert mesh_volume(mesh2) == pytest.approx(midpoint, rel=1e-3)


def test_2d_and_tetra_volumes():
    quad = box_quad()
    assert mesh_volume(quad) == pytest.approx(2.0)
    F = np.array([[1.1, 0.4], [-0.2, 0.8]])
    assert mesh_volume(quad, quad.points @ F.T - quad.points) == pytest.approx(np.linalg.det(F) * 2.0)
    # non-parallelogram quad: bilinear area equals the polygon area
    q = Mesh(points=[[0, 0], [3, 0], [2, 2], [0, 1]], cells=[[0, 1, 2, 3]], cell_type="quad")
    assert mesh_volume(q) == pytest.approx(0.5 * abs(3 * 2 - 0) + 0.5 * abs(2 * 1 - 0))
    tri = Mesh(points=[[0, 0], [2, 0], [0, 3]], cells=[[0, 1, 2]], cell_type="triangle")
    assert mesh_volume(tri) == pytest.approx(3.0)
    tet = Mesh(points=[[0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]], cells=[[0, 1, 2, 3]], cell_type="tetra")
    assert mesh_volume(tet) == pytest.approx(1.0)
    with pytest.raises(ValueError):
        mesh_volume(tet, np.zeros((3, 3)))

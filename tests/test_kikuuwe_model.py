"""The model kikuuwe_tetrahedron on irregular gmsh meshes: forces and energy equal an independent
St Venant-Kirchhoff assembly (P = F S per element, from the deformation gradient) node by node at
large strain, and its linearisation equals the linear FEM stiffness."""

from __future__ import annotations

import numpy as np
import pytest

from fem_helpers import fem_stiffness
from msslib import mesh as M
from msslib import models
from msslib.system import Model


def _ellipsoid():
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.02)
        occ = gmsh.model.occ
        s = occ.addSphere(0, 0, 0, 0.05)
        occ.dilate([(3, s)], 0, 0, 0, 1.0, 0.7, 0.5)
        occ.synchronize()
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
        index = {int(t): i for i, t in enumerate(tags)}
        cells = np.array([index[int(t)] for t in conn[0]]).reshape(-1, 4)
        points = xyz.reshape(-1, 3)
    finally:
        gmsh.finalize()
    used = np.unique(cells)
    renum = np.full(len(points), -1)
    renum[used] = np.arange(len(used))
    return M.orient(M.Mesh(points[used], renum[cells], "tetra"))


MESHES = {"cylinder_with_hole": lambda: M.cylinder_with_hole_mesh(0.05, 0.1, 0.02, 0.03),
          "ellipsoid": _ellipsoid}


def _svk(mesh, x, E, nu):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    X, x = mesh.points, x.reshape(-1, 3)
    f, w = np.zeros_like(x), 0.0
    for c in mesh.cells:
        Dm = (X[c[1:]] - X[c[0]]).T
        Gi = np.linalg.inv(Dm)
        F = (x[c[1:]] - x[c[0]]).T @ Gi
        G = 0.5 * (F.T @ F - np.eye(3))
        V = abs(np.linalg.det(Dm)) / 6
        S = lam * np.trace(G) * np.eye(3) + 2 * mu * G
        w += V * (lam / 2 * np.trace(G) ** 2 + mu * np.sum(G * G))
        g = np.vstack([-Gi.sum(axis=0), Gi])  # shape-function gradients (rows)
        f[c] += V * (F @ S @ g.T).T  # internal force dW/dx_a
    return w, f.ravel()


def _model(mesh, E, nu):
    spec = models.registry()["kikuuwe_tetrahedron"]
    ctx = models.BuildContext(mesh=mesh, materials=[(E, nu)], options={"terms": spec.defaults})
    return Model(mesh, spec.build(ctx)["springs"])


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_equals_svk_node_by_node_at_large_strain(name, nu):
    mesh = MESHES[name]()
    E = 5.0e3
    model = _model(mesh, E, nu)
    rng = np.random.default_rng(1)
    A = np.eye(3) + 0.4 * rng.standard_normal((3, 3))  # large homogeneous strain plus a random field
    x = (mesh.points @ A.T + 0.002 * rng.standard_normal(mesh.points.shape)).ravel()
    w_ref, g_ref = _svk(mesh, x, E, nu)
    assert abs(model.energy(x) - w_ref) <= 1e-8 * abs(w_ref)
    g = -model.force(x)
    assert np.abs(g - g_ref).max() <= 1e-8 * np.abs(g_ref).max()


def test_linearisation_is_the_linear_fem_stiffness():
    mesh = MESHES["cylinder_with_hole"]()
    model = _model(mesh, 2.0, 0.45)
    K = model.stiffness(model.x0).toarray()
    K_fem = fem_stiffness(mesh, 2.0, 0.45, 1.0)
    assert np.abs(K - K_fem).max() <= 1e-9 * np.abs(K_fem).max()


def test_static_solve_equals_st_venant_kirchhoff_fem():
    """A 20 % stretch of a tetrahedral bar: the static solve agrees with svk FEM to solver tolerance."""
    from msslib.scene import load_scene, run_scene

    scene = {
        "name": "bar", "model": "kikuuwe_tetrahedron",
        "geometry": {"generator": "tet_grid", "args": {"lx": 0.04, "ly": 0.01, "lz": 0.01, "nx": 4, "ny": 1, "nz": 1}},
        "materials": [{"E": 1.0e4, "nu": 0.45}],
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["x", 0.04]}, "traction": [2000.0, 0.0, 0.0]}],
        "solver": {"type": "static", "load_steps": 4, "tol": 1.0e-10},
    }
    mss = run_scene(load_scene(scene), progress=False)
    ref = run_scene(load_scene({**scene, "model": "fem_svk"}), progress=False)
    u, u_ref = mss["displacement"].values, ref["displacement"].values
    assert np.abs(u_ref).max() > 0.1 * 0.04  # a large deformation
    assert np.abs(u - u_ref).max() <= 1e-6 * np.abs(u_ref).max()


def test_simulator_steps_equal_integrate_and_settle_on_the_static_solution():
    """The stepping API (generic engine) equals integrate() step for step, and a damped run settles on
    the static solution."""
    import msslib
    from msslib import solvers as S
    from msslib.stepping import integrate
    from msslib.stepping import Simulator

    mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
    setup = msslib.build_model("kikuuwe_tetrahedron", mesh, msslib.Material(1e4, 0.3, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]})
    model = setup.model
    dt = 0.8 * S.explicit_stability_limit(model, model.x0)
    ref = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=100 * dt, damping=3.0, save_every=100)
    sim = Simulator(model, dt=dt, damping=3.0)
    sim.step(100)
    moved = np.abs(ref.x_final - model.x0).max()
    assert moved > 0 and np.abs(np.ravel(sim.x) - ref.x_final).max() <= 1e-12 * moved
    sim = Simulator(model, dt=dt, damping=16.0)
    sim.run(3.0)
    static = S.static_solve(model, model.x0)
    sag = np.abs(static.x - model.x0).max()
    assert np.abs(np.ravel(sim.x) - static.x).max() <= 1e-3 * sag

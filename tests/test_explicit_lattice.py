"""msslib.stepping.lattice: lattice kernels give the model's forces and integrate's trajectories."""

from __future__ import annotations

import numpy as np
import pytest

from msslib.models.common import _pairs_of
from msslib.models.golec import golec_cube_springs
from msslib.models.lloyd import lloyd_tet_springs
from msslib import mesh as M
from msslib import system as MD
from msslib import solvers as S
from msslib.stepping import integrate
from msslib import terms as T
from msslib.stepping.lattice import LatticeExplicit, lattice_index
from msslib.generated import kernels as K


def _golec_sample(n=(4, 4, 4), a=0.01, nu=0.3, E=2e4, rho=1000.0, alpha=0.0):
    """Golec cubes (springs + hex volume), bottom clamped, gravity: the benchmark's model, smaller."""
    nx, ny, nz = n
    mesh = M.hex_grid(nx * a, ny * a, nz * a, nx, ny, nz)
    terms = golec_cube_springs(mesh, [(E, nu)], 1.0)
    masses = M.lumped_masses(mesh, rho)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    grav = T.Gravity(masses, [0.0, 0.0, -9.81])
    return MD.Model(mesh, terms + [grav], fixed=fixed, masses=masses, damping=alpha)


def _rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def _irregular_model(seed=0):
    """3 x 4 x 5 cells, non-uniform spacing along every axis, shuffled node numbering, springs on
    every lattice-neighbour pair kind with random constants and prestrain, a second Springs term on
    some of the same pairs (combined by the kernel), hex volume terms (negative and positive kappa)
    on a subset of the cells, nodal loads, one clamped face."""
    rng = np.random.default_rng(seed)
    nx, ny, nz = 3, 4, 5
    xs = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, nx))]) * 0.01
    ys = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, ny))]) * 0.01
    zs = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, nz))]) * 0.01
    box = M.hex_grid(1.0, 1.0, 1.0, nx, ny, nz)
    ijk = np.rint(box.points * [nx, ny, nz]).astype(int)
    pts = np.column_stack([xs[ijk[:, 0]], ys[ijk[:, 1]], zs[ijk[:, 2]]])
    perm = rng.permutation(len(pts))  # new id of old node i: perm[i]
    points = np.empty_like(pts)
    points[perm] = pts
    cells = perm[box.cells]
    mesh = M.Mesh(points, cells, "hexahedron")
    terms = []
    for kind in ("edges", "face_diagonals", "inner_diagonals"):
        pairs = _pairs_of(mesh, kind).pairs
        L = np.linalg.norm(points[pairs[:, 1]] - points[pairs[:, 0]], axis=1)
        # random orientation of the pairs too
        flip = rng.random(len(pairs)) < 0.5
        pairs = np.where(flip[:, None], pairs[:, ::-1], pairs)
        terms.append(T.Springs(pairs, rng.uniform(50, 150, len(pairs)), L * rng.uniform(0.95, 1.05, len(pairs)), 3))
    extra = _pairs_of(mesh, "edges").pairs[::3]
    Le = np.linalg.norm(points[extra[:, 1]] - points[extra[:, 0]], axis=1)
    terms.append(T.Springs(extra, rng.uniform(10, 20, len(extra)), Le * rng.uniform(0.9, 1.1, len(extra)), 3))
    keep = rng.random(mesh.n_cells) < 0.7
    hx = cells[keep]
    p = points[hx]
    V0 = np.asarray(K.hex_averaged_volume(*[p[:, c, d] for c in range(8) for d in range(3)]), dtype=float)
    terms.append(T.HexVolume(hx, rng.uniform(-500, 3000, len(hx)), V0 * rng.uniform(0.97, 1.03, len(hx))))
    terms.append(T.NodalForces(rng.standard_normal((mesh.n_nodes, 3)) * 1e-2))
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[np.isclose(points[:, 0], 0.0)] = True
    fixed[np.isclose(points[:, 1], ys[-1]), 2] = True  # a single fixed component on one face
    return MD.Model(mesh, terms, fixed=fixed, masses=masses)


@pytest.mark.parametrize("scale", [1e-3, 1e-1])
def test_forces_equal_model_golec(scale):
    model = _golec_sample()
    fast = LatticeExplicit(model)
    assert fast.n_hexes == 64 and fast.n_springs == len(model.terms[0].conn)
    rng = np.random.default_rng(1)
    for _ in range(3):
        x = model.x0 + scale * 0.01 * rng.standard_normal(model.n_dof)
        assert _rel(fast.force(x), model.force(x)) <= 1e-12
        # the volume term alone (nu = 0.3: kappa > 0, active)
        g_hex = model.terms[1].gradient(x)
        assert np.abs(g_hex).max() > 0
        assert _rel(fast.internal_gradient(x), model.terms[0].gradient(x) + g_hex) <= 1e-12
    assert _rel(fast.force(model.x0), model.force(model.x0)) <= 1e-12  # at rest: gravity only


def test_forces_equal_model_irregular_lattice():
    model = _irregular_model()
    fast = LatticeExplicit(model)
    assert fast.shape == (4, 5, 6)
    rng = np.random.default_rng(2)
    for scale in (1e-4, 1e-3, 3e-2):
        x = model.x0 + scale * rng.standard_normal(model.n_dof)
        assert _rel(fast.force(x), model.force(x)) <= 1e-12
        hexv = [t for t in model.terms if isinstance(t, T.HexVolume)][0]
        g_int = sum(t.gradient(x) for t in model.terms if not isinstance(t, T.ExternalForce))
        assert _rel(fast.internal_gradient(x), g_int) <= 1e-12
        assert np.abs(hexv.gradient(x)).max() > 1e-3 * np.abs(g_int).max()


def _compare_trajectory(model, x0, v0, h, n_steps, alpha, save_every):
    fast = LatticeExplicit(model)
    xf, vf, saved = fast.run(x0, v0, h, n_steps, alpha, save_every)
    ref = integrate(model, x0, v0, dt=h, t_end=n_steps * h, method="symplectic_euler", damping=alpha,
                      save_every=save_every)
    assert ref.stats["n_steps"] == n_steps
    assert saved.shape == (n_steps // save_every, model.n_dof)
    disp = np.abs(ref.x - x0).max()
    assert disp > 0
    assert np.abs(saved - ref.x[1:]).max() <= 1e-10 * disp
    assert np.abs(xf - ref.x_final).max() <= 1e-10 * disp
    assert np.abs(vf - ref.v_final).max() <= 1e-10 * np.abs(ref.v).max()
    assert np.all(xf[model.fixed] == x0[model.fixed]) and np.all(vf[model.fixed] == 0)


def test_trajectory_equals_integrate_golec():
    model = _golec_sample(n=(3, 3, 3), alpha=5.0)
    h = 0.9 * S.explicit_stability_limit(model, model.x0)
    rng = np.random.default_rng(3)
    v0 = 1e-3 * rng.standard_normal(model.n_dof)
    # alpha=None: the model's damping (5/s)
    _compare_trajectory(model, model.x0, v0, h, 400, None, 20)


def test_trajectory_equals_integrate_irregular():
    model = _irregular_model(seed=4)
    h = 0.5 * S.explicit_stability_limit(model, model.x0)
    rng = np.random.default_rng(5)
    x0 = model.x0 + 1e-4 * rng.standard_normal(model.n_dof) * model.free
    _compare_trajectory(model, x0, np.zeros(model.n_dof), h, 300, 2.0, 10)


def test_lattice_index_and_errors():
    mesh = M.hex_grid(0.03, 0.02, 0.01, 3, 2, 1)
    shape, ijk = lattice_index(mesh.points)
    assert shape == (4, 3, 2)
    assert np.array_equal(ijk[:, 0] + 4 * (ijk[:, 1] + 3 * ijk[:, 2]), np.arange(mesh.n_nodes))
    with pytest.raises(ValueError, match="not a structured lattice"):
        lattice_index(mesh.points[1:])
    bent = mesh.points.copy()
    bent[5, 0] += 1e-4
    with pytest.raises(ValueError, match="lattice|tensor-product"):
        lattice_index(bent)
    # a tetrahedral model: its nodes form a lattice, but the volume term is not supported
    tets = M.tet_grid(0.02, 0.02, 0.02, 2, 2, 2)
    tmodel = MD.Model(tets, lloyd_tet_springs(tets, [(1e4, 0.3)], volume=True))
    with pytest.raises(ValueError, match="TetVolume"):
        LatticeExplicit(tmodel)
    # springs that do not join lattice neighbours
    far = T.Springs([[0, 2]], [1.0], [0.02], 3)
    with pytest.raises(ValueError, match="lattice neighbours"):
        LatticeExplicit(MD.Model(mesh, [far]))
    # a hexahedron with its corners in another order
    cells = mesh.cells.copy()
    cells[0] = cells[0][[1, 2, 3, 0, 5, 6, 7, 4]]
    hexv = T.HexVolume(cells, np.ones(len(cells)), np.full(len(cells), 1e-6))
    with pytest.raises(ValueError, match="VTK order"):
        LatticeExplicit(MD.Model(mesh, [hexv]))
    # Rayleigh damping is not supported by run()
    model = _golec_sample(n=(2, 2, 2))
    fast = LatticeExplicit(model)
    with pytest.raises(ValueError, match="mass-proportional"):
        model.damping = (1.0, 1e-3)
        fast.run(model.x0, np.zeros(model.n_dof), 1e-4, 2)


@pytest.mark.parametrize("make", [_golec_sample, _irregular_model])
def test_single_precision_forces_within_rounding_of_positions(make):
    """Single-precision kernels: the forces differ from the model's by the rounding of the
    positions to 24 bits, which the cancellation in x_a - x_b amplifies by |x| / |x - x0|; at
    strains of 1e-3 and more that stays below 1e-4 of the largest force."""
    model = make()
    fast = LatticeExplicit(model, precision="single")
    assert fast.dtype == np.float32 and fast._K.dtype == np.float32
    rng = np.random.default_rng(7)
    span = np.abs(model.x0).max()
    for strain in (1e-3, 1e-2, 1e-1):
        x = model.x0 + strain * 0.01 * rng.standard_normal(model.n_dof) * model.free
        f_single, f_model = fast.force(x), model.force(x)
        rel = _rel(f_single, f_model)
        assert rel <= 1e-4
        # and not better than single precision can be (it does compute in single)
        assert rel >= 0.1 * np.finfo(np.float32).eps * span / np.abs(x - model.x0).max() * 1e-3
    # the gradient buffer must match the kernels' precision
    with pytest.raises(ValueError, match="float32"):
        fast.gradient_lattice(fast.to_lattice(model.x0), np.empty((3, fast.N)))


def test_single_precision_trajectory_close_to_double():
    model = _golec_sample(n=(3, 3, 3), alpha=5.0)
    h = 0.9 * S.explicit_stability_limit(model, model.x0)
    rng = np.random.default_rng(8)
    v0 = 1e-2 * rng.standard_normal(model.n_dof)
    xs, vs, ss = LatticeExplicit(model, precision="single").run(model.x0, v0, h, 600, None, 20)
    xd, vd, sd = LatticeExplicit(model).run(model.x0, v0, h, 600, None, 20)
    disp = np.abs(sd - model.x0).max()
    assert disp > 0
    diff = np.abs(ss - sd).max() / disp
    # position rounding relative to the motion, eps |x| / disp, amplified modestly over 600
    # steps: the state stays double, so rounding does not pile up step by step
    rounding = np.finfo(np.float32).eps * np.abs(model.x0).max() / disp
    assert 0 < diff <= 100 * rounding, (diff, rounding)
    assert np.all(xs[model.fixed] == model.x0[model.fixed]) and np.all(vs[model.fixed] == 0)


def test_precision_must_be_known():
    with pytest.raises(ValueError, match="precision must be 'double' or 'single', got 'half'"):
        LatticeExplicit(_golec_sample(n=(2, 2, 2)), precision="half")

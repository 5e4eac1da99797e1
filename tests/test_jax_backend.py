"""The JAX backend of the explicit steps (msslib.stepping.jax_backend) on JAX's CPU backend,
against the numba kernels: a Lloyd tetrahedral network (gmsh cylinder) and a Golec lattice
(with and without the hexahedron volume term), positions after 200 steps to 1e-12 of the body's
size in fp64; the force against Model.force and the load balance; the fp32 error bounded; the
refusals, the stability guard, the divergence report and the fallback to numba."""

from __future__ import annotations

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.errors import DivergenceError, MsslibWarning, StabilityError
from msslib.stepping import LatticeExplicit
from msslib.stepping.network_kernels import N_MONITOR, network_forces, network_layout, network_steps, records
from msslib.system import Model
from msslib.models.golec import golec_cube_springs
from msslib.terms import Gravity

jax = pytest.importorskip("jax")

from msslib.stepping import jax_backend as JB  # noqa: E402

N_STEPS = 200
ALPHA = 3.0  # mass-proportional damping (1/s)


def _size(model):
    return float(np.ptp(model.x0.reshape(-1, 3), axis=0).max())


@pytest.fixture(scope="module")
def lloyd():
    mesh = M.cylinder_mesh(0.05, 0.2, 0.02)
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e6, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    h = 0.9 * S.explicit_stability_limit(model, model.x0)
    v0 = 0.2 * np.random.default_rng(0).standard_normal(model.n_dof) * model.free  # m/s: the springs work
    return model, h, v0


def _golec(n, nu, volume=True):
    mesh = M.hex_grid(0.01 * n, 0.01 * n, 0.01 * n, n, n, n)
    terms = golec_cube_springs(mesh, [(2e4, nu)], 1.0)[:None if volume else 1]
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    model = Model(mesh, [t for t in terms if len(t.conn)] + [Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed,
                  masses=masses)
    return model, 0.9 * S.explicit_stability_limit(model, model.x0)


@pytest.fixture(scope="module")
def golec():
    """6^3 Golec cubes, nu = 0.3: springs and the hexahedron volume term."""
    return _golec(6, 0.3)


def _numba_network(model, h, v0, n):
    """The numba kernels of msslib.stepping.network_kernels called directly: positions after n steps."""
    arrays = JB.network_arrays(model)
    rowptr_ib_kl = network_layout(arrays["conn"], arrays["k"], arrays["rest_length"], model.n_nodes)
    free = model.free
    w = h * np.where(free, 1.0 / np.where(free, model.mass, 1.0), 0.0)  # as the stepping API
    v = np.where(free, v0, 0.0)
    R = records(model.x0)
    state = (R, v, np.zeros(model.n_dof), w, 1.0 - h * ALPHA, h, arrays["fext"], model.x0.copy(), np.zeros(model.n_dof))
    mon = np.zeros((max(n, 1), N_MONITOR))
    network_forces(state, rowptr_ib_kl, mon)
    network_steps(state, rowptr_ib_kl, mon, n)
    return R[:, :3].reshape(-1).copy()


def test_available_names_the_device():
    ok, reason = JB.available()
    assert ok, reason
    assert JB.default_device().platform in reason and jax.__version__ in reason


def test_lloyd_network_matches_numba(lloyd):
    model, h, v0 = lloyd
    ref = _numba_network(model, h, v0, N_STEPS)
    net = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0)
    assert net.n_springs > 1500 and net.precision == "double"
    net.steps(N_STEPS)
    x = net.positions()
    size = _size(model)
    moved = np.abs(ref - model.x0).max() / size
    assert moved > 1e-3  # the comparison is over a real motion, not the rest state
    err = np.abs(x - ref).max() / size
    assert err <= 1e-12, f"JAX vs numba after {N_STEPS} steps: {err:.3g} of the body's size"
    assert np.all(x[~model.free] == model.x0[~model.free])  # fixed dofs stay put


def test_network_force_is_the_models_and_balances_the_load(lloyd):
    """The force after the steps equals Model.force at the same positions (msslib's generic
    kernels); springs only exchange forces, so the total force is the applied weight."""
    model, h, v0 = lloyd
    net = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0).steps(50)
    x = net.positions()
    F = net.forces()
    ref = model.force(x, 1.0)
    assert np.abs(F - ref).max() <= 1e-11 * np.abs(ref).max()
    weight = model.mass.reshape(-1, 3)[:, 2].sum() * 9.81
    total = F.reshape(-1, 3).sum(axis=0)
    assert np.allclose(total, [0.0, 0.0, -weight], rtol=0, atol=1e-9 * weight)
    # the reactions carry what the free nodes do not: reactions = -(force on the fixed dofs)
    r = net.reactions()
    assert np.all(r[model.free] == 0.0) and np.allclose(r[~model.free], -F[~model.free])


def test_split_calls_and_unroll_give_the_same_state(lloyd):
    model, h, v0 = lloyd
    one = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0, unroll=8).steps(N_STEPS).positions()
    split = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0, unroll=1).steps(37).steps(N_STEPS - 37).positions()
    assert np.abs(one - split).max() <= 1e-13 * _size(model)


def test_network_from_arrays_equals_from_model(lloyd):
    model, h, v0 = lloyd
    a = JB.network_arrays(model)
    net = JB.JaxNetwork(a["x0"], a["conn"], a["k"], a["rest_length"], a["mass"], a["free"], a["fext"], h, ALPHA, v0=v0)
    assert net.stability["stability_limit"] >= h  # checked on the springs alone
    ref = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0)
    assert np.array_equal(net.steps(20).positions(), ref.steps(20).positions())


def test_network_single_precision_error_is_bounded(lloyd):
    model, h, v0 = lloyd
    ref = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0).steps(N_STEPS).positions()
    single = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0, precision="single").steps(N_STEPS).positions()
    size = _size(model)
    err = np.abs(single - ref).max() / size
    print(f"fp32 forces, Lloyd network, {N_STEPS} steps: {err:.3g} of the body's size")
    assert 1e-10 < err < 1e-5, err  # rounded (not double in disguise), and far below the motion (> 1e-3)


def test_golec_lattice_matches_numba(golec):
    model, h = golec
    cpu = LatticeExplicit(model, precision="double")
    lat = JB.JaxLattice(model)
    assert lat.n_hexes == 6 ** 3
    v0 = np.zeros(model.n_dof)
    x_ref, v_ref, saved_ref = cpu.run(model.x0, v0, h, N_STEPS, ALPHA, 50)
    x, v, saved = lat.run(model.x0, v0, h, N_STEPS, ALPHA, 50)
    size = _size(model)
    assert np.abs(x_ref - model.x0).max() / size > 1e-3
    err = max(np.abs(x - x_ref).max(), np.abs(saved - saved_ref).max()) / size
    assert saved.shape == saved_ref.shape == (4, model.n_dof)
    assert err <= 1e-12, f"JaxLattice vs LatticeExplicit after {N_STEPS} steps: {err:.3g} of the size"
    assert np.abs(v - v_ref).max() <= 1e-10 * np.abs(v_ref).max()


def test_golec_lattice_force_is_the_models(golec):
    model, _ = golec
    lat = JB.JaxLattice(model)
    x = model.x0 + 1e-3 * np.random.default_rng(2).standard_normal(model.n_dof)
    ref = model.force(x, 1.0)  # the generic kernels of the terms
    assert np.abs(lat.force(x) - ref).max() <= 1e-12 * np.abs(ref).max()


def test_lattice_single_precision_error_is_bounded(golec):
    model, h = golec
    v0 = np.zeros(model.n_dof)
    x_ref = JB.JaxLattice(model).run(model.x0, v0, h, N_STEPS, ALPHA, N_STEPS)[0]
    x32 = JB.JaxLattice(model, precision="single").run(model.x0, v0, h, N_STEPS, ALPHA, N_STEPS)[0]
    err = np.abs(x32 - x_ref).max() / _size(model)
    print(f"fp32 forces, Golec lattice, {N_STEPS} steps: {err:.3g} of the body's size")
    assert 1e-10 < err < 1e-5, err


def test_generic_network_on_a_lattice_agrees_with_the_stencil_and_numba():
    """nu = 1/4: Golec's volume term vanishes (kappa = 0), the springs alone; three kernels, one answer."""
    model, h = _golec(5, 0.25, volume=False)
    assert [t.kind for t in model.terms] == ["springs", "external"]
    v0 = 0.05 * np.random.default_rng(3).standard_normal(model.n_dof) * model.free
    ref = _numba_network(model, h, v0, N_STEPS)
    net = JB.JaxNetwork.from_model(model, h, ALPHA, v0=v0).steps(N_STEPS).positions()
    lat = JB.JaxLattice(model).run(model.x0, v0, h, N_STEPS, ALPHA, N_STEPS)[0]
    size = _size(model)
    assert np.abs(ref - model.x0).max() / size > 1e-3
    assert np.abs(net - ref).max() <= 1e-12 * size
    assert np.abs(lat - ref).max() <= 1e-12 * size


def test_models_that_are_not_springs_are_refused(golec, lloyd):
    with pytest.raises(ValueError) as e:
        JB.JaxNetwork.from_model(golec[0], golec[1])
    assert "HexVolume" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(ValueError, match="not a structured lattice"):
        JB.JaxLattice(lloyd[0])
    with pytest.raises(ValueError, match="precision must be 'double' or 'single'"):
        JB.JaxNetwork.from_model(lloyd[0], lloyd[1], precision="half")


def test_stability_guard_and_divergence(lloyd):
    model, h, _ = lloyd
    limit = S.explicit_stability_limit(model, model.x0)
    with pytest.raises(StabilityError, match="stability limit"):
        JB.JaxNetwork.from_model(model, 1.5 * limit, 0.0)
    net = JB.JaxNetwork.from_model(model, 3.0 * limit, 0.0, allow_unstable=True).steps(3)
    before = net.positions()
    with pytest.raises(DivergenceError, match="non-finite state"):
        net.steps(5000)
    assert np.array_equal(net.positions(), before) and net.n_steps == 3


def test_double_precision_is_scoped(lloyd):
    model, h, _ = lloyd
    JB.JaxNetwork.from_model(model, h).steps(2)
    assert not jax.config.jax_enable_x64
    assert jax.numpy.zeros(1).dtype == np.float32  # JAX's default is untouched


def test_backend_option_falls_back_to_numba_with_a_warning(lloyd, golec, monkeypatch):
    model, h, v0 = lloyd
    ref = _numba_network(model, h, v0, 30)
    assert isinstance(JB.network_engine(model, h, ALPHA, v0=v0), JB.JaxNetwork)
    monkeypatch.setattr(JB.device, "available", lambda: (False, "jax cannot be imported (test)"))
    with pytest.warns(MsslibWarning, match=r"backend 'jax' is not available \(jax cannot be imported \(test\)\)"):
        net = JB.network_engine(model, h, ALPHA, v0=v0, precision="double", unroll=4)
    assert isinstance(net, JB.CpuNetwork)
    assert np.abs(net.steps(30).positions() - ref).max() == 0.0
    with pytest.warns(MsslibWarning, match="numba CPU path"):
        assert isinstance(JB.lattice_engine(golec[0]), LatticeExplicit)
    with pytest.raises(ValueError, match="backend must be one of"):
        JB.network_engine(model, h, backend="cuda")


def test_the_cpu_network_holds_a_bounded_monitor_for_many_steps(lloyd, monkeypatch):
    """Many steps in one call run in kernel calls of at most 256 steps (the monitor used to hold a
    row per step), bitwise the same as the steps taken one call at a time."""
    model, h, v0 = lloyd
    monkeypatch.setattr(JB.device, "available", lambda: (False, "jax cannot be imported (test)"))
    with pytest.warns(MsslibWarning):
        a = JB.network_engine(model, h, ALPHA, v0=v0, precision="double")
    with pytest.warns(MsslibWarning):
        b = JB.network_engine(model, h, ALPHA, v0=v0, precision="double")
    a.steps(600)
    for _ in range(6):
        b.steps(100)
    assert a._st.mon.shape[0] <= 256  # the network engine's monitor
    assert np.array_equal(a.positions(), b.positions()) and np.array_equal(a.velocities(), b.velocities())

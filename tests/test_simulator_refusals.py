"""Every wrong call to the stepping API is refused in one line naming the argument, before anything
changes: after a refused call the simulator steps exactly as one that never saw it."""

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib.stepping import Simulator


@pytest.fixture(scope="module")
def model():
    mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
    setup = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]})
    return setup.model


def _top(model):
    return np.flatnonzero(np.isclose(model.x0.reshape(-1, 3)[:, 2], 0.08))


def _snapshot(sim):
    return (sim.x.copy(), sim.v.copy(), sim.t, sim.n_steps, sorted(sim._forces), sorted(sim._paths), sim._next,
            sim.engine)


def _same(a, b):
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert a[2:] == b[2:]


def _sim(model, engine="network", **kw):
    from msslib.solvers import explicit_stability_limit

    dt = 0.5 * explicit_stability_limit(model, model.x0)
    sim = Simulator(model, dt=dt, engine=engine, **kw)
    sim.step(3)
    return sim


def _calls(model):
    top = _top(model)
    n = model.n_nodes
    return [
        ("axes", lambda s: s.prescribe(top, [0, 0, -1e-4], axes=[-1])),
        ("axes", lambda s: s.prescribe(top, [0, 0, -1e-4], axes=[3])),
        ("axes", lambda s: s.prescribe(top, [0, 0, -1e-4], axes=[True])),
        ("axes", lambda s: s.prescribe(top, [0, 0, -1e-4], axes=[2, 2])),
        ("displacement", lambda s: s.prescribe(top, lambda t: [0.0, 1e-4])),
        ("displacement", lambda s: s.prescribe(top, lambda t: 1e-4)),
        ("displacement", lambda s: s.prescribe(top, lambda t: [0, 0, float("nan")])),
        ("force", lambda s: s.apply_force(top, lambda t: [1.0, 2.0])),
        ("force", lambda s: s.apply_force(top, lambda t: 1.0)),
        ("force", lambda s: s.apply_force(top, [0, 0, float("nan")])),
        ("force", lambda s: s.apply_force(top, lambda t: [0, 0, float("nan")])),
        ("load", lambda s: s.set_load(lambda t: [1.0, 2.0])),
        ("load", lambda s: s.set_load(float("inf"))),
        ("nodes", lambda s: s.apply_force([1.7], [0, 0, 1.0])),
        ("nodes", lambda s: s.apply_force([n], [0, 0, 1.0])),
        ("nodes", lambda s: s.apply_force([-1], [0, 0, 1.0])),
        ("nodes", lambda s: s.apply_force(np.ones(n - 1, dtype=bool), [0, 0, 1.0])),
        ("nodes", lambda s: s.apply_force([], [0, 0, 1.0])),
        ("n", lambda s: s.step(-1)),
        ("n", lambda s: s.step(0)),
        ("n", lambda s: s.step(2.5)),
        ("n", lambda s: s.step(True)),
        ("h", lambda s: s.step(1, h=-1e-5)),
        ("h", lambda s: s.step(1, h=float("nan"))),
        ("t_new", lambda s: s.step(1, t_new=s.t - 1.0)),
        ("t_new", lambda s: s.step(1, t_new=s.t)),
        ("t_new", lambda s: s.step(1, t_new=float("inf"))),
        ("t_end", lambda s: s.run(float("nan"))),
        ("t_end", lambda s: s.run(float("inf"))),
        ("every", lambda s: s.run(s.t + 1e-3, lambda _: None, every=0)),
        ("every", lambda s: s.run(s.t + 1e-3, lambda _: None, every=1.5)),
        ("handle", lambda s: s.remove(99)),
    ]


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_a_refused_call_names_its_argument_and_changes_nothing(model, engine):
    sim = _sim(model, engine)
    twin = _sim(model, engine)
    for name, call in _calls(model):
        before = _snapshot(sim)
        with pytest.raises((ValueError, KeyError)) as info:
            call(sim)
        msg = str(info.value)
        assert "\n" not in msg and name in msg, (name, msg)
        _same(_snapshot(sim), before)
    sim.step(5)
    twin.step(5)
    assert np.array_equal(sim.x, twin.x) and np.array_equal(sim.v, twin.v)
    sim.reset()  # no entry left behind: reset and step still run
    sim.step(2)


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_a_callable_that_fails_on_its_first_evaluation_leaves_nothing_registered(model, engine):
    sim = _sim(model, engine)
    before = _snapshot(sim)
    with pytest.raises(ZeroDivisionError):
        sim.apply_force(_top(model), lambda t: [0.0, 0.0, 1.0 / 0.0])
    _same(_snapshot(sim), before)
    sim.reset()
    sim.step(2)


def test_a_callable_that_fails_later_rolls_the_step_call_back(model):
    sim = _sim(model, "network")
    limit = sim.t + 2.5 * sim.dt

    def force(t):
        if t > limit:
            raise ZeroDivisionError("boom")
        return [0.0, 0.0, 1e-3]

    h = sim.apply_force(_top(model), force)
    before = _snapshot(sim)
    with pytest.raises(ZeroDivisionError):
        sim.step(5)
    _same(_snapshot(sim), before)
    sim.remove(h)  # a handle removes the failing entry
    sim.step(5)


def test_negative_damping_and_wrong_options_are_refused(model):
    for kw, name in [(dict(damping=-1.0), "damping"), (dict(damping=(1.0, -1e-4)), "damping"),
                     (dict(damping=float("nan")), "damping"), (dict(dt=float("nan")), "dt"), (dict(dt=-1e-4), "dt"),
                     (dict(method="rk4"), "method"), (dict(blowup=0.0), "blowup")]:
        kw = {"dt": 1e-4, **kw}
        with pytest.raises(ValueError, match=name):
            Simulator(model, **kw)


def test_the_jax_engine_refuses_the_schemes_it_does_not_run(model):
    for method in ("implicit_euler", "velocity_verlet"):
        with pytest.raises(ValueError, match="method") as info:
            Simulator(model, dt=1e-4, engine="jax", method=method)
        assert "\n" not in str(info.value)


def test_values_of_callables_are_not_stretched(model):
    """[1, 2] in 3D used to become [1, 2, 1]; a value of the right shape is used as given."""
    sim = _sim(model, "network")
    with pytest.raises(ValueError, match="force"):
        sim.apply_force(_top(model), lambda t: [1.0, 2.0])
    top = _top(model)
    sim.prescribe(top, lambda t: [0.0, 0.0, -1e-4 * min(t / 1e-3, 1.0)], axes=[2])
    sim.step(4)
    z = sim.x[top, 2] - model.x0.reshape(-1, 3)[top, 2]
    assert np.allclose(z, -1e-4 * min(sim.t / 1e-3, 1.0), rtol=0, atol=1e-15)


def test_many_steps_in_one_call_hold_a_bounded_monitor(model):
    sim = _sim(model, "network")
    sim.step(5000)
    assert sim._stepper.mon.shape[0] <= 256
    twin = _sim(model, "network")
    for _ in range(50):
        twin.step(100)
    assert np.array_equal(sim.x, twin.x) and np.array_equal(sim.v, twin.v)


def test_a_nan_from_a_path_beyond_the_bound_is_a_divergence_not_an_attribute_error(model):
    from msslib.errors import DivergenceError

    sim = _sim(model, "network", blowup=10.0)
    jump = sim.t + 1.5 * sim.dt
    sim.prescribe(_top(model), lambda t: [0.0, 0.0, 0.0] if t < jump else [0.0, 0.0, 50.0])
    with pytest.raises(DivergenceError):
        sim.step(5)


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_potential_energy_does_not_depend_on_where_the_mesh_sits(engine):
    """The same column 1 m away: the same potential energy (it used to hold -f.x in absolute
    positions, 9.81 J per kg per metre of height), and KE + PE conserved without damping."""
    energies = []
    for z0 in (0.0, 1.0):
        mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
        mesh.points[:, 2] += z0
        model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                                   fixed={"plane": ["z", z0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
        from msslib.solvers import explicit_stability_limit

        sim = Simulator(model, dt=0.3 * explicit_stability_limit(model, model.x0), engine=engine, damping=0.0)
        e0 = sim.potential_energy()
        sim.step(200)
        energies.append((e0, sim.potential_energy(), sim.kinetic_energy()))
    (a0, a1, k_a), (b0, b1, k_b) = energies
    assert a0 == 0.0 and abs(b0) < 1e-12
    assert abs(a1 - b1) < 1e-9 * abs(a1) and a1 < 0
    # energy conserved without damping to the bound of symplectic Euler: its energy error is
    # bounded (no drift) by about h omega_max / 2 = dt / limit of the energy exchanged
    assert abs((a1 + k_a) - a0) < 0.3 * max(k_a, abs(a1))
    assert abs((b1 + k_b) - b0) < 0.3 * max(k_b, abs(b1))


def test_the_work_of_nodal_forces_counts_in_the_potential_energy(model):
    from msslib.solvers import explicit_stability_limit

    sim = Simulator(model, dt=0.3 * explicit_stability_limit(model, model.x0), damping=0.0, load=0.0)
    sim.apply_force(_top(model), [0.0, 0.0, -1e-3])
    assert abs(sim.potential_energy()) < 1e-25
    sim.step(200)
    pe, ke = sim.potential_energy(), sim.kinetic_energy()
    assert pe < 0 < ke and abs(pe + ke) < 0.3 * max(ke, abs(pe))

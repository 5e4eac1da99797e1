"""Property-based tests of the stepping API (Hypothesis): over random sequences of calls, a run is
reproducible bit for bit (twice from scratch, and after reset() with the same steps), a refused
call changes nothing, the network and generic engines agree to round-off, energy is conserved
without damping to the bound of symplectic Euler, and a held tool's force is the static one."""

import functools

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import msslib  # noqa: E402
from msslib import mesh as M  # noqa: E402
from msslib import solvers as S  # noqa: E402
from msslib.stepping import Simulator  # noqa: E402

SETTINGS = settings(max_examples=15, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


@functools.lru_cache(maxsize=None)
def column():
    mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    return model, S.explicit_stability_limit(model, model.x0)


def _top(model):
    return np.flatnonzero(model.mesh.points[:, 2] > 0.08 - 1e-9)


# one call of the API, drawn at random: (kind, arguments)
nodes = st.lists(st.integers(0, 207), min_size=1, max_size=6, unique=True)
vec = st.lists(st.floats(-1e-3, 1e-3, allow_nan=False), min_size=3, max_size=3)
call = st.one_of(
    st.tuples(st.just("step"), st.integers(1, 40)),
    st.tuples(st.just("force"), nodes, vec),
    st.tuples(st.just("ramp_force"), nodes, vec),
    st.tuples(st.just("path"), nodes, vec),
    st.tuples(st.just("load"), st.floats(0.0, 2.0)),
    st.tuples(st.just("remove"), st.integers(0, 5)),
)
bad_call = st.sampled_from([
    lambda s: s.step(0), lambda s: s.step(-3), lambda s: s.step(1.5), lambda s: s.step(1, t_new=s.t - 1e-3),
    lambda s: s.run(float("nan")), lambda s: s.run(s.t + 1e-3, lambda _: None, every=0),
    lambda s: s.apply_force([0.5], [0, 0, 1.0]), lambda s: s.apply_force([0], lambda t: [1.0, 2.0]),
    lambda s: s.prescribe([3], [0, 0, 1e-4], axes=[-1]), lambda s: s.prescribe([3], lambda t: 1.0 / 0.0),
    lambda s: s.set_load(float("inf")), lambda s: s.remove(1000),
])


def _apply(sim, c, handles):
    kind = c[0]
    if kind == "step":
        sim.step(c[1])
    elif kind == "force":
        handles.append(sim.apply_force(c[1], c[2]))
    elif kind == "ramp_force":
        handles.append(sim.apply_force(c[1], [[0.0, 0, 0, 0], [0.01 + sim.t, *c[2]]]))
    elif kind == "path":
        handles.append(sim.prescribe(c[1], [[sim.t, 0, 0, 0], [sim.t + 0.02, *(0.1 * np.asarray(c[2]))]]))
    elif kind == "load":
        sim.set_load(c[1])
    elif kind == "remove" and handles:
        sim.remove(handles.pop(c[1] % len(handles)))


def _run(calls, engine="network", bad=None):
    model, limit = column()
    sim = Simulator(model, dt=0.7 * limit, engine=engine, damping=5.0)
    handles = []
    for i, c in enumerate(calls):
        if bad is not None:
            before = (sim.x, sim.v, sim.t, sim.n_steps)
            with pytest.raises((ValueError, KeyError, ZeroDivisionError)):
                bad[i % len(bad)](sim)
            after = (sim.x, sim.v, sim.t, sim.n_steps)
            assert np.array_equal(before[0], after[0]) and np.array_equal(before[1], after[1])
            assert before[2:] == after[2:]
        _apply(sim, c, handles)
    return sim


@SETTINGS
@given(st.lists(call, min_size=1, max_size=8))
def test_a_run_is_reproducible_bit_for_bit(calls):
    a, b = _run(calls), _run(calls)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v) and a.t == b.t
    # reset() and the same steps under the final loads: the same states as a second reset and replay
    n = a.n_steps
    if n:
        a.reset()
        a.step(n)
        x1, v1 = a.x, a.v
        a.reset()
        for _ in range(n):
            a.step()
        assert np.array_equal(a.x, x1) and np.array_equal(a.v, v1)


@SETTINGS
@given(st.lists(call, min_size=1, max_size=6), st.lists(bad_call, min_size=1, max_size=4))
def test_a_refused_call_changes_nothing(calls, bad):
    clean, noisy = _run(calls), _run(calls, bad=bad)
    assert np.array_equal(clean.x, noisy.x) and np.array_equal(clean.v, noisy.v) and clean.t == noisy.t


@SETTINGS
@given(st.lists(call, min_size=1, max_size=6))
def test_the_engines_agree(calls):
    a, b = _run(calls, "network"), _run(calls, "generic")
    model = column()[0]
    scale = max(np.abs(b.x.ravel() - model.x0).max(), 1e-9)
    assert np.abs(a.x - b.x).max() <= 1e-9 * scale
    assert a.t == pytest.approx(b.t, rel=1e-14)


@SETTINGS
@given(st.floats(0.1, 0.9), st.floats(0.0, 2.0), nodes, vec, st.integers(20, 200))
def test_energy_is_conserved_without_damping(ratio, load, on, force, n):
    """Constant loads, no damping: KE + PE stays within (dt / limit) x the energy exchanged of its
    start (symplectic Euler's energy error is bounded by about h omega_max / 2, without drift)."""
    model, limit = column()
    sim = Simulator(model, dt=ratio * limit, damping=0.0, load=load)
    sim.apply_force(on, 1e2 * np.asarray(force))
    e0 = sim.potential_energy() + sim.kinetic_energy()
    for _ in range(n // 10):
        sim.step(10)
        ke, pe = sim.kinetic_energy(), sim.potential_energy()
        # 1e-15 J: round-off where nothing moves (no load, a force on a supported node)
        assert abs(ke + pe - e0) <= ratio * max(ke, abs(pe)) + 1e-15


@settings(max_examples=3, deadline=None, derandomize=True)
@given(st.floats(-2e-3, -2e-4))
def test_a_held_tool_force_is_the_static_one(depth):
    model, limit = column()
    top = _top(model)
    sim = Simulator(model, dt=0.8 * limit, damping=16.0, load=0.0)
    sim.prescribe(top, [[0.0, 0.0, 0.0, 0.0], [0.05, 0.0, 0.0, depth]])
    sim.run(2.0)
    setup = msslib.build_model("lloyd_tetrahedron", model.mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed=[{"plane": ["z", 0.0]},
                                      {"select": {"plane": ["z", 0.08]}, "displacement": [0.0, 0.0, depth]}])
    static = S.static_solve(setup.model, setup.model.x0)
    expected = setup.model.reaction(static.x)[top].sum(axis=0)
    assert sim.reaction[top].sum(axis=0)[2] == pytest.approx(expected[2], rel=1e-4)

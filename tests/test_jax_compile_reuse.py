"""The JAX engine compiles its step once per (node count, precision, unroll): a reset(), a new load,
or a second Simulator on the same model reuse the compiled step (JAX traces a
function again only when it compiles it again, so the trace count of the spring force counts
the compilations), and the state after the steps is bitwise that of the first run."""

from __future__ import annotations

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.stepping import Simulator

pytest.importorskip("jax")

from msslib.stepping.jax_backend import network as JN  # noqa: E402


@pytest.fixture(scope="module")
def column():
    mesh = M.cylinder_mesh(0.02, 0.06, 0.01)
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e5, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    return model, 0.8 * S.explicit_stability_limit(model, model.x0)


@pytest.fixture
def traces(monkeypatch):
    """The number of times JAX has traced the spring force since the fixture started."""
    count = [0]
    inner = JN._spring_force

    def counted(*args, **kwargs):
        count[0] += 1  # a Python side effect: runs when JAX traces, not when the compiled code runs
        return inner(*args, **kwargs)

    monkeypatch.setattr(JN, "_spring_force", counted)
    return count


def test_reset_rebuilds_and_a_second_simulator_do_not_compile_again(column, traces):
    model, dt = column
    a = Simulator(model, dt=dt, damping=3.0, engine="jax")
    a.step(37)
    first = a.x.copy()
    assert a.engine == "jax"
    after_first = traces[0]
    a.reset()
    a.step(37)
    assert np.array_equal(a.x, first)
    b = Simulator(model, dt=dt, damping=3.0, engine="jax")
    b.step(37)
    assert np.array_equal(b.x, first)
    b.set_load(0.5)
    b.step(5)
    assert traces[0] == after_first


def test_new_shapes_or_options_do_compile(column, traces):
    """The counter does count: a new precision traces again (the cache is keyed on it)."""
    model, dt = column
    from msslib.stepping.jax_backend import JaxNetwork

    JN._compiled.cache_clear()
    net = JaxNetwork.from_model(model, dt, 3.0)
    net.steps(3)
    assert traces[0] >= 1
    before = traces[0]
    JaxNetwork.from_model(model, dt, 3.0).steps(3)
    assert traces[0] == before
    JaxNetwork.from_model(model, dt, 3.0, precision="single").steps(3)
    assert traces[0] > before

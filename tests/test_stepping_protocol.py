"""One home for time stepping: every engine behind the Simulator follows the one Stepper protocol,
the Simulator calls nothing else, and the engines' reactions agree through it."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.stepping import ENGINES, Simulator, Stepper
from msslib.stepping.protocol import Stepper as ProtocolClass
from test_simulator import column  # noqa: F401 - the tetrahedral column fixture, shared

ROOT = Path(__file__).resolve().parents[1]


def _engines():
    engines = ["network", "generic"]
    try:
        import jax  # noqa: F401

        engines.append("jax")
    except ImportError:
        pass
    return engines


@pytest.mark.parametrize("engine", _engines())
def test_every_engine_is_a_stepper_and_reacts_alike(column, engine):
    model, limit = column
    sim = Simulator(model, dt=0.8 * limit, damping=3.0, engine=engine)
    assert sim.engine == engine
    assert isinstance(sim._stepper, Stepper)
    sim.step(40)
    ref = Simulator(model, dt=0.8 * limit, damping=3.0, engine="generic").step(40)
    scale = np.abs(ref.reaction).max()
    assert scale > 0
    assert np.abs(sim.reaction - ref.reaction).max() < 1e-10 * scale
    # the protocol's reaction is minus the total force on the dofs that do not move
    st = sim._stepper
    f = np.asarray(st.full_force())
    np.testing.assert_allclose(np.ravel(st.reaction()), np.where(st.free, 0.0, -f), rtol=0, atol=1e-12 * scale)


def test_an_engine_missing_a_member_is_not_a_stepper():
    class Incomplete:
        explicit = conservative = True
        free = np.ones(3, bool)
        load, extra, t, n_taken, stats, messages = 1.0, None, 0.0, 0, {}, []
        x = v = np.zeros(3)

        def steps(self, n, h=None, t_new=None):
            pass

    assert not isinstance(Incomplete(), Stepper)


def test_the_simulator_uses_only_the_protocol_of_its_stepper():
    """Every attribute the Simulator reads or calls on its stepper is a member of Stepper (plus
    the flag it sets on a network stepper whose driven load reads the state)."""
    members = {n for n in dir(ProtocolClass) if not n.startswith("_")} | set(ProtocolClass.__annotations__)
    tree = ast.parse((ROOT / "msslib" / "stepping" / "simulator.py").read_text())
    used = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in ("st", "stepper"):
            used.add(node.attr)
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute)
                and node.value.attr == "_stepper"):
            used.add(node.attr)
    extra = used - members - {"drive_reads_state"}
    assert not extra, f"the Simulator reaches past the Stepper protocol: {sorted(extra)}"
    assert set(ENGINES) >= {"network", "generic", "jax"}


@pytest.fixture(scope="module")
def beam():
    """Golec's cubes on a structured lattice: a cantilever under its weight."""
    mesh = M.hex_grid(0.4, 0.1, 0.1, 8, 2, 2)
    setup = msslib.build_model("golec_cube", mesh, msslib.Material(1000.0, 0.3, density=0.3125),
                               fixed={"plane": ["x", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]})
    model = setup.model
    return model, S.explicit_stability_limit(model, model.x0)


def test_the_lattice_engine_is_a_stepper_behind_the_simulator(beam):
    model, limit = beam
    dt = 0.8 * limit
    a = Simulator(model, dt=dt, damping=3.0, engine="lattice")
    b = Simulator(model, dt=dt, damping=3.0, engine="network")
    assert a.engine == "lattice" and isinstance(a._stepper, Stepper)
    a.step(120).step(80)
    b.step(200)
    scale = np.abs(b.x - model.x0.reshape(-1, 3)).max()
    assert np.abs(a.x - b.x).max() < 1e-11 * scale
    assert np.abs(a.v - b.v).max() < 1e-10 * np.abs(b.v).max()
    assert np.abs(a.reaction - b.reaction).max() < 1e-10 * np.abs(b.reaction).max()
    assert a.t == pytest.approx(200 * dt) and a.n_steps == 200
    x_before = a.x
    a.reset()
    np.testing.assert_array_equal(a.x, model.x0.reshape(-1, 3))
    a.step(200)
    np.testing.assert_array_equal(a.x, x_before)  # reset and replay: bitwise the same


def test_the_lattice_engine_refuses_what_it_cannot_run(beam, column):
    model, limit = beam
    dt = 0.8 * limit
    with pytest.raises(ValueError, match="engine='lattice' runs constant loads"):
        Simulator(model, dt=dt, engine="lattice", load=[[0.0, 0.0], [0.1, 1.0]])
    with pytest.raises(ValueError, match="engine='lattice' runs symplectic_euler only"):
        Simulator(model, dt=dt, engine="lattice", method="velocity_verlet")
    sim = Simulator(model, dt=dt, engine="lattice")
    with pytest.raises(ValueError, match="engine='lattice' runs constant loads"):
        sim.apply_force([5], [0.0, 0.0, -1.0])
    assert sim.engine == "lattice" and sim.n_steps == 0  # the refused call changed nothing
    tet, tet_limit = column
    with pytest.raises(ValueError, match="engine='lattice' runs models on a full structured hexahedral lattice.*not a "
                                         "structured lattice"):
        Simulator(tet, dt=0.5 * tet_limit, engine="lattice")
    from msslib.errors import StabilityError

    with pytest.raises(StabilityError):
        Simulator(model, dt=1.05 * limit, engine="lattice")

"""The divergence detector is scale-aware at rest: a tool pressed into an unloaded body (J ~ 0 at
the start), a ramp from zero or an impulsive path is no false alarm at any dt within the stability
limit, on both engines, while a step over the limit is still stopped within a few steps."""

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib.errors import DivergenceError
from msslib.stepping import Simulator
from msslib.solvers import explicit_stability_limit


@pytest.fixture(scope="module")
def cube():
    """Golec cubes, base clamped, no load: the case the issue reported diverged at step 1."""
    model = msslib.build_model("golec_cube", M.hex_grid(0.1, 0.1, 0.1, 6, 6, 6),
                               msslib.Material(1e5, 0.25, density=1000.0), fixed={"plane": ["z", 0.0]}).model
    top = np.flatnonzero(np.isclose(model.x0.reshape(-1, 3)[:, 2], 0.1))[:5]
    return model, top, explicit_stability_limit(model, model.x0)


PATHS = {
    "ramp": [[0, 0, 0, 0], [0.05, 0, 0, -2e-3]],
    "impulsive": lambda t: [0.0, 0.0, -1e-3 if t > 0 else 0.0],
    "oscillating": lambda t: [0.0, 1e-3 * np.sin(200 * t), -1e-3 * (1 - np.cos(100 * t))],
}


@pytest.mark.parametrize("engine", ["network", "generic"])
@pytest.mark.parametrize("ratio", [0.05, 0.3, 0.6, 0.9])
@pytest.mark.parametrize("path", sorted(PATHS))
def test_a_tool_pressed_into_an_unloaded_body_is_no_false_alarm(cube, engine, ratio, path):
    model, top, limit = cube
    sim = Simulator(model, dt=ratio * limit, engine=engine)
    sim.prescribe(top, PATHS[path])
    sim.step(150)
    assert np.all(np.isfinite(sim.x))


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_a_ramped_force_from_zero_is_no_false_alarm(cube, engine):
    model, top, limit = cube
    sim = Simulator(model, dt=0.9 * limit, engine=engine)
    sim.apply_force(top, [[0, 0, 0, 0], [0.02, 0, 0, -1.0]])
    sim.step(150)


@pytest.mark.parametrize("engine", ["network", "generic"])
@pytest.mark.parametrize("ratio", [1.05, 1.5])
def test_a_step_over_the_limit_under_a_tool_is_still_stopped_within_a_few_steps(cube, engine, ratio):
    model, top, limit = cube
    sim = Simulator(model, dt=ratio * limit, engine=engine, damping=0.0, allow_unstable=True)
    sim.prescribe(top, PATHS["ramp"])
    with pytest.raises(DivergenceError) as info:
        sim.step(400)
    err = info.value
    # stopped by the growth detector within a few steps (19 at 1.05 x the limit, 5 at 1.5 x), the
    # motion still within 10 x the tool's depth, not by the displacement bound of the last resort
    assert err.quantity == "growth" and err.step <= 25 and err.max_displacement < 2e-2


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_a_constant_force_on_a_body_without_load_is_no_false_alarm(engine):
    """The reference of the detector is taken with the forces the simulator applies (it was taken
    before them: J ~ 0 at rest, and the first steps 'grew' 1e8-fold)."""
    mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    sim = Simulator(model, dt=0.5 * explicit_stability_limit(model, model.x0), engine=engine, damping=0.0, load=0.0)
    sim.apply_force([2], [0.0, 0.0, 0.0832])
    sim.step(100)
    assert np.all(np.isfinite(sim.x))

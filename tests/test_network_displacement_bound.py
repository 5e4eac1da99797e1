"""The network engine's calls of several steps bound the monitor's max |x - x_ref| by v.v instead
of computing it (msslib.stepping.network_kernels.fused_steps_lean): a body that drifts beyond the
divergence bound stops at the same step, on the same quantity, as in single steps and on the
generic engine; a body that moves fast but within it (the bound passes the divergence bound, the
displacement does not) runs on as the generic engine does, and the bound restarts from the exact
value."""

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib.errors import DivergenceError
from msslib.solvers import explicit_stability_limit
from msslib.stepping.generic import Integrator
from msslib.stepping.network import NetworkStepper


@pytest.fixture(scope="module")
def block():
    """A free-floating block (no support, no load): it drifts at the speed it is given."""
    from msslib.system import Model

    mesh = M.tet_grid(0.03, 0.03, 0.03, 3, 3, 3)
    held = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                              fixed={"plane": ["x", 0.0]}).model
    model = Model(mesh, [t for t in held.terms if t.kind == "springs"], masses=M.lumped_masses(mesh, 1000.0))
    assert model.free.all()
    return model, explicit_stability_limit(model, model.x0)


def _drift(model, speed):
    v0 = np.zeros(model.n_dof)
    v0[0::3] = speed
    return v0


def _run(stepper, calls):
    with pytest.raises(DivergenceError) as info:
        for n in calls:
            stepper.steps(n)
    return info.value


def test_a_drift_beyond_the_bound_stops_at_the_same_step_as_single_steps_and_the_generic_engine(block):
    model, limit = block
    dt = 0.5 * limit
    size = float(np.linalg.norm(np.ptp(model.x0.reshape(-1, 3), axis=0)))
    v0 = _drift(model, 2.0 * size / (150 * dt))  # two body sizes in 150 steps
    kw = dict(dt=dt, damping=0.0, blowup=2.0)
    lean = _run(NetworkStepper(model, model.x0, v0, **kw), [400])
    single = _run(NetworkStepper(model, model.x0, v0, **kw), [1] * 400)
    generic = _run(Integrator(model, model.x0, v0, method="symplectic_euler", **kw), [1] * 400)
    assert lean.quantity == single.quantity == generic.quantity == "displacement"
    assert lean.step == single.step == generic.step and 140 <= lean.step <= 160
    assert np.array_equal(lean.x_last, single.x_last)


def test_a_fast_body_within_the_bound_runs_on_and_the_bound_restarts_from_the_exact_value(block):
    model, limit = block
    dt = 0.5 * limit
    size = float(np.linalg.norm(np.ptp(model.x0.reshape(-1, 3), axis=0)))
    st = NetworkStepper(model, model.x0, _drift(model, 0.0), dt=dt, damping=0.0)
    bound = st.bound
    # 256 steps travel bound / 4; their bound from v.v (sqrt(n_nodes) times the speed) passes bound
    speed = 0.25 * bound / (256 * dt)
    assert np.sqrt(model.n_nodes) * speed * 256 * dt > bound
    kw = dict(dt=dt, damping=0.0)
    lean = NetworkStepper(model, model.x0, _drift(model, speed), **kw)
    lean.steps(256)
    generic = Integrator(model, model.x0, _drift(model, speed), method="symplectic_euler", **kw)
    for _ in range(256):
        generic.steps(1)
    travelled = np.abs(np.asarray(lean.x).reshape(-1) - model.x0).max()
    assert travelled == pytest.approx(0.25 * bound, rel=1e-6) and travelled < bound
    assert np.abs(np.asarray(lean.x).reshape(-1) - np.asarray(generic.x).reshape(-1)).max() <= 1e-9 * size
    assert lean._dmax_ub == pytest.approx(travelled, rel=1e-12)

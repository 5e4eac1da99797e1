"""The stability check on a second thread (msslib.stepping.check): a step the cheap bound cannot
decide is checked while the first call steps; a refused step ends that call and every later one
with the check's StabilityError and the state as before the call, on the network and the generic
engine, with and without a path; an accepted one runs exactly the steps of a check decided at
once."""

import time

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib.errors import StabilityError
from msslib.stepping import Simulator
from msslib.stepping import check as CK


def _exact_limit(model):
    free = model.free
    K = model.stiffness(model.x0).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    return 2.0 / float(np.sqrt(np.linalg.eigvalsh(0.5 * d[:, None] * (K + K.T) * d[None, :]).max()))


@pytest.fixture(scope="module")
def mesh():
    return M.cylinder_mesh(0.02, 0.06, 0.008)


@pytest.fixture
def column(mesh):
    """A new model per test: a check left running by another test writes into its model's cache."""
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    assert int(model.free.sum()) > 400  # the certificates run (below, the dense check decides at once)
    return model, _exact_limit(model)


def _state(sim):
    return sim.x.copy(), sim.v.copy(), sim.reaction.copy(), sim.t, sim.n_steps


@pytest.mark.parametrize("engine", ["network", "network renumbered", "generic"])
@pytest.mark.parametrize("path", [False, True], ids=["loads", "tool path"])
def test_a_refused_step_refuses_the_first_call_and_every_later_one_and_changes_nothing(column, monkeypatch,
                                                                                        engine, path):
    model, limit = column
    monkeypatch.setattr(CK, "DEFER_MIN_DOFS", 0)
    if engine == "network renumbered":  # the engine steps in its own node numbering, if it has one
        from msslib.stepping import network_kernels

        monkeypatch.setattr(network_kernels, "REORDER_MIN_NODES", 0, raising=False)
        engine = "network"
    check = CK.check_time_step

    def slow(*args, **kw):  # the thread's check outlasts the set-up below: the call waits for it
        if not kw.get("cheap_only"):
            time.sleep(0.2)
        return check(*args, **kw)

    monkeypatch.setattr(CK, "check_time_step", slow)
    model._spectrum_cache = {}
    sim = Simulator(model, dt=1.02 * limit, damping=0.0, engine=engine)  # not decided yet: no refusal here
    assert sim.stats["stability_estimate"] is None and sim.stats["stability_limit"] is None
    if path:
        top = np.flatnonzero(model.mesh.points[:, 2] > model.mesh.points[:, 2].max() - 1e-9)
        sim.prescribe(top, [[0.0, 0, 0, 0], [0.01, 0, 0, -1e-4]])
    before = _state(sim)
    for n in (50, 1, 3):
        with pytest.raises(StabilityError, match="1.02 x the explicit stability limit"):
            sim.step(n)
        after = _state(sim)
        for a, b in zip(before, after):
            assert np.array_equal(a, b)
    # the refusal is known now: a rebuild refuses at once, and changes nothing either
    with pytest.raises(StabilityError, match="1.02 x the explicit stability limit"):
        sim.reset()
    with pytest.raises(StabilityError, match="1.02 x the explicit stability limit"):
        sim.apply_force([0], [0.0, 0.0, -1e-3])
    for a, b in zip(before, _state(sim)):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("engine", ["network", "generic"])
@pytest.mark.parametrize("fraction", [0.9, 0.995])
def test_an_accepted_step_runs_the_same_steps_as_a_check_decided_at_once(column, monkeypatch, engine, fraction):
    """At 0.9 of the limit the cheap stages (a few passes of the directional bound) decide the
    step at once, deferred or not; at 0.995 only the whole check does, on the thread."""
    model, limit = column
    runs = {}
    for defer in (False, True):
        monkeypatch.setattr(CK, "DEFER_MIN_DOFS", 0 if defer else 10**12)
        model._spectrum_cache = {}
        sim = Simulator(model, dt=fraction * limit, damping=0.0, engine=engine)
        assert (sim.stats["stability_estimate"] is None) == (defer and fraction > 0.99)
        sim.step(120)
        sim.step(7)
        runs[defer] = (sim.x.copy(), sim.v.copy(), sim.reaction.copy(), dict(sim.stats))
    for a, b in zip(runs[False][:3], runs[True][:3]):
        assert np.array_equal(a, b)
    sync, deferred = runs[False][3], runs[True][3]
    assert deferred["stability_estimate"] == sync["stability_estimate"]
    assert deferred["stability_estimate"].startswith(("certified (", "bound, ", "lanczos"))
    if fraction == 0.9:
        assert sync["stability_estimate"].startswith("bound, directional (")
    assert deferred["stability_limit"] == sync["stability_limit"]
    assert fraction * limit <= sync["stability_limit"] <= limit * (1.0 + 1e-12)
    if fraction > 0.99:
        assert deferred["stability_check_wait"] >= 0.0


def test_below_the_size_a_refusal_still_comes_from_the_constructor(column):
    model, limit = column
    assert int(model.free.sum()) < CK.DEFER_MIN_DOFS
    model._spectrum_cache = {}
    with pytest.raises(StabilityError, match="1.02 x the explicit stability limit"):
        Simulator(model, dt=1.02 * limit, damping=0.0)


def test_the_docs_name_the_size_from_which_the_check_runs_on_a_thread():
    from pathlib import Path

    size = f"{CK.DEFER_MIN_DOFS:,}".replace(",", " ")
    assert f"{size} free dofs or more" in Path(__file__).resolve().parents[1].joinpath("README.md").read_text()
    assert f"{size} free dofs or more" in " ".join(Simulator.__doc__.split())

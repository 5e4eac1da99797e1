"""The network engine's internal node numbering: a large network whose numbering scatters its
springs is stepped in reverse Cuthill-McKee order, and nothing of it shows: positions,
velocities, forces and reactions come back in the model's numbering, equal to the same run
without renumbering and to integrate() to round-off; paths, forces, load curves and the
divergence detector act on the same nodes and stop at the same step."""

import dataclasses

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.errors import DivergenceError
from msslib.mesh.groups import _renumbered_groups
from msslib.stepping import Curve, Simulator, integrate
from msslib.stepping import network_kernels as NK


def _scattered(mesh, seed=3):
    """``mesh`` with its nodes numbered at random (what a generator's numbering does at scale)."""
    order = np.random.default_rng(seed).permutation(mesh.n_nodes)
    new = np.empty(mesh.n_nodes, dtype=np.int64)
    new[order] = np.arange(mesh.n_nodes)
    groups = _renumbered_groups(mesh, new, "test")
    return dataclasses.replace(mesh, points=np.array(mesh.points)[order], cells=new[np.asarray(mesh.cells)], **groups)


@pytest.fixture(scope="module")
def scattered():
    mesh = _scattered(M.cylinder_mesh(0.02, 0.08, 0.01))
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    return model, S.explicit_stability_limit(model, model.x0)


def _conn(model):
    return np.concatenate([t.conn for t in model.terms if t.kind == "springs"])


def _sim(model, monkeypatch, renumber, **kw):
    """A network Simulator built with (``renumber``) or without the internal numbering."""
    monkeypatch.setattr(NK, "REORDER_MIN_NODES", 0 if renumber else 10**12)
    sim = Simulator(model, engine="network", **kw)
    assert (sim._stepper.order is not None) == renumber
    return sim


def test_cache_order_renumbers_only_a_large_scattered_network(scattered, monkeypatch):
    model, _ = scattered
    conn = _conn(model)
    assert model.n_nodes < NK.REORDER_MIN_NODES and NK.cache_order(conn, model.n_nodes) is None  # fits in cache
    monkeypatch.setattr(NK, "REORDER_MIN_NODES", 0)
    order = NK.cache_order(conn, model.n_nodes)
    assert order is not None and np.array_equal(np.sort(order), np.arange(model.n_nodes))
    new = np.empty(model.n_nodes, dtype=np.int64)
    new[order] = np.arange(model.n_nodes)
    span, span_new = np.abs(conn[:, 0] - conn[:, 1]).mean(), np.abs(new[conn[:, 0]] - new[conn[:, 1]]).mean()
    assert span_new * NK.REORDER_GAIN <= span
    # a numbering that is banded already is kept
    banded = (new[conn[:, 0]], new[conn[:, 1]])
    assert NK.cache_order(np.stack(banded, axis=1), model.n_nodes) is None


def test_renumbered_steps_equal_the_model_numbering_and_integrate(scattered, monkeypatch):
    model, limit = scattered
    dt = 0.8 * limit
    ref = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=150 * dt, damping=3.0, save_every=150)
    runs = {}
    for renumber in (False, True):
        sim = _sim(model, monkeypatch, renumber, dt=dt, damping=3.0)
        sim.step(100)
        for _ in range(50):
            sim.step()
        runs[renumber] = (sim.x.copy(), sim.v.copy(), sim.reaction.copy(), sim.kinetic_energy())
        scale = np.abs(ref.x_final - model.x0).max()
        assert np.abs(sim.x.ravel() - ref.x_final).max() < 1e-12 * scale
        assert np.abs(sim.v.ravel() - ref.v_final).max() < 1e-12 * np.abs(ref.v_final).max()
        if renumber:  # reset and replay: bitwise the same states
            sim.reset()
            sim.step(100)
            for _ in range(50):
                sim.step()
            assert np.array_equal(sim.x, runs[True][0]) and np.array_equal(sim.v, runs[True][1])
    (xa, va, ra, ka), (xb, vb, rb, kb) = runs[False], runs[True]
    assert np.abs(xa - xb).max() < 1e-13 * np.abs(xa - model.x0.reshape(-1, 3)).max()
    assert np.abs(va - vb).max() < 1e-12 * np.abs(va).max()
    assert np.abs(ra - rb).max() < 1e-11 * np.abs(ra).max() and np.any(ra)
    assert kb == pytest.approx(ka, rel=1e-11)


def test_paths_forces_and_curves_act_on_the_same_nodes(scattered, monkeypatch):
    """A tool on a path, a nodal force and a load curve: the renumbered engine moves the path's
    nodes exactly along it, and its states and reactions equal the model numbering's."""
    model, limit = scattered
    pts = model.mesh.points
    top = np.flatnonzero(pts[:, 2] > 0.08 - 1e-9)
    side = np.flatnonzero((pts[:, 2] > 0.04) & (pts[:, 0] > 0.015))
    path = [[0.0, 0.0, 0.0, 0.0], [0.01, 0.0, 0.0, -0.001]]
    curve = Curve(path)
    out = {}
    for renumber in (False, True):
        sim = _sim(model, monkeypatch, renumber, dt=0.8 * limit, damping=16.0, load=Curve([[0, 0], [0.01, 1.0]]))
        sim.prescribe(top, path)
        sim.apply_force(side, [0.01, 0.0, 0.0], total=True)
        seen = []
        for _ in range(40):
            sim.step()
            seen.append(np.abs(sim.x[top] - pts[top] - curve(sim.t)).max())
        sim.step(60)
        assert max(seen) < 1e-15
        out[renumber] = (sim.x.copy(), sim.reaction.copy())
    (xa, ra), (xb, rb) = out[False], out[True]
    assert np.abs(xa - xb).max() < 1e-12 * np.abs(xa - pts).max()
    assert np.abs(ra - rb).max() < 1e-10 * np.abs(ra).max()
    assert ra[top].sum(axis=0)[2] == pytest.approx(rb[top].sum(axis=0)[2], rel=1e-11)


def test_a_divergence_stops_at_the_same_step_with_the_state_before(scattered, monkeypatch):
    model, limit = scattered
    errors = {}
    for renumber in (False, True):
        for calls in ([300], [1] * 300):
            sim = _sim(model, monkeypatch, renumber, dt=1.2 * limit, allow_unstable=True)
            with pytest.raises(DivergenceError) as info:
                for n in calls:
                    sim.step(n)
            errors[(renumber, len(calls))] = info.value
    b = errors[(False, 1)]
    for key in ((True, 1), (True, 300)):
        a = errors[key]
        assert a.step == b.step and a.quantity == b.quantity
        assert np.abs(a.x_last - b.x_last).max() <= 1e-9 * np.abs(b.x_last).max()

"""The stepping API: both engines equal integrate(), loads and paths changed between steps reach the
static solutions they must reach, reactions balance the loads, the guards still stop a bad run,
and the state is read without copies."""

import numpy as np
import pytest

from cell_helpers import example_mesh

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.stepping import integrate
from msslib.errors import DivergenceError, StabilityError
from msslib.stepping import Curve, Simulator


@pytest.fixture(scope="module")
def column():
    """A tetrahedral column (Lloyd's springs), base clamped, gravity."""
    mesh = M.cylinder_mesh(0.02, 0.08, 0.01)
    setup = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]})
    model = setup.model
    return model, S.explicit_stability_limit(model, model.x0)


def _rel(a, b, model):
    return np.abs(np.ravel(a) - np.ravel(b)).max() / max(np.abs(np.ravel(b) - model.x0).max(), 1e-300)


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_engines_equal_integrate(column, engine):
    model, limit = column
    dt = 0.8 * limit
    ref = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=250 * dt, damping=3.0, save_every=250)
    sim = Simulator(model, dt=dt, damping=3.0, engine=engine)
    assert sim.engine == engine
    sim.step(100)
    for _ in range(150):  # one at a time and many per call are the same steps
        sim.step()
    assert sim.n_steps == 250 and sim.t == pytest.approx(250 * dt)
    assert _rel(sim.x, ref.x_final, model) < 1e-12
    assert np.abs(sim.v.ravel() - ref.v_final).max() < 1e-12 * np.abs(ref.v_final).max()


@pytest.mark.parametrize("method", ["velocity_verlet", "implicit_euler"])
def test_other_schemes_run_on_the_generic_engine(column, method):
    model, limit = column
    dt = (0.8 if method == "velocity_verlet" else 4.0) * limit
    ref = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=40 * dt, method=method, damping=3.0,
                      save_every=40)
    sim = Simulator(model, dt=dt, method=method, damping=3.0)
    assert sim.engine == "generic"
    sim.step(40)
    assert _rel(sim.x, ref.x_final, model) < 1e-12


def test_settled_reactions_balance_the_weight_and_equal_the_static_solution(column):
    model, limit = column
    sim = Simulator(model, dt=0.8 * limit, damping=16.0)  # about critical for the slowest motion (8 rad/s)
    sim.run(3.0)
    static = S.static_solve(model, model.x0)
    weight = model.mass.reshape(-1, 3)[:, 2].sum() * 9.81
    assert sim.reaction[:, 2].sum() == pytest.approx(weight, rel=1e-6)
    assert np.abs(sim.reaction[:, :2].sum(axis=0)).max() < 1e-8 * weight
    assert _rel(sim.x, static.x, model) < 1e-6  # settled: e^-24 left of the start


def test_a_tool_pushed_along_a_path_gives_the_static_reaction(column):
    """The top face moved down 2 mm along a ramp, then held: the tool's force after settling is
    the static one of the same prescribed displacement (the static solver on a model with the top
    fixed and displaced), and the tool's nodes follow the path exactly at every step."""
    model, limit = column
    top = np.flatnonzero(model.mesh.points[:, 2] > 0.08 - 1e-9)
    path = [[0.0, 0.0, 0.0, 0.0], [0.05, 0.0, 0.0, -0.002]]
    sim = Simulator(model, dt=0.8 * limit, damping=16.0, load=0.0)
    tool = sim.prescribe(top, path)
    curve = Curve(path)
    seen = []
    while sim.t < 3.0:
        sim.step()
        seen.append(np.abs(sim.x[top] - model.mesh.points[top] - curve(sim.t)).max())
    assert max(seen) < 1e-15
    setup = msslib.build_model("lloyd_tetrahedron", model.mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed=[{"plane": ["z", 0.0]},
                                      {"select": {"plane": ["z", 0.08]}, "displacement": [0.0, 0.0, -0.002]}])
    static = S.static_solve(setup.model, setup.model.x0)
    expected = setup.model.reaction(static.x)[top].sum(axis=0)
    got = sim.reaction[top].sum(axis=0)
    assert got[2] == pytest.approx(expected[2], rel=1e-4)
    base = np.flatnonzero(model.mesh.points[:, 2] < 1e-9)
    assert sim.reaction[base].sum(axis=0)[2] == pytest.approx(-got[2], rel=1e-4)  # no load: they balance
    sim.remove(tool)  # released: the column springs back towards rest
    sim.run(sim.t + 3.0)
    assert np.abs(sim.displacement).max() < 1e-3 * 0.002


def test_nodal_force_and_load_curve_reach_the_static_solution(column):
    model, limit = column
    top = {"plane": ["z", 0.08]}
    total = np.array([0.005, 0.0, 0.0])
    sim = Simulator(model, dt=0.8 * limit, damping=16.0, load=[[0.0, 0.0], [0.05, 1.0]])
    sim.apply_force(top, [[0.0, 0, 0, 0], [0.05, *total]], total=True)
    assert sim.engine == "network"
    sim.run(3.0)
    setup = msslib.build_model("lloyd_tetrahedron", model.mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["z", 0.0]},
                               loads=[{"type": "gravity", "g": [0, 0, -9.81]},
                                      {"type": "nodal_force", "select": top, "total": total.tolist()}])
    static = S.static_solve(setup.model, setup.model.x0)
    assert _rel(sim.x, static.x, model) < 1e-5
    assert sim.reaction[:, 0].sum() == pytest.approx(-total[0], rel=1e-6)


@pytest.mark.parametrize("load", [1.0, [[0.0, 1.0], [1.0, 2.0]]], ids=["constant", "load curve"])
def test_a_step_over_the_limit_is_refused_and_an_allowed_one_stopped_with_the_state_before(column, load):
    """Many steps per call, one per call, constant loads or a curve (the network engine then
    steps one at a time): the same failing step and the same state before it as the generic engine."""
    model, limit = column
    with pytest.raises(StabilityError):
        Simulator(model, dt=1.2 * limit)
    errors = {}
    for engine, calls in (("network", [400]), ("network", [1] * 400), ("generic", [1] * 400)):
        sim = Simulator(model, dt=1.2 * limit, allow_unstable=True, engine=engine, load=load)
        with pytest.raises(DivergenceError) as info:
            for n in calls:
                sim.step(n)
        errors[(engine, len(calls))] = info.value
    b = errors[("generic", 400)]
    for a in (errors[("network", 1)], errors[("network", 400)]):
        assert a.step == b.step and a.quantity == b.quantity
        assert np.abs(a.x_last - b.x_last).max() <= 1e-9 * np.abs(b.x_last).max()


def test_reset_and_views(column):
    model, limit = column
    sim = Simulator(model, dt=0.8 * limit)
    x_view = sim.x
    with pytest.raises(ValueError):
        x_view[0, 0] = 1.0
    before = x_view.copy()
    sim.step(30)
    # a snapshot: it does not follow the state, and what it holds is not changed by the steps
    assert not np.shares_memory(sim.x, x_view) and np.array_equal(x_view, before)
    assert not np.array_equal(sim.x, before)
    first = sim.x.copy()
    sim.reset()
    assert sim.t == 0.0 and sim.n_steps == 0 and np.array_equal(sim.x.ravel(), model.x0)
    sim.step(30)
    assert np.array_equal(sim.x, first)
    assert sim.real_time_factor > 0


def test_a_model_the_network_engine_cannot_run_is_refused_in_one_line():
    mesh = M.triangle_grid_right(0.04, 0.02, 4, 2)
    model = msslib.build_model("lloyd_triangle", mesh, msslib.Material(1e4, 0.3, density=1000.0),
                               fixed={"plane": ["x", 0.0]}, thickness=0.001).model
    with pytest.raises(ValueError, match="engine='network' cannot run this model: the network engine is 3D"):
        Simulator(model, dt=1e-5, engine="network")
    assert Simulator(model, dt=1e-5).engine == "generic"


def test_scene_load_curve(tmp_path, column):
    """The scene's dynamic solver takes a load curve; a ramp held to the end settles on the
    static solution."""
    model, limit = column
    mesh_file = tmp_path / "column.vtu"
    M.write_vtu(mesh_file, model.mesh)
    scene = {"geometry": {"file": str(mesh_file)}, "model": {"type": "lloyd_tetrahedron"},
             "materials": [{"E": 1e4, "nu": 0.25, "density": 1000.0}],
             "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": ["x", "y", "z"]}],
             "loads": [{"type": "gravity", "g": [0, 0, -9.81]}],
             "solver": {"type": "dynamic", "dt": 0.8 * limit, "t_end": 3.0, "damping": 16.0, "save_every": 500,
                        "load_curve": [[0.0, 0.0], [0.05, 1.0]]}}
    ds = msslib.run_scene(scene, progress=False)
    static = S.static_solve(model, model.x0)
    u = ds["displacement"].values.reshape(-1)
    assert np.abs(u - (static.x - model.x0)).max() < 1e-6 * np.abs(static.x - model.x0).max()
    with pytest.raises(ValueError, match="load_curve"):
        msslib.run_scene({**scene, "solver": {**scene["solver"], "load_curve": [[0.1, 0.0], [0.05, 1.0]]}},
                         progress=False)


def _registry_cases():
    from msslib import models

    for name in models.names():
        spec = models.get(name)
        if spec.kind == "mss":  # the cell registry's example of its first cell type, 2 cm across
            yield name, spec.cells[0], lambda cell=spec.cells[0]: example_mesh(cell, 0.02)


@pytest.mark.parametrize("name,cell,make", list(_registry_cases()), ids=lambda v: v if isinstance(v, str) else "")
def test_every_model_steps_as_integrate_does(name, cell, make):
    """Every registered MSS model runs on the simulator (the engine it picks) and equals integrate."""
    mesh = make()
    dim = mesh.dim
    axis = "x"  # clamped at x = 0
    g = [0.0, -9.81] if dim == 2 else [0.0, 0.0, -9.81]
    kw = {"thickness": 0.001} if dim == 2 else {}
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = msslib.build_model(name, mesh, msslib.Material(1e4, 0.3, density=1000.0),
                                   fixed={"plane": [axis, 0.0]}, loads={"type": "gravity", "g": g}, **kw).model
        dt = 0.8 * S.explicit_stability_limit(model, model.x0)
        ref = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=60 * dt, damping=3.0, save_every=60)
        sim = Simulator(model, dt=dt, damping=3.0)
        sim.step(60)
    # the fused kernel runs 3D spring networks: Baudet's correction and Kikuuwe's edge energy are not springs
    assert sim.engine == ("network" if dim == 3 and name not in ("baudet_cube", "kikuuwe_tetrahedron") else "generic")
    assert _rel(sim.x, ref.x_final, model) < 1e-12


def test_jax_engine_equals_the_network_engine_and_refuses_what_it_cannot_run(column, monkeypatch):
    """engine='jax' (JAX's CPU backend here): the same steps to 1e-12; time-varying loads are
    refused in one line; without JAX a warning names the reason and the network engine runs."""
    pytest.importorskip("jax")
    model, limit = column
    dt = 0.8 * limit
    a = Simulator(model, dt=dt, damping=3.0, engine="jax")
    b = Simulator(model, dt=dt, damping=3.0, engine="network")
    assert a.engine == "jax"
    a.step(150)
    a.step(50)
    b.step(200)
    assert _rel(a.x, b.x, model) < 1e-12
    assert np.abs(a.reaction - b.reaction).max() < 1e-12 * np.abs(b.reaction).max()
    with pytest.raises(ValueError, match="engine='jax' runs constant loads"):
        Simulator(model, dt=dt, engine="jax", load=[[0.0, 0.0], [0.1, 1.0]])
    from msslib.stepping.jax_backend import device

    monkeypatch.setattr(device, "available", lambda: (False, "jax cannot be imported (test)"))
    with pytest.warns(msslib.errors.MsslibWarning, match="jax cannot be imported"):
        c = Simulator(model, dt=dt, damping=3.0, engine="jax")
    assert c.engine == "network"


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_a_path_on_permuted_axes_and_one_on_a_support_removed(column, engine):
    """Paths are written from indices kept per build: axes named in any order take their own
    components of the displacement, and a support that a path moved returns to its rest position when the path is
    removed (the support's own prescribed displacement is zero)."""
    model, limit = column
    pts = model.mesh.points
    top = int(np.argmax(pts[:, 2]))
    base = int(np.flatnonzero(pts[:, 2] < 1e-12)[0])
    sim = Simulator(model, dt=0.5 * limit, damping=3.0, engine=engine)
    sim.prescribe([top], [[0.0, 0.0, 0.0, 0.0], [10 * sim.dt, 1e-4, 2e-4, 3e-4]], axes=[2, 0])
    h = sim.prescribe([base], [[0.0, 0.0, 0.0, 0.0], [10 * sim.dt, 1e-4, 0.0, 0.0]])
    sim.step(10)
    assert sim.displacement[top][[0, 2]].tolist() == pytest.approx([1e-4, 3e-4], rel=0, abs=1e-17)
    assert sim.displacement[top][1] != 0.0  # y moves freely
    assert sim.displacement[base].tolist() == pytest.approx([1e-4, 0.0, 0.0], rel=0, abs=1e-17)
    sim.remove(h)
    assert sim.displacement[base].tolist() == [0.0, 0.0, 0.0]
    sim.step(3)
    assert sim.displacement[base].tolist() == [0.0, 0.0, 0.0]
    assert sim.displacement[top][[0, 2]].tolist() == pytest.approx([1e-4, 3e-4], rel=0, abs=1e-17)

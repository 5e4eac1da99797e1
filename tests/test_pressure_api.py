"""Pressure loads in the Python API (every mass-spring model, 2D and 3D) and in the stepping API
(Simulator.apply_pressure)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib.scene import MSS_MODELS
from msslib.terms import pressure_nodal_forces

MESHES = {
    "triangle": lambda: M.triangle_grid_equilateral(2.0, 2.0, 2, 2),
    "quad": lambda: M.quad_grid(1.0, 2.0, 2, 4),
    "tetra": lambda: M.tet_grid(1.0, 1.0, 2.0, 1, 1, 2),
    "hexahedron": lambda: M.hex_grid(1.0, 1.0, 2.0, 1, 1, 2),
}


def _top(mesh):
    return ["y" if mesh.dim == 2 else "z", float(mesh.points[:, -1].max())]


@pytest.mark.parametrize("name", sorted(MSS_MODELS))
def test_every_mss_model_takes_a_pressure_equal_to_the_traction_minus_p_n(name):
    mesh = MESHES[MSS_MODELS[name][0]]()
    top = _top(mesh)
    p = 40.0
    kw = {"thickness": 0.2} if mesh.dim == 2 else {}
    base = {"plane": [top[0], float(mesh.points[:, -1].min())]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dead = msslib.build_model(name, mesh, msslib.Material(1.0e4, 0.3), fixed=base,
                                  loads={"type": "pressure", "select": {"plane": top}, "pressure": p, "follow": False},
                                  **kw)
        traction = msslib.build_model(name, mesh, msslib.Material(1.0e4, 0.3), fixed=base,
                                      loads={"type": "traction", "select": {"plane": top},
                                             "traction": [0.0] * (mesh.dim - 1) + [-p]}, **kw)
        follower = msslib.build_model(name, mesh, msslib.Material(1.0e4, 0.3), fixed=base,
                                      loads={"type": "pressure", "select": {"plane": top}, "pressure": p}, **kw)
    np.testing.assert_allclose(dead.model.external_force(1.0), traction.model.external_force(1.0), atol=1e-12)
    assert len(dead.pressures) == 1 and dead.pressures[0][2] is False and follower.pressures[0][2] is True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u_dead = msslib.solve_static(dead, progress=False).displacement.values
        u_traction = msslib.solve_static(traction, progress=False).displacement.values
        u_follower = msslib.solve_static(follower, progress=False).displacement.values
    np.testing.assert_allclose(u_dead, u_traction, rtol=1e-8, atol=1e-14)
    assert np.abs(u_dead).max() > 1e-5
    # small load: the follower solution is close to the dead one, but not the same
    assert 0 < np.abs(u_follower - u_dead).max() < 0.2 * np.abs(u_dead).max()


def _simulator(**kw):
    mesh = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2)
    setup = msslib.build_model("golec_cube", mesh, msslib.Material(1.0e4, 0.3, density=1000.0),
                               fixed={"plane": ["z", 0.0]})
    return msslib.Simulator(setup, dt=1e-3, **kw), mesh


def _top_facets(mesh):
    f = M.boundary_facets(mesh)
    return f[np.all(np.isclose(mesh.points[f][:, :, 2], 1.0), axis=1)]


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_dead_apply_pressure_equals_the_nodal_forces_of_the_rest_surface(engine):
    sim, mesh = _simulator(engine=engine)
    top = _top_facets(mesh)
    sim.apply_pressure(top[:, ::-1], 200.0, follow=False)  # any node order: turned outward
    ref, _ = _simulator(engine=engine)
    f = pressure_nodal_forces(mesh.points, top, 200.0)
    for node in np.flatnonzero(np.any(f != 0, axis=1)):
        ref.apply_force([node], f[node])
    sim.step(40)
    ref.step(40)
    np.testing.assert_array_equal(sim.x, ref.x)
    assert sim.x[:, 2].min() < 1.0 - 1e-6 or np.abs(sim.displacement).max() > 1e-6


@pytest.mark.parametrize("engine", ["network", "generic"])
def test_follower_apply_pressure_is_evaluated_on_the_current_positions(engine):
    sim, mesh = _simulator(engine=engine)
    top = _top_facets(mesh)
    sim.apply_pressure({"plane": ["z", 1.0]}, [[0.0, 0.0], [0.02, 3000.0]])
    # the same run with the force of every step set by hand from the positions before the step
    ref, _ = _simulator(engine=engine)
    handles = []
    for k in range(30):
        for h in handles:
            ref.remove(h)
        f = pressure_nodal_forces(ref.x, top, min(ref.t / 0.02, 1.0) * 3000.0)
        handles = [ref.apply_force([n], f[n]) for n in np.flatnonzero(np.any(f != 0, axis=1))]
        ref.step(1)
        sim.step(1)
    np.testing.assert_allclose(sim.x, ref.x, rtol=0, atol=1e-12)
    # the same pressure held dead ends elsewhere: the load followed the surface
    dead, _ = _simulator(engine=engine)
    dead.apply_pressure(top, [[0.0, 0.0], [0.02, 3000.0]], follow=False)
    dead.step(30)
    assert np.abs(dead.x - sim.x).max() > 1e-9


def test_apply_pressure_can_be_removed_and_scales_with_its_curve_not_the_load_factor():
    sim, mesh = _simulator()
    h = sim.apply_pressure(_top_facets(mesh), 100.0, follow=False)
    sim.set_load(0.0)
    sim.step(5)
    assert np.abs(sim.displacement).max() > 0
    sim.remove(h)
    sim.reset()
    sim.step(5)
    assert np.abs(sim.displacement).max() == 0.0


@pytest.mark.parametrize("facets, pressure, message", [
    (np.array([[0, 1, 2]]), 1.0, r"^facets must be node ids of shape \(k, 4\) with k >= 1 \(the facets of the "
                                 r"mesh's hexahedron cells\), got array\(\[\[0, 1, 2\]\]\)"),
    (np.array([[0, 1, 4, 3]]) + 100, 1.0, r"^facets: node ids must lie in 0\.\.26, got 100"),
    (np.zeros((0, 4), dtype=int), 1.0, r"^facets must be node ids of shape \(k, 4\) with k >= 1"),
    ([[0.5, 1, 4, 3]], 1.0, r"^facets must be node ids of shape \(k, 4\)"),
    (None, float("nan"), r"^pressure: expected a number or a table \[\[t, \.\.\.\], \.\.\.\], got nan"),
    (None, float("inf"), r"^pressure: expected a number or a table"),
    (None, [1.0, 2.0], r"^pressure: expected a number or a table"),
    ("interior", 1.0, r"^facets: 1 of 1 facets are not on the boundary of the mesh \(facet 0, nodes"),
    ({"box": [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]]}, 1.0, r"selects no node"),
])
def test_apply_pressure_refusals_change_nothing(facets, pressure, message):
    sim, mesh = _simulator()
    sim.step(3)
    before = (sim.x.copy(), sim.t)
    if facets is None:
        facets = _top_facets(mesh)
    elif isinstance(facets, str):
        facets = np.array([[1, 4, 13, 10]])  # the face x = 0.5 between two cells of the bottom row
        assert M.facet_cell_counts(mesh, facets)[0] == 2
    with pytest.raises(ValueError, match=message) as info:
        sim.apply_pressure(facets, pressure)
    assert "\n" not in str(info.value)
    np.testing.assert_array_equal(sim.x, before[0])
    assert sim.t == before[1]
    sim.step(1)  # still steps with no pressure on it
    assert np.abs(sim.displacement).max() == 0.0


def test_apply_pressure_in_2d_takes_the_thickness():
    mesh = M.quad_grid(1.0, 1.0, 2, 2)
    setup = msslib.build_model("lloyd_square", mesh, msslib.Material(1.0e4, 1.0 / 3.0, density=1000.0),
                               fixed={"plane": ["y", 0.0]}, thickness=0.1)
    sim = msslib.Simulator(setup, dt=1e-3)
    ref = msslib.Simulator(setup, dt=1e-3)
    assert sim.engine == "generic"
    edges = M.boundary_facets(mesh)
    top = edges[np.all(np.isclose(mesh.points[edges][:, :, 1], 1.0), axis=1)]
    sim.apply_pressure(top, 50.0, follow=False, thickness=0.1)
    f = pressure_nodal_forces(mesh.points, top, 50.0, thickness=0.1)
    np.testing.assert_allclose(f.sum(axis=0), [0.0, -50.0 * 0.1 * 1.0], atol=1e-14)
    for node in np.flatnonzero(np.any(f != 0, axis=1)):
        ref.apply_force([node], f[node])
    sim.step(20)
    ref.step(20)
    np.testing.assert_array_equal(sim.x, ref.x)
    with pytest.raises(ValueError, match=r"^thickness must be a finite thickness > 0 \(m\), on a 2D mesh only, got -1"):
        sim.apply_pressure(top, 50.0, thickness=-1.0)
    with pytest.raises(ValueError, match=r"^follow must be True or False, got 1"):
        sim.apply_pressure(top, 50.0, follow=1)

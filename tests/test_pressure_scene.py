"""Pressure loads in scenes: facets re-oriented outward, the dead reading against the equivalent
traction, inflation of a hollow body, the load factor and load curve, a free body's momentum, and
the one-line refusals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from msslib import mesh as M
from msslib.scene import load_scene, prepare, run_scene

E = 1.0e4


def hollow_hex(n=3):
    """An n^3 grid of unit cubes without its centre cube (n odd): a hollow body whose cavity walls
    are the facet group ``inner``, listed with their nodes in reverse (inward) order."""
    grid = M.hex_grid(float(n), float(n), float(n), n, n, n)
    centre = np.full(3, n / 2.0)
    middle = int(np.argmin(np.linalg.norm(grid.points[grid.cells].mean(axis=1) - centre, axis=1)))
    keep = np.arange(grid.n_cells) != middle
    mesh = dataclasses.replace(grid, cells=grid.cells[keep], material=grid.material[keep])
    walls = [f for f in M.boundary_facets(mesh) if np.all(np.abs(mesh.points[f] - centre) <= 0.5 + 1e-9)]
    return dataclasses.replace(mesh, facet_groups={"inner": np.array(walls)[:, ::-1].copy()})


def hollow_scene(model="golec_cube", pressure=500.0, follow=True, solver=None, mesh=None, extra_loads=()):
    return {
        "name": "hollow", "geometry": {"mesh": hollow_hex() if mesh is None else mesh},
        "materials": [{"E": E, "nu": 0.3, "density": 1000.0}], "model": model,
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
        "loads": [{"type": "pressure", "select": {"group": "inner"}, "pressure": pressure, "follow": follow},
                  *extra_loads],
        "solver": solver or {"type": "static", "load_steps": 2}}


def _normals(points, facets):
    x = points[facets]
    return np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])


def test_a_facet_group_in_any_node_order_is_turned_outward():
    mesh = hollow_hex()
    setup = prepare(load_scene(hollow_scene(mesh=mesh)))
    (facets, p, follow), = setup.pressures
    assert p == 500.0 and follow is True and facets.shape == (6, 4)
    outward = {tuple(f) for f in M.boundary_facets(mesh).tolist()}
    assert all(tuple(f) in outward for f in facets.tolist())
    # the body's outward normal on the cavity walls points into the cavity (to its centre)
    to_centre = 1.5 - mesh.points[facets].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", _normals(mesh.points, facets), to_centre) > 0)
    # the group as given pointed the other way
    given = mesh.facet_groups["inner"]
    assert np.all(np.einsum("ij,ij->i", _normals(mesh.points, given), 1.5 - mesh.points[given].mean(axis=1)) < 0)


@pytest.mark.parametrize("model", ["golec_cube", "baudet_cube", "fem_linear"])
def test_inflation_of_a_hollow_body_opens_the_cavity(model):
    ds = run_scene(load_scene(hollow_scene(model, follow=model != "fem_linear")), progress=False)
    mesh = hollow_hex()
    u = ds.displacement.values
    walls = np.unique(mesh.facet_groups["inner"])
    centre = np.full(3, 1.5)
    # every cavity wall node moves away from the cavity's centre
    radial = np.einsum("ij,ij->i", u[walls], mesh.points[walls] - centre)
    assert np.all(radial > 0)


@pytest.mark.parametrize("model", ["golec_cube", "lloyd_square", "fem_linear"])
def test_dead_pressure_on_a_flat_face_is_the_traction_minus_p_n(model):
    dim = 2 if model == "lloyd_square" else 3
    geo = ({"generator": "quad_grid", "args": {"lx": 1.0, "ly": 2.0, "nx": 2, "ny": 4}} if dim == 2 else
           {"generator": "hex_grid", "args": {"lx": 1.0, "ly": 1.0, "lz": 2.0, "nx": 2, "ny": 2, "nz": 4}})
    top = ["y", 2.0] if dim == 2 else ["z", 2.0]
    base = {"name": "flat", "geometry": geo, "materials": [{"E": E, "nu": 1.0 / 3.0}], "model": model,
            "boundary": [{"select": {"plane": [top[0], 0.0]}, "fix": "all"}],
            **({"thickness": 0.1} if dim == 2 else {})}
    p = 300.0
    pressure = run_scene(load_scene({**base, "loads": [{"type": "pressure", "select": {"plane": top},
                                                       "pressure": p, "follow": False}]}), progress=False)
    traction = run_scene(load_scene({**base, "loads": [{"type": "traction", "select": {"plane": top},
                                                       "traction": [0.0] * (dim - 1) + [-p]}]}), progress=False)
    np.testing.assert_allclose(pressure.displacement.values, traction.displacement.values, rtol=1e-9, atol=1e-14)
    assert np.abs(pressure.displacement.values).max() > 1e-4


def test_follower_differs_from_dead_under_large_rotation_and_scales_with_the_load_factor():
    follower = prepare(load_scene(hollow_scene(pressure=2000.0))).model
    dead = prepare(load_scene(hollow_scene(pressure=2000.0, follow=False))).model
    x = follower.x0 + 0.05 * np.random.default_rng(1).standard_normal(follower.n_dof)
    for lam in (0.25, 1.0):
        np.testing.assert_allclose(follower.external_force(lam), lam * follower.external_force(1.0))
        np.testing.assert_allclose(dead.force(x, lam) - dead.force(x, 0.0), dead.external_force(lam), atol=1e-9)
    # at rest both readings agree; deformed, the follower's forces are those of the current surface
    np.testing.assert_allclose(follower.external_force(1.0), dead.external_force(1.0), atol=1e-9)
    assert np.abs((follower.force(x, 1.0) - follower.force(x, 0.0)) - dead.external_force(1.0)).max() > 1.0


def test_a_load_curve_scales_the_pressure_in_a_dynamic_scene():
    dyn = {"type": "dynamic", "dt": 2e-3, "t_end": 0.1, "damping": 5.0}
    half_curve = run_scene(load_scene(hollow_scene(pressure=400.0, solver={**dyn, "load_curve": [[0.0, 0.5]]})),
                           progress=False)
    half_pressure = run_scene(load_scene(hollow_scene(pressure=200.0, solver=dyn)), progress=False)
    zero = run_scene(load_scene(hollow_scene(pressure=400.0, solver={**dyn, "load_curve": [[0.0, 0.0]]})),
                     progress=False)
    np.testing.assert_allclose(half_curve.displacement.values, half_pressure.displacement.values, rtol=1e-9,
                               atol=1e-15)
    assert np.abs(half_curve.displacement.values).max() > 1e-5
    assert np.abs(zero.displacement.values).max() == 0.0


def test_free_body_under_follower_pressure_on_all_sides_keeps_zero_momentum():
    # no support: the pressure forces have zero resultant and torque at every deformed state, so
    # linear and angular momentum stay zero while the body is squeezed and rings
    scene = hollow_scene(pressure=800.0, solver={"type": "dynamic", "dt": 2e-3, "t_end": 0.2},
                         extra_loads=[{"type": "pressure", "select": "all", "pressure": 300.0}])
    scene["boundary"] = []
    scene["output"] = {"history": True}
    ds = run_scene(load_scene(scene), progress=False)
    setup = prepare(load_scene(scene))
    m = setup.model.node_masses
    x0 = setup.mesh.points
    v = ds.velocity_history.values
    x = x0[None] + ds.displacement_history.values
    assert np.abs(v).max() > 1e-4 and len(v) == 101
    scale = m.sum() * np.abs(v).max()
    momentum = np.einsum("n,tnd->td", m, v)
    assert np.abs(momentum).max() < 1e-10 * scale
    # symplectic Euler: positions and velocities are half a step apart; the angular momentum it keeps
    # is that of x_n and v_n, and it stays at zero (the body turns not at all)
    angular = np.einsum("n,tnd->td", m, np.cross(x, v))
    assert np.abs(angular).max() < 1e-10 * scale * 3.0


@pytest.mark.parametrize("load, message", [
    ({"pressure": ".nan"}, r"scene\.loads\[0\]\.pressure: expected a finite number, got nan"),
    ({"pressure": 1.0e5}, r"scene\.loads\[0\]: the load is 10 E \(pressure \|p\| = 1e\+05 Pa against"),
    ({"pressure": -2.0e5}, r"scene\.loads\[0\]: the load is 20 E \(pressure \|p\| = 2e\+05 Pa against"),
    ({"follow": "yes"}, r"scene\.loads\[0\]\.follow: expected true or false, got 'yes'"),
    ({"select": {"box": [[10.0, 10.0, 10.0], [11.0, 11.0, 11.0]]}}, r"scene\.loads\[0\]\.select: .*selects no node"),
    ({"select": {"group": "middle"}}, r"scene\.loads\[0\]\.select\.group: 1 of the 2 facets of group 'middle' are not "
                                      r"on the boundary of the mesh: .*; allowed: a pressure on boundary facets"),
    ({"pressur": 1.0}, r"scene\.loads\[0\]\.pressur: unknown key; expected one of follow, pressure, select, type "
                       r"\(did you mean 'pressure'\?\)"),
])
def test_refusals_name_the_key_in_one_line(load, message):
    mesh = hollow_hex()
    # a facet group with one interior facet (between two cells) and one boundary facet
    facets = np.vstack([M.boundary_facets(mesh)[0], _interior_facet(mesh)])
    mesh = dataclasses.replace(mesh, facet_groups={**mesh.facet_groups, "middle": facets})
    scene = hollow_scene(mesh=mesh)
    entry = dict(scene["loads"][0])
    for key, value in load.items():
        if key == "pressur":
            entry.pop("pressure")
        entry[key] = float("nan") if value == ".nan" else value
    scene["loads"] = [entry]
    with pytest.raises(ValueError, match=message) as info:
        prepare(load_scene(scene))
    assert "\n" not in str(info.value)


def _interior_facet(mesh):
    """A quad shared by two cells of ``mesh``."""
    from msslib.mesh import facet_cell_counts

    for cell in mesh.cells:
        for local in ([1, 2, 6, 5], [0, 1, 5, 4], [3, 2, 6, 7], [0, 3, 7, 4], [0, 1, 2, 3], [4, 5, 6, 7]):
            if facet_cell_counts(mesh, cell[local][None])[0] == 2:
                return cell[local]
    raise AssertionError("no interior facet")


def test_a_linear_solve_reads_a_follower_pressure_on_the_rest_surface_as_linear_fem_does():
    linear = {"type": "static", "linear": True}
    follower = run_scene(load_scene(hollow_scene(pressure=2000.0, solver=linear)), progress=False)
    dead = run_scene(load_scene(hollow_scene(pressure=2000.0, follow=False, solver=linear)), progress=False)
    np.testing.assert_allclose(follower.displacement.values, dead.displacement.values, rtol=1e-10, atol=1e-15)
    assert np.abs(dead.displacement.values).max() > 1e-3

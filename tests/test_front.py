"""Speed-against-error study: the quadratic-element reference (msslib.planning.reference on
msslib.fem's element order), the linear MSS solve, nested levels and the crossover budget
(experiments/performance/front.py)."""

import copy
import math

import numpy as np
import pytest
import xarray as xr

from experiments.performance import front
from msslib import fem
from msslib.planning.reference import at_points, solve_setup
from msslib.scene import load_scene, prepare, run_scene

MEMBRANE = {
    "name": "m", "geometry": {"generator": "triangle_grid_equilateral", "args": {"width": 0.0720534, "height": 0.0521, "n": 6}},
    "materials": [{"E": 14630.0, "nu": 1 / 3}], "thickness": 0.01, "model": "fem_svk",
    "boundary": [{"select": {"plane": ["y", 0.0]}, "fix": "all"}],
    "loads": [{"type": "traction", "select": {"box": [[None, 0.0519], [None, None]]}, "traction": [0.0, 1755.6]}],
    "solver": {"type": "static", "load_steps": 4, "tol": 1e-10},
}


def _bar(generator, args, g=(9.81, 0.0, 0.0)):
    return {"name": "bar", "geometry": {"generator": generator, "args": args},
            "materials": [{"E": 1000.0, "nu": 0.0, "density": 10.0}], "model": "fem_linear",
            "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
            "loads": [{"type": "gravity", "g": list(g)}], "solver": {"type": "static"}}


def _solve(setup, **kw):
    """The reference's displacement at the mesh's nodes, and the whole result."""
    r = solve_setup(setup, **kw)
    return r.displacement, r


def _setup(raw):
    return prepare(load_scene(raw))


def test_order_one_reference_is_the_library_fem():
    """Loads, supports and laws of the reference, with P1 elements, equal msslib.fem's to round-off."""
    raw = copy.deepcopy(MEMBRANE)
    raw["geometry"]["refine"] = 1
    s = _setup(raw)
    ds = run_scene(load_scene(raw), progress=False)
    u_fem = ds["displacement"].transpose("node", "axis").values
    u1, _ = _solve(s, order=1, law="svk", steps=4)
    assert np.abs(u1 - u_fem).max() <= 1e-9 * np.abs(u_fem).max()
    lin = fem.solve_linear(s.mesh, 14630.0, 1 / 3, fixed=s.fixed, nodal_forces=s.surface_forces, thickness=0.01)
    u1l, _ = _solve(s, order=1, law=None)
    assert np.abs(u1l - lin.displacement).max() <= 1e-12 * np.abs(lin.displacement).max()


@pytest.mark.parametrize("generator, args", [
    ("hex_grid", {"lx": 1.0, "ly": 0.2, "lz": 0.2, "nx": 3, "ny": 1, "nz": 1}),
    ("tet_grid", {"lx": 1.0, "ly": 0.2, "lz": 0.2, "nx": 3, "ny": 1, "nz": 1}),
    ("triangle_grid_right", {"lx": 1.0, "ly": 0.2, "nx": 3, "ny": 1}),
])
def test_quadratic_elements_reproduce_the_quadratic_bar_under_its_weight(generator, args):
    """nu = 0, clamped at x = 0, gravity along x: u_x = rho g / E (L x - x^2 / 2) exactly."""
    raw = _bar(generator, args, g=(9.81, 0.0, 0.0) if "lz" in args else (9.81, 0.0))
    s = _setup(raw)
    _, info = _solve(s, order=2, law=None)
    x = info.dof_points[:, 0]
    exact = 10.0 * 9.81 / 1000.0 * (1.0 * x - x**2 / 2)
    np.testing.assert_allclose(info.dof_displacement[:, 0], exact, rtol=0, atol=1e-12 * exact.max())
    assert np.abs(info.dof_displacement[:, 1:]).max() <= 1e-12 * exact.max()


def test_nonlinear_quadratic_reference_tends_to_the_linear_one_at_small_load():
    raw = copy.deepcopy(MEMBRANE)
    raw["loads"][0]["traction"] = [0.0, 1755.6e-4]
    s = _setup(raw)
    u_nl, _ = _solve(s, order=2, law="svk", steps=1)
    u_l, _ = _solve(s, order=2, law=None)
    assert np.abs(u_nl - u_l).max() / np.abs(u_l).max() < 1e-3  # relative difference ~ strain ~ 1e-5
    assert np.abs(u_nl - u_l).max() / np.abs(u_l).max() > 1e-8  # and not identical: a non-linear solve


@pytest.mark.parametrize("raw", [MEMBRANE, _bar("tet_grid", {"lx": 1.0, "ly": 0.2, "lz": 0.2, "nx": 2, "ny": 1, "nz": 1}),
                                 _bar("hex_grid", {"lx": 1.0, "ly": 0.2, "lz": 0.2, "nx": 2, "ny": 1, "nz": 1})])
def test_quadratic_dofs_are_the_nodes_of_the_refined_mesh(raw):
    s0 = _setup(raw)
    fine = copy.deepcopy(raw)
    fine["geometry"]["refine"] = 1
    s1 = _setup(fine)
    _, info = _solve(s0, order=2, law=None)
    assert len(info.dof_points) == s1.mesh.n_nodes
    at_points(info, s1.mesh.points)  # every node of the refined mesh is a dof location


def test_linear_mss_solve_is_one_solve_with_the_hessian_at_rest():
    raw = copy.deepcopy(MEMBRANE)
    raw["model"] = "lloyd_triangle"
    raw["solver"] = {"type": "static", "linear": True}
    s = _setup(raw)
    ds = run_scene(load_scene(raw), progress=False)
    u = ds["displacement"].transpose("node", "axis").values.ravel()
    K = s.model.stiffness(s.model.x0, 1.0)
    free = s.model.free
    f = s.model.force(s.model.x0, 1.0)
    assert np.abs((K @ u)[free] - f[free]).max() <= 1e-9 * np.abs(f[free]).max()
    assert np.all(u[~free] == 0)
    # reactions of the linearised forces balance the load
    reaction = ds["reaction_force"].transpose("node", "axis").values
    load = s.surface_forces
    np.testing.assert_allclose(reaction.sum(axis=0), -load.sum(axis=0), rtol=1e-9, atol=1e-12 * np.abs(load).sum())
    # small load: the non-linear solve approaches the linear one
    small = copy.deepcopy(raw)
    small["loads"][0]["traction"] = [0.0, 1.7556e-3]
    u_lin = run_scene(load_scene(small), progress=False)["displacement"].values
    small["solver"] = {"type": "static", "tol": 1e-12}
    u_nl = run_scene(load_scene(small), progress=False)["displacement"].values
    assert np.abs(u_nl - u_lin).max() < 1e-5 * np.abs(u_lin).max()


def test_lloyd_springs_linearised_on_equilateral_triangles_are_linear_fem():
    """Lloyd's derivation: on equilateral triangles at nu = 1/3 the springs' stiffness at rest is the
    linear FEM stiffness, so the linear MSS solve equals linear FEM."""
    raw = copy.deepcopy(MEMBRANE)
    raw["geometry"]["refine"] = 1
    raw["model"] = "fem_linear"
    u_fem = run_scene(load_scene(raw), progress=False)["displacement"].values
    raw["model"] = "lloyd_triangle"
    raw["solver"] = {"type": "static", "linear": True}
    u_mss = run_scene(load_scene(raw), progress=False)["displacement"].values
    np.testing.assert_allclose(u_mss, u_fem, rtol=0, atol=1e-9 * np.abs(u_fem).max())


def test_linear_option_is_validated():
    raw = copy.deepcopy(MEMBRANE)
    raw["solver"] = {"type": "static", "linear": "yes"}
    with pytest.raises(ValueError, match="linear"):
        load_scene(raw)
    raw["solver"] = {"type": "static"}
    raw["geometry"]["refine"] = -1
    with pytest.raises(ValueError, match="refine"):
        load_scene(raw)


def _front(points):
    """A front dataset from {model: [(time, error), ...]} over levels 0.."""
    names = list(points)
    n = max(len(v) for v in points.values())
    t = np.full((len(names), n), np.nan)
    e = np.full((len(names), n), np.nan)
    for i, m in enumerate(names):
        for j, (ti, ei) in enumerate(points[m]):
            t[i, j], e[i, j] = ti, ei
    return xr.Dataset({"wall_time": (("model", "level"), t), "error_max": (("model", "level"), e),
                       "error_mean": (("model", "level"), e), "n_dofs": (("model", "level"), np.ones_like(t, int)),
                       "status": (("model", "level"), np.full(t.shape, "ok")),
                       "family": (("model",), ["fem" if m.startswith("fem") else "mss" for m in names])},
                      coords={"model": names, "level": list(range(n))},
                      attrs={"reference_model": "x", "reference_level": 1})


def test_crossover_is_the_most_accurate_mss_point_when_fem_wins_below_it():
    f = _front({"mss": [(0.01, 0.20), (0.05, 0.10), (1.0, 0.09)], "fem_x": [(0.02, 0.30), (0.2, 0.05), (2.0, 0.01)]})
    c = front.crossover(f)
    assert c["crossover_error"] == 0.10 and c["crossover_kind"] == "single crossover"
    f = _front({"mss": [(1.0, 0.2)], "fem_x": [(0.1, 0.1), (2.0, 0.01)]})
    c = front.crossover(f)
    assert math.isnan(c["crossover_error"]) and c["crossover_kind"] == "fem everywhere"
    f = _front({"mss": [(0.05, 0.1)], "fem_x": [(0.01, 0.3), (1.0, 0.01)]})
    c = front.crossover(f)
    assert (c["crossover_error"], c["mss_window_upper"], c["crossover_kind"]) == (0.1, 0.3, "mss window")
    f = _front({"mss": [(0.01, 0.2), (1.0, 0.01)], "fem_x": [(0.1, 0.1)]})
    assert front.crossover(f)["crossover_kind"] == "interleaved"


def _ranged(points, spans, runs=7):
    """``_front`` with the time ranges ``spans`` ({model: [(min, max), ...]}) and ``runs`` runs each."""
    f = _front(points)
    lo, hi = np.full(f.wall_time.shape, np.nan), np.full(f.wall_time.shape, np.nan)
    for i, m in enumerate(f.model.values):
        for j, (a, b) in enumerate(spans[str(m)]):
            lo[i, j], hi[i, j] = a, b
    f["time_min"], f["time_max"] = (("model", "level"), lo), (("model", "level"), hi)
    f["time_median"] = f.wall_time
    f["runs"] = (("model", "level"), np.full(lo.shape, runs))
    return f


def test_crossover_resolved_only_where_the_time_ranges_do_not_overlap():
    pts = {"mss": [(0.01, 0.20), (0.05, 0.10)], "fem_x": [(0.08, 0.05), (2.0, 0.01)]}
    # the MSS point at 0.05 s (0.04-0.06) and the FEM point at 0.08 s (0.07-0.09): apart
    apart = _ranged(pts, {"mss": [(0.009, 0.011), (0.04, 0.06)], "fem_x": [(0.07, 0.09), (1.9, 2.1)]})
    c = front.crossover(apart)
    assert (c["crossover_error"], c["crossover_kind"], c["crossover_resolved"]) == (0.10, "single crossover", 1)
    # the same medians, the ranges overlapping (0.04-0.075 and 0.07-0.09): unresolved
    overlap = _ranged(pts, {"mss": [(0.009, 0.011), (0.04, 0.075)], "fem_x": [(0.07, 0.09), (1.9, 2.1)]})
    assert front.crossover(overlap)["crossover_resolved"] == 0
    # ranges apart but each from one run: unresolved; no ranges at all (an older front): unresolved
    assert front.crossover(_ranged(pts, {"mss": [(0.01, 0.01), (0.05, 0.05)], "fem_x": [(0.08, 0.08), (2.0, 2.0)]},
                                   runs=1))["crossover_resolved"] == 0
    assert front.crossover(_front(pts))["crossover_resolved"] == 0
    # no change of family along the front: nothing to resolve
    assert front.crossover(_front({"mss": [(1.0, 0.2)], "fem_x": [(0.1, 0.1)]}))["crossover_resolved"] == 1


def test_plan_says_when_its_choice_ties_within_the_timing_spread():
    from msslib.planning import report
    from msslib.planning.front import ties

    pts = {"baudet_cube": [(0.009, 0.10), (0.05, 0.05)], "fem_linear": [(0.010, 0.08), (0.06, 0.02)]}
    f = _ranged(pts, {"baudet_cube": [(0.0087, 0.0112), (0.045, 0.055)],
                      "fem_linear": [(0.0089, 0.0110), (0.058, 0.062)]})
    f.attrs.update(reference_error=math.nan)
    lines = report(f, 0.2)
    assert lines[-2].startswith("choice: baudet_cube at resolution level 0")
    assert lines[-1] == ("tie: within the timing spread (0.0087-0.0112 s over 7 runs) of fem_linear level 0 "
                         "(0.0089-0.011 s); another run may choose any of them")
    # a budget that only the finer points meet: fem_linear level 1 (0.058-0.062 s) is apart from the choice
    assert ties(f, ("baudet_cube", 1), 0.05) == []
    assert not report(f, 0.05)[-1].startswith("tie")
    # apart ranges: no tie line
    g = _ranged(pts, {"baudet_cube": [(0.0087, 0.0095), (0.045, 0.055)], "fem_linear": [(0.0096, 0.011), (0.058, 0.062)]})
    g.attrs.update(reference_error=math.nan)
    assert report(g, 0.2)[-1].startswith("choice: baudet_cube")

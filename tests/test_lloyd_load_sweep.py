"""The Lloyd load sweep and ratio studies: load scaling, deformation measures, load distributions,
the constant-strain split of the square mesh, and the error law of an MSS that matches FEM exactly."""

import numpy as np
import pytest

from experiments.lloyd.studies import load_sweep as sweep
from experiments.lloyd.studies import ratio_causes as causes
from msslib import fem
from msslib import mesh as M


def test_scaled_multiplies_only_load_magnitudes():
    scene = {"model": "fem_linear", "loads": [{"type": "traction", "select": {"plane": ["y", 1.0]}, "traction": [0.0, 2.0]},
                                              {"type": "nodal_force", "select": {"plane": ["y", 1.0]}, "total": [3.0, -1.0]}]}
    out = sweep.scaled(scene, 0.5)
    assert out["loads"][0]["traction"] == [0.0, 1.0]
    assert out["loads"][1]["total"] == [1.5, -0.5]
    assert out["loads"][0]["select"] == scene["loads"][0]["select"]
    assert scene["loads"][0]["traction"] == [0.0, 2.0]  # the input is not changed
    np.testing.assert_allclose(sweep.load_direction(scene), [0.0, 1.0])


def test_deformation_of_a_uniform_strain_and_a_shear():
    mesh = M.quad_grid(0.05, 0.04, 5, 4)
    X = mesh.points
    eps, gamma = 0.12, 0.07
    u = np.column_stack([-0.3 * eps * X[:, 0], eps * X[:, 1]])
    assert sweep.deformation(X, u, np.array([0.0, 1.0])) == pytest.approx(eps, rel=1e-12)
    assert sweep.deformation(X, -u, np.array([0.0, -1.0])) == pytest.approx(eps, rel=1e-12)
    shear = np.column_stack([gamma * X[:, 1], np.zeros(len(X))])
    assert sweep.deformation(X, shear, np.array([1.0, 0.0])) == pytest.approx(gamma, rel=1e-12)
    c, m = causes.corner_middle(mesh, "stretch", u)
    assert c == pytest.approx(eps) and m == pytest.approx(eps)


def test_levels_end_at_the_stated_deformation():
    lv = sweep.levels_of(0.112, 0.136, quick=False)
    assert lv[0] == pytest.approx(sweep.SMALL) and lv[-1] == pytest.approx(0.136)
    assert np.any(np.isclose(lv, 0.112)) and np.all(np.diff(lv) > 0)
    assert len(sweep.levels_of(0.12, 0.12, quick=False)) == sweep.N_LOG
    np.testing.assert_allclose(sweep.levels_of(0.1, 0.13, quick=True), [sweep.SMALL, 0.13])


@pytest.mark.parametrize("section", ["5.1", "5.3"])
def test_equal_and_consistent_forces_have_the_same_resultant(section):
    mesh = causes.membrane(section)
    top = np.isclose(mesh.points[:, 1], mesh.points[:, 1].max())
    width = np.ptp(mesh.points[top, 0])
    for case, direction in causes.DIRECTION.items():
        f_c = causes.loads(mesh, case, equal=False)
        f_e = causes.loads(mesh, case, equal=True)
        # 1 Pa on the top edge of length `width`, thickness 1 cm
        np.testing.assert_allclose(f_c.sum(axis=0), np.asarray(direction) * width * causes.THICKNESS, rtol=1e-12)
        np.testing.assert_allclose(f_e.sum(axis=0), f_c.sum(axis=0), rtol=1e-12)
        assert np.all(f_c[~top] == 0) and np.all(f_e[~top] == 0)
        corner = np.flatnonzero(top)[np.argmin(mesh.points[top, 0])]
        inner = np.flatnonzero(top)[np.argsort(mesh.points[top, 0])[1]]
        # consistent: a corner node carries half an inner node's share; equal: the same share
        assert np.linalg.norm(f_c[corner]) == pytest.approx(0.5 * np.linalg.norm(f_c[inner]))
        assert np.linalg.norm(f_e[corner]) == pytest.approx(np.linalg.norm(f_e[inner]))


@pytest.mark.parametrize("how", ["cst_slash", "cst_backslash", "cst_crossed"])
def test_constant_strain_split_covers_the_squares_and_is_exact_for_linear_fields(how):
    quads = M.quad_grid(0.05, 0.05, 5, 5)
    tri = causes.split_squares(quads, how)
    assert np.all(M.cell_measures(tri) > 0)
    assert M.cell_measures(tri).sum() == pytest.approx(0.05 * 0.05, rel=1e-12)
    np.testing.assert_array_equal(tri.points[:quads.n_nodes], quads.points)
    # a uniform stretch under the exact plane-stress boundary tractions: every element reproduces it
    E, nu, t, sigma = causes.E, causes.NU, causes.THICKNESS, 1000.0
    fixed = np.zeros((tri.n_nodes, 2), dtype=bool)
    bottom = np.isclose(tri.points[:, 1], 0.0)
    fixed[bottom, 1] = True
    fixed[np.flatnonzero(bottom & np.isclose(tri.points[:, 0], 0.0)), 0] = True
    f = np.zeros((tri.n_nodes, 2))
    f[:quads.n_nodes] = sigma * causes.loads(quads, "stretch", equal=False)
    u = fem.solve_linear(tri, E, nu, fixed=fixed, nodal_forces=f, thickness=t).displacement
    np.testing.assert_allclose(u[:, 1], sigma / E * tri.points[:, 1], atol=1e-12)
    np.testing.assert_allclose(u[:, 0], -nu * sigma / E * tri.points[:, 0], atol=1e-12)


def test_mss_strain_factor_reaches_the_target_in_the_mss():
    r = causes.run("5.1", "stretch", "mss_strain")
    assert 0.5 * (r["corner_mss"] + r["middle_mss"]) == pytest.approx(causes.TARGET[("5.1", "stretch")], rel=1e-6)
    base = causes.run("5.1", "stretch", "baseline")
    assert 0.5 * (base["corner_fem"] + base["middle_fem"]) == pytest.approx(causes.TARGET[("5.1", "stretch")], rel=1e-9)


def test_exact_small_strain_match_gives_a_quadratic_error_and_a_constant_ratio():
    """Eq. 8 on equilateral triangles equals the FEM stiffness at nu = 1/3, so the MSS - FEM
    difference starts at second order in the load: doubling a small load multiplies the error by
    four and leaves mean/max unchanged."""
    exp = sweep.load_experiment(sweep.LLOYD / "membrane_equilateral.yaml")
    err = []
    for f in (1e-3, 2e-3):
        u = sweep.solve(exp, "stretch", "mss", f, False)["displacement"].values
        ur = sweep.solve(exp, "stretch", "fem", f, False)["displacement"].values
        e = np.linalg.norm(u - ur, axis=1)
        err.append((e.max(), e.mean()))
    (m1, a1), (m2, a2) = err
    assert m2 / m1 == pytest.approx(4.0, rel=0.01)
    assert a2 / m2 == pytest.approx(a1 / m1, rel=0.01)


def test_crossing_of_two_error_curves_is_log_interpolated():
    import xarray as xr

    d = np.array([0.01, 0.1, 1.0])
    ea = 1e-3 * d          # linear
    eb = 1e-2 * d ** 2     # quadratic: equal at d = 0.1
    ds = xr.Dataset({"deformation": (("run", "level"), np.vstack([d, d])),
                     "error_max": (("run", "level"), np.vstack([ea, eb]))}, coords={"run": ["a", "b"]})
    ds["error_max"][0, 1] *= 1.001  # a is just above b at 0.1: the crossing lies between 0.1 and 1
    x = sweep.crossing(ds, "a", "b")
    assert 0.1 < x < 0.1 * 1.01
    assert np.isnan(sweep.crossing(ds, "b", "a"))  # b never falls below a
    assert np.isnan(sweep.crossing(ds, "a", "missing"))

"""Guards of the solvers: the explicit time step checked against the stability limit before a run,
the divergence detector, and the Newton convergence test with its round-off floor (static MSS
solves, implicit Euler, the FEM references), through the API, scenes and the command line."""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib.models.golec import golec_cube_springs
from msslib import cli, fem
from msslib import mesh as M
from msslib import system as MD
from msslib import solvers as S
from msslib.stepping import integrate
from msslib import terms as T
from msslib.errors import StabilityError
from msslib.stepping import LatticeExplicit
from msslib.scene import load_scene, prepare, run_scene

E0, RHO, G = 1.0e6, 1000.0, 9.81


def cantilever(nx=10, nyz=2, length=0.2, damping=0.0):
    """Golec cantilever ``length`` x (length nyz / nx)^2 clamped at x = 0, under gravity."""
    a = length / nx
    mesh = M.hex_grid(length, nyz * a, nyz * a, nx, nyz, nyz)
    masses = M.lumped_masses(mesh, RHO)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    terms = golec_cube_springs(mesh, [(E0, 0.3)], 1.0) + [T.Gravity(masses, [0.0, 0.0, -G])]
    return MD.Model(mesh, terms, fixed=fixed, masses=masses, damping=damping)


def static_deflection(model):
    return float(np.abs(S.static_solve(model, model.x0).x - model.x0).max())


def _number_after(pattern, text):
    m = re.search(pattern + r" ([0-9.]+(?:e[+-]?[0-9]+)?) s", text)
    assert m, (pattern, text)
    return float(m.group(1))


# --------------------------------------------------------------------------------------------
# the time step is checked before an explicit run
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
@pytest.mark.parametrize("factor", [1.05, 1.2, 2.0])
def test_step_over_limit_is_refused_with_both_numbers(method, factor):
    model = cantilever()
    limit = S.explicit_stability_limit(model, model.x0)
    dt = factor * limit
    with pytest.raises(StabilityError) as info:
        integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=100 * dt, method=method, damping=0.0)
    msg = str(info.value)
    assert _number_after("dt =", msg) == pytest.approx(dt, rel=1e-6)
    assert _number_after("the explicit stability limit", msg) == pytest.approx(limit, rel=1e-6)
    assert f"is {factor:.3g} x the explicit stability limit" in msg
    assert "allow_unstable" in msg and "\n" not in msg
    assert isinstance(info.value, ValueError)  # the command line reports it as one error line


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_step_below_limit_runs_and_records_the_limit(method):
    model = cantilever()
    limit = S.explicit_stability_limit(model, model.x0)
    res = integrate(model, model.x0, np.zeros(model.n_dof), dt=0.9 * limit, t_end=400 * limit, method=method,
                      damping=0.0, save_every=50)
    assert res.stats["stability_limit"] == pytest.approx(limit, rel=1e-12)
    assert res.stats["dt_over_limit"] == pytest.approx(0.9, rel=1e-12)
    assert res.stats["omega_max"] == pytest.approx(2.0 / limit, rel=1e-12)
    assert np.isfinite(res.x).all()
    # implicit Euler has no limit
    imp = integrate(model, model.x0, np.zeros(model.n_dof), dt=3 * limit, t_end=30 * limit, method="implicit_euler")
    assert imp.stats["stability_limit"] is None


def test_lanczos_limit_is_accurate_and_errs_on_the_safe_side():
    """Above 400 free dofs the limit comes from Lanczos: it must decide 1.05 x and 0.95 x of the
    exact limit (dense eigenvalues of the same matrix) correctly, and never exceed it by more
    than its tolerance."""
    model = cantilever(nx=16, nyz=3, length=0.32)
    free = model.free
    assert free.sum() > 400
    K = model.stiffness(model.x0).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    exact = 2.0 / np.sqrt(np.linalg.eigvalsh(d[:, None] * K * d[None, :]).max())
    est = S.explicit_stability_limit(model, model.x0)
    assert exact * (1.0 - 1e-3) <= est <= exact * (1.0 + 1e-9)
    with pytest.raises(StabilityError):
        S.check_time_step(model, model.x0, 1.05 * exact)
    info = S.check_time_step(model, model.x0, 0.95 * exact)
    assert info["dt_over_limit"] == pytest.approx(0.95 * exact / est, rel=1e-12)


class Oscillator:
    """One mass on a linear spring (the top mode of everything): the limits are known exactly."""

    def __init__(self, k=400.0, m=1.0, damping=0.0):
        self.n_dof, self.dim, self.k = 1, 1, k
        self.mass = np.array([m])
        self.free = np.array([True])
        self.damping = damping

    def force(self, x, load=1.0):
        return -self.k * (x - 1.0)

    def stiffness(self, x, load=1.0, out=None):
        import scipy.sparse as sp

        return sp.csr_matrix(np.array([[self.k]]))

    def energy(self, x, load=1.0):
        return float(0.5 * self.k * (x[0] - 1.0) ** 2)


@pytest.mark.parametrize("method,damping", [
    ("symplectic_euler", 0.0), ("symplectic_euler", 8.0), ("symplectic_euler", (3.0, 0.02)),
    ("velocity_verlet", 8.0), ("velocity_verlet", (3.0, 0.02)),
])
def test_damped_limit_is_the_step_where_the_scheme_turns_unstable(method, damping):
    """The limit with damping (critical_time_step) separates decaying from growing runs of the
    integrator itself: mass-proportional damping lowers symplectic Euler's limit and leaves
    velocity Verlet's at 2/omega; Rayleigh beta lowers both."""
    prob = Oscillator(damping=damping)
    x0, v0 = np.array([1.01]), np.zeros(1)
    info = S.check_time_step(prob, x0, 1e-3, method=method)
    limit, omega = info["stability_limit"], info["omega_max"]
    assert omega == pytest.approx(20.0, rel=1e-12)
    alpha, beta = (damping, 0.0) if np.ndim(damping) == 0 else damping
    if method == "velocity_verlet" and beta == 0.0 or damping == 0.0:
        assert limit == pytest.approx(2.0 / omega, rel=1e-12)
    else:
        assert limit < 2.0 / omega * (1.0 - 1e-3)
    if method == "symplectic_euler":
        c = alpha + beta * omega**2
        assert limit == pytest.approx((np.sqrt(c * c + 4 * omega**2) - c) / omega**2, rel=1e-12)
    stable = integrate(prob, x0, v0, dt=0.999 * limit, t_end=3000 * limit, method=method)
    u = np.abs(stable.x[:, 0] - 1.0)  # bounded (no growth from the first half to the second)
    assert u[1500:].max() <= 1.01 * u[:1500].max() and np.isfinite(u).all()
    with pytest.raises(S.DivergenceError):
        integrate(prob, x0, v0, dt=1.01 * limit, t_end=3000 * limit, method=method, allow_unstable=True)


# --------------------------------------------------------------------------------------------
# the divergence detector
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
@pytest.mark.parametrize("factor,max_steps", [(1.05, 40), (1.2, 15), (2.0, 6)])
def test_allow_unstable_runs_and_is_stopped_early(method, factor, max_steps):
    model = cantilever()
    limit = S.explicit_stability_limit(model, model.x0)
    u_static = static_deflection(model)
    dt = factor * limit
    with pytest.raises(S.DivergenceError) as info:
        integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=1000 * dt, method=method, damping=0.0,
                    allow_unstable=True)
    err = info.value
    assert err.quantity == "growth" and err.step <= max_steps
    # stopped while the body has moved less than a fifth of its static deflection (measured: at
    # most 0.14 of it, at 1.05 x, mostly physical motion), finite
    assert err.max_displacement < 0.2 * u_static
    assert np.isfinite(err.x_last).all() and np.isfinite(err.v_last).all()
    # the hint is the limit of the model at rest, computed before the run
    assert err.stability_limit == pytest.approx(limit, rel=1e-12)
    assert _number_after("the explicit stability limit", str(err)) == pytest.approx(limit, rel=1e-6)
    assert "at rest" in str(err)


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
@pytest.mark.parametrize("damping", [0.0, 5.0, (2.0, 2e-5)])
def test_physical_runs_do_not_trip_the_detector(method, damping):
    """Undamped oscillation under gravity at 0.95 x the limit, mass-proportional and Rayleigh
    damping: 2000 steps (a few periods of the first bending mode), no alarm, bounded motion."""
    model = cantilever()
    u_static = static_deflection(model)
    limit = S.check_time_step(model, model.x0, 1e-9, method=method, damping=damping)["stability_limit"]
    dt = 0.95 * limit
    res = integrate(model, model.x0, np.zeros(model.n_dof), dt=dt, t_end=2000 * dt, method=method,
                      damping=damping, save_every=100)
    umax = np.abs(res.x - model.x0).max()
    assert u_static < umax <= 2.5 * u_static  # a suddenly applied load overshoots to ~2x the static


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_baudet_correction_run_does_not_trip_the_detector(method):
    """Baudet's correction is a non-conservative, load-dependent force: the detector works on
    forces and velocities only."""
    mesh = M.hex_grid(0.5, 0.1, 0.1, 10, 2, 2)
    masses = M.lumped_masses(mesh, RHO)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    facets = M.boundary_facets(mesh)
    end = np.isclose(mesh.points[facets][:, :, 0], 0.5).all(axis=1)
    pull = T.Traction(mesh, facets[end], [1.0e4, 0.0, 0.0])
    terms = baudet_cube_springs(mesh, [(E0, 0.3)]) + [baudet_correction(mesh, [(E0, 0.3)], [pull]), pull]
    model = MD.Model(mesh, terms, fixed=fixed, masses=masses)
    assert not model.conservative
    limit = S.explicit_stability_limit(model, model.x0)
    res = integrate(model, model.x0, np.zeros(model.n_dof), dt=0.95 * limit, t_end=1500 * limit, method=method,
                      damping=0.0, save_every=100)
    u_static = np.abs(S.static_solve(model, model.x0).x - model.x0).max()
    assert np.abs(res.x - model.x0).max() <= 2.5 * u_static
    with pytest.raises(S.DivergenceError, match="explicit instability"):
        integrate(model, model.x0, np.zeros(model.n_dof), dt=1.2 * limit, t_end=300 * limit, method=method,
                    damping=0.0, allow_unstable=True)


def test_lattice_explicit_checks_the_step():
    mesh = M.hex_grid(0.04, 0.04, 0.04, 4, 4, 4)
    masses = M.lumped_masses(mesh, RHO)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    model = MD.Model(mesh, golec_cube_springs(mesh, [(2e4, 0.3)], 1.0) + [T.Gravity(masses, [0, 0, -G])],
                     fixed=fixed, masses=masses)
    fast = LatticeExplicit(model)
    limit = S.explicit_stability_limit(model, model.x0)
    assert fast.stability_limit(model.x0)["stability_limit"] == pytest.approx(limit, rel=1e-12)
    v0 = np.zeros(model.n_dof)
    with pytest.raises(StabilityError, match="1.2 x the explicit stability limit"):
        fast.run(model.x0, v0, 1.2 * limit, 10, 0.0)
    x, _, _ = fast.run(model.x0, v0, 0.9 * limit, 10, 0.0)
    assert np.isfinite(x).all()
    with pytest.raises(S.DivergenceError, match="non-finite"):
        fast.run(model.x0, v0, 2.0 * limit, 3000, 0.0, allow_unstable=True)


# --------------------------------------------------------------------------------------------
# Newton's convergence test: the round-off floor
# --------------------------------------------------------------------------------------------


def test_unloaded_static_solve_returns_at_once():
    mesh = M.hex_grid(0.1, 0.1, 0.1, 3, 3, 3)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    model = MD.Model(mesh, golec_cube_springs(mesh, [(E0, 0.3)], 1.0), fixed=fixed)
    res = S.static_solve(model, model.x0)
    assert res.iterations == [0]
    assert res.residuals[0][0] <= res.roundoff_floor == res.threshold
    assert np.abs(res.x - model.x0).max() == 0.0
    assert res.roundoff_steps == [1] and "converged to round-off" in res.messages[0]


def slender_beam(nx, nyz, length=1.0, width=0.02, E=1e9):
    mesh = M.hex_grid(length, width, width, nx, nyz, nyz)
    masses = M.lumped_masses(mesh, RHO)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    terms = golec_cube_springs(mesh, [(E, 0.3)], 1.0) + [T.Gravity(masses, [0.0, 0.0, -G])]
    return MD.Model(mesh, terms, fixed=fixed, masses=masses), mesh, fixed


def test_slender_beam_converges_at_the_default_tolerance():
    """0.5 m x 2 cm x 2 cm, E = 1 GPa, under its own weight: tol x F_ref lies 150 x below the
    round-off of the spring forces (their stall is 0.1 of the floor); the solve converges at the
    floor, says so, and agrees with linear FEM on the same mesh and with Euler-Bernoulli."""
    length = 0.5
    model, mesh, fixed = slender_beam(100, 4, length=length)
    res = S.static_solve(model, model.x0)
    assert res.roundoff_floor > 100 * 1e-8 * res.force_scale  # the old criterion could not be met
    assert res.residuals[-1][-1] <= res.roundoff_floor and res.roundoff_steps == [1]
    assert len(res.messages) == 1 and re.search(
        r"converged to round-off: residual [0-9.e+-]+ at the round-off floor [0-9.e+-]+", res.messages[0])
    assert res.total_iterations <= 15
    tip = -float((res.x - model.x0).reshape(-1, 3)[:, 2].min())
    ref = fem.solve_linear(mesh, 1e9, 0.3, fixed=fixed, body_force=[0.0, 0.0, -RHO * G])
    tip_fem = -float(ref.displacement[:, 2].min())
    assert tip == pytest.approx(tip_fem, rel=0.05)  # measured: 3.3 % (MSS vs Q1, 4 cells thick)
    q, inertia = RHO * G * 0.02**2, 0.02**4 / 12
    assert tip == pytest.approx(q * length**4 / (8 * 1e9 * inertia), rel=0.1)  # measured: 6.8 % below


def test_a_residual_above_the_floor_is_never_accepted():
    model, _, _ = slender_beam(50, 1)
    with pytest.raises(S.ConvergenceError) as info:
        S.static_solve(model, model.x0, max_iter=1, max_cuts=0)
    msg = str(info.value)
    assert "is above the round-off floor" in msg and "round-off floor" in msg.split("threshold")[1]
    assert info.value.residual > 10 * _number_after_floor(msg)


def _number_after_floor(msg):
    return float(re.search(r"is above the round-off floor ([0-9.e+-]+)", msg).group(1))


def test_implicit_euler_uses_the_floor():
    model, _, _ = slender_beam(50, 1)
    res = integrate(model, model.x0, np.zeros(model.n_dof), dt=1e-3, t_end=5e-3, method="implicit_euler")
    assert res.stats["n_newton_iterations"] <= 3 * 5
    assert np.isfinite(res.x).all()


def test_fem_reference_unloaded_and_small_load():
    mesh = M.hex_grid(1.0, 0.02, 0.02, 50, 1, 1)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    free = fem.solve_nonlinear(mesh, 1e9, 0.3, fixed=fixed, law="neohookean", steps=1)
    assert free.stats["iterations"] == [0] and np.abs(free.displacement).max() == 0.0
    small = fem.solve_nonlinear(mesh, 1e9, 0.3, fixed=fixed, body_force=[0, 0, -1e-3], law="neohookean", steps=1)
    assert small.stats["iterations"][0] <= 3 and small.stats["roundoff_floor"] > 0
    assert small.stats["threshold"] >= small.stats["roundoff_floor"]
    # a tolerance below the round-off converges at the floor (it used to fail) and says so
    tight = fem.solve_nonlinear(mesh, 1e9, 0.3, fixed=fixed, body_force=[0, 0, -1e-3], law="neohookean", steps=1,
                                tol=1e-15)
    assert tight.stats["roundoff_steps"] == [1] and "converged to round-off" in tight.stats["messages"][0]
    scale = np.abs(small.displacement).max()
    np.testing.assert_allclose(tight.displacement, small.displacement, rtol=0, atol=1e-6 * scale)


# --------------------------------------------------------------------------------------------
# scenes and the command line
# --------------------------------------------------------------------------------------------


def _dynamic_scene(dt, t_end, allow_unstable=None):
    solver = {"type": "dynamic", "method": "velocity_verlet", "dt": float(dt), "t_end": float(t_end), "save_every": 10}
    if allow_unstable is not None:
        solver["allow_unstable"] = allow_unstable
    return {
        "name": "cantilever_guard",
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.2, "ly": 0.04, "lz": 0.04, "nx": 10, "ny": 2, "nz": 2}},
        "materials": [{"E": E0, "nu": 0.3, "density": RHO}],
        "model": {"type": "golec_cube", "A": 1.0},
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": [{"type": "gravity", "g": [0.0, 0.0, -G]}],
        "solver": solver,
    }


def _scene_limit():
    setup = prepare(load_scene(_dynamic_scene(1e-4, 1e-3)))
    return S.explicit_stability_limit(setup.model, setup.model.x0)


def test_run_scene_refuses_and_allow_unstable_passes_through():
    limit = _scene_limit()
    with pytest.raises(StabilityError, match="1.2 x the explicit stability limit"):
        run_scene(_dynamic_scene(1.2 * limit, 100 * limit), progress=False)
    with pytest.raises(S.DivergenceError, match="explicit instability"):
        run_scene(_dynamic_scene(1.2 * limit, 100 * limit, allow_unstable=True), progress=False)
    ds = run_scene(_dynamic_scene(0.9 * limit, 50 * limit), progress=False)
    assert ds.attrs["solver_stability_limit"] == pytest.approx(limit, rel=1e-12)


def test_cli_reports_one_error_line(tmp_path, capsys):
    limit = _scene_limit()
    for allow, what in ((False, "explicit stability limit"), (True, "diverged")):
        scene = tmp_path / f"over_{allow}.yaml"
        scene.write_text(yaml.safe_dump(_dynamic_scene(2.0 * limit, 100 * limit, allow_unstable=allow)))
        out = tmp_path / f"over_{allow}.nc"
        assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
        err = capsys.readouterr().err
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("msslib: error:") and what in lines[0], err
        assert _number_after("stability limit", lines[0]) == pytest.approx(limit, rel=1e-6)
        assert not out.exists()


def test_cli_unloaded_and_slender_beam_scenes_converge(tmp_path, capsys):
    from msslib.results import read_result

    base = {"materials": [{"E": 1.0e9, "nu": 0.3, "density": RHO}], "model": "golec_cube",
            "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}]}
    beam = dict(base, geometry={"generator": "hex_grid", "args": {"lx": 1.0, "ly": 0.02, "lz": 0.02, "nx": 50,
                                                                   "ny": 1, "nz": 1}},
                loads=[{"type": "gravity", "g": [0.0, 0.0, -G]}])
    unloaded = dict(base, geometry={"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 3,
                                                                       "ny": 3, "nz": 3}})
    for name, scene in (("beam", beam), ("unloaded", unloaded)):
        path, out = tmp_path / f"{name}.yaml", tmp_path / f"{name}.nc"
        path.write_text(yaml.safe_dump(scene))
        assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0, capsys.readouterr().err
        ds = read_result(out)
        assert ds.attrs["solver_final_residual"] <= ds.attrs["solver_roundoff_floor"] == ds.attrs["solver_threshold"]
        assert "converged to round-off" in ds.attrs["solver_messages"]
        if name == "unloaded":
            assert int(ds.attrs["solver_total_iterations"]) == 0
            assert np.abs(ds["displacement"].values).max() == 0.0

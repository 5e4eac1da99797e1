"""Tests of msslib.solvers on small self-contained toy problems (see the problem protocol in the module)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from solver_problems import (
    Circulatory,
    LinearProblem,
    SpringNetwork,
    chain,
    hardening_stretch,
)

from msslib.solvers import (
    ConvergenceError,
    DivergenceError,
    explicit_stability_limit,
    static_solve,
)
from msslib.stepping import integrate

# ---------------------------------------------------------------------------------------------
# statics
# ---------------------------------------------------------------------------------------------


def test_linear_problem_one_newton_iteration():
    rng = np.random.default_rng(1)
    n = 30
    K = sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    f = rng.standard_normal(n)
    x_ref = rng.standard_normal(n)
    prob = LinearProblem(K, f, x_ref)
    res = static_solve(prob, x_ref)
    assert res.converged and res.iterations == [1] and res.n_load_steps == 1
    np.testing.assert_allclose(res.x, x_ref + np.linalg.solve(K.toarray(), f), rtol=1e-10, atol=1e-12)
    assert res.line_search_merit == "energy"
    assert res.residuals[0][-1] <= 1e-8 * np.linalg.norm(f)


def test_linear_problem_cg_path():
    n = 200
    K = sp.diags([-np.ones(n - 1), 2.01 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    prob = LinearProblem(K, np.ones(n), np.zeros(n))
    res = static_solve(prob, np.zeros(n), linear_solver="cg", tol=1e-9)
    np.testing.assert_allclose(res.x, np.linalg.solve(K.toarray(), np.ones(n)), rtol=1e-7)


@pytest.mark.parametrize("k3", [0.0, 5.0])
def test_chain_stretches_to_analytic_length(k3):
    n, k, F = 6, 2.0, 3.0
    prob = chain(n, 2, k=k, k3=k3, end_force=F, zigzag=0.1, prestretch=1.05)
    res = static_solve(prob, prob.x0())
    s = hardening_stretch(k, k3, F)
    p = res.x.reshape(-1, 2)
    np.testing.assert_allclose(p[:, 0], np.arange(n + 1) * (1.0 + s), atol=1e-7)
    np.testing.assert_allclose(p[:, 1], 0.0, atol=1e-7)
    assert np.linalg.norm(prob.force(res.x)[prob.free]) <= 1e-8 * F


def test_quadratic_convergence():
    prob = chain(6, 2, k=2.0, k3=5.0, end_force=3.0, zigzag=0.1, prestretch=1.05)
    calls = []
    res = static_solve(prob, prob.x0(), tol=1e-13, progress=calls.append)
    assert [c["residual"] for c in calls] == res.residuals[0][1:]
    rel = np.array(res.residuals[0]) / res.force_scale
    pairs = [(a, b) for a, b in zip(rel[:-1], rel[1:]) if a < 1e-2 and b > 1e-14]
    assert pairs, rel
    for a, b in pairs:
        assert b <= 10.0 * a**2, rel  # r_{k+1} ~ C r_k^2


def test_load_stepping_where_single_step_fails():
    # strongly nonlinear (S-shaped atan springs), plain Newton: one full step diverges
    prob = Circulatory(P=[2.5, 0.5], c=0.01, a=5.0)
    with pytest.raises(ConvergenceError):
        static_solve(prob, np.zeros(2), line_search=False, load_steps=1, max_cuts=0)
    res = static_solve(prob, np.zeros(2), line_search=False, load_steps=20, max_cuts=0, tol=1e-12)
    assert res.n_load_steps == 20 and res.loads[-1] == 1.0 and res.n_cuts == 0
    assert np.linalg.norm(prob.force(res.x)) <= 1e-8 * np.linalg.norm(prob.P)
    # same root as the (globalised) single-step solve with the residual line search
    np.testing.assert_allclose(res.x, static_solve(prob, np.zeros(2), tol=1e-12).x, rtol=1e-9)


def test_automatic_step_halving():
    prob = Circulatory(P=[2.5, 0.5], c=0.01, a=5.0)
    res = static_solve(prob, np.zeros(2), line_search=False, load_steps=1)
    assert res.n_cuts > 0 and res.n_load_steps > 1 and res.loads[-1] == 1.0
    assert np.all(np.diff(res.loads) > 0)
    assert any("halving" in m for m in res.messages)
    assert np.linalg.norm(prob.force(res.x)) <= 1e-8 * np.linalg.norm(prob.P)


def test_hardening_chain_large_force():
    n, k, k3, F = 4, 1.0, 100.0, 1000.0
    prob = chain(n, 1, k=k, k3=k3, end_force=F)
    res = static_solve(prob, prob.x0(), load_steps=5)
    np.testing.assert_allclose(res.x, np.arange(n + 1) * (1.0 + hardening_stretch(k, k3, F)), rtol=1e-9)


def test_convergence_error_message():
    prob = chain(4, 1, k=1.0, k3=100.0, end_force=1000.0)
    with pytest.raises(ConvergenceError) as info:
        static_solve(prob, prob.x0(), max_iter=2, max_cuts=1)
    msg = str(info.value)
    for word in ("load step", "load factor", "iteration", "residual"):
        assert word in msg
    assert np.all(np.isfinite(info.value.x_last))
    assert isinstance(info.value, RuntimeError)


def test_non_conservative_residual_line_search():
    prob = Circulatory(P=[2.0, 1.0], c=0.05, a=3.0)
    with pytest.raises(ConvergenceError):
        static_solve(prob, np.zeros(2), line_search=False, max_cuts=0)
    res = static_solve(prob, np.zeros(2), max_cuts=0, tol=1e-12)
    assert res.line_search_merit == "residual" and res.n_load_steps == 1
    assert np.linalg.norm(prob.force(res.x)) <= 1e-8 * np.linalg.norm(prob.P)
    # the residual decreases monotonically along the iteration (merit = ||r||)
    assert np.all(np.diff(res.residuals[0]) < 0)
    # same root as a load-stepped plain Newton run
    stepped = static_solve(prob, np.zeros(2), line_search=False, load_steps=20, max_cuts=0, tol=1e-12)
    np.testing.assert_allclose(res.x, stepped.x, rtol=1e-9)


def test_prescribed_displacement():
    prob = chain(5, 1, k=1.0, k3=1.0)
    prob.free[-1] = False
    delta = 2.5

    def apply_prescribed(x, load):
        x = x.copy()
        x[-1] = 5.0 + load * delta
        return x

    prob.apply_prescribed = apply_prescribed
    res = static_solve(prob, prob.x0(), load_steps=2)
    np.testing.assert_allclose(res.x, np.arange(6) * (1.0 + delta / 5), rtol=1e-9)


# ---------------------------------------------------------------------------------------------
# dynamics
# ---------------------------------------------------------------------------------------------

M, K_SPRING = 2.0, 8.0
OMEGA = np.sqrt(K_SPRING / M)
AMP = 0.5  # initial stretch; the mass oscillates as x = 1 + AMP cos(OMEGA t)


def oscillator(**kw):
    """One free mass on a linear spring (1D, node 0 fixed); rest length 1, start stretched by AMP."""
    prob = SpringNetwork([0.0, 1.0], [[0, 1]], K_SPRING, fixed_nodes=(0,), mass=M, **kw)
    x0 = np.array([0.0, 1.0 + AMP])
    return prob, x0


def osc_error(method, dt, t_end=1.0):
    prob, x0 = oscillator()
    res = integrate(prob, x0, np.zeros(2), dt=dt, t_end=t_end, method=method)
    assert res.t[-1] == pytest.approx(t_end)
    return abs(res.x_final[1] - (1.0 + AMP * np.cos(OMEGA * t_end)))


@pytest.mark.parametrize("method, order", [("symplectic_euler", 1), ("velocity_verlet", 2), ("implicit_euler", 1)])
def test_oscillator_convergence_order(method, order):
    errs = [osc_error(method, dt) for dt in (0.01, 0.005, 0.0025)]
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    np.testing.assert_allclose(rates, order, atol=0.15)
    assert errs[-1] < (0.05 if order == 1 else 1e-4)


def test_oscillator_matches_cosine_and_constrained_dof_still():
    prob, x0 = oscillator()
    res = integrate(prob, x0, np.zeros(2), dt=1e-3, t_end=2.0, method="velocity_verlet", save_every=10)
    assert res.x.shape == (201, 2) and res.v.shape == (201, 2) and res.t.shape == (201,)
    np.testing.assert_allclose(res.x[:, 1], 1.0 + AMP * np.cos(OMEGA * res.t), atol=1e-5)
    np.testing.assert_allclose(res.v[:, 1], -AMP * OMEGA * np.sin(OMEGA * res.t), atol=1e-5)
    assert np.all(res.x[:, 0] == 0.0) and np.all(res.v[:, 0] == 0.0)


def test_verlet_energy_bounded_over_many_periods():
    prob, x0 = oscillator()
    period = 2 * np.pi / OMEGA
    dt = period / 20
    res = integrate(prob, x0, np.zeros(2), dt=dt, t_end=200 * period, method="velocity_verlet")
    e = res.kinetic_energy + res.potential_energy
    e0 = e[0]
    dev = np.abs(e - e0) / e0
    assert dev.max() < 0.05
    first, last = dev[:20].max(), dev[-20:].max()
    assert last <= 1.05 * first + 1e-12  # bounded oscillation, no secular drift


def test_implicit_euler_dissipates():
    prob, x0 = oscillator()
    period = 2 * np.pi / OMEGA
    res = integrate(prob, x0, np.zeros(2), dt=period / 20, t_end=5 * period, method="implicit_euler")
    e = res.kinetic_energy + res.potential_energy
    assert np.all(np.diff(e) <= 1e-12)
    assert e[-1] < 0.5 * e[0]
    assert res.stats["n_newton_iterations"] >= len(res.t) - 1


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_mass_proportional_damping_decays_like_analytic(method):
    alpha = 0.4  # c = alpha * m, zeta = alpha / (2 omega)
    prob, x0 = oscillator(damping=alpha)  # taken from problem.damping since damping=None
    res = integrate(prob, x0, np.zeros(2), dt=1e-3, t_end=3.0, method=method, save_every=100)
    zeta = alpha / (2 * OMEGA)
    wd = OMEGA * np.sqrt(1 - zeta**2)
    t = res.t
    exact = AMP * np.exp(-zeta * OMEGA * t) * (np.cos(wd * t) + zeta * OMEGA / wd * np.sin(wd * t))
    np.testing.assert_allclose(res.x[:, 1] - 1.0, exact, atol=5e-3 if method == "symplectic_euler" else 1e-5)
    # explicit damping=0.0 overrides problem.damping
    undamped = integrate(prob, x0, np.zeros(2), dt=1e-3, t_end=3.0, method=method, damping=0.0)
    assert abs(undamped.x_final[1] - 1.0 - AMP * np.cos(OMEGA * 3.0)) < 5e-3


def test_rayleigh_damping_decays():
    prob, x0 = oscillator()
    res = integrate(prob, x0, np.zeros(2), dt=2e-3, t_end=5.0, method="velocity_verlet",
                    damping=(0.0, 0.05), save_every=50)
    e = res.kinetic_energy + res.potential_energy
    # beta K gives zeta = beta omega / 2 = 0.05: energy ~ exp(-2 zeta omega t)
    assert e[-1] / e[0] == pytest.approx(np.exp(-2 * 0.05 * OMEGA * 5.0), rel=0.05)


def test_stability_limit_estimate():
    prob, x0 = oscillator()
    assert explicit_stability_limit(prob, x0) == pytest.approx(2 / OMEGA, rel=1e-10)
    ch = chain(20, 2, k=3.0, zigzag=0.2, prestretch=1.1, mass=0.5)
    x = ch.x0()
    Kf = ch.stiffness(x).toarray()[np.ix_(ch.free, ch.free)]
    lam = np.linalg.eigvalsh(Kf / 0.5).max()
    assert explicit_stability_limit(ch, x) == pytest.approx(2 / np.sqrt(lam), rel=1e-8)


def _unstable_setup():
    prob = chain(10, 1, k=50.0, mass=0.1)
    x0 = prob.x0()
    x0[1:] += 0.01 * np.sin(np.arange(1, 11))
    dt = 1.5 * explicit_stability_limit(prob, x0)
    return prob, x0, dt


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
def test_explicit_step_above_limit_raises(method):
    prob, x0, dt = _unstable_setup()
    with pytest.raises(DivergenceError) as info:  # refused up front unless allow_unstable
        integrate(prob, x0, np.zeros(prob.n_dof), dt=dt, t_end=500 * dt, method=method, allow_unstable=True)
    err = info.value
    msg = str(err)
    assert f"at step {err.step}," in msg and "t = " in msg and "stability limit" in msg
    assert 0 < err.step < 500 and err.time == pytest.approx(err.step * dt)
    assert np.all(np.isfinite(err.x_last)) and np.all(np.isfinite(err.v_last))


def test_implicit_euler_stable_at_same_step():
    prob, x0, dt = _unstable_setup()
    res = integrate(prob, x0, np.zeros(prob.n_dof), dt=dt, t_end=500 * dt, method="implicit_euler",
                    save_every=50)
    assert np.all(np.isfinite(res.x)) and np.all(np.isfinite(res.v))
    assert np.max(np.abs(res.x_final - prob.x0())) < 0.05

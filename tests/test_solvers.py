"""Tests of msslib.solvers on small self-contained toy problems (see the problem protocol in the module)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from msslib.solvers import (
    ConvergenceError,
    DivergenceError,
    explicit_stability_limit,
    integrate,
    static_solve,
)

# ---------------------------------------------------------------------------------------------
# toy problems
# ---------------------------------------------------------------------------------------------


class SpringNetwork:
    """Springs with energy k/2 s^2 + k3/4 s^4, s = |x_j - x_i| - L, plus a constant external force."""

    def __init__(self, points, edges, k, rest=None, k3=0.0, fixed_nodes=(), f_ext=None, mass=1.0,
                 damping=None):
        points = np.asarray(points, dtype=float)
        if points.ndim == 1:
            points = points[:, None]
        self.n_nodes, self.dim = points.shape
        self.n_dof = points.size
        self.points = points
        self.edges = np.asarray(edges, dtype=np.int64)
        d = points[self.edges[:, 1]] - points[self.edges[:, 0]]
        self.rest = np.linalg.norm(d, axis=1) if rest is None else np.broadcast_to(np.asarray(rest, float), len(self.edges)).copy()
        self.k = float(k)
        self.k3 = float(k3)
        self.free = np.ones(self.n_dof, dtype=bool)
        for node in fixed_nodes:
            self.free[self.dim * node:self.dim * node + self.dim] = False
        self.f_ext = np.zeros(self.n_dof) if f_ext is None else np.asarray(f_ext, dtype=float)
        self.mass = np.full(self.n_dof, float(mass))
        if damping is not None:
            self.damping = damping

    def _geometry(self, x):
        p = x.reshape(-1, self.dim)
        d = p[self.edges[:, 1]] - p[self.edges[:, 0]]
        length = np.linalg.norm(d, axis=1)
        return d, length, length - self.rest

    def energy(self, x, load=1.0):
        _, _, s = self._geometry(x)
        return float(np.sum(0.5 * self.k * s**2 + 0.25 * self.k3 * s**4) - load * self.f_ext @ x)

    def force(self, x, load=1.0):
        d, length, s = self._geometry(x)
        tension = self.k * s + self.k3 * s**3
        fe = (tension / length)[:, None] * d  # force pulling node j back towards i
        f = np.zeros((self.n_nodes, self.dim))
        np.add.at(f, self.edges[:, 0], fe)
        np.add.at(f, self.edges[:, 1], -fe)
        return f.reshape(-1) + load * self.f_ext

    def stiffness(self, x, load=1.0):
        d, length, s = self._geometry(x)
        dim = self.dim
        n = d / length[:, None]
        tension = self.k * s + self.k3 * s**3
        dtension = self.k + 3 * self.k3 * s**2
        nn = n[:, :, None] * n[:, None, :]
        ke = dtension[:, None, None] * nn + (tension / length)[:, None, None] * (np.eye(dim) - nn)
        rows, cols, vals = [], [], []
        a, b = np.meshgrid(np.arange(dim), np.arange(dim), indexing="ij")
        for p, q, sign in ((0, 0, 1.0), (1, 1, 1.0), (0, 1, -1.0), (1, 0, -1.0)):
            rows.append((dim * self.edges[:, p])[:, None, None] + a)
            cols.append((dim * self.edges[:, q])[:, None, None] + b)
            vals.append(sign * ke)
        rows, cols, vals = (np.concatenate([r.reshape(-1) for r in arr]) for arr in (rows, cols, vals))
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_dof, self.n_dof))

    def x0(self):
        return self.points.reshape(-1).copy()


def chain(n_springs, dim, *, k=1.0, k3=0.0, rest=1.0, end_force=0.0, zigzag=0.0, prestretch=1.0, **kw):
    """Chain of springs along x, node 0 fixed, force ``end_force`` along +x on the last node."""
    pts = np.zeros((n_springs + 1, dim))
    pts[:, 0] = np.arange(n_springs + 1) * rest * prestretch
    if dim > 1:
        pts[1::2, 1] = zigzag * rest
    edges = np.column_stack([np.arange(n_springs), np.arange(1, n_springs + 1)])
    f = np.zeros(pts.size)
    f[dim * n_springs] = end_force
    return SpringNetwork(pts, edges, k, rest=rest, k3=k3, fixed_nodes=(0,), f_ext=f, **kw)


class LinearProblem:
    """force = load * f - K (x - x_ref), a fixed SPD K."""

    def __init__(self, K, f, x_ref):
        self.K = sp.csr_matrix(K)
        self.f = np.asarray(f, float)
        self.x_ref = np.asarray(x_ref, float)
        self.n_dof = len(f)
        self.free = np.ones(self.n_dof, bool)
        self.mass = np.ones(self.n_dof)

    def force(self, x, load=1.0):
        return load * self.f - self.K @ (x - self.x_ref)

    def stiffness(self, x, load=1.0):
        return self.K

    def energy(self, x, load=1.0):
        u = x - self.x_ref
        return 0.5 * u @ (self.K @ u) - load * self.f @ x


class Circulatory:
    """Non-conservative: f(u) = load*P - k*(atan(u - a) - atan(-a)) - load*c*J u, J = 90-degree rotation.

    The circulatory term load*c*J u has no potential, so there is no energy and the stiffness is
    non-symmetric. With a shift ``a`` the atan springs are soft at u = 0 and stiff near u = a, which
    throws a plain Newton iteration started at 0 far away (the classic atan divergence)."""

    symmetric = False
    n_dof = 2
    free = np.ones(2, bool)
    mass = np.ones(2)
    J = np.array([[0.0, -1.0], [1.0, 0.0]])

    def __init__(self, P, k=1.0, c=0.5, a=0.0):
        self.P, self.k, self.c, self.a = np.asarray(P, float), k, c, a

    def force(self, x, load=1.0):
        return load * self.P - self.k * (np.arctan(x - self.a) - np.arctan(-self.a)) - load * self.c * self.J @ x

    def stiffness(self, x, load=1.0):
        return sp.csr_matrix(np.diag(self.k / (1 + (x - self.a) ** 2)) + load * self.c * self.J)

    def energy(self, x, load=1.0):
        return None


def hardening_stretch(k, k3, force):
    roots = np.roots([k3, 0.0, k, -force]) if k3 else np.array([force / k])
    return float(np.real(roots[np.argmin(np.abs(roots.imag))]))


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


# ---------------------------------------------------------------------------------------------
# linear algebra of the static solver: free-dof extraction, banded direct, CG, forcing term
# ---------------------------------------------------------------------------------------------


def lattice_block(nx, ny, nz, *, k3=2.0, g=0.05):
    """3D lattice of nodes joined to their 26 neighbours (springs), bottom layer fixed, a uniform
    downward load; dofs interleaved by node (``dim = 3``), so the AMG path sees node blocks."""
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    pts = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"), -1).reshape(-1, 3)
    edges = []
    for di in (0, 1):
        for dj in (-1, 0, 1):
            for dk in (-1, 0, 1):
                if (di, dj, dk) <= (0, 0, 0):
                    continue
                a = idx[max(0, -di):nx - max(0, di), max(0, -dj):ny - max(0, dj), max(0, -dk):nz - max(0, dk)]
                b = idx[max(0, di):nx - max(0, -di) or None, max(0, dj):ny - max(0, -dj) or None,
                        max(0, dk):nz - max(0, -dk) or None]
                edges.append(np.column_stack([a.ravel(), b.ravel()]))
    edges = np.concatenate(edges)
    f = np.zeros(pts.size)
    f[2::3] = -g
    fixed = np.flatnonzero(pts[:, 2] == 0)
    return SpringNetwork(pts.astype(float), edges, 1.0, k3=k3, fixed_nodes=fixed, f_ext=f)


def test_submatrix_plan_matches_fancy_indexing_and_is_reused():
    from msslib.solvers import _submatrix

    rng = np.random.default_rng(4)
    for t in range(30):
        K = sp.random(40, 40, 0.08, random_state=t, format="csr") + (sp.eye(40) if t % 2 else 0)
        K = sp.csr_matrix(K)
        K.sum_duplicates()
        free = rng.random(40) < 0.7
        idx = np.flatnonzero(free)
        for _ in range(2):  # the second call goes through the cached plan
            A = _submatrix(K, free)
            A.check_format(full_check=True)
            assert A.shape == (len(idx), len(idx))
            assert abs(A - K[idx][:, idx]).max() == 0 if A.nnz else K[idx][:, idx].nnz == 0
        K2 = K.copy()
        K2.data = rng.standard_normal(K2.nnz)  # same pattern, new values
        assert abs(_submatrix(K2, free) - K2[idx][:, idx]).max() == 0 if K2[idx][:, idx].nnz else True


def clamped_golec_block(nx, ny, nz, nu=0.3):
    """Golec cube lattice of nx x ny x nz 1 cm cells, clamped at x = 0."""
    from msslib import mesh as M
    from msslib.model import Model, golec_cube_springs

    mesh = M.hex_grid(0.01 * nx, 0.01 * ny, 0.01 * nz, nx, ny, nz)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    return Model(mesh, golec_cube_springs(mesh, [(1e4, nu)], 1.0), fixed=fixed)


def test_submatrix_refill_in_place_equals_fresh_extraction():
    from msslib.solvers import _submatrix

    model = clamped_golec_block(3, 2, 2)
    free = model.free
    idx = np.flatnonzero(free)
    rng = np.random.default_rng(5)
    K = model.stiffness(model.x0)
    A = _submatrix(K, free)
    for _ in range(2):
        x = model.x0 + 1e-3 * rng.standard_normal(model.n_dof)
        K = model.stiffness(x, out=K)
        A2 = _submatrix(K, free, out=A)
        assert A2 is A  # values overwritten in place
        ref = K.tocsc()[idx][:, idx]
        assert abs(A2 - ref).max() == 0.0
    # a matrix of another pattern is not reused
    other = sp.csr_matrix(np.eye(len(idx)))
    assert _submatrix(K, free, out=other) is not other


@pytest.mark.parametrize("shift", [0.0, -0.5])  # SPD (banded Cholesky) and indefinite (banded LU)
def test_banded_direct_solve_matches_dense(shift):
    from msslib.solvers import _direct_solve, _solver_context

    prob = lattice_block(3, 3, 6)
    x = prob.x0()
    free = prob.free
    from msslib.solvers import _submatrix

    A = _submatrix(prob.stiffness(x) + shift * sp.eye(prob.n_dof, format="csr"), free)
    A = sp.csr_matrix(A)
    A.sum_duplicates()
    b = np.random.default_rng(0).standard_normal(A.shape[0])
    ctx = _solver_context(prob, x, free)
    sol = _direct_solve(A, b, True, ctx)
    ref = np.linalg.solve(A.toarray(), b)
    np.testing.assert_allclose(sol, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    assert bool(ctx.get("band_indefinite")) == (np.linalg.eigvalsh(A.toarray()).min() < 0)
    # the band arrays kept in the context are refilled for new values of the same pattern
    A2 = A.copy()
    A2.data *= np.random.default_rng(1).uniform(0.9, 1.1, A2.nnz)
    A2 = sp.csr_matrix(0.5 * (A2 + A2.T))
    A2.sum_duplicates()
    sol2 = _direct_solve(A2, b, True, ctx)
    ref2 = np.linalg.solve(A2.toarray(), b)
    np.testing.assert_allclose(sol2, ref2, rtol=1e-8, atol=1e-10 * np.abs(ref2).max())


def test_pcg_converges_and_detects_negative_curvature():
    from msslib.solvers import _pcg

    n = 100
    K = sp.diags([-np.ones(n - 1), 2.05 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    b = np.random.default_rng(2).standard_normal(n)
    identity = sp.eye(n, format="csr")
    x, info, its = _pcg(K, b, identity, 1e-10, 1000)
    assert info == 0 and 0 < its <= n and np.linalg.norm(K @ x - b) <= 1e-10 * np.linalg.norm(b)
    # indefinite: a negative-curvature direction is reported, and what is returned still descends
    # the quadratic model 1/2 x.A x - b.x (direction of positive b.x)
    Kn = K - 1.0 * identity
    x, info, its = _pcg(Kn, b, identity, 1e-10, 1000)
    assert info == -1 and np.all(np.isfinite(x)) and float(b @ x) > 0


def test_forcing_term_loose_far_tight_near():
    from msslib.solvers import _ETA_MAX, _forcing_term

    threshold = 1e-8
    assert _forcing_term(1.0, None, None, threshold) == _ETA_MAX
    # quadratic convergence phase: eta follows (r_k / r_k-1)^2
    assert _forcing_term(1e-3, 1e-1, 1e-2, threshold) == pytest.approx(0.9e-4)
    # close to the threshold it never asks more than needed (0.1 threshold / r), nor < 1e-10
    assert _forcing_term(1e-6, 1e-3, 1e-4, threshold) == pytest.approx(1e-3)
    assert _forcing_term(1e-20, 1e-3, 1e-4, 1e-30) == 1e-10


def test_static_solve_cg_and_direct_agree_on_a_nonlinear_lattice():
    prob = lattice_block(4, 4, 7)
    x0 = prob.x0()
    direct = static_solve(prob, x0, linear_solver="direct", tol=1e-10)
    iterative = static_solve(prob, x0, linear_solver="cg", tol=1e-10)
    assert direct.cg_iterations == 0 and iterative.cg_iterations > 0
    for r in (direct, iterative):
        assert r.residuals[-1][-1] <= 1e-10 * r.force_scale
        assert np.linalg.norm(prob.force(r.x)[prob.free]) <= 1e-10 * r.force_scale
    u = direct.x - x0
    assert np.abs(u).max() > 0.05  # a genuinely deformed state
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())
    # the inexact Newton (loose CG early on) does not cost many more Newton iterations
    assert iterative.total_iterations <= direct.total_iterations + 3


def test_free_node_blocks_as_bsr_equal_the_csr_block_and_refill_in_place():
    from msslib.solvers import _is_node_blocked, _solver_context, _submatrix_bsr

    model = clamped_golec_block(3, 2, 2)
    free = model.free
    idx = np.flatnonzero(free)
    ctx = _solver_context(model, model.x0, free)
    rng = np.random.default_rng(6)
    K = model.stiffness(model.x0)
    B = _submatrix_bsr(K, ctx["node_free"], 3)
    assert B.format == "bsr" and B.blocksize == (3, 3)
    B.check_format(full_check=True)
    for _ in range(2):
        K = model.stiffness(model.x0 + 1e-3 * rng.standard_normal(model.n_dof), out=K)
        B2 = _submatrix_bsr(K, ctx["node_free"], 3, out=B)
        assert B2 is B  # values overwritten in place
        np.testing.assert_array_equal(B2.toarray(), K.toarray()[np.ix_(idx, idx)])
    # patterns that are not whole node blocks are refused (the caller then extracts a CSR block)
    assert not _is_node_blocked(sp.csr_matrix(np.eye(6)).indptr, sp.csr_matrix(np.eye(6)).indices, 3)
    assert _submatrix_bsr(sp.csr_matrix(np.eye(6)), np.ones(2, dtype=bool), 3) is None
    full = sp.csr_matrix(np.ones((6, 6)))
    assert _is_node_blocked(full.indptr, full.indices, 3)
    holed = sp.csr_matrix(np.ones((6, 6)) - np.eye(6)[::-1])  # one entry missing per row
    assert _submatrix_bsr(holed, np.ones(2, dtype=bool), 3) is None
    assert _submatrix_bsr(full, np.ones(3, dtype=bool), 3) is None  # mask of the wrong size


def test_cg_newton_systems_go_through_node_blocks(monkeypatch):
    import msslib.solvers as S

    prob = lattice_block(4, 4, 7)
    x0 = prob.x0()
    calls = []
    real = S._submatrix_bsr

    def spy(*a, **kw):
        out = real(*a, **kw)
        calls.append(None if out is None else out.format)
        return out

    monkeypatch.setattr(S, "_submatrix_bsr", spy)
    iterative = static_solve(prob, x0, linear_solver="cg", tol=1e-10)
    assert calls and set(calls) == {"bsr"}
    direct = static_solve(prob, x0, linear_solver="direct", tol=1e-10)
    assert len(calls) == iterative.total_iterations  # the direct solver keeps the CSR block
    u = direct.x - x0
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())


@pytest.mark.parametrize("shape", [(16, 4, 4), (12, 12, 12), (30, 2, 2), (8, 8, 3)])
def test_band_width_bound_never_exceeds_the_bandwidth_found(shape, monkeypatch):
    """The breadth-first bound that skips the band orderings is a lower bound of the bandwidth
    of every ordering, so it never rejects a body the banded Cholesky would take."""
    from msslib.solvers import (BAND_AUTO_COST, _band_plan, _band_surely_wide, _bsr_entry,
                                _eccentricity, _solver_context, _submatrix)

    nx, ny, nz = shape
    model = clamped_golec_block(nx, ny, nz)
    K = model.stiffness(model.x0)
    ctx = _solver_context(model, model.x0, model.free)
    entry = _bsr_entry(K, ctx["node_free"], 3)
    e = _eccentricity(entry["bptr"], entry["bind"])
    # 26-neighbour lattice: Chebyshev distance from the first free node (a corner of layer x = 1)
    assert e == max(nx - 1, ny, nz)
    A = _submatrix(K, model.free)
    import msslib.solvers as S

    monkeypatch.setattr(S, "BAND_COST_MAX", float("inf"))  # a plan whatever the bandwidth
    plan = _band_plan(sp.csr_matrix(A.toarray()), ctx)
    n = A.shape[0]
    assert plan["bw"] >= (n - 1) / (2.0 * e)
    cheap = n * (plan["bw"] + 1.0) ** 2 <= BAND_AUTO_COST
    assert not (cheap and _band_surely_wide(entry, 3))
    if shape == (12, 12, 12):
        assert _band_surely_wide(entry, 3)
    if shape in ((16, 4, 4), (30, 2, 2)):
        assert cheap and not _band_surely_wide(entry, 3)


def _lattice_system(n=8):
    from msslib import mesh as M
    from msslib.model import Model, golec_cube_springs
    from msslib.solvers import _rigid_body_modes, _solver_context, _submatrix_bsr

    mesh = M.hex_grid(0.01 * n, 0.01 * n, 0.01 * n, n, n, n)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    model = Model(mesh, golec_cube_springs(mesh, [(1e4, 0.3)], 1.0), fixed=fixed)
    x = model.x0 + 2e-4 * np.random.default_rng(7).standard_normal(model.n_dof)
    ctx = _solver_context(model, x, model.free)
    A = _submatrix_bsr(model.stiffness(x), ctx["node_free"], 3)
    return A, _rigid_body_modes(ctx["coords"], 3), ctx


def test_block_jacobi_radius_is_the_largest_eigenvalue():
    from scipy.linalg import eigh

    from msslib.solvers import _block_diag_inverse, _block_jacobi_radius

    A, _, _ = _lattice_system(5)
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    D = sp.block_diag(list(np.linalg.inv(dinv))).toarray()
    lam = eigh(A.toarray(), D, eigvals_only=True)[-1]
    rho = _block_jacobi_radius(A, dinv)
    assert 0.97 * lam <= rho <= lam * (1 + 1e-10)  # a Ritz value: from below, close


def test_finest_level_prolongator_is_the_jacobi_smoothed_tentative_one():
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.strength import symmetric_strength_of_connection

    from msslib.solvers import _SA_OPTIONS, _block_diag_inverse, _block_jacobi_radius, _sa_solver

    A, B, _ = _lattice_system(8)
    ml = _sa_solver(A, B, 3)
    assert ml is not None and len(ml.levels) >= 2
    T, _ = fit_candidates(standard_aggregation(symmetric_strength_of_connection(A, 0.0))[0], B)
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    Dinv = sp.block_diag(list(dinv)).toarray()
    omega = _SA_OPTIONS["smooth"][1]["omega"]
    P_ref = T.toarray() - omega / _block_jacobi_radius(A, dinv) * Dinv @ A.toarray() @ T.toarray()
    np.testing.assert_allclose(ml.levels[0].P.toarray(), P_ref, rtol=0, atol=1e-12 * np.abs(P_ref).max())
    A_c = ml.levels[1].A.toarray()
    np.testing.assert_allclose(A_c, P_ref.T @ A.toarray() @ P_ref, rtol=0, atol=1e-10 * np.abs(A_c).max())


def test_own_finest_level_preconditions_as_well_as_pyamg():
    import pyamg

    from msslib.solvers import _SA_OPTIONS, _pcg, _sa_solver

    A, B, _ = _lattice_system(9)
    b = np.random.default_rng(8).standard_normal(A.shape[0])
    its = {}
    for name, ml in (("own", _sa_solver(A, B, 3)), ("pyamg", pyamg.smoothed_aggregation_solver(A, B=B, **_SA_OPTIONS))):
        x, info, its[name] = _pcg(A, b, ml.aspreconditioner(cycle="V"), 1e-10, 500)
        assert info == 0
        assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001
    assert its["own"] <= its["pyamg"] + 1


@pytest.mark.parametrize("d", [3, 6])
def test_compiled_block_gauss_seidel_sweeps_equal_pyamg(d):
    from pyamg.relaxation.relaxation import block_gauss_seidel

    from msslib.solvers import _block_diag_inverse, _BlockGaussSeidel

    rng = np.random.default_rng(d)
    nb = 40
    pattern = sp.random(nb, nb, 0.15, random_state=d, format="csr") + sp.eye(nb)
    pattern = (pattern + pattern.T).tocsr()
    M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
    M = M + M.T + 4 * d * np.eye(nb * d)  # symmetric, blocks on a symmetric node pattern
    A = sp.bsr_matrix(M, blocksize=(d, d))
    A.sort_indices()
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    np.testing.assert_allclose(dinv[3], np.linalg.inv(M[3 * d:4 * d, 3 * d:4 * d]), rtol=1e-12, atol=1e-14)
    b = rng.standard_normal(nb * d)
    for forward, sweep in ((True, "forward"), (False, "backward")):
        x0 = rng.standard_normal(nb * d)
        x_ref, x = x0.copy(), x0.copy()
        block_gauss_seidel(A, x_ref, b, iterations=1, sweep=sweep, blocksize=d, Dinv=dinv)
        _BlockGaussSeidel(dinv, forward)(A, x, b)
        np.testing.assert_allclose(x, x_ref, rtol=1e-12, atol=1e-12 * np.abs(x_ref).max())
    with pytest.raises(TypeError):
        _BlockGaussSeidel(dinv, True)(A, np.zeros((nb * d, 1)), b)


def _count_tangent_fills(monkeypatch, model):
    """Count the calls of ``model.stiffness_blocks`` ("blocks") and ``model.stiffness``
    ("full"); returns the live dict of counts."""
    calls = {"blocks": 0, "full": 0}

    def count(name, fn):
        def wrapped(*a, **kw):
            calls[name] += 1
            return fn(*a, **kw)
        return wrapped

    monkeypatch.setattr(model, "stiffness_blocks", count("blocks", model.stiffness_blocks))
    monkeypatch.setattr(model, "stiffness", count("full", model.stiffness))
    return calls


def test_model_newton_systems_filled_as_free_node_blocks(monkeypatch):
    """With CG, a Model's Newton systems come from ``stiffness_blocks`` (no full tangent is
    formed); the solution equals the direct solve's."""
    from msslib import mesh as M
    from msslib import terms as T
    from msslib.model import Model, golec_cube_springs

    mesh = M.hex_grid(0.05, 0.02, 0.02, 5, 2, 2)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    model = Model(mesh, golec_cube_springs(mesh, [(1e3, 0.3)], 1.0) + [T.Gravity(masses, [0, 0, -9.81])],
                  fixed=fixed)
    calls = _count_tangent_fills(monkeypatch, model)
    iterative = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert calls == {"blocks": iterative.total_iterations, "full": 0}
    direct = static_solve(model, model.x0, linear_solver="direct", tol=1e-10)
    assert calls["blocks"] == iterative.total_iterations and calls["full"] == direct.total_iterations
    u = direct.x - model.x0
    assert np.abs(u).max() > 1e-3
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())


def test_galerkin_product_equals_the_dense_one():
    import msslib.solvers as S

    A, B, _ = _lattice_system(8)
    ml = S._sa_solver(A, B, 3)
    P = ml.levels[0].P
    A_c = S._galerkin(A, P)
    assert A_c.format == "bsr" and A_c.blocksize == (B.shape[1], B.shape[1])
    ref = (P.T @ A @ P).toarray()
    np.testing.assert_allclose(A_c.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    # generic block sizes (the unrolled loops are for 3 x d blocks of A)
    rng = np.random.default_rng(5)
    for d, m in ((2, 3), (6, 6), (3, 2)):
        nb, nc = 25, 7
        pattern = sp.random(nb, nb, 0.2, random_state=d + m, format="csr") + sp.eye(nb)
        pattern = (pattern + pattern.T).tocsr()
        M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
        M = M + M.T
        Pd = sp.kron(sp.random(nb, nc, 0.3, random_state=m, format="csr"), np.ones((d, m))).toarray()
        Pd *= rng.standard_normal(Pd.shape)
        C = S._galerkin(sp.bsr_matrix(M, blocksize=(d, d)), sp.bsr_matrix(Pd, blocksize=(d, m)))
        ref = Pd.T @ M @ Pd
        np.testing.assert_allclose(C.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_compiled_v_cycle_equals_pyamg_cycle():
    """The compiled V-cycle (forward sweep from zero on the lower blocks, residual on the others
    fused with the restriction, prolongation, backward sweep) is pyamg's V-cycle with the same
    smoothers, on a hierarchy with 3 x 3 and 6 x 6 block levels and on the own finest level."""
    import pyamg

    import msslib.solvers as S

    A, B, _ = _lattice_system(8)
    b = np.random.default_rng(3).standard_normal(A.shape[0])
    deep = S._compiled_smoothers(pyamg.smoothed_aggregation_solver(A, B=B, **dict(S._SA_OPTIONS, max_coarse=8)))
    assert len(deep.levels) >= 3 and deep.levels[1].A.blocksize == (6, 6)
    for ml in (deep, S._sa_solver(A, B, 3)):
        cycle = S._VCycle.build(ml, single=False)
        assert cycle is not None
        ref = ml.aspreconditioner(cycle="V") @ b
        for _ in range(2):  # work vectors are reused: a second application gives the same
            z = cycle @ b
            np.testing.assert_allclose(z, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
        # a symmetric operator (CG needs it)
        c = np.random.default_rng(4).standard_normal(A.shape[0])
        assert abs(c @ (cycle @ b) - b @ (cycle @ c)) <= 1e-10 * abs(c @ (cycle @ b))
    # single precision on the finest level: the exact V-cycle of the rounded matrix and
    # prolongator; after update(), of the rounded new matrix
    ml = S._sa_solver(A, B, 3)
    cycle = S._VCycle.build(ml, single=True)
    assert cycle.levels[0]["a_data"].dtype == np.float32 and cycle.levels[0]["p_data"].dtype == np.float32
    v = np.random.default_rng(6).standard_normal(A.shape[0])
    np.testing.assert_allclose(ml.levels[0].R @ v, ml.levels[0].P.T @ v, rtol=1e-14, atol=0)  # lazy R
    A2 = A.copy()
    A2.data *= 1.0 + 0.1 * np.random.default_rng(5).random(A2.data.shape[0])[:, None, None]
    approx = cycle @ b
    assert cycle.update(A2)
    updated = cycle @ b
    assert not cycle.update(A.tocsr()[:30, :30].tobsr(blocksize=(3, 3)))  # another pattern: ignored
    assert not cycle.update(sp.bsr_matrix(sp.identity(A.shape[0]), blocksize=(3, 3)))  # same shape
    for mat, z in ((A, approx), (A2, updated)):
        lvl = ml.levels[0]
        keep = lvl.A, lvl.P, lvl.R
        lvl.A = sp.bsr_matrix((mat.data.astype(np.float32).astype(float), mat.indices, mat.indptr), shape=mat.shape)
        lvl.P = sp.bsr_matrix((keep[1].data.astype(np.float32).astype(float), keep[1].indices, keep[1].indptr),
                              shape=keep[1].shape)
        lvl.R = lvl.P.T.tobsr()
        ref = ml.aspreconditioner(cycle="V") @ b
        lvl.A, lvl.P, lvl.R = keep
        np.testing.assert_allclose(z, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert np.abs(approx - S._VCycle.build(ml, single=False) @ b).max() <= 1e-5 * np.abs(approx).max()
    # the preconditioner that CG gets is the compiled cycle
    ctx = {"dim": 3, "coords": _lattice_system(8)[2]["coords"]}
    assert isinstance(S._amg_preconditioner(A, ctx), S._VCycle)
    # a level without the compiled smoother: no compiled cycle (pyamg's is used)
    plain = pyamg.smoothed_aggregation_solver(A, B=B, **S._SA_OPTIONS)
    assert S._VCycle.build(plain) is None


def _random_spd_bsr(nb, d, rng):
    """A random symmetric positive definite BSR matrix of nb x nb blocks of size d (sparse block
    pattern, sorted indices, diagonally dominant) and its dense array."""
    pattern = sp.random(nb, nb, 0.2, random_state=d, format="csr") + sp.eye(nb)
    pattern = (pattern + pattern.T).tocsr()
    M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
    M = M + M.T + 4 * d * np.eye(nb * d)
    A = sp.bsr_matrix(M, blocksize=(d, d))
    A.sort_indices()
    return A, M


@pytest.mark.parametrize("d,m", [(3, 3), (3, 6), (6, 6), (2, 2)])
def test_compiled_bsr_kernels_equal_dense_products(d, m):
    import msslib.solvers as S

    rng = np.random.default_rng(d * 10 + m)
    nb, nc = 30, 12
    A, M = _random_spd_bsr(nb, d, rng)
    Pd = sp.kron(sp.random(nb, nc, 0.3, random_state=m, format="csr"), np.ones((d, m))).toarray()
    Pd *= rng.standard_normal(Pd.shape)
    P = sp.bsr_matrix(Pd, blocksize=(d, m))
    v = rng.standard_normal(nb * d)
    np.testing.assert_allclose(S._matvec_of(A)(v), M @ v, rtol=0, atol=1e-12 * np.abs(M @ v).max())
    vc = rng.standard_normal(nc * m)
    np.testing.assert_allclose(S._matvec_of(P)(vc), Pd @ vc, rtol=0, atol=1e-12 * np.abs(Pd @ vc).max())
    dinv = S._block_diag_inverse(A.indptr, A.indices, A.data)
    L = np.tril(M, -1) * (np.abs(np.subtract.outer(np.arange(nb * d) // d, np.arange(nb * d) // d)) > 0)
    D = M - L - (np.triu(M, 1) * (np.subtract.outer(np.arange(nb * d) // d, np.arange(nb * d) // d) < 0))
    kernels = ((S._gs3_forward_from_zero, S._residual3_restrict),) if d == 3 else ()
    for fwd, res in kernels + ((S._gs_forward_from_zero, S._residual_restrict),):
        x, s, bc = np.empty(nb * d), np.empty(nb * d), np.zeros(nc * m)
        fwd(A.indptr, A.indices, A.data, dinv, v, x, s)
        x_ref = np.linalg.solve(D + L, v)  # block forward substitution
        np.testing.assert_allclose(x, x_ref, rtol=0, atol=1e-10 * np.abs(x_ref).max())
        res(A.indptr, A.indices, A.data, x, s, P.indptr, P.indices, P.data, bc)
        ref = Pd.T @ (v - M @ x)
        np.testing.assert_allclose(bc, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    x0 = rng.standard_normal(nb * d)
    x_ref = x0.copy()
    S._block_gauss_seidel_sweep(A.indptr, A.indices, A.data, dinv, x_ref, v, False)
    if d == 3:
        x = x0.copy()
        S._gs3_backward(A.indptr, A.indices, A.data, dinv, x, v)
        np.testing.assert_allclose(x, x_ref, rtol=0, atol=1e-12 * np.abs(x_ref).max())
    x = x0.copy()
    S._prolong_add(P.indptr, P.indices, P.data, vc, x)
    np.testing.assert_allclose(x, x0 + Pd @ vc, rtol=0, atol=1e-12 * np.abs(Pd @ vc).max())


def _gravity_cube(n, E=1e4):
    from msslib import mesh as M
    from msslib import terms as T
    from msslib.model import Model, golec_cube_springs

    mesh = M.hex_grid(0.1, 0.1, 0.1, n, n, n)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return Model(mesh, golec_cube_springs(mesh, [(E, 0.25)], 1.0) + [T.Gravity(masses, [0, 0, -9.81])],
                 fixed=fixed, masses=masses)


def test_repeated_solves_of_a_problem_keep_the_amg_hierarchy(monkeypatch):
    """A second solve of the same model starts with the hierarchy and matrix left by the first
    (no new set-up) and gives the same result; another start, another linear solver or a model
    whose values changed still solve correctly; the state goes with the model."""
    import gc

    import msslib.solvers as S

    builds = []
    original = S._preconditioner

    def counting(A, context=None):
        builds.append(A.shape)
        return original(A, context)

    monkeypatch.setattr(S, "_preconditioner", counting)
    model = _gravity_cube(6)
    direct = static_solve(model, model.x0, linear_solver="direct", tol=1e-10)  # the reference
    first = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 1 and first.cg_iterations > 0
    ctx = S._STATIC_CONTEXTS[model]
    K = ctx["K"]
    second = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 1  # kept: CG converged as fast with it
    assert S._STATIC_CONTEXTS[model] is ctx and ctx["K"] is K  # the matrix refilled in place
    assert second.cg_iterations == first.cg_iterations
    scale = np.abs(first.x - model.x0).max()
    np.testing.assert_allclose(second.x, first.x, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(second.x, direct.x, rtol=0, atol=1e-7 * scale)
    # another initial configuration: new context (rigid-body modes of other coordinates)
    x0 = model.x0 + 1e-4 * np.random.default_rng(1).standard_normal(model.n_dof) * model.free
    third = static_solve(model, x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 2
    np.testing.assert_allclose(third.x, direct.x, rtol=0, atol=1e-6 * scale)
    # a state left by a stiffer model's solve: still converges to the right answer
    soft, stiff = _gravity_cube(6, E=1e4), _gravity_cube(6, E=1e6)
    static_solve(stiff, stiff.x0, linear_solver="cg", tol=1e-10)
    S._STATIC_CONTEXTS[soft] = S._STATIC_CONTEXTS[stiff]  # as if the values had changed
    r = static_solve(soft, soft.x0, linear_solver="cg", tol=1e-10)
    np.testing.assert_allclose(r.x, direct.x, rtol=0, atol=1e-7 * scale)
    assert r.residuals[-1][-1] <= 1e-10 * r.force_scale
    # the state goes with the model
    n = len(S._STATIC_CONTEXTS)
    del model, soft, stiff
    gc.collect()
    assert len(S._STATIC_CONTEXTS) <= n - 2


def test_static_context_in_use_is_not_shared():
    import msslib.solvers as S

    model = _gravity_cube(3)
    free = np.asarray(model.free, dtype=bool)
    a = S._static_context(model, model.x0, free, "cg")
    b = S._static_context(model, model.x0, free, "cg")  # `a` is in use (another thread)
    assert b is not a and S._STATIC_CONTEXTS[model] is a
    S._release_context(a)
    S._release_context(b)
    c = S._static_context(model, model.x0, free, "cg")
    assert c is a
    S._release_context(c)
    assert S._static_context(model, model.x0, free, "direct") is not a
    assert S._static_context(model, model.x0, free, lambda K, b: b) is not a  # user solver: never kept


@pytest.mark.parametrize("d,m", [(3, 6), (2, 3)])
def test_smoothed_prolongator_equals_the_dense_formula(d, m):
    import msslib.solvers as S

    rng = np.random.default_rng(d + m)
    nb, nc = 30, 8
    A, M = _random_spd_bsr(nb, d, rng)
    agg = rng.integers(0, nc, nb)
    agg[:nc] = np.arange(nc)
    agg[5] = -1  # a node in no aggregate: an empty row of T
    Td = np.zeros((nb * d, nc * m))
    for i, a in enumerate(agg):
        if a >= 0:
            Td[i * d:(i + 1) * d, a * m:(a + 1) * m] = rng.standard_normal((d, m))
    T = sp.bsr_matrix(Td, blocksize=(d, m))
    dinv = S._block_diag_inverse(A.indptr, A.indices, A.data)
    p_ptr = np.empty(nb + 1, dtype=np.int64)
    args = (A.indptr, A.indices, A.data, dinv, T.indptr, T.indices, T.data, -0.3, nc, p_ptr)
    assert S._smoothed_prolongator(*args, np.empty(0, dtype=np.int64), np.empty((0, d, m)))
    p_ind, p_data = np.empty(p_ptr[-1], dtype=np.int64), np.empty((p_ptr[-1], d, m))
    assert S._smoothed_prolongator(*args, p_ind, p_data)
    P = sp.bsr_matrix((p_data, p_ind, p_ptr), shape=Td.shape)
    ref = Td - 0.3 * sp.block_diag(list(dinv)).toarray() @ M @ Td
    np.testing.assert_allclose(P.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert all(np.all(np.diff(p_ind[p_ptr[i]:p_ptr[i + 1]]) > 0) for i in range(nb))  # sorted rows


def test_mid_size_decision_from_the_node_blocks_forms_no_full_tangent(monkeypatch):
    """Between ITERATIVE_THRESHOLD and BAND_PLAN_MAX_DOFS, "auto" decides from the graph of the
    free node blocks when that shows the band too wide: no full tangent is formed, and the
    blocks filled for the decision are the first Newton matrix."""
    import msslib.solvers as S

    model = _gravity_cube(13)  # 7,644 free dofs: banded Cholesky surely too wide
    n = int(model.free.sum())
    assert S.ITERATIVE_THRESHOLD < n <= S.BAND_PLAN_MAX_DOFS
    calls = _count_tangent_fills(monkeypatch, model)
    r = static_solve(model, model.x0)
    assert r.cg_iterations > 0
    assert calls == {"blocks": r.total_iterations, "full": 0}
    monkeypatch.undo()  # the model's own fills again
    ref = static_solve(model, model.x0, linear_solver="direct")
    np.testing.assert_allclose(r.x, ref.x, rtol=0, atol=1e-7 * np.abs(ref.x - model.x0).max())


@pytest.mark.parametrize("d", [3, 2, 6])
def test_block_diagonal_and_its_inverse(d):
    import msslib.solvers as S

    rng = np.random.default_rng(d)
    nb = 12
    blocks = rng.standard_normal((nb, d, d))
    blocks = blocks @ blocks.transpose(0, 2, 1) + 0.1 * np.eye(d)  # SPD, some ill-conditioned
    blocks[4] *= 1e9
    M = sp.block_diag(list(blocks)).tolil()
    M[0, d * 3] = 1.0  # an off-diagonal block
    A = sp.bsr_matrix(M.tocsr(), blocksize=(d, d))
    A.sort_indices()
    dinv = S._block_diag_inverse(A.indptr, A.indices, A.data)
    ref = np.linalg.inv(blocks)
    for i in range(nb):
        np.testing.assert_allclose(dinv[i], ref[i], rtol=1e-9 * np.linalg.cond(blocks[i]) * 1e-3,
                                   atol=1e-12 * np.abs(ref[i]).max())
    np.testing.assert_array_equal(S._block_diag(A.indptr, A.indices, A.data), blocks)
    singular = blocks.copy()
    singular[2] = np.outer(np.arange(1.0, d + 1), np.arange(1.0, d + 1))  # rank one
    B = sp.bsr_matrix(sp.block_diag(list(singular)).tocsr(), blocksize=(d, d))
    with pytest.raises(np.linalg.LinAlgError):
        S._block_diag_inverse(B.indptr, B.indices, B.data)
    # a missing diagonal block: NaN inverse, zero block
    C = sp.bsr_matrix((blocks[:2], np.array([1, 0]), np.array([0, 1, 2])), shape=(2 * d, 2 * d))
    assert np.isnan(S._block_diag_inverse(C.indptr, C.indices, C.data)).all()
    assert not S._block_diag(C.indptr, C.indices, C.data).any()

"""The directional bound of the stability check (msslib.solvers.directional): never below the
exact top eigenvalue of M^-1 K (dense eigenvalues) on every 3D spring model, at rest, prestressed
with compressed springs, with unequal masses and with nodes fixed in one direction only; never
accepting a target below it; the 3x3 eigenvalue bound it takes per node never below LAPACK's and
at most 0.08 times the eigenvalues' deviation above it (2 times, at most 2e-6 of the eigenvalue, when
the matrix is that close to isotropic); and, on the benchmark's kind of network, a step at 0.9 of the limit decided in
two passes, with the check's cheap bound tighter than Gershgorin's."""

import numpy as np
import pytest

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.solvers import directional as D
from msslib.solvers import stability as ST

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


def _exact_lambda(model, x, free):
    K = model.stiffness(x).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    return float(np.linalg.eigvalsh(0.5 * d[:, None] * (K + K.T) * d[None, :]).max())


def _golec_lattice(n, size):
    """Golec's cubes at nu = 1/4 (his volume term vanishes: the springs alone), bottom fixed."""
    from msslib.models.golec import golec_cube_springs
    from msslib.system import Model
    from msslib.terms import Gravity

    mesh = M.hex_grid(size, size, size, n, n, n)
    springs = golec_cube_springs(mesh, [(1e6, 0.25)], 1.0)[0]
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return Model(mesh, [springs, Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed, masses=masses)


def _models():
    mat = msslib.Material(1e4, 0.25, density=1000.0)
    tet = M.tet_grid(0.04, 0.02, 0.02, 6, 3, 3)
    yield "lloyd_tetrahedron", msslib.build_model("lloyd_tetrahedron", tet, mat, fixed={"plane": ["x", 0.0]},
                                                  loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    yield "golec_cube springs", _golec_lattice(5, 0.05)


MODELS = list(_models())


def _cases(model):
    """(x, free): at rest; prestressed (some springs compressed); with the top nodes held in z
    only (a node with some free dofs) and the masses made unequal."""
    rng = np.random.default_rng(4)
    size = float(np.ptp(model.x0.reshape(-1, 3), axis=0).max())
    free = model.free.copy()
    yield model.x0, free
    yield model.x0 + 0.01 * size * rng.standard_normal(model.n_dof) * free, free
    partial = free.copy().reshape(-1, 3)
    top = model.x0.reshape(-1, 3)[:, 2] > model.x0.reshape(-1, 3)[:, 2].max() - 1e-12
    partial[top, 2] = False
    yield model.x0, partial.ravel()


@pytest.mark.parametrize("name,model", MODELS, ids=[n for n, _ in MODELS])
def test_the_bound_is_never_below_the_top_eigenvalue(name, model, monkeypatch):
    assert all(ST._spring_terms(m) is not None for _, m in MODELS)
    rng = np.random.default_rng(9)
    mass = model.mass.copy()
    for unequal in (False, True):
        if unequal:  # a node's three dofs keep one mass; nodes differ by up to 10x
            monkeypatch.setattr(model, "mass", mass * np.repeat(10.0 ** rng.uniform(-0.5, 0.5, model.n_nodes), 3),
                                raising=False)
        for x, free in _cases(model):
            exact = _exact_lambda(model, x, free)
            setup = D.directional_setup(model, x, free)
            first = float(setup[5].max())
            assert first >= exact * (1.0 - 1e-12)
            lam, passes = D.directional_bound(model, x, free, 2.0 * exact)
            assert lam is not None and exact * (1.0 - 1e-12) <= lam <= 2.0 * exact
            # run to its end: the tightest bound it reaches is still above, and close
            tight = [f for f in (1.3, 1.2, 1.15, 1.1) if D.directional_bound(model, x, free, f * exact)[0] is not None]
            assert tight, (name, unequal)
            assert D.directional_bound(model, x, free, 0.999 * exact)[0] is None


def test_the_check_accepts_through_it_only_steps_within_the_exact_limit():
    model = _golec_lattice(6, 0.06)
    free = model.free.copy()
    assert free.sum() > 400  # below, the check solves the dense problem
    exact = 2.0 / np.sqrt(_exact_lambda(model, model.x0, free))
    for f in (0.85, 0.9, 0.95):
        model._spectrum_cache = {}
        info = S.check_time_step(model, model.x0, f * exact)
        assert info["stability_estimate"].startswith("bound, directional (")
        assert f * exact <= info["stability_limit"] <= exact * (1.0 + 1e-12)
        assert info["omega_max"] >= 2.0 / exact * (1.0 - 1e-12)


def test_a_coincident_pair_of_nodes_leaves_the_decision_to_the_other_stages():
    name, model = MODELS[0]
    x = model.x0.copy().reshape(-1, 3)
    a, b = model.terms[0].conn[0]
    x[b] = x[a]
    assert D.directional_setup(model, x.ravel(), model.free.copy()) is None
    assert D.directional_bound(model, x.ravel(), model.free.copy(), 1e30) == (None, 0)


def test_two_passes_decide_a_step_at_09_of_the_limit_on_a_lattice_and_the_cheap_bound_beats_gershgorin():
    model = _golec_lattice(8, 0.08)
    free = model.free.copy()
    exact = _exact_lambda(model, model.x0, free)
    lam, passes = D.directional_bound(model, model.x0, free, exact / 0.81)
    assert lam is not None and passes <= 2 and lam >= exact
    gershgorin, _ = S.omega_max_bound(model, model.x0)
    cheap = np.sqrt(float(D.directional_setup(model, model.x0, free)[5].max()))
    assert np.sqrt(exact) <= cheap < 0.95 * gershgorin  # 0.90 here (omega; 0.81 in omega^2)


_ENTRY = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(st.lists(_ENTRY, min_size=6, max_size=6), st.sampled_from([0.0, 1e-12, 1e-6, 1.0]),
       st.floats(-1e6, 1e6, allow_nan=False))
def test_the_3x3_bound_is_never_below_lapack_and_close_to_it(entries, spread, shift):
    """Any symmetric matrix ``shift I + spread B``: nearly isotropic (tiny spread against the
    shift), with repeated eigenvalues or not, definite or not."""
    b00, b11, b22, b01, b02, b12 = entries
    A = shift * np.eye(3) + spread * np.array([[b00, b01, b02], [b01, b11, b12], [b02, b12, b22]])
    _check_top(A)


def _check_top(A):
    exact = np.linalg.eigvalsh(A)
    top = D._sym3_top(A[0, 0], A[1, 1], A[2, 2], A[0, 1], A[0, 2], A[1, 2])
    scale = max(float(np.abs(exact).max()), 1e-300)
    q = float(exact.mean())
    p = float(np.sqrt(np.sum((exact - q) ** 2) / 6.0))
    excess = 2.0 * p if p <= 1e-6 * abs(q) else 0.0796 * p  # nearly isotropic: q + 2 p, within 2e-6 |q|
    assert exact[-1] - 1e-13 * scale <= top <= exact[-1] + excess + 1e-9 * scale, (A, top, exact)


def test_the_3x3_bound_on_its_hard_cases():
    for A in (np.diag([2.0, 2.0, 1.0]), np.diag([4.8e7, 4.8e7, 4.8e7]) + 1e-9 * np.ones((3, 3)),
              np.zeros((3, 3)), np.outer([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]), -np.eye(3), np.diag([1.0, 0.0, 0.0])):
        _check_top(A)

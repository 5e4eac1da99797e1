"""The stability check's compiled runs on springs stored by lower node (the fused step kernel's
layout), in the given numbering and renumbered for locality: the certified Lanczos run gives the
same steps and bound as the reference run with the matrix-free product, whose product is the mass-scaled stiffness, and its Ritz value from Sturm
bisection is never below LAPACK's (tests/test_stability_certificate.py checks that the
Collatz-Wielandt product in the same layout is at least the absolute stiffness)."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.linalg import eigvalsh_tridiagonal

import msslib
from msslib import mesh as M
from msslib.solvers import certificate as C
from msslib.solvers import stability as ST


def _spring_models():
    """3D models of springs and dead loads only (over 400 free dofs), at rest and prestressed."""
    from msslib.models.golec import golec_cube_springs
    from msslib.system import Model
    from msslib.terms import Gravity

    tet = msslib.build_model("lloyd_tetrahedron", M.cylinder_mesh(0.02, 0.06, 0.008),
                             msslib.Material(1e4, 0.3, density=1000.0), fixed={"plane": ["z", 0.0]},
                             loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    mesh = M.hex_grid(0.06, 0.06, 0.06, 6, 6, 6)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    cubes = Model(mesh, [golec_cube_springs(mesh, [(1e6, 0.25)], 1.0)[0], Gravity(masses, [0.0, 0.0, -9.81])],
                  fixed=fixed, masses=masses)
    for name, model in (("lloyd_tetrahedron", tet), ("golec_springs", cubes)):
        size = float(np.ptp(model.x0.reshape(-1, 3), axis=0).max())
        rng = np.random.default_rng(3)
        yield name + "_rest", model, model.x0
        yield name + "_prestressed", model, model.x0 + 0.002 * size * rng.standard_normal(model.n_dof) * model.free


CASES = list(_spring_models())


def _exact(model, x):
    free = model.free
    K = model.stiffness(x).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    return float(np.sqrt(np.linalg.eigvalsh(0.5 * d[:, None] * (K + K.T) * d[None, :]).max()))


@pytest.fixture(params=["given numbering", "renumbered"])
def numbering(request, monkeypatch):
    """The springs' numbering, or a reverse Cuthill-McKee renumbering forced on a small network."""
    if request.param == "renumbered":
        monkeypatch.setattr(C, "_RENUMBER_MIN_NODES", 0)
        monkeypatch.setattr(C, "_RENUMBER_GAIN", 0.0)
    return request.param


@pytest.mark.parametrize("name,model,x", CASES, ids=[c[0] for c in CASES])
def test_the_compiled_certified_run_is_the_reference_run(name, model, x, numbering):
    free = model.free.copy()
    assert int(free.sum()) > 400
    isq = ST._free_isq(model, free)
    springs = C._spring_terms(model)
    assert springs is not None
    rows = C.spring_rows(x, springs, isq)
    assert (rows[5] is None) == (numbering == "given numbering")
    matvec, n, shift = ST._scaled_operator(model, x, 1.0, free)
    assert rows[3] == pytest.approx(shift, rel=1e-12, abs=0.0)
    if name.endswith("_rest"):
        assert rows[3] == 0.0
    exact = _exact(model, x)
    for factor, seed in ((1 / 0.9, 11), (1 / 0.95, 4), (1 / 0.99, 5), (0.99, 7)):
        fast = C.certified_springs(rows, factor * exact, seed)
        ref = C.certified_omega_max(matvec, n, shift, factor * exact, seed)
        assert fast[1] == ref[1]  # the same steps
        if ref[0] is None:
            assert fast[0] is None
        else:
            assert fast[0] == pytest.approx(ref[0], rel=1e-11)
            assert exact * (1 - 1e-12) <= fast[0] <= factor * exact
    assert C.certified_springs(rows, 0.99 * exact, 7)[0] is None  # below the exact value: never


@pytest.mark.parametrize("name,model,x", CASES, ids=[c[0] for c in CASES])
def test_the_row_product_is_the_scaled_stiffness(name, model, x, numbering):
    free = model.free.copy()
    isq = ST._free_isq(model, free)
    rowptr, ib, coef, _, isq_r, order = C.spring_rows(x, C._spring_terms(model), isq)
    A = (sp.diags(isq) @ sp.csr_matrix(model.stiffness(x)) @ sp.diags(isq)).toarray()
    A = 0.5 * (A + A.T)
    R = np.zeros((model.n_nodes, 6))
    w = np.empty(model.n_dof)
    matvec = ST._scaled_operator(model, x, 1.0, free)[0]
    for q in np.random.default_rng(1).standard_normal((3, model.n_dof)):
        dot = C._row_product(R, rowptr, ib, coef, isq_r, C._internal(q, order), 0.5, w)
        want = A @ q + 0.5 * q
        assert np.abs(w - C._internal(want, order)).max() <= 1e-12 * np.abs(want).max()
        assert dot == pytest.approx(q @ want, rel=1e-11)
        assert np.abs(matvec(q) + 0.5 * q - want).max() <= 1e-12 * np.abs(want).max()


def test_the_ritz_value_of_the_bisection_is_never_below_lapacks():
    rng = np.random.default_rng(0)
    for k in (1, 2, 3, 10, 40, 64):
        for _ in range(20):
            a = rng.standard_normal(k) * 10.0 ** rng.uniform(-3, 6)
            b = np.abs(rng.standard_normal(k)) * np.abs(a).max()
            top = C._top_ritz(a, b, k)
            want = float(eigvalsh_tridiagonal(a, b[: k - 1])[-1]) if k > 1 else a[0]
            assert want <= top <= want + 2e-13 * max(abs(want), np.abs(a).max() + 2 * b[: k - 1].max(initial=0))


@pytest.mark.parametrize("name,model,x", CASES, ids=[c[0] for c in CASES])
def test_the_collatz_wielandt_bound_does_not_depend_on_the_numbering(name, model, x, monkeypatch):
    free = model.free.copy()
    exact = _exact(model, x)
    runs = []
    for renumber in (False, True):
        if renumber:
            monkeypatch.setattr(C, "_RENUMBER_MIN_NODES", 0)
            monkeypatch.setattr(C, "_RENUMBER_GAIN", 0.0)
        assert (C._row_layout(C._spring_terms(model), model.n_nodes)[5] is not None) == renumber
        runs.append([C.collatz_wielandt_bound(model, x, free, (exact / f) ** 2) for f in (0.85, 0.9, 0.95)])
    for (lam, k), (lam_r, k_r) in zip(*runs):
        assert k == k_r and (lam is None) == (lam_r is None)
        assert lam is None or (lam_r == pytest.approx(lam, rel=1e-12) and lam >= exact**2)

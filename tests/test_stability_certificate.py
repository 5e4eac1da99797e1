"""The certified short Lanczos run of the stability check: the step it accepts is never above the
exact limit (dense eigenvalues) on every mass-spring model of the registry, on each of its cells,
with springs run without a matrix and other terms assembled, at rest and prestressed; a step over
the limit is refused; steps at 0.99 of the limit it certifies stay bounded where steps just over
the exact limit blow up."""

import numpy as np
import pytest
import scipy.sparse as sp

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.stepping import integrate
from msslib.errors import DivergenceError, StabilityError
from msslib.solvers import stability as ST


def _exact_omega(model, x):
    free = model.free
    K = model.stiffness(x).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    return float(np.sqrt(np.linalg.eigvalsh(0.5 * (d[:, None] * (K + K.T) * d[None, :])).max()))


def _models():
    """Over 400 free dofs each (below, the check solves the dense problem exactly)."""
    mat = msslib.Material(1e4, 0.3, density=1000.0)
    tet = M.cylinder_mesh(0.02, 0.06, 0.008)
    hexm = M.hex_grid(0.04, 0.02, 0.02, 8, 4, 4)
    grav = {"type": "gravity", "g": [0, 0, -9.81]}
    for name, mesh, axis in (("lloyd_tetrahedron", tet, "z"), ("kikuuwe_tetrahedron", tet, "z"),
                             ("golec_cube", hexm, "x"), ("baudet_cube", hexm, "x")):
        yield name, msslib.build_model(name, mesh, mat, fixed={"plane": [axis, 0.0]}, loads=grav).model
    yield "lloyd_triangle", msslib.build_model("lloyd_triangle", M.triangle_grid_right(0.04, 0.02, 24, 12), mat,
                                               fixed={"plane": ["x", 0.0]}, thickness=0.001).model


MODELS = list(_models())


def _states(model):
    rng = np.random.default_rng(5)
    size = float(np.ptp(model.x0.reshape(-1, model.dim), axis=0).max())
    # at rest, and prestressed (some springs compressed: the shift is needed)
    return model.x0, model.x0 + 0.002 * size * rng.standard_normal(model.n_dof) * model.free


@pytest.mark.parametrize("name,model", MODELS, ids=[n for n, _ in MODELS])
def test_a_certified_step_is_never_above_the_exact_limit(name, model):
    assert int(model.free.sum()) > 400
    for x in _states(model):
        exact = _exact_omega(model, x)
        limit = 2.0 / exact
        model._spectrum_cache = {}
        info = S.check_time_step(model, x, 0.9 * limit)
        stages = ("certified (", "bound, Collatz-Wielandt (", "bound, directional (")
        assert info["stability_estimate"].startswith(stages), info
        assert info["omega_max"] >= exact * (1.0 - 1e-12)  # an upper bound of the exact value
        assert 0.9 * limit <= info["stability_limit"] <= limit * (1.0 + 1e-12)
        with pytest.raises(StabilityError):  # over the limit: neither bound can accept it
            S.check_time_step(model, x, 1.02 * limit)
        # the certificate itself, whichever stage accepted the step above
        matvec, n, shift = ST._scaled_operator(model, x, 1.0, model.free.copy())
        omega, steps = ST.certified_omega_max(matvec, n, shift, exact / 0.9, 11)
        assert omega is not None and exact * (1.0 - 1e-12) <= omega <= exact / 0.9 and steps <= 64
        # a target below the exact value is never certified
        assert ST.certified_omega_max(matvec, n, shift, 0.99 * exact, 7)[0] is None


@pytest.mark.parametrize("name,model", MODELS, ids=[n for n, _ in MODELS])
def test_the_operator_is_the_scaled_stiffness_and_its_shift_makes_it_semidefinite(name, model):
    isq = np.where(model.free, 1.0 / np.sqrt(model.mass), 0.0)
    for x in _states(model):
        matvec, n, shift = ST._scaled_operator(model, x, 1.0, model.free.copy())
        A = (sp.diags(isq) @ sp.csr_matrix(model.stiffness(x)) @ sp.diags(isq)).toarray()
        A = 0.5 * (A + A.T)
        V = np.random.default_rng(1).standard_normal((n, 3))
        got = np.column_stack([matvec(v) for v in V.T])
        assert np.abs(got - A @ V).max() <= 1e-12 * np.abs(A @ V).max()
        lam = np.linalg.eigvalsh(A)
        assert lam.min() + shift >= -1e-9 * lam.max()
        if x is model.x0 and name == "lloyd_tetrahedron":
            assert shift == 0.0  # springs at rest: semidefinite as they are


@pytest.mark.parametrize("name", ["lloyd_tetrahedron", "lsq_tetrahedron"])
def test_collatz_wielandt_bound_is_never_below_the_top_eigenvalue(name):
    """The deterministic bound of 3D spring models: its matrix B is at least |D K D| entrywise
    (built column by column), and the bound it accepts is never below the exact top eigenvalue,
    at rest and prestressed (compressed springs), while it cannot go below rho(|D K D|)."""
    mesh = M.tet_grid(0.04, 0.02, 0.02, 8, 4, 4)
    model = msslib.build_model(name, mesh, msslib.Material(1e4, 0.25, density=1000.0),
                               fixed={"plane": ["x", 0.0]}).model
    free = model.free.copy()
    isq = np.where(free, 1.0 / np.sqrt(model.mass), 0.0)
    for x in _states(model):
        exact = _exact_omega(model, x) ** 2
        A = np.abs((sp.diags(isq) @ sp.csr_matrix(model.stiffness(x)) @ sp.diags(isq)).toarray())
        rho = float(np.abs(np.linalg.eigvals(A[np.ix_(free, free)])).max())
        lam, products = ST.collatz_wielandt_bound(model, x, free, 1.3 * rho)
        assert lam is not None and rho * (1.0 - 1e-12) <= lam <= 1.3 * rho and lam >= exact
        assert ST.collatz_wielandt_bound(model, x, free, 0.999 * rho)[0] is None
        # B column by column, from the same kernels
        springs = ST._spring_terms(model)
        rowptr, ib, conn, k, L0, order = ST._row_layout(springs, model.n_nodes)
        assert order is None  # a small network keeps its numbering
        diag = np.zeros((model.n_nodes, 3, 3))
        coef = np.empty((len(conn), 5))
        assert ST._spring_abs_prep(np.ravel(x), conn, k, L0, isq, coef, diag)
        R = np.zeros((model.n_nodes, 6))
        cols = []
        for j in range(model.n_dof):
            e = np.zeros(model.n_dof)
            e[j] = 1.0
            out = np.zeros(model.n_dof)
            ST._abs_row_product(R, rowptr, ib, coef, isq, np.abs(diag), e, out)
            cols.append(out)
        B = np.column_stack(cols)
        assert np.all(B >= A - 1e-12 * A.max())


def test_steps_at_099_of_the_certified_limit_stay_bounded_and_over_the_exact_limit_blow_up():
    model = dict(MODELS)["lloyd_tetrahedron"]
    x0 = model.x0
    exact = 2.0 / _exact_omega(model, x0)
    model._spectrum_cache = {}
    info = S.check_time_step(model, x0, 0.96 * exact)
    assert info["stability_estimate"].startswith(("certified (", "bound, directional ("))
    accepted = info["stability_limit"]
    assert 0.96 * exact <= accepted <= exact
    rng = np.random.default_rng(2)
    v0 = 1e-3 * rng.standard_normal(model.n_dof) * model.free  # every mode excited

    def amplitude(dt, n):
        out = integrate(model, x0, v0, dt=dt, t_end=n * dt, damping=0.0, allow_unstable=True, save_every=n)
        return float(np.abs(out.x_final - x0).max())

    n = 3000
    bounded = amplitude(0.99 * accepted, n)
    assert bounded < 1e-3 * n * 0.99 * accepted * 10  # a few times what the start velocity travels
    with pytest.raises(DivergenceError):
        amplitude(1.02 * exact, n)


def _registry_cases():
    from msslib import models

    return [(name, cell) for name, spec in models.registry().items() if not name.startswith("fem_")
            for cell in spec.cells]


_GRIDS = {"triangle": lambda: M.triangle_grid_right(0.04, 0.02, 24, 12),
          "quad": lambda: M.quad_grid(0.04, 0.02, 24, 12),
          "tetra": lambda: M.tet_grid(0.04, 0.02, 0.02, 8, 4, 4),
          "hexahedron": lambda: M.hex_grid(0.04, 0.02, 0.02, 8, 4, 4),
          "wedge": lambda: M.wedge_grid(0.04, 0.02, 0.02, 8, 4, 4)}


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("name,cell", _registry_cases())
def test_every_registry_model_a_step_accepted_at_09_is_within_the_exact_limit(name, cell):
    """Every mass-spring model of the registry on each of its cells (over 400 free dofs, at rest):
    the check at 0.9 of the exact limit (the bound or the certificate) reports an omega_max never
    below the exact one, and 1.02 of the exact limit is refused."""
    mesh = _GRIDS[cell]()
    extra = {"thickness": 0.001} if mesh.dim == 2 else {}
    model = msslib.build_model(name, mesh, msslib.Material(1e4, 0.25, density=1000.0), fixed={"plane": ["x", 0.0]},
                               **extra).model
    assert int(model.free.sum()) > 400
    exact = _exact_omega(model, model.x0)
    model._spectrum_cache = {}
    info = S.check_time_step(model, model.x0, 0.9 * 2.0 / exact)
    assert info["stability_estimate"].startswith(("bound", "certified ("))
    assert info["omega_max"] >= exact * (1.0 - 1e-12)
    with pytest.raises(StabilityError):
        S.check_time_step(model, model.x0, 1.02 * 2.0 / exact)

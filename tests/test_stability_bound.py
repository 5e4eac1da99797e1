"""The cheap stability bound (Gershgorin on M^-1/2 K M^-1/2) is safe on every model family, lets a
step within it run without Lanczos, and the Lanczos estimate is reused only for an unchanged model."""

import numpy as np
import pytest
import scipy.sparse as sp

import msslib
from msslib import mesh as M
from msslib import solvers as S
from msslib.errors import StabilityError
from msslib.terms.bounds import csr_abs_rows


def _exact_omega(model, x):
    free = model.free
    K = model.stiffness(x).toarray()[np.ix_(free, free)]
    d = 1.0 / np.sqrt(model.mass[free])
    return float(np.sqrt(np.linalg.eigvalsh(0.5 * (d[:, None] * (K + K.T) * d[None, :])).max()))


def _models():
    tet = M.cylinder_mesh(0.02, 0.06, 0.012)
    hexm = M.hex_grid(0.04, 0.01, 0.01, 4, 1, 1)
    tri = M.triangle_grid_right(0.04, 0.02, 4, 2)
    mat = msslib.Material(1e4, 0.3, density=1000.0)
    grav = {"type": "gravity", "g": [0, 0, -9.81]}
    yield "lloyd_tetrahedron", msslib.build_model("lloyd_tetrahedron", tet, mat, fixed={"plane": ["z", 0.0]},
                                                  loads=grav).model
    yield "golec_cube", msslib.build_model("golec_cube", hexm, mat, fixed={"plane": ["x", 0.0]}, loads=grav).model
    yield "baudet_cube", msslib.build_model("baudet_cube", hexm, mat, fixed={"plane": ["x", 0.0]}, loads=grav).model
    yield "lloyd_triangle", msslib.build_model("lloyd_triangle", tri, mat, fixed={"plane": ["x", 0.0]},
                                               thickness=0.001).model


@pytest.mark.parametrize("name,model", list(_models()), ids=lambda v: v if isinstance(v, str) else "")
def test_bound_is_never_below_the_top_eigenvalue(name, model):
    rng = np.random.default_rng(3)
    for x in (model.x0, model.x0 + 2e-3 * rng.standard_normal(model.n_dof) * model.free):
        exact = _exact_omega(model, x)
        bound, rows = S.omega_max_bound(model, x)
        assert bound >= exact * (1.0 - 1e-12), (name, bound, exact)
        assert bound <= 3.0 * exact  # and useful: within a small factor
        # the terms' own row sums bound those of the assembled matrix (triangle inequality)
        isq = np.where(model.free, 1.0 / np.sqrt(model.mass), 0.0)
        K = sp.csr_matrix(model.stiffness(x))
        assembled = np.zeros(model.n_dof)
        csr_abs_rows(K.indptr, K.indices.astype(np.int64), K.data, isq, assembled)
        assert np.all(rows >= assembled * (1.0 - 1e-12))


def test_a_step_within_the_bound_needs_no_lanczos_and_a_larger_one_is_decided_by_it():
    model = dict(_models())["lloyd_tetrahedron"]
    exact = 2.0 / _exact_omega(model, model.x0)
    gershgorin, _ = S.omega_max_bound(model, model.x0)
    small = 0.9 * 2.0 / gershgorin
    info = S.check_time_step(model, model.x0, small)
    assert info["stability_estimate"] == "bound"
    # on a spring model the cheap bound is the directional bound's first pass: still safe, and
    # here tighter than Gershgorin's
    bound = info["omega_max_bound"]
    assert 2.0 / exact * (1.0 - 1e-12) <= bound < gershgorin
    assert info["stability_limit"] == pytest.approx(2.0 / bound, rel=1e-12) and info["stability_limit"] <= exact
    assert S.check_time_step(model, model.x0, 0.99 * 2.0 / bound)["stability_estimate"] == "bound"
    model._spectrum_cache = {}
    info = S.check_time_step(model, model.x0, 0.95 * exact)
    assert info["stability_estimate"] == "lanczos"
    assert info["stability_limit"] == pytest.approx(exact, rel=1e-3)
    again = S.check_time_step(model, model.x0, 0.95 * exact)
    assert again["stability_estimate"] == "lanczos (reused)" and again["omega_max"] == info["omega_max"]
    with pytest.raises(StabilityError):
        S.check_time_step(model, model.x0, 1.05 * exact)


def test_the_kept_estimate_is_not_reused_for_another_state():
    model = dict(_models())["lloyd_tetrahedron"]
    exact = 2.0 / _exact_omega(model, model.x0)
    assert S.check_time_step(model, model.x0, 0.95 * exact)["stability_estimate"] == "lanczos"
    # prestretched by 5 % along z: the geometric stiffness changes the spectrum
    moved = model.x0.copy().reshape(-1, 3)
    moved[:, 2] *= 1.05
    moved = moved.ravel()
    info = S.check_time_step(model, moved, 0.5 * exact)
    assert info["stability_estimate"] in ("bound", "lanczos")
    info = S.check_time_step(model, moved, 0.95 * exact, allow_unstable=True)
    assert info["stability_estimate"] == "lanczos"
    assert info["omega_max"] == pytest.approx(_exact_omega(model, moved), rel=1e-3)

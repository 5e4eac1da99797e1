"""Golec's hybrid MSS below nu = 1/4 (kappa < 0), and why the beam variant without face diagonals
comes out closest to the same-mesh FEM at nu = 0.3 (experiments/golec/studies/poisson_range.py).
Every expected value is independent of the model: the target material, the continuum moduli of a
nu = 1/4 spring lattice, or FEM."""

import numpy as np
import pytest

from experiments.golec.studies.poisson_range import (
    E, L, N, VARIANTS, beam_q2, experiment_scene, min_eigenvalue, sample_terms, solve_mss, uniaxial)
from msslib.mesh import hex_grid
from msslib.metrics import displacement_error, mesh_volume, youngs_modulus_poisson
from msslib.models.golec import golec_cube
from msslib.results import mesh_from_result
from msslib.scene import run_scene


@pytest.fixture(scope="module")
def sample():
    return hex_grid(L, L, L, N, N, N)


def moduli(mesh, nu, variant, strain=1e-3):
    model, x, sigma = uniaxial(mesh, sample_terms(mesh, nu, *VARIANTS[variant]), strain)
    return youngs_modulus_poisson(mesh.points, x.reshape(-1, 3), sigma, axis=2)


@pytest.mark.parametrize("nu", [0.1, 0.2, 0.3, 0.4])
def test_kappa_is_lambda_minus_mu_and_negative_below_a_quarter(nu):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    kappa = golec_cube(E, nu=nu, a=0.01, A=1.0).kappa
    assert kappa == pytest.approx(lam - mu, rel=1e-12)
    assert (kappa < 0) == (nu < 0.25)


@pytest.mark.parametrize("nu", [0.1, 0.2])
def test_hybrid_lattice_has_the_target_moduli_with_negative_kappa(sample, nu):
    E_eff, nu_eff = moduli(sample, nu, "golec")
    assert E_eff == pytest.approx(E, rel=2e-3)
    assert nu_eff == pytest.approx(nu, abs=1e-3)


@pytest.mark.parametrize("nu", [0.1, 0.3])
def test_springs_only_lattice_is_the_quarter_lattice_with_shear_modulus_mu(sample, nu):
    """Without the correction the derived springs give nu = 1/4 and G = mu = E/(2(1+nu)), hence
    E' = 2 mu (1 + 1/4): stiffer than E below nu = 1/4, softer above (the beam's compensation)."""
    E_eff, nu_eff = moduli(sample, nu, "springs")
    assert nu_eff == pytest.approx(0.25, abs=1e-3)
    assert E_eff / E == pytest.approx(1.25 / (1 + nu), rel=2e-3)


def test_hybrid_sample_stays_stable_under_strong_compression_at_nu_0_1(sample):
    model, x, sigma = uniaxial(sample, sample_terms(sample, 0.1, *VARIANTS["golec"]), -0.3)
    assert sigma < 0
    assert min_eigenvalue(model, x) > 0


def test_compression_at_nu_0_1_keeps_the_fem_volume():
    """The reduced compression experiment (3^3 cubes clamped, 10 %) with nu = 0.1: the hybrid MSS is
    stable and its volume is the neo-Hookean FEM's (Q1 does not lock at nu = 0.1)."""
    ref = run_scene(experiment_scene("compression", "clamped", "fem", 0.1, True))
    v_ref = mesh_volume(mesh_from_result(ref), ref["displacement"].transpose("node", "axis").values)
    setup, model, x = solve_mss(experiment_scene("compression", "clamped", "golec", 0.1, True))
    v0 = mesh_volume(setup.mesh)
    v = mesh_volume(setup.mesh, (x - model.x0).reshape(-1, 3))
    assert v < 0.97 * v0  # nu = 0.1: the clamped cube loses volume
    assert v == pytest.approx(v_ref, rel=5e-3)
    assert min_eigenvalue(model, x) > 0


@pytest.mark.parametrize("nu", [0.1, 0.3])
def test_beam_accuracy_of_springs_only_depends_on_the_side_of_a_quarter(nu):
    """The reduced beam (10 x 2 x 2 cubes) against Q2 FEM on its mesh: springs only are less
    accurate than the hybrid MSS below 1/4 and more accurate above, with or without face diagonals."""
    u_ref = beam_q2(nu, True)
    err = {}
    for var in VARIANTS:
        _, model, x = solve_mss(experiment_scene("beam", "default", var, nu, True))
        err[var] = displacement_error((x - model.x0).reshape(-1, 3), u_ref).rel_mean
    assert np.isfinite(list(err.values())).all()
    if nu < 0.25:
        assert err["springs"] > err["golec"] and err["springs_no_face"] > err["golec_no_face"]
    else:
        assert err["springs"] < err["golec"] and err["springs_no_face"] < err["golec_no_face"]

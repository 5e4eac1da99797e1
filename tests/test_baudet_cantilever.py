"""The cantilever studies' own pieces (experiments/baudet/cantilever_common.py): the numeric lattice
tensor against the symbolic derivation, the cubic-elasticity solver against msslib's FEM and beam
theory, and the error statistics on fields with known errors."""

import numpy as np
import pytest

from experiments.baudet import cantilever_common as K


@pytest.mark.parametrize("nu", [0.1, 0.3, 0.45])
def test_lattice_tensor_is_the_derivation(nu):
    from derivations.elements import cube_baudet as cb
    from derivations.elasticity import E
    from derivations.elasticity import nu as snu

    Cl, lat = cb.assembled_lattice()
    sub = {E: 1000.0, snu: nu}
    expected = np.array(Cl.subs(sub).evalf(), dtype=float)
    np.testing.assert_allclose(K.lattice_tensor(1000.0, nu, a=0.1), expected, rtol=1e-12, atol=1e-9)
    m = K.lattice_moduli(1000.0, nu)
    assert m["E_axis"] == pytest.approx(float(lat["uniaxial E along an axis"].subs(sub)), rel=1e-12)
    assert m["nu_axis"] == pytest.approx(float(lat["nu_lattice"].subs(sub)), rel=1e-12)
    assert m["C44"] == pytest.approx(1000.0 / (2 * (1 + nu)), rel=1e-12)  # k_d gives the exact shear modulus


def test_lattice_is_isotropic_at_nu_one_quarter():
    m, iso = K.lattice_moduli(1000.0, 0.25), K.isotropic_moduli(1000.0, 0.25)
    for k in ("C11", "C12", "C44"):
        assert m[k] == pytest.approx(iso[k], rel=1e-12)
    assert m["E_axis"] == pytest.approx(1000.0, rel=1e-12)


def test_q1_isotropic_equals_msslib_fem():
    from msslib import mesh as M
    from msslib.fem import solve_linear

    size, n = (0.4, 0.1, 0.1), (6, 2, 3)
    mesh = M.hex_grid(*size, *n)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    b = (0.0, 1.0, -2.0)
    ref = solve_linear(mesh, 1000.0, 0.3, fixed=fixed, body_force=b).displacement
    sol = K.solve_cubic(K.isotropic_moduli(1000.0, 0.3), n, order=1, body_force=b, size=size)
    np.testing.assert_allclose(sol.displacement_at(mesh.points), ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_q2_slender_beam_matches_timoshenko():
    # nu = 0: no lateral constraint at the clamp, so the 3D solution is Timoshenko's (kappa = 5/6)
    L, T, H, E, q = 1.0, 0.1, 0.1, 1000.0, 1.0
    sol = K.solve_cubic(K.isotropic_moduli(E, 0.0), (20, 2, 2), order=2, body_force=(0.0, 0.0, -q), size=(L, T, H))
    A, I, G = T * H, T * H**3 / 12, E / 2
    w = q * A * L**4 / (8 * E * I) + q * A * L**2 / (2 * 5 / 6 * G * A)
    tip = -sol.displacement_at(np.array([[L, T / 2, H / 2]]))[0, 2]
    assert tip == pytest.approx(w, rel=5e-3)


def test_error_stats_on_known_errors():
    u_ref = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    u = np.array([[0.0, 0, 0], [1.1, 0, 0], [2.0, 0.2, 0]])  # errors 0, 0.1, 0.2
    s = K.error_stats(u, u_ref)
    rel = np.array([0.0, 0.05, 0.1])
    assert s["max_mean"] == pytest.approx(0.05)
    assert s["max_sd"] == pytest.approx(np.sqrt(0.05**2 * 2 / 3))
    assert s["max_variance"] == pytest.approx(0.05**2 * 2 / 3)
    assert s["max_second_moment"] == pytest.approx(np.mean(rel**2))
    assert s["max_max"] == pytest.approx(0.1)
    assert s["local_mean"] == pytest.approx(0.1)  # 0.1 / 1 and 0.2 / 2; the fixed node left out
    assert s["local_sd"] == pytest.approx(0.0, abs=1e-15)
    assert s["local_max"] == pytest.approx(0.1)


def test_mass_readings():
    r = K.mass_readings()
    assert r["density"] == pytest.approx(0.0125)
    assert r["linear_density"] == pytest.approx(0.0125 / (0.1 * 0.1))
    assert r["total_mass"] == pytest.approx(0.0125 / (0.4 * 0.1 * 0.1))

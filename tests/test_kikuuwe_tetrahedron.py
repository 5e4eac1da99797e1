"""The edge-based St Venant-Kirchhoff tetrahedron (derivations/elements/kikuuwe_tetrahedron.py):
the Green strain identity, the unique exact match, and the generated constants against an
independent numpy St Venant-Kirchhoff energy on random tetrahedra, deformations and nu."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from derivations.elements import kikuuwe_tetrahedron as kt
from msslib.generated import kikuuwe_tetrahedron as gen

REGULAR = np.array([[0, 0, 0], [1, 0, 0], [0.5, 3 ** 0.5 / 2, 0], [0.5, 3 ** 0.5 / 6, (2 / 3) ** 0.5]])
EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def test_green_strain_is_linear_in_the_squared_lengths():
    assert kt.green_strain_identity() == sp.zeros(3, 3)


def test_one_exact_solution_and_zero_volume_is_the_only_failure():
    sol, n = kt.exact()
    assert n == 21 and len(sol) == 1 and len(sol[0]) == 21
    assert sp.expand(kt.edge_map_determinant() - 512 * (kt.a * kt.y2 * kt.z3) ** 4) == 0


def _svk_energy(X, x, E, nu):
    """St Venant-Kirchhoff energy of one linear tetrahedron from its deformation gradient."""
    Dm = (X[1:] - X[0]).T
    F = (x[1:] - x[0]).T @ np.linalg.inv(Dm)
    G = 0.5 * (F.T @ F - np.eye(3))
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    return abs(np.linalg.det(Dm)) / 6 * (lam / 2 * np.trace(G) ** 2 + mu * np.sum(G * G))


def _frame(X):
    e1, e2, e3 = X[1] - X[0], X[2] - X[0], X[3] - X[0]
    a = np.linalg.norm(e1)
    u = e1 / a
    x2 = e2 @ u
    v = e2 - x2 * u
    y2 = np.linalg.norm(v)
    v /= y2
    w = np.cross(u, v)
    return a, x2, y2, e3 @ u, e3 @ v, abs(e3 @ w)


@pytest.mark.parametrize("nu", [0.3, 0.45, -0.2])
def test_generated_edge_energy_is_the_svk_energy(nu):
    rng = np.random.default_rng(int(100 * abs(nu)))
    E = 3.0e4
    for _ in range(20):
        X = REGULAR + 0.3 * rng.standard_normal((4, 3))  # irregular, not a sliver (round-off grows as 1/V)
        x = X @ (np.eye(3) + 0.6 * rng.standard_normal((3, 3))).T + rng.standard_normal(3)  # large strain
        const = dict(zip(gen.OUTPUTS["kikuuwe_tetrahedron"], gen.kikuuwe_tetrahedron(E, nu, *_frame(X))))
        D = [np.sum((x[j] - x[i]) ** 2) - np.sum((X[j] - X[i]) ** 2) for i, j in EDGES]
        names = ["01", "02", "03", "12", "13", "23"]
        w = sum(const[f"k_{names[e]}"] / 4 * D[e] ** 2 for e in range(6))
        w += sum(const[f"c_{names[e]}_{names[f]}"] / 2 * D[e] * D[f] for e in range(6) for f in range(e + 1, 6))
        ref = _svk_energy(X, x, E, nu)
        assert abs(w - ref) <= 1e-9 * abs(ref), (w, ref)


def test_regular_diagonal_against_lloyd():
    """On the regular tetrahedron the diagonal, as a linear spring 2 k_e l^2, is 55/48 of Lloyd's
    eq. 12 constant 2 sqrt(2)/25 E l at nu = 1/4."""
    v = kt.diagonal_as_linear_spring().subs(kt.nu, sp.Rational(1, 4))
    assert sp.simplify(v / (2 * sp.sqrt(2) / 25 * kt.l * kt.E) - sp.Rational(55, 48)) == 0

"""Isotropic linear elasticity, symbolically.

Voigt order: 2D ``(xx, yy, xy)``, 3D ``(xx, yy, zz, yz, xz, xy)``; shear components are engineering
strains (gamma = 2 eps), so the strain energy density is ``e^T D e / 2``.
"""

from __future__ import annotations

import sympy as sp

E, nu, t = sp.symbols("E nu t", positive=True)

VOIGT = {2: [(0, 0), (1, 1), (0, 1)], 3: [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]}
KINDS = ("plane_stress", "plane_strain", "3d")


def lame(E=E, nu=nu):
    """Lamé parameters (lambda, mu) of the 3D material."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def dimension(kind: str) -> int:
    if kind not in KINDS:
        raise ValueError(f"unknown elasticity kind {kind!r}; expected one of {KINDS}")
    return 3 if kind == "3d" else 2


def elasticity_matrix(kind: str, E=E, nu=nu) -> sp.Matrix:
    """The Voigt elasticity matrix D (sigma = D e) of an isotropic material."""
    dimension(kind)
    if kind == "plane_stress":
        return E / (1 - nu**2) * sp.Matrix([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    lam, mu = lame(E, nu)
    if kind == "plane_strain":
        return sp.Matrix([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, mu]])
    D = sp.zeros(6, 6)
    for i in range(3):
        for j in range(3):
            D[i, j] = lam + (2 * mu if i == j else 0)
        D[i + 3, i + 3] = mu
    return D


def isotropic_moduli_2d(D: sp.Matrix, kind: str = "plane_stress"):
    """Read (E, nu) back from a 2D Voigt matrix, assuming it is isotropic in the given plane model.

    For plane stress, D11 = E/(1-nu^2) and D12 = nu E/(1-nu^2).
    """
    d11, d12 = D[0, 0], D[0, 1]
    if kind == "plane_stress":
        nu_ = sp.simplify(d12 / d11)
        return sp.simplify(d11 * (1 - nu_**2)), nu_
    raise NotImplementedError(kind)


def isotropic_moduli_3d(D: sp.Matrix):
    """(E, nu, G, K) of a 3D Voigt matrix read from its C11, C12 (valid when the tensor is isotropic)."""
    c11, c12 = D[0, 0], D[0, 1]
    nu_ = sp.simplify(c12 / (c11 + c12))
    E_ = sp.simplify((c11 - c12) * (c11 + 2 * c12) / (c11 + c12))
    return E_, nu_, sp.simplify((c11 - c12) / 2), sp.simplify((c11 + 2 * c12) / 3)


def is_isotropic(D: sp.Matrix) -> sp.Expr:
    """Zero exactly when the (cubic-symmetric) Voigt matrix is isotropic: C11 - C12 - 2 C44 (3D) or
    D11 - D12 - 2 D33 (2D)."""
    n = D.shape[0]
    shear = D[n - 1, n - 1]
    return sp.simplify(D[0, 0] - D[0, 1] - 2 * shear)

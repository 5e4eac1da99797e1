# Generated from derivations/elements/triangle_angular.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 3f3e6594a47f17c23760017ea2dfd73e990a9e5823b3b48bb95a1ec61cefbda3
# body-sha256: 78f610b395f66b3386e90107428ca7773530e33fcbcc276aa35a1fc1c4b897a8
"""Triangle of any shape with tensile and angular springs (Delingette 2008).

Generated from derivations/elements/triangle_angular.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('delingette_triangle',)


OUTPUTS = {'delingette_triangle': ('k_01', 'k_12', 'k_02', 'c_01_12', 'c_12_02', 'c_01_02')}


def delingette_triangle(E, nu, t, a, x2, y2):
    """Tensile constants k_ij (edge i-j) and angular constants c_ij_pq (edges i-j and p-q) of one triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, in the energy sum k/4 D^2 + sum c/2 D D (D = l^2 - L^2, squared lengths). Exact against the CST for every triangle and nu.

    Returns (k_01, k_12, k_02, c_01_12, c_12_02, c_01_02).
    """
    _c0 = x2**3
    _c1 = 4*a
    _c2 = a**2
    _c3 = y2**2
    _c4 = _c2*_c3
    _c5 = _c3*a
    _c6 = x2**2
    _c7 = 2*_c6
    _c8 = (1/8)*E*t/(y2**3*(nu - 1)*(nu + 1))
    _c9 = _c3*nu
    _c10 = _c3 + _c7 - _c9
    _c11 = _c8/a
    _c12 = 2*_c2
    _c13 = _c9*a
    _c14 = 2*x2
    _c15 = 2*_c0 + _c14*_c3 - _c5
    _c16 = _c8/_c2
    return (
        -_c8*(-_c0*_c1 + _c2*_c7 + 4*_c3*_c6 - _c4*nu + _c4 - 4*_c5*x2 + 2*x2**4 + 2*y2**4)/a**3,
        -_c10*_c11,
        -_c11*(-_c1*x2 + _c10 + _c12),
        -_c16*(_c13 + _c15 - _c7*a),
        -_c11*(_c14*a - _c3 - _c7 + _c9),
        _c16*(-_c1*_c6 + _c12*x2 - _c13 + _c15),
    )

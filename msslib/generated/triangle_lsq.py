# Generated from derivations/elements/triangle_lsq.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: ff8a051dcdda6c6edcadb1b42336594c8aa81007b02247f1f63582cd22d3de6a
# body-sha256: 57450fa1afc4ade7ef6a3d860ad9bb3d9c204b40b131686eafec79f025b5913c
"""Triangle of any shape, three springs fitted to its own CST by least squares (Natsupakpong and Cavusoglu 2010, closed form).

Generated from derivations/elements/triangle_lsq.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('lsq_triangle',)


OUTPUTS = {'lsq_triangle': ('k_01', 'k_12', 'k_02')}


def lsq_triangle(E, nu, t, a, x2, y2):
    """Spring constants k_ij (edge i-j, N/m) of one triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, minimising the Frobenius distance of the springs' stiffness at rest from the triangle's own plane-stress CST (thickness t); per element (sum over the triangles sharing an edge). Exact only on the equilateral triangle at nu = 1/3; can be negative for obtuse triangles.

    Returns (k_01, k_12, k_02).
    """
    _c0 = a*x2
    _c1 = 16*_c0
    _c2 = a**2
    _c3 = x2**2
    _c4 = y2**2
    _c5 = 4*_c2
    _c6 = _c5*nu
    _c7 = 16*_c3
    _c8 = 4*_c0
    _c9 = 4*_c3
    _c10 = 8*_c4
    _c11 = _c2*nu
    _c12 = _c10 - _c11 + _c2 + _c8*nu - _c8 - _c9*nu + _c9
    _c13 = _c3 + _c4
    _c14 = -2*_c0 + _c13 + _c2
    _c15 = _c14**(-2.0)
    _c16 = -_c0 + _c13
    _c17 = _c15*_c16**4
    _c18 = _c13**(-2.0)
    _c19 = (1/4)*_c18
    _c20 = x2**3
    _c21 = _c20*a
    _c22 = 4*_c21
    _c23 = _c4*_c8
    _c24 = x2**4
    _c25 = y2**4
    _c26 = _c24*nu
    _c27 = _c25*nu
    _c28 = 2*_c3
    _c29 = _c28*_c4
    _c30 = _c24 + _c25 - _c26 - _c27 - _c29*nu + _c29
    _c31 = _c10*_c2 + _c22*nu - _c22 + _c23*nu - _c23 + _c3*_c5 - _c3*_c6 + _c30
    _c32 = _c18*_c31
    _c33 = _c3*_c32
    _c34 = a - x2
    _c35 = _c34**2
    _c36 = a**4
    _c37 = _c36*nu
    _c38 = _c2*_c4
    _c39 = _c11*_c28 + 2*_c11*_c4 - _c2*_c28 + _c30 + _c36 - _c37 + 6*_c38
    _c40 = _c15*_c39
    _c41 = _c16**2
    _c42 = 2*_c18
    _c43 = _c15*_c34**4
    _c44 = (1/2)*E*t/(a*y2*(nu - 1)*(nu + 1)*(-_c15*_c18*_c3*_c35*_c41 + _c17*_c42 + _c24*_c42 + 2*_c43 - 32))
    _c45 = 4*_c26
    _c46 = 4*_c27
    _c47 = 8*_c3
    _c48 = _c10*_c3
    _c49 = _c48*nu
    _c50 = _c12*_c3
    return (
        _c44*(-_c1 - _c12*_c17*_c19 + (1/4)*_c15*_c18*_c3*_c39*_c41 + (1/4)*_c15*_c18*_c31*_c35*_c41 + 4*_c2 + 16*_c3 - _c33 - _c35*_c40 + 32*_c4 - _c6 - _c7*nu + 16*a*nu*x2),
        _c44*(_c10*_c11 + _c11*_c47 - _c12*_c35 - _c19*_c24*_c39 + _c19*_c41*_c50 - _c2*_c47 + 4*_c24 + 4*_c25 - _c32*_c41 + (1/4)*_c33*_c35 + 4*_c36 - 4*_c37 + 24*_c38 - _c45 - _c46 + _c48 - _c49)/_c14,
        _c44*(-_c1*_c4 - _c11*_c7 + (1/4)*_c12*_c15*_c35*_c41 + (1/4)*_c15*_c3*_c35*_c39 + 16*_c2*_c3 + 32*_c2*_c4 + 16*_c20*a*nu - 16*_c21 + 4*_c24 + 4*_c25 + 8*_c3*_c4 - 1/4*_c31*_c43 + 16*_c4*a*nu*x2 - _c40*_c41 - _c45 - _c46 - _c49 - _c50)/_c13,
    )

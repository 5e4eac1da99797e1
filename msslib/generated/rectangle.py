# Generated from derivations/elements/rectangle.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: e92947b5ec9d5de17ea0a6e1b85c5c02f45582c90490a75e958fed379a5743ba
# body-sha256: db29faa74ff7404feba006e6ace82b27c52bd21abe4f6887e99cdde9589f8694
"""Rectangle of aspect ratio r, plane stress, six prestrained springs (generalising Lloyd et al. Sec. 4.1).

Generated from derivations/elements/rectangle.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('lloyd_rectangle',)


OUTPUTS = {'rectangle_least_squares': ('k_h', 'k_v', 'k_d', 'c_h', 'c_v', 'c_d'), 'rectangle_least_squares_equilibrium': ('k_h', 'k_v', 'k_d', 'c_h', 'c_v', 'c_d'), 'rectangle_least_squares_nu': ('k_h', 'k_v', 'k_d', 'c_h', 'c_v', 'c_d')}


def rectangle_least_squares(E, t, r):
    """Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. Exact only for r = 1 (Lloyd's 5/16, 7/16 E t; 6/5, 6/7); k and c are positive only for 0.4920 < r < 2.0324, and for r != 1 the element is NOT in equilibrium at rest (see rectangle_least_squares_equilibrium).

    Returns (k_h, k_v, k_d, c_h, c_v, c_d).
    """
    _c0 = r**2
    _c1 = r**4
    _c2 = r**6
    _c3 = -3*_c0 + 28*_c1 + 6*_c2 - 1
    _c4 = _c1 + 1
    _c5 = (1/16)*E*t/(r*(4*_c0 + _c4))
    _c6 = -28*_c0 + 3*_c1 + _c2 - 6
    _c7 = _c0 + 1
    _c8 = 19*_c0 + _c4
    _c9 = 3*r
    return (
        _c3*_c5,
        -_c5*_c6,
        _c5*_c7*_c8,
        2*(14*_c1 + 2*_c2 + _c7)/_c3,
        -2*(14*_c0 + _c1 + _c2 + 2)/_c6,
        2*(-_c0 + _c9 + 1)*(_c0 + _c9 - 1)/_c8,
    )


def rectangle_least_squares_equilibrium(E, t, r):
    """Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, restricted to elements in equilibrium at rest (spring tensions balance at every node), per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. Equal to rectangle_least_squares at r = 1; k and c are positive for every r.

    Returns (k_h, k_v, k_d, c_h, c_v, c_d).
    """
    _c0 = r**4
    _c1 = 5*_c0
    _c2 = r**2
    _c3 = 14*_c2
    _c4 = _c1 + _c3
    _c5 = _c4 + 1
    _c6 = E*t/(_c4 + 5)
    _c7 = (3/8)*_c6
    _c8 = r**(-1.0)
    _c9 = _c0 + _c3 + 5
    _c10 = _c1 + 5
    _c11 = _c10 + 32*_c2
    _c12 = r**6
    return (
        _c5*_c7*r,
        _c7*_c8*_c9,
        (1/8)*_c11*_c6*_c8*(_c2 + 1),
        (1/6)*(91*_c0 + 35*_c12 + 13*_c2 + 5)/(_c2*_c5),
        (1/6)*(13*_c0 + 5*_c12 + 91*_c2 + 35)/_c9,
        (1/2)*(_c10 + 62*_c2)/_c11,
    )


def rectangle_least_squares_nu(E, nu, t, r):
    """Least-squares springs of an a x b rectangle (r = b/a), plane stress, any Poisson's ratio nu, per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. rectangle_least_squares is its value at nu = 1/3; not in equilibrium at rest.

    Returns (k_h, k_v, k_d, c_h, c_v, c_d).
    """
    _c0 = 2*nu
    _c1 = r**2
    _c2 = r**4
    _c3 = r**6
    _c4 = 3*nu
    _c5 = 7*nu
    _c6 = _c0 + _c1*_c4 - 5*_c1 + _c2*_c5 + 35*_c2 + 8*_c3 - 2
    _c7 = nu + 1
    _c8 = (1/24)*E*t/(_c7*r*(nu - 1)*(4*_c1 + _c2 + 1))
    _c9 = 2*_c3
    _c10 = _c1*_c5
    _c11 = _c0*_c3 + 35*_c1 + _c10 + _c2*_c4 - 5*_c2 - _c9 + 8
    _c12 = _c1 + 1
    _c13 = -_c0*_c2 - _c0 + 23*_c1 + _c10 + 2*_c2 + 2
    _c14 = 2*_c7
    _c15 = 3*r
    return (
        -_c6*_c8,
        -_c11*_c8,
        -_c12*_c13*_c8,
        _c14*(_c12 + 14*_c2 + _c9)/_c6,
        _c14*(14*_c1 + _c2 + _c3 + 2)/_c11,
        _c14*(-_c1 + _c15 + 1)*(_c1 + _c15 - 1)/_c13,
    )

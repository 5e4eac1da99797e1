# Generated from derivations/elements/cube_baudet.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 805c5add68aa437da1e97b29747d7bdd7abf33d152a3c10f7f10b91873681ac4
# body-sha256: ead1efdd2788a93d1bcf1adc1fdb9209f754b2834f6888e42bd556b419504f40
"""Cube with edge and inner-diagonal springs and orthogonal correction (Baudet et al.).

Generated from derivations/elements/cube_baudet.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('baudet_cube',)


OUTPUTS = {'baudet_cube': ('k_edge', 'k_diagonal', 'correction_factor'), 'baudet_cube_published': ('k_edge', 'k_diagonal', 'correction_factor')}


def baudet_cube(E, nu, a):
    """Per-element constants of a cube of edge a: edge springs (sum over the cubes sharing the edge), inner diagonals, and the factor c of the correction force F_perp = c F_i applied, as a total per face, on each face orthogonal to the elongation force F_i (Baudet eqs. 7-8).

    Returns (k_edge, k_diagonal, correction_factor).
    """
    _c0 = E*a/(nu + 1)
    return (
        (1/8)*_c0*(4*nu + 1),
        (3/8)*_c0,
        1/2 - 2*nu,
    )


def baudet_cube_published(E, nu, a):
    """Baudet et al.'s eqs. 7-8 as printed (correction factor -(4 nu - 1)/16).

    Returns (k_edge, k_diagonal, correction_factor).
    """
    _c0 = 4*nu
    _c1 = E*a/(nu + 1)
    return (
        (1/8)*_c1*(_c0 + 1),
        (3/8)*_c1,
        1/16 - 1/16*_c0,
    )

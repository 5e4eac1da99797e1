# Generated from derivations/elements/square.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 9804f2206eea30d6e805ab4abac0719d5f3426bc3efb00253187c092359974e1
# body-sha256: 1dd982c2337e75087dee499cd350e6dc2d1ddc93b1216533dccefec5767742ed
"""Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11).

Generated from derivations/elements/square.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('lloyd_square',)


OUTPUTS = {'lloyd_square': ('k_edge', 'k_diagonal', 'rest_factor_edge', 'rest_factor_diagonal')}


def lloyd_square(E, t):
    """Per-element constants of the square: edge springs (sum over the squares sharing the edge) and diagonal springs, with rest length = factor x rest distance. Exact for nu = 1/3.

    Returns (k_edge, k_diagonal, rest_factor_edge, rest_factor_diagonal).
    """
    _c0 = E*t
    return (
        (5/16)*_c0,
        (7/16)*_c0,
        6/5,
        6/7,
    )

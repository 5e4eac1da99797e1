# Generated from derivations/elements/square.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 4391d66bca66ad1ed64f4db415fdd3579e07eda530fe2570cc7c17cd83ca699d
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

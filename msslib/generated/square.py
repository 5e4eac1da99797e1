# Generated from derivations/square.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: c0069f9f6eb5a78a05fa70496f1202aaaf0f27c52251913c1f32c13bc7b6e248
# body-sha256: 7ecb914d1852416401807e86d947e0367f8126e72b51da001538baf27e8712cf
"""Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11).

Generated from derivations/square.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


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

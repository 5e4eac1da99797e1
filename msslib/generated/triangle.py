# Generated from derivations/triangle.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 3f66ca96955156fe7cbad8f6629de3b00e6197115b582e69663d5e890b262d9b
# body-sha256: c6ba7510b590fab05b555a4882f6db07bb64bbe5ac2fa7a67658d8e149997bb2
"""Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9).

Generated from derivations/triangle.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


OUTPUTS = {'lloyd_triangle': ('k',), 'van_gelder_triangle': ('k',)}


def lloyd_triangle(E, t):
    """Spring constant of each edge of an equilateral triangle, per element (sum over the triangles sharing the edge). Exact for nu = 1/3.

    Returns (k).
    """
    return (1/4)*sqrt(3)*E*t


def van_gelder_triangle(E, t, A_e, l):
    """Van Gelder's spring constant, per element: E t A_e / l^2.

    Returns (k).
    """
    return A_e*E*t/l**2

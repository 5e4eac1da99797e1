# Generated from derivations/elements/triangle.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 0d9f220e94ad8c1b2208895a0c09a40ffc8c3fa8c40bfea289537f12f5c48f4e
# body-sha256: 4015acd45b86546c6a6abfcd250b2d8757c57c8cce0e75c00be6d90ffeb475b9
"""Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9).

Generated from derivations/elements/triangle.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('lloyd_triangle', 'van_gelder')


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

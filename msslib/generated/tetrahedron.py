# Generated from derivations/elements/tetrahedron.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 5bb62d6e7e2cb1f7e003dcfe035a9bb825e60f4b36a4cf6de13003e8a19891dd
# body-sha256: 0b2dbb0b56041ab2d1c0d5c290b0fcfc5ecc68a47555a831b2b6251b8cfd020f
"""Regular tetrahedron, least squares (Lloyd et al. eqs. 12-14).

Generated from derivations/elements/tetrahedron.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('lloyd_tetrahedron', 'lloyd_tetrahedron_volume')


OUTPUTS = {'lloyd_tetrahedron': ('k',), 'lloyd_tetrahedron_general_nu': ('k',), 'lloyd_tetrahedron_volume': ('k', 'k_volume'), 'equivalent_edge_length': ('l',), 'lloyd_tetrahedron_volume_published': ('k', 'k_volume')}


def lloyd_tetrahedron(E, l):
    """Per-element spring constant of a regular tetrahedron of edge l (least squares at nu = 1/4, eq. 12); use the equivalent edge length of eq. 13 for other shapes; sum over the tetrahedra sharing the edge.

    Returns (k).
    """
    return (2/25)*sqrt(2)*E*l


def lloyd_tetrahedron_general_nu(E, nu, l):
    """Least-squares spring constant for any nu (per element).

    Returns (k).
    """
    return (1/15)*sqrt(2)*E*l*(nu - 1)/((nu + 1)*(2*nu - 1))


def lloyd_tetrahedron_volume(E, nu, l):
    """Per-element spring constant and volume-energy coefficient k_V of E_V = k_V/(2 V0^2)(V - V0)^2, least squares for any nu (eq. 14 is the case nu = 1/4).

    Returns (k, k_volume).
    """
    _c0 = sqrt(2)*E/(nu + 1)
    return (
        (2/21)*_c0*l,
        -1/84*_c0*l**3*(13*nu - 3)/(2*nu - 1),
    )


def equivalent_edge_length(V):
    """Edge of the regular tetrahedron of volume V (eq. 13).

    Returns (l).
    """
    return sqrt(2)*3**(1/3)*V**(1/3)


def lloyd_tetrahedron_volume_published(E, l):
    """Lloyd et al.'s eq. 14 as printed (the optimum at nu = 1/4).

    Returns (k, k_volume).
    """
    _c0 = sqrt(2)*E
    return (
        (8/105)*_c0*l,
        (1/210)*_c0*l**3,
    )

# Generated from derivations/elements/cube_golec.py by `python -m derivations.codegen`. Do not edit.
# source-sha256: 2baf740924006b24ab708a6eb9fe0afe8cc5962c5c534f961faf5ee0c0b2c7f1
# body-sha256: ead38ff0979f342e371691d41eaa2c1fcc80bd8a3ec45ce6848072726eb1950e
"""Cube with edge, face and inner springs and volume correction (Golec et al.).

Generated from derivations/elements/cube_golec.py by `python -m derivations.codegen`; do not edit.
"""

from numpy import sqrt  # noqa: F401


# the simulator models whose parameters come from this module (its ELEMENT declaration)
MODELS = ('golec_cube',)


OUTPUTS = {'golec_cube': ('k_edge', 'k_face', 'k_inner', 'kappa'), 'golec_cube_published': ('k_edge', 'k_face', 'k_inner', 'kappa')}


def golec_cube(E, nu, a, A):
    """Per-element constants of a cube of edge a (sum the edge springs over the up to 4 cubes sharing an edge, face diagonals over the up to 2 cubes sharing a face) and kappa [Pa] of the volume energy kappa/(2 V0) (V - V0)^2. The lattice reproduces the isotropic (lambda, mu) exactly.

    Returns (k_edge, k_face, k_inner, kappa).
    """
    _c0 = 2*A
    _c1 = E*a/(_c0*nu + _c0 + 3*nu + 3)
    _c2 = (3/4)*_c1
    return (
        (1/8)*_c1*(4*A + 3),
        _c2,
        A*_c2,
        -1/2*E*(4*nu - 1)/(2*nu**2 + nu - 1),
    )


def golec_cube_published(E, nu, a, A):
    """Golec et al.'s constants as printed (k_edge and k_face are the assembled values of an interior spring).

    Returns (k_edge, k_face, k_inner, kappa).
    """
    _c0 = (6/5)*E*a/(4*A + 3)
    return (
        _c0*((8/3)*A + 1),
        _c0,
        A*_c0,
        -1/2*E*(4*nu - 1)/((nu + 1)*(2*nu - 1)),
    )

"""Effective elastic tensor of a periodic lattice under homogeneous strain.

An independent check of an element derivation: tile space with the element, deform *every* node
affinely, x = (I + eps) X, and read the elastic tensor off the energy density,
C = d^2 W / d e^2 at e = 0 (Voigt, engineering shears). Using each element's own (per-element)
constants is the same as summing them over the elements sharing a spring. The affine deformation
is the lattice's equilibrium when every node is a centre of inversion symmetry of the lattice
(triangular, square and simple-cubic lattices), so no internal relaxation is missed.
"""

from __future__ import annotations

import sympy as sp

from .elasticity import VOIGT
from .mss import _to_vectors


def strain_symbols(dim: int):
    names = ["e_xx", "e_yy", "g_xy"] if dim == 2 else ["e_xx", "e_yy", "e_zz", "g_yz", "g_xz", "g_xy"]
    return sp.symbols(names, real=True)


def strain_matrix(e, dim):
    eps = sp.zeros(dim, dim)
    for s, (i, j) in zip(e, VOIGT[dim]):
        if i == j:
            eps[i, i] = s
        else:
            eps[i, j] = eps[j, i] = s / 2
    return eps


def energy_density(terms, coords, volume, strain=None):
    """Energy per unit volume (area x thickness in 2D) of the cell under a homogeneous strain."""
    R = _to_vectors(coords)
    dim = len(R[0])
    e = strain_symbols(dim) if strain is None else strain
    F = sp.eye(dim) + strain_matrix(e, dim)
    P = [F * r for r in R]
    W = sum((t.energy([P[a] for a in t.nodes], [R[a] for a in t.nodes]) for t in terms), sp.Integer(0))
    return W / volume, e


def effective_tensor(terms, coords, volume):
    """(C, sigma0): the Voigt elastic matrix and the residual stress of the lattice at rest."""
    W, e = energy_density(terms, coords, volume)
    zero = {s: 0 for s in e}
    sigma0 = sp.Matrix([sp.simplify(sp.diff(W, s).subs(zero)) for s in e])
    C = sp.hessian(W, e).subs(zero).applyfunc(lambda v: sp.simplify(sp.radsimp(v)))
    return C, sigma0

"""Mass-spring systems as sums of energy terms, linearised at rest.

A *term* is an energy of a few nodes: a function of their current positions ``P`` and rest positions
``R`` (lists of SymPy column vectors). The MSS stiffness matrix at rest is the sum of the terms'
Hessians, evaluated at the rest positions, obtained by differentiating the energies — nothing about
a spring's stiffness matrix is typed in. The same energy functions feed the code generator, so the
simulator integrates exactly the energies the derivations linearise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import sympy as sp


def norm(v: sp.Matrix) -> sp.Expr:
    return sp.sqrt((v.T * v)[0, 0])


def cross(a: sp.Matrix, b: sp.Matrix) -> sp.Matrix:
    return a.cross(b)


# ---- energies (shared with the code generator) -----------------------------------------------

def spring_energy(p, q, k, rest_length):
    """Hookean spring between positions p and q: k/2 (|p - q| - L0)^2."""
    return k / 2 * (norm(p - q) - rest_length) ** 2


def tet_volume(p0, p1, p2, p3):
    """Signed volume of a tetrahedron, positive for VTK orientation."""
    return sp.Matrix.hstack(p1 - p0, p2 - p0, p3 - p0).det() / 6


def tet_volume_energy(P, k_v, V0):
    """Lloyd et al. (App. C.2, after Teschner et al.): k_V / (2 V0^2) (V - V0)^2."""
    return k_v / (2 * V0**2) * (tet_volume(*P) - V0) ** 2


def hex_averaged_axes(P):
    """The averaged edge vectors (x, y, z) of a hexahedron in VTK order (Golec et al.)."""
    x = (P[1] - P[0] + P[2] - P[3] + P[5] - P[4] + P[6] - P[7]) / 4
    y = (P[3] - P[0] + P[2] - P[1] + P[7] - P[4] + P[6] - P[5]) / 4
    z = (P[4] - P[0] + P[5] - P[1] + P[6] - P[2] + P[7] - P[3]) / 4
    return x, y, z


def hex_averaged_volume(P):
    """Golec's volume approximation V = x . (y cross z) from the averaged edge vectors."""
    x, y, z = hex_averaged_axes(P)
    return (x.T * cross(y, z))[0, 0]


def hex_volume_energy(P, kappa, V0):
    """Volume correction energy kappa / (2 V0) (V - V0)^2 with Golec's averaged volume V.

    Its force -dW/dP = -(kappa / V0) (V - V0) dV/dP is Golec's correction force made dimensionally
    consistent (the printed force kappa (V - V0) dV/dP is not a force when kappa is a modulus);
    its small-strain energy density is kappa/2 (tr eps)^2, i.e. it adds kappa to Lamé's lambda.
    """
    return kappa / (2 * V0) * (hex_averaged_volume(P) - V0) ** 2


# ---- terms ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Term:
    """An energy of the nodes ``nodes``; ``energy(P, R)`` takes their current and rest positions."""

    name: str
    nodes: tuple
    energy: Callable


def spring(i: int, j: int, k, rest_factor=1, name=None) -> Term:
    """A spring (i, j) of constant k whose rest length is ``rest_factor`` times the rest distance
    (``rest_factor != 1`` is a prestrained spring)."""
    return Term(name or f"spring({i},{j})", (i, j),
                lambda P, R: spring_energy(P[0], P[1], k, rest_factor * norm(R[0] - R[1])))


def tet_volume_term(nodes, k_v) -> Term:
    return Term("tet_volume", tuple(nodes), lambda P, R: tet_volume_energy(P, k_v, tet_volume(*R)))


def hex_volume_term(nodes, kappa) -> Term:
    return Term("hex_volume", tuple(nodes), lambda P, R: hex_volume_energy(P, kappa, hex_averaged_volume(R)))


def position_symbols(n: int, dim: int):
    names = "xyz"[:dim]
    return [sp.Matrix([sp.Symbol(f"{c}_{a}", real=True) for c in names]) for a in range(n)]


def _to_vectors(coords):
    return [sp.Matrix([sp.sympify(c) for c in p]) for p in coords]


def _simplify(e):
    e = sp.radsimp(sp.nsimplify(e) if e.is_number else e)
    return sp.simplify(e)


def energy(terms, coords, positions=None):
    """Total energy of ``terms`` for rest coordinates ``coords`` and current ``positions``."""
    R = _to_vectors(coords)
    P = R if positions is None else _to_vectors(positions)
    return sum((t.energy([P[a] for a in t.nodes], [R[a] for a in t.nodes]) for t in terms), sp.Integer(0))


def stiffness_at_rest(terms, coords) -> sp.Matrix:
    """Sum of the terms' Hessians with respect to the node positions, at the rest positions.

    Degrees of freedom are interleaved by node, as in :func:`derivations.element_stiffness.element_stiffness`.
    """
    R = _to_vectors(coords)
    dim = len(R[0])
    K = sp.zeros(dim * len(R), dim * len(R))
    for term in terms:
        S = position_symbols(len(term.nodes), dim)
        W = term.energy(S, [R[a] for a in term.nodes])
        flat = [s for v in S for s in v]
        rest = {s: r for v, a in zip(S, term.nodes) for s, r in zip(v, R[a])}
        H = sp.hessian(W, flat).subs(rest)
        for p, a in enumerate(term.nodes):
            for q, b in enumerate(term.nodes):
                for i in range(dim):
                    for j in range(dim):
                        K[dim * a + i, dim * b + j] += H[dim * p + i, dim * q + j]
    return K.applyfunc(_simplify)


def unit_springs(coords, edges) -> tuple:
    """Stiffness at rest of a unit spring (k = 1) on each edge ``(i, j)`` of ``edges``: the basis
    ``K_e`` of the springs' stiffness ``sum_e k_e K_e``."""
    return tuple(stiffness_at_rest([spring(i, j, sp.Integer(1))], coords) for i, j in edges)


def forces_at_rest(terms, coords) -> sp.Matrix:
    """Net force -dW/dx on every dof at the rest positions (zero when the element is in equilibrium)."""
    R = _to_vectors(coords)
    dim = len(R[0])
    f = sp.zeros(dim * len(R), 1)
    for term in terms:
        S = position_symbols(len(term.nodes), dim)
        W = term.energy(S, [R[a] for a in term.nodes])
        rest = {s: r for v, a in zip(S, term.nodes) for s, r in zip(v, R[a])}
        for p, a in enumerate(term.nodes):
            for i in range(dim):
                f[dim * a + i] -= sp.diff(W, S[p][i]).subs(rest)
    return f.applyfunc(_simplify)


def spring_tensions_at_rest(terms, coords):
    """Axial force k (|d| - L0) of every spring term at rest (positive in tension)."""
    R = _to_vectors(coords)
    out = {}
    for term in terms:
        if not term.name.startswith("spring"):
            continue
        a, b = term.nodes
        s = sp.Symbol("s", positive=True)
        # tension = dW/d(length) at the rest length
        d = R[a] - R[b]
        L = norm(d)
        W = term.energy([R[b] + d / L * s, R[b]], [R[a], R[b]])
        out[term.name] = _simplify(sp.diff(W, s).subs(s, L))
    return out

"""FEM element stiffness matrices with shape functions integrated exactly.

Node order is meshio's/VTK's (see :mod:`msslib.mesh`); degrees of freedom are interleaved by node,
``(x0, y0[, z0], x1, y1, ...)``. For affine elements (simplices, parallelograms, parallelepipeds) the
integrand is a polynomial in the reference coordinates and is integrated monomial by monomial,
exactly; other shapes fall back to ``sympy.integrate``.
"""

from __future__ import annotations

from math import factorial

import sympy as sp

from .elasticity import VOIGT, dimension, elasticity_matrix

xi, eta, zeta = sp.symbols("xi eta zeta", real=True)

# reference coordinates of the nodes, VTK order
_REF = {
    "triangle": [(0, 0), (1, 0), (0, 1)],
    "quad": [(-1, -1), (1, -1), (1, 1), (-1, 1)],
    "tetra": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
    "hexahedron": [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                   (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)],
}


def shape_functions(cell_type: str):
    """(shape functions, reference coordinates) of the linear/multilinear Lagrange element."""
    if cell_type == "triangle":
        return [1 - xi - eta, xi, eta], (xi, eta)
    if cell_type == "tetra":
        return [1 - xi - eta - zeta, xi, eta, zeta], (xi, eta, zeta)
    if cell_type == "quad":
        return [(1 + a * xi) * (1 + b * eta) / 4 for a, b in _REF["quad"]], (xi, eta)
    if cell_type == "hexahedron":
        return [(1 + a * xi) * (1 + b * eta) * (1 + c * zeta) / 8 for a, b, c in _REF["hexahedron"]], (xi, eta, zeta)
    raise ValueError(f"unknown cell type {cell_type!r}")


def _integrate_monomial(cell_type, powers):
    if cell_type in ("quad", "hexahedron"):
        out = sp.Integer(1)
        for p in powers:
            out *= 0 if p % 2 else sp.Rational(2, p + 1)
        return out
    # unit simplex: int x^a y^b (z^c) = a! b! (c!) / (a+b(+c)+d)!
    num = 1
    for p in powers:
        num *= factorial(p)
    return sp.Rational(num, factorial(sum(powers) + len(powers)))


def integrate_reference(expr, cell_type: str):
    """Exact integral of ``expr`` over the reference element."""
    _, ref = shape_functions(cell_type)
    expr = sp.expand(expr)
    try:
        poly = sp.Poly(expr, *ref)
    except sp.PolynomialError:
        poly = None
    if poly is not None and all(c.free_symbols.isdisjoint(ref) for c in poly.coeffs()):
        return sum(c * _integrate_monomial(cell_type, m) for m, c in poly.terms())
    if cell_type in ("quad", "hexahedron"):
        bounds = [(r, -1, 1) for r in ref]
    elif cell_type == "triangle":
        bounds = [(eta, 0, 1 - xi), (xi, 0, 1)]
    else:
        bounds = [(zeta, 0, 1 - xi - eta), (eta, 0, 1 - xi), (xi, 0, 1)]
    return sp.integrate(expr, *bounds)


def strain_displacement(cell_type: str, coords):
    """(B, det J) for an element with node coordinates ``coords`` (list of tuples)."""
    N, ref = shape_functions(cell_type)
    dim = len(ref)
    X = sp.Matrix(coords)  # (n, dim)
    dN = sp.Matrix([[sp.diff(n, r) for r in ref] for n in N])  # (n, dim) d/dref
    J = (X.T * dN).applyfunc(sp.expand)  # J[i, a] = dx_i / dref_a
    detJ = sp.factor(J.det())
    grad = (dN * J.inv()).applyfunc(sp.cancel)  # (n, dim) dN/dx
    voigt = VOIGT[dim]
    B = sp.zeros(len(voigt), dim * len(N))
    for r, (i, j) in enumerate(voigt):
        for a in range(len(N)):
            if i == j:
                B[r, dim * a + i] = grad[a, i]
            else:
                B[r, dim * a + i] = grad[a, j]
                B[r, dim * a + j] = grad[a, i]
    return B, detJ


def element_stiffness(cell_type: str, coords, kind: str, E=None, nu=None, thickness=None) -> sp.Matrix:
    """Element stiffness K = int B^T D B dV (times the thickness ``t`` in 2D), exact.

    ``coords`` must be positively oriented (det J > 0).
    """
    from . import elasticity as el

    E = el.E if E is None else E
    nu = el.nu if nu is None else nu
    dim = dimension(kind)
    _, ref = shape_functions(cell_type)
    if len(ref) != dim:
        raise ValueError(f"{cell_type} is not a {dim}D element ({kind})")
    B, detJ = strain_displacement(cell_type, coords)
    D = elasticity_matrix(kind, E, nu)
    # K = sum_pq D_pq int B_p^T B_q det J: the integrals are purely geometric (no material symbols)
    n = B.cols
    K = sp.zeros(n, n)
    for p in range(D.rows):
        for q in range(D.cols):
            if D[p, q] == 0:
                continue
            M = (B[p, :].T * B[q, :] * detJ).applyfunc(lambda e: integrate_reference(sp.cancel(e), cell_type))
            K += D[p, q] * M
    K = K.applyfunc(sp.factor)
    if dim == 2:
        K = K * (el.t if thickness is None else thickness)
    return K

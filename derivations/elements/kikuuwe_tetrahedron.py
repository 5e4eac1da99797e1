# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Tetrahedron of any shape: the St Venant-Kirchhoff element in edge coordinates
#
# Kikuuwe, Tabuchi and Yamamoto (2009, "An edge-based computationally efficient formulation of
# Saint Venant-Kirchhoff tetrahedral finite elements", ACM TOG 28(1)). With the change of squared
# length `D_e = l_e^2 - L_e^2` of edge `e` (edges 0-1, 0-2, 0-3, 1-2, 1-3, 2-3), the energy of one
# tetrahedron is
#
#     W = sum_e k_e / 4 D_e^2 + sum_{e<f} c_ef / 2 D_e D_f,
#
# the 3D analogue of Delingette's triangle (`triangle_angular.py`): 6 "tensile" and 15 coupling
# constants per element. The Green strain of a linear tetrahedron is linear in the six `D_e`,
# `E_G = sum_e D_e S_e` with `S_e = -(g_a g_b^T + g_b g_a^T) / 4` (`g_a` the gradient of the shape
# function of node `a`, edge `e = (a, b)`), so the St Venant-Kirchhoff energy
# `V (lambda / 2 tr(E_G)^2 + mu E_G : E_G)` is a quadratic form in the `D_e`. Here the engine proves
# the identity for a general tetrahedron (node 0 at the origin, node 1 at `(a, 0, 0)`, node 2 at
# `(x2, y2, 0)`, node 3 at `(x3, y3, z3)`, any current positions), reads the 21 constants off the
# quadratic form, and shows where the map from strain to edge coordinates fails (zero volume).

# %%
from functools import lru_cache

import sympy as sp

from derivations import show
from derivations.elasticity import E, nu
from derivations.records import Derivation, Element, Formula

ELEMENT = Element("kikuuwe_tetrahedron", cell="tetra", models=("kikuuwe_tetrahedron",),
                  source="Kikuuwe, Tabuchi and Yamamoto (2009), An edge-based computationally efficient formulation "
                         "of Saint Venant-Kirchhoff tetrahedral finite elements, ACM TOG 28(1)",
                  extends="tetrahedron")

a, y2, z3 = sp.symbols("a y2 z3", positive=True)
x2, x3, y3 = sp.symbols("x2 x3 y3", real=True)
COORDS = [(0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3)]
EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
NAMES = ["01", "02", "03", "12", "13", "23"]
PAIRS = [(e, f) for e in range(6) for f in range(e + 1, 6)]
D = sp.symbols("D_0:6", real=True)  # the six changes of squared edge length, as free symbols
LAM = E * nu / ((1 + nu) * (1 - 2 * nu))
MU = E / (2 * (1 + nu))


def _rest():
    return [sp.Matrix(c) for c in COORDS]


@lru_cache(maxsize=None)
def gradients():
    """Shape-function gradients g_0..g_3 of the rest tetrahedron (columns), and its volume."""
    R = _rest()
    Dm = sp.Matrix.hstack(*[R[i] - R[0] for i in (1, 2, 3)])
    Gi = Dm.inv()
    g = [-(Gi[0, :] + Gi[1, :] + Gi[2, :]).T] + [Gi[i, :].T for i in range(3)]
    return [v.applyfunc(sp.cancel) for v in g], Gi, Dm.det() / 6


def S(e):
    g, _, _ = gradients()
    i, j = EDGES[e]
    return -(g[i] * g[j].T + g[j] * g[i].T) / 4


# %% [markdown]
# ## The Green strain is linear in the D_e, for every shape and every deformation

# %%
@lru_cache(maxsize=None)
def green_strain_identity():
    """E_G(P) - sum_e D_e(P) S_e for symbolic current positions P (zero: the identity holds)."""
    _, Gi, _ = gradients()
    R = _rest()
    P = sp.Matrix(sp.symbols("p0:12", real=True)).reshape(4, 3)
    X = [P[i, :].T for i in range(4)]
    F = sp.Matrix.hstack(*[X[i] - X[0] for i in (1, 2, 3)]) * Gi
    EG = (F.T * F - sp.eye(3)) / 2
    d = [((X[j] - X[i]).T * (X[j] - X[i]))[0] - ((R[j] - R[i]).T * (R[j] - R[i]))[0] for i, j in EDGES]
    return (EG - sum((d[e] * S(e) for e in range(6)), sp.zeros(3, 3))).applyfunc(sp.cancel)


@lru_cache(maxsize=None)
def edge_map_determinant():
    """det of the linear map strain (Voigt, 6) -> D (6): D_e = 2 L_e^T E L_e. Zero iff the volume is."""
    R = _rest()
    e = sp.symbols("e_xx e_yy e_zz e_yz e_xz e_xy", real=True)
    Et = sp.Matrix([[e[0], e[5], e[4]], [e[5], e[1], e[3]], [e[4], e[3], e[2]]])
    M = sp.Matrix([[sp.expand(2 * ((R[j] - R[i]).T * Et * (R[j] - R[i]))[0]).coeff(v) for v in e] for i, j in EDGES])
    return sp.factor(M.det())


# %%
if __name__ == "__main__":
    show.check(r"E_G = \sum_e D_e S_e\ \text{for every tetrahedron and every deformation}",
               green_strain_identity() == sp.zeros(3, 3))
    show.math(r"\det\left(\partial D / \partial \varepsilon\right)", edge_map_determinant())


# %% [markdown]
# ## The energy, exactly in the D_e
#
# With `E_G = sum_e D_e S_e` substituted, the St Venant-Kirchhoff energy is the quadratic form
# `W = 1/2 D^T Q D` with `Q_ef = V (lambda tr S_e tr S_f + 2 mu S_e : S_f)`. The edge energy is
# `1/2 D^T Q' D` with `Q'_ee = k_e / 2` and `Q'_ef = c_ef / 2`, so matching every coefficient of
# the quadratic polynomial in the free symbols D_e gives `k_e = 2 Q_ee`, `c_ef = 2 Q_ef`: 21
# linear equations with one solution.

# %%
k = sp.symbols("k_" + " k_".join(NAMES), real=True)
c = sp.symbols(" ".join(f"c_{NAMES[e]}_{NAMES[f]}" for e, f in PAIRS), real=True)


def edge_energy(ks, cs, Ds=D):
    return (sum(ks[e] / 4 * Ds[e] ** 2 for e in range(6))
            + sum(cs[n] / 2 * Ds[e] * Ds[f] for n, (e, f) in enumerate(PAIRS)))


def svk_energy(EG, V):
    return V * (LAM / 2 * EG.trace() ** 2 + MU * (EG * EG).trace())


@lru_cache(maxsize=None)
def exact():
    """The unique solution of the coefficient match (dict unknown -> expression) and the number of
    equations. Both energies are homogeneous quadratics in the D_e, so their coefficients are their
    second derivatives in the D_e: one equation per monomial D_e D_f."""
    _, _, V = gradients()
    EG = sum((D[e] * S(e) for e in range(6)), sp.zeros(3, 3))
    w_svk, w_edge = svk_energy(EG, V), edge_energy(k, c)
    eqs = [sp.diff(w_svk, D[e], D[f]) - sp.diff(w_edge, D[e], D[f]) for e in range(6) for f in range(e, 6)]
    sol = sp.solve(eqs, list(k) + list(c), dict=True)
    return [{key: sp.factor(v) for key, v in s.items()} for s in sol], len(eqs)


# %%
if __name__ == "__main__":
    (s,), n_eqs = exact()
    show.solution(r"k_{01}, c_{01,23}", {k[0]: s[k[0]], c[4]: s[c[4]]})
    show.check(r"\text{one solution of the " + str(n_eqs) + r" coefficient equations}", len(exact()[0]) == 1)


# %% [markdown]
# ## Its diagonal against Lloyd's tetrahedron springs
#
# A biquadratic spring `k_e/4 D^2 = k_e L^2 (l - L)^2 + O((l-L)^3)` is, to second order, a linear
# spring of constant `2 k_e L^2`. On the regular tetrahedron of edge `l` all six `k_e` are equal and
# all couplings are non-zero (the shear part couples opposite edges, the volume part every pair),
# so no exact element is a mass-spring model. Its diagonal is compared with Lloyd's eq. 12.

# %%
l = sp.Symbol("l", positive=True)


@lru_cache(maxsize=None)
def regular():
    s = exact()[0][0]
    at = {a: l, x2: l / 2, y2: sp.sqrt(3) * l / 2, x3: l / 2, y3: sp.sqrt(3) * l / 6, z3: sp.sqrt(sp.Rational(2, 3)) * l}
    return {key: sp.simplify(v.subs(at)) for key, v in s.items()}


@lru_cache(maxsize=None)
def diagonal_as_linear_spring():
    """2 k_e l^2 on the regular tetrahedron: the linear spring its diagonal alone is."""
    return sp.factor(2 * regular()[k[0]] * l ** 2)


# %%
if __name__ == "__main__":
    from derivations.elements import tetrahedron as lloyd

    show.solution(r"\text{regular tetrahedron}", regular())
    k_lloyd = lloyd.derive().formulas[0].outputs["k"]
    show.math(r"2 k_e l^2", diagonal_as_linear_spring())
    show.math(r"2 k_e l^2 / k_{\text{Lloyd, eq. 12}}\ (\nu = 1/4)",
              sp.simplify(diagonal_as_linear_spring().subs(nu, sp.Rational(1, 4)) / k_lloyd))


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    sol, n_eqs = exact()
    assert len(sol) == 1, sol
    s = sol[0]
    d = Derivation("kikuuwe_tetrahedron",
                   "Tetrahedron of any shape: the St Venant-Kirchhoff element in edge coordinates (Kikuuwe et al. 2009)")
    d.formulas.append(Formula(
        "kikuuwe_tetrahedron", (E, nu, a, x2, y2, x3, y3, z3), {str(key): s[key] for key in list(k) + list(c)},
        "Tensile constants k_ij (edge i-j) and coupling constants c_ij_pq (edges i-j and p-q) of one tetrahedron "
        "with nodes (0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3), a, y2, z3 > 0, in the energy "
        "sum k/4 D^2 + sum c/2 D D (D = l^2 - L^2, squared lengths), N m^-2. Equal to the St Venant-Kirchhoff "
        "element's energy for every tetrahedron of non-zero volume, every deformation and every nu < 1/2."))
    reg = regular()
    d.findings += [
        ("green strain", r"E_G = \sum_e D_e S_e,\ S_e = -\frac{1}{4}(g_a g_b^T + g_b g_a^T)\ \text{for every tetrahedron}"),
        ("exact", f"one solution of the {n_eqs} coefficient equations: the St Venant-Kirchhoff energy for every "
                  "tetrahedron, deformation and Poisson ratio"),
        ("degenerate", r"\det \partial D / \partial \varepsilon = " + sp.latex(edge_map_determinant())
         + r" = 512 (6 V)^4\ \text{: no edge form at zero volume}"),
        ("regular diagonal", r"2 k_e l^2 = " + sp.latex(diagonal_as_linear_spring())),
    ]
    d.data.update(solution=s, regular=reg)
    return d


# %%
if __name__ == "__main__":
    d = show.summary(derive())

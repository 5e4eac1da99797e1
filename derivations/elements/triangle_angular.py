# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Triangle of any shape: tensile and angular springs against the CST
#
# Three springs cannot match the constant-strain triangle (CST) unless the triangle is equilateral
# and nu = 1/3 (`triangle.py`). Delingette (2008, "Triangular springs for modeling nonlinear
# membranes", IEEE TVCG 14(2)) adds, per triangle, a coupling between every pair of edges. With the
# change of squared edge length `D_i = l_i^2 - L_i^2` of edge `i`, the energy of one triangle is
#
#     W = sum_i k_i / 4 D_i^2 + sum_{i<j} c_ij / 2 D_i D_j
#
# ("tensile" biquadratic springs `k_i` and "angular" springs `c_ij`). Six constants per triangle:
# here the engine linearises this energy at rest and matches it with the CST of a general triangle
# (node 0 at the origin, node 1 at `(a, 0)`, node 2 at `(x2, y2)`, any Poisson's ratio). The
# match is exact, and unique, for every triangle and every nu.

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, match, mss, show
from derivations.elasticity import E, nu, t
from derivations.records import Derivation, Element, Formula

ELEMENT = Element("triangle_angular", cell="triangle", models=("delingette_triangle",),
                  source="Delingette (2008), Triangular springs for modeling nonlinear membranes, IEEE TVCG 14(2)",
                  extends="triangle")

a = sp.Symbol("a", positive=True)
x2 = sp.Symbol("x2", real=True)
y2 = sp.Symbol("y2", positive=True)
COORDS = [(0, 0), (a, 0), (x2, y2)]
EDGES = [(0, 1), (1, 2), (0, 2)]
PAIRS = [(0, 1), (1, 2), (0, 2)]  # the edge pairs of the angular springs c_01_12, c_12_02, c_01_02
k = sp.symbols("k_01 k_12 k_02", real=True)
c = sp.symbols("c_01_12 c_12_02 c_01_02", real=True)


def _d2(P, i, j):
    d = P[i] - P[j]
    return (d.T * d)[0]


def tensile(e, kk):
    """Biquadratic spring on edge ``e``: ``kk / 4 (l^2 - L^2)^2``."""
    i, j = EDGES[e]
    return mss.Term(f"tensile{i}{j}", (0, 1, 2), lambda P, R: kk / 4 * (_d2(P, i, j) - _d2(R, i, j)) ** 2)


def angular(e, f, cc):
    """Coupling of edges ``e`` and ``f``: ``cc / 2 (l_e^2 - L_e^2)(l_f^2 - L_f^2)``."""
    (i, j), (p, q) = EDGES[e], EDGES[f]
    return mss.Term(f"angular{i}{j}_{p}{q}", (0, 1, 2),
                    lambda P, R: cc / 2 * (_d2(P, i, j) - _d2(R, i, j)) * (_d2(P, p, q) - _d2(R, p, q)))


def terms(ks, cs):
    return [tensile(e, ks[e]) for e in range(3)] + [angular(e, f, cs[n]) for n, (e, f) in enumerate(PAIRS)]


# %% [markdown]
# ## The match

# %%
@lru_cache(maxsize=None)
def K_fem():
    """6x6 plane-stress CST stiffness of the general triangle; dofs (x0, y0, x1, y1, x2, y2)."""
    return fem.element_stiffness("triangle", COORDS, "plane_stress")


@lru_cache(maxsize=None)
def K_mss():
    """Linearised stiffness of the six terms at rest (linear in the constants)."""
    return mss.stiffness_at_rest(terms(k, c), COORDS)


@lru_cache(maxsize=None)
def exact():
    return match.match_exact(K_fem(), K_mss(), list(k) + list(c))


# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", K_fem())
    show.matrix(r"K_{\text{MSS}}", K_mss())
    (s,) = exact().solutions
    show.solution(r"\text{solution}", {key: sp.factor(v) for key, v in s.items()})
    show.check(r"K_{\text{FEM}} - K_{\text{MSS}} = 0\ \text{for every triangle and every}\ \nu",
               (K_fem() - K_mss().subs(s)).applyfunc(sp.simplify) == sp.zeros(6, 6))
    show.check(r"\text{at rest the terms exert no force}", mss.forces_at_rest(terms(k, c), COORDS) == sp.zeros(6, 1))


# %% [markdown]
# On an equilateral triangle at nu = 1/3 the angular constants vanish and the tensile ones are the
# three springs of Lloyd's eq. 8 in biquadratic form: `k/2 (l - L)^2 = k / (8 L^2) D^2 + O(D^3)`,
# so `k_i = k / (2 L^2)` with Lloyd's `k` (`triangle.py`); the check below compares them (L = 1).

# %%
@lru_cache(maxsize=None)
def equilateral():
    s = exact().solutions[0]
    at = {a: 1, x2: sp.Rational(1, 2), y2: sp.sqrt(3) / 2, nu: sp.Rational(1, 3)}
    return {key: sp.simplify(v.subs(at)) for key, v in s.items()}


# %%
if __name__ == "__main__":
    from derivations.elements import triangle as lloyd

    k_lloyd = lloyd.exact().solutions[0][lloyd.k[0]]
    show.solution(r"\text{equilateral},\ \nu = 1/3", equilateral())
    show.check(r"c_{ij} = 0,\ k_i = k_{\text{Lloyd}} / (2 L^2)",
               all(equilateral()[cc] == 0 for cc in c) and all(sp.simplify(equilateral()[kk] - k_lloyd / 2) == 0 for kk in k))


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    sol = exact().solutions
    assert len(sol) == 1, sol
    s = sol[0]
    d = Derivation("triangle_angular", "Triangle of any shape with tensile and angular springs (Delingette 2008)")
    outputs = {str(key): sp.factor(s[key]) for key in list(k) + list(c)}
    d.formulas.append(Formula(
        "delingette_triangle", (E, nu, t, a, x2, y2), outputs,
        "Tensile constants k_ij (edge i-j) and angular constants c_ij_pq (edges i-j and p-q) of one "
        "triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, in the energy sum k/4 D^2 + sum c/2 D D "
        "(D = l^2 - L^2, squared lengths). Exact against the CST for every triangle and nu."))
    eq = equilateral()
    d.findings += [
        ("exact", "one exact match with the CST for every triangle and every Poisson ratio"),
        ("equilateral", ", ".join(f"{sp.latex(key)} = {sp.latex(v)}" for key, v in eq.items())),
    ]
    d.data.update(solution=s, equilateral=eq)
    return d


# %%
if __name__ == "__main__":
    d = show.summary(derive())

# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Triangle of any shape: three springs fitted to its own CST by least squares
#
# Three springs match the constant-strain triangle (CST) only on the equilateral triangle at
# nu = 1/3 (`triangle.py`). On an irregular mesh every triangle has its own shape: here the three
# spring constants of one triangle minimise the Frobenius distance ||K_CST - sum_e k_e K_e|| between
# its own CST stiffness (plane stress, thickness t) and the linearised stiffness of springs on its
# edges, for any triangle (node 0 at the origin, node 1 at `(a, 0)`, node 2 at `(x2, y2)`) and any
# Poisson's ratio. This is the closed-form counterpart of the per-element fit of Natsupakpong and
# Cavusoglu (2010, "Determination of elasticity parameters in lumped element (mass-spring) models
# of deformable objects", Graphical Models 72(6)).
#
# `K_e` is the stiffness at rest of a unit spring on edge `e`; the optimum solves the normal
# equations `G k = b`, `G_pq = <K_p, K_q>`, `b_p = <K_p, K_CST>`. Each entry is cancelled to one
# rational function of the shape, and the 3x3 system is solved by Cramer's rule on those entries
# without expanding them (the engine's `match.least_squares` simplifies the whole solution and takes
# minutes with the symbolic shape; the tests check it against this solution at rational shapes).
# `G` has 4 on its diagonal and the squared cosines of the angles between edges off it: it is
# diagonally dominant, so the solve is well conditioned for every non-degenerate triangle.

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, match, mss, show
from derivations.elasticity import E, nu, t
from derivations.records import Derivation, Element, Formula

ELEMENT = Element("triangle_lsq", cell="triangle", models=("lsq_triangle",),
                  source="Natsupakpong and Cavusoglu (2010), Graphical Models 72(6): per-element least squares, "
                         "closed form for any triangle")

a = sp.Symbol("a", positive=True)
x2 = sp.Symbol("x2", real=True)
y2 = sp.Symbol("y2", positive=True)
COORDS = [(0, 0), (a, 0), (x2, y2)]
EDGES = [(0, 1), (1, 2), (0, 2)]
k = sp.symbols("k_01 k_12 k_02", real=True)


# %% [markdown]
# ## The two stiffness matrices

# %%
@lru_cache(maxsize=None)
def K_fem():
    """6x6 plane-stress CST stiffness of the general triangle; dofs (x0, y0, x1, y1, x2, y2)."""
    return fem.element_stiffness("triangle", COORDS, "plane_stress")


@lru_cache(maxsize=None)
def K_mss():
    return sum((kk * K for kk, K in zip(k, mss.unit_springs(COORDS, EDGES))), sp.zeros(6, 6))


# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", K_fem())
    show.matrix(r"K_{\text{MSS}}", K_mss())


# %% [markdown]
# ## Normal equations and their solution

# %%
@lru_cache(maxsize=None)
def normal_equations():
    """(G, b): G_pq = <K_p, K_q> (geometry only), b_p = <K_p, K_CST>."""
    return match.normal_equations(mss.unit_springs(COORDS, EDGES), K_fem())


def cramer(G, b):
    """The solution of G x = b by Cramer's rule, entries of G and b kept as they are."""
    g = sp.Matrix(3, 3, lambda p, q: sp.Symbol(f"g{min(p, q)}{max(p, q)}"))
    r = sp.Matrix(sp.symbols("r0:3"))
    det = g.det()
    generic = [sp.factor(sp.Matrix.hstack(*[r if c == col else g[:, c] for c in range(3)]).det()) / det
               for col in range(3)]
    at = {g[p, q]: G[p, q] for p in range(3) for q in range(3)} | {r[p]: b[p] for p in range(3)}
    return [x.subs(at) for x in generic]


@lru_cache(maxsize=None)
def solution():
    return dict(zip(k, cramer(*normal_equations())))


@lru_cache(maxsize=None)
def equilateral(n=None):
    """The fit on the equilateral triangle of side ``a`` (at Poisson's ratio ``n``, default free)."""
    at = {x2: a / 2, y2: sp.sqrt(3) * a / 2}
    if n is not None:
        at[nu] = n
    G, b = (M.subs(at) for M in normal_equations())
    return {kk: sp.factor(sp.radsimp(v)) for kk, v in zip(k, cramer(G, b))}


# %%
if __name__ == "__main__":
    G, b = normal_equations()
    show.matrix("G", G)
    show.matrix("b", b)
    show.solution(r"k = G^{-1} b", solution())
    eq = equilateral()
    show.solution(r"\text{equilateral}", eq)
    show.check(r"\text{equilateral},\ \nu = 1/3:\ k = \frac{\sqrt{3}}{4} E t\ \text{(Lloyd eq. 8)}",
               all(sp.simplify(v - sp.sqrt(3) / 4 * E * t) == 0 for v in equilateral(sp.Rational(1, 3)).values()))


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    s = solution()
    d = Derivation("triangle_lsq", "Triangle of any shape, three springs fitted to its own CST by least squares "
                                   "(Natsupakpong and Cavusoglu 2010, closed form)")
    d.formulas.append(Formula(
        "lsq_triangle", (E, nu, t, a, x2, y2), {str(kk): s[kk] for kk in k},
        "Spring constants k_ij (edge i-j, N/m) of one triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, "
        "minimising the Frobenius distance of the springs' stiffness at rest from the triangle's own "
        "plane-stress CST (thickness t); per element (sum over the triangles sharing an edge). Exact only on "
        "the equilateral triangle at nu = 1/3; can be negative for obtuse triangles."))
    eq = equilateral()
    d.findings += [
        ("equilateral", ",\\ ".join(f"{sp.latex(kk)} = {sp.latex(sp.factor(v))}" for kk, v in eq.items())),
        ("equilateral at nu = 1/3", ",\\ ".join(f"{sp.latex(kk)} = {sp.latex(v)}"
                                                for kk, v in equilateral(sp.Rational(1, 3)).items())),
    ]
    d.data.update(solution=s, equilateral=eq)
    return d


# %%
if __name__ == "__main__":
    d = show.summary(derive())

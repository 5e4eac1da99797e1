# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Square: bilinear plane-stress element against 4 edge + 2 diagonal springs with prestrain
#
# Lloyd et al. (2007), Sec. 4.1, eqs. 10-11. Poisson's ratio is a condition symbol; the springs'
# constants and rest-length factors (rest length = c x the rest distance) are the unknowns.

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, lattice, match, mss, show
from derivations.elasticity import E, elasticity_matrix, nu, t
from derivations.records import Derivation, Element, Formula

# what this module derives and which simulator models the generated code feeds (derivations.registry)
ELEMENT = Element("square", cell="quad", models=("lloyd_square",),
                  source="Lloyd et al. (2007), Sec. 4.1, eqs. 10-11")

a = sp.Symbol("a", positive=True)
nu_c = sp.Symbol("nu_c", real=True)
k_e, k_d, c_e, c_d = sp.symbols("k_e k_d c_e c_d", real=True)
COORDS = [(0, 0), (a, 0), (a, a), (0, a)]
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0)]
DIAGONALS = [(0, 2), (1, 3)]


def springs(ke, kd, ce=1, cd=1):
    return ([mss.spring(i, j, ke, ce, name=f"spring_edge({i},{j})") for i, j in EDGES]
            + [mss.spring(i, j, kd, cd, name=f"spring_diagonal({i},{j})") for i, j in DIAGONALS])


@lru_cache(maxsize=None)
def K_fem():
    return fem.element_stiffness("quad", COORDS, "plane_stress").subs(nu, nu_c)


# %% [markdown]
# ## Without prestrain: no exact match for any Poisson's ratio

# %%
@lru_cache(maxsize=None)
def without_prestrain():
    return match.match_exact(K_fem(), mss.stiffness_at_rest(springs(k_e, k_d), COORDS), (k_e, k_d), (nu_c,))


# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", K_fem())
    show.matrix(r"K_{\text{MSS}}", mss.stiffness_at_rest(springs(k_e, k_d), COORDS), what="springs without prestrain")
    show.equations(r"K_{\text{FEM}} = K_{\text{MSS}}", without_prestrain().equations)
    show.check(r"\text{no solution}\ (k_e, k_d, \nu)", not without_prestrain().exists)


# %% [markdown]
# ## With prestrain: the exact match and its conditions

# %%
@lru_cache(maxsize=None)
def with_prestrain():
    return match.match_exact(K_fem(), mss.stiffness_at_rest(springs(k_e, k_d, c_e, c_d), COORDS),
                             (k_e, k_d, c_e, c_d), (nu_c,))


# %%
if __name__ == "__main__":
    K_pre = mss.stiffness_at_rest(springs(k_e, k_d, c_e, c_d), COORDS)
    show.matrix(r"K_{\text{MSS}}", K_pre, what="prestrained springs, rest length c times the rest distance")
    show.equations(r"K_{\text{FEM}} = K_{\text{MSS}}", with_prestrain().equations)
    (s,) = with_prestrain().solutions
    show.solution(r"\text{solution}", s)
    show.matrix(r"K_{\text{FEM}} = K_{\text{MSS}}", K_fem().subs(s).applyfunc(sp.simplify), what="at the solution")
    show.check(r"K_{\text{FEM}} - K_{\text{MSS}} = 0\ \text{at the solution}",
               (K_fem() - K_pre).subs(s).applyfunc(sp.simplify) == sp.zeros(8, 8))


# %% [markdown]
# ## Equilibrium at rest and the lattice check
#
# The prestrained element is in equilibrium at rest (net force zero at every node) although every
# spring carries a force: edges are compressed, diagonals stretched, self-equilibrated.

# %%
def _tension_tex(name: str) -> str:
    """LaTeX of a spring's tension, from its term name: spring_edge(0,1) -> T_{\\text{edge}\\,(0,1)}
    (the name's words as text, not as subscripts)."""
    kind, _, nodes = name.partition("(")
    return f"T_{{\\text{{{kind.removeprefix('spring_')}}}\\,({nodes}}}"


@lru_cache(maxsize=None)
def derive() -> Derivation:
    sols = with_prestrain().solutions
    assert len(sols) == 1, sols
    s = sols[0]
    terms = springs(s[k_e], s[k_d], s[c_e], s[c_d])
    f_rest = mss.forces_at_rest(terms, COORDS)
    tensions = mss.spring_tensions_at_rest(terms, COORDS)
    C, sigma0 = lattice.effective_tensor(terms, COORDS, a**2 * t)
    d = Derivation("square", "Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11)")
    d.formulas.append(Formula(
        "lloyd_square", (E, t),
        {"k_edge": s[k_e], "k_diagonal": s[k_d], "rest_factor_edge": s[c_e], "rest_factor_diagonal": s[c_d]},
        "Per-element constants of the square: edge springs (sum over the squares sharing the edge) and "
        "diagonal springs, with rest length = factor x rest distance. Exact for nu = 1/3."))
    d.findings += [
        ("without prestrain", "\\text{no exact match for any}\\ \\nu" if not without_prestrain().exists else str(without_prestrain().solutions)),
        ("conditions", f"\\nu = {sp.latex(s[nu_c])}"),
        ("k_edge", sp.latex(s[k_e])), ("k_diagonal", sp.latex(s[k_d])),
        ("rest factors", f"c_e = {sp.latex(s[c_e])},\\ c_d = {sp.latex(s[c_d])}"),
        ("net force at rest", "zero at every node" if f_rest == sp.zeros(*f_rest.shape) else sp.latex(f_rest.T)),
        ("spring forces at rest", ",\\ ".join(f"{_tension_tex(n)} = {sp.latex(v)}" for n, v in tensions.items())),
        ("lattice", sp.latex(C)),
    ]
    d.data.update(solution=s, forces_at_rest=f_rest, tensions=tensions, lattice=C, sigma0=sigma0,
                  no_prestrain=without_prestrain())
    printed = {k_e: sp.Rational(5, 16) * t * E, k_d: sp.Rational(7, 16) * t * E, c_e: sp.Rational(6, 5),
               c_d: sp.Rational(6, 7)}  # Lloyd eqs. 10-11 as printed
    d.checks.update(exact_with_prestrain=len(sols), exact_nu=float(s[nu_c]),
                    exact_without_prestrain=int(bool(without_prestrain().exists)),
                    eqs10_11_match_printed=int(all(sp.simplify(s[q] - v) == 0 for q, v in printed.items())),
                    equilibrium_at_rest=int(f_rest == sp.zeros(*f_rest.shape)))
    return d


# %%
if __name__ == "__main__":
    d = derive()
    show.math(r"f_{\text{rest}}^T", d.data["forces_at_rest"].T)
    show.solution(r"\text{spring tensions at rest}", {sp.Symbol(_tension_tex(n)): v for n, v in d.data["tensions"].items()})
    show.math(r"C_{\text{lattice}}", d.data["lattice"])
    show.math(r"\sigma_0^T", d.data["sigma0"].T)
    show.check(r"C_{\text{lattice}} = D_{\text{plane stress}}(\nu = 1/3)",
               (d.data["lattice"] - elasticity_matrix("plane_stress", E, sp.Rational(1, 3))).applyfunc(sp.simplify) == sp.zeros(3, 3))


# %%
if __name__ == "__main__":
    d = show.summary(derive())
    s = d.data["solution"]
    pub = {k_e: 5 * E * t / 16, k_d: 7 * E * t / 16, c_e: sp.Rational(6, 5), c_d: sp.Rational(6, 7)}
    print("  eqs. 10-11 reproduced:", all(sp.simplify(s[key] - v) == 0 for key, v in pub.items()))
    print("  lattice = plane stress at nu = 1/3:",
          sp.simplify(d.data["lattice"] - elasticity_matrix("plane_stress", E, sp.Rational(1, 3))) == sp.zeros(3, 3))

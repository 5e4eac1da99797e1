# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Triangle: plane-stress CST against three springs
#
# Lloyd et al. (2007), Sec. 3: equate the stiffness matrix of the constant-strain triangle with the
# linearised stiffness of three springs. Here node 0 is at the origin, node 1 on the x-axis at
# distance `a`, node 2 anywhere above the axis at `(x2, y2)`, and Poisson's ratio is left free: the
# conditions of an exact match (nu = 1/3, equilateral) come out of the equations.

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, lattice, match, mss, show
from derivations.elasticity import E, elasticity_matrix, nu, t
from derivations.records import Derivation, Element, Erratum, Formula

# what this module derives and which simulator models the generated code feeds (derivations.registry)
ELEMENT = Element("triangle", cell="triangle", models=("lloyd_triangle", "van_gelder"),
                  source="Lloyd et al. (2007), Sec. 3; van Gelder (1998)")

a = sp.Symbol("a", positive=True)
x2 = sp.Symbol("x2", real=True)
y2 = sp.Symbol("y2", positive=True)
nu_c = sp.Symbol("nu_c", real=True)  # Poisson's ratio as a condition symbol (any real value)
k = sp.symbols("k_01 k_12 k_02", real=True)
PAIRS = [(0, 1), (1, 2), (0, 2)]


def springs(ks):
    return [mss.spring(i, j, kk) for (i, j), kk in zip(PAIRS, ks)]


# %% [markdown]
# ## Exact match

# %%
COORDS = [(0, 0), (a, 0), (x2, y2)]


@lru_cache(maxsize=None)
def K_fem():
    """6x6 plane-stress CST stiffness, nu free (``nu_c``); dofs (x0, y0, x1, y1, x2, y2)."""
    return fem.element_stiffness("triangle", COORDS, "plane_stress").subs(nu, nu_c)


@lru_cache(maxsize=None)
def K_mss():
    """Linearised stiffness of the three springs at rest."""
    return mss.stiffness_at_rest(springs(k), COORDS)


@lru_cache(maxsize=None)
def exact():
    return match.match_exact(K_fem(), K_mss(), k, (nu_c, x2, y2))


# %% [markdown]
# The two matrices, the equations K_FEM = K_MSS (numerators of the entries' differences), their only
# solution, and both matrices at that solution.

# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", K_fem())
    show.matrix(r"K_{\text{MSS}}", K_mss())
    show.equations(r"K_{\text{FEM}} = K_{\text{MSS}}", exact().equations)
    (s,) = exact().solutions
    show.solution(r"\text{solution}", s)
    K_at = K_fem().subs(s).applyfunc(sp.simplify)
    show.matrix(r"K_{\text{FEM}} = K_{\text{MSS}}", K_at)
    show.check(r"K_{\text{FEM}} - K_{\text{MSS}} = 0\ \text{at the solution}",
               (K_at - K_mss().subs(s)).applyfunc(sp.simplify) == sp.zeros(6, 6))
    show.check(r"k = \frac{\sqrt{3}}{4} E t\ \text{(Lloyd eq. 8)}", sp.simplify(s[k[0]] - sp.sqrt(3) / 4 * E * t) == 0)


# %% [markdown]
# ## Van Gelder's formula, and the lattice check
#
# Van Gelder: k = sum_e E t A_e / l^2. For an equilateral triangle A_e = sqrt(3)/4 l^2, so his
# constant equals Lloyd's eq. 8; Lloyd's eq. 9 writes it as sqrt(3)/4 E t A_e / A_0.

# %%
A_e, l = sp.symbols("A_e l", positive=True)
VAN_GELDER = E * t * A_e / l**2
LLOYD_EQ9 = sp.sqrt(3) / 4 * E * t * A_e / (sp.sqrt(3) / 4 * l**2)


@lru_cache(maxsize=None)
def lattice_check():
    """Elastic tensor of the equilateral triangular lattice with the derived constant."""
    kk = exact().solutions[0][k[0]]
    coords = [(0, 0), (a, 0), (a / 2, sp.sqrt(3) * a / 2)]
    C, s0 = lattice.effective_tensor(springs([kk] * 3), coords, sp.sqrt(3) / 4 * a**2 * t)
    return C, s0


# %%
if __name__ == "__main__":
    show.check(r"k_{\text{van Gelder}} = \frac{\sqrt{3}}{4} E t \frac{A_e}{A_0}\ \text{(Lloyd eq. 9)}",
               sp.simplify(VAN_GELDER - LLOYD_EQ9) == 0)
    C_lat, s0_lat = lattice_check()
    show.math(r"C_{\text{lattice}}", C_lat)
    show.check(r"C_{\text{lattice}} = D_{\text{plane stress}}(\nu = 1/3)",
               (C_lat - elasticity_matrix("plane_stress", E, sp.Rational(1, 3))).applyfunc(sp.simplify) == sp.zeros(3, 3))


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    sol = exact().solutions
    assert len(sol) == 1, sol
    s = sol[0]
    k_tri = s[k[0]]
    C, _ = lattice_check()
    d = Derivation("triangle", "Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9)")
    d.formulas.append(Formula("lloyd_triangle", (E, t), {"k": k_tri},
                              "Spring constant of each edge of an equilateral triangle, per element "
                              "(sum over the triangles sharing the edge). Exact for nu = 1/3."))
    d.formulas.append(Formula("van_gelder_triangle", (E, t, A_e, l), {"k": VAN_GELDER},
                              "Van Gelder's spring constant, per element: E t A_e / l^2."))
    d.findings += [
        ("conditions", f"\\nu = {sp.latex(s[nu_c])},\\ x_2 = {sp.latex(s[x2])},\\ y_2 = {sp.latex(s[y2])}"),
        ("k", sp.latex(k_tri)),
        ("lattice", sp.latex(C)),
    ]
    d.data.update(solution=s, lattice=C, van_gelder=VAN_GELDER, lloyd_eq9=LLOYD_EQ9)
    d.checks.update(
        eq8_matches_printed=int(sp.simplify(k_tri - sp.sqrt(3) / 4 * E * t) == 0),  # Lloyd eq. 8 as printed
        exact_solutions=len(sol), exact_nu=float(s[nu_c]),
        exact_at_nu_0=int(any(so[nu_c] == 0 for so in sol)),  # van Gelder's validity claim
        lattice_is_plane_stress_at_one_third=int((C - elasticity_matrix("plane_stress", E, sp.Rational(1, 3)))
                                                 .applyfunc(sp.simplify) == sp.zeros(3, 3)))
    d.errata.append(Erratum(
        "van Gelder (1998), as discussed by Lloyd et al. Sec. 3.5", "validity of k = E t A_e / l^2",
        r"\nu = 0", r"\nu = 1/3",
        "The only exact match of three springs with the CST needs nu = 1/3 and an equilateral triangle; "
        "van Gelder's claim of validity at nu = 0 is false (Lloyd et al. say so too; the derivation proves it).",
        "tests/test_derivations.py::test_triangle_conditions"))
    return d


# %%
if __name__ == "__main__":
    show.summary(derive())

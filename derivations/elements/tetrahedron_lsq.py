# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Tetrahedron of any shape: six springs fitted to its own linear element by least squares
#
# Lloyd et al. fit one spring constant to the regular tetrahedron (`tetrahedron.py`) and use it
# for every shape through an equivalent edge length. Here the six spring constants of one
# tetrahedron of any shape minimise the Frobenius distance ||K_FEM - sum_e k_e K_e|| between its own
# linear-tetrahedron stiffness and the linearised stiffness of springs on its edges (the per-element
# fit of Natsupakpong and Cavusoglu, 2010, "Determination of elasticity parameters in lumped element
# (mass-spring) models of deformable objects", Graphical Models 72(6)). A closed form of the 6x6
# solve is too large to be useful; what is generated are the normal equations `G k = b`,
# `G_pq = <K_p, K_q>`, `b_p = <K_p, K_FEM>` (`K_e` the stiffness at rest of a unit spring on edge
# `e`), as rational functions of `E`, `nu` and the shape in its own frame (node 0 at the origin, node
# 1 at `(a, 0, 0)`, node 2 at `(x2, y2, 0)`, node 3 at `(x3, y3, z3)`, `y2, z3 > 0`: springs and
# element are invariant under rotation, so six numbers fix the fit); the simulator solves them per
# element. `G` is the same as for the triangle: 4 on the diagonal, the
# squared cosine of the angle between two edges sharing a node, 0 for opposite edges.

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, match, mss, show
from derivations.elasticity import E, nu
from derivations.records import Derivation, Element, Formula

ELEMENT = Element("tetrahedron_lsq", cell="tetra", models=("lsq_tetrahedron",),
                  source="Natsupakpong and Cavusoglu (2010), Graphical Models 72(6): per-element least squares, "
                         "normal equations for any tetrahedron", extends="tetrahedron")

a = sp.Symbol("a", positive=True)
x2, x3, y3 = sp.symbols("x2 x3 y3", real=True)
y2, z3 = sp.symbols("y2 z3", positive=True)
X = (a, x2, y2, x3, y3, z3)
COORDS = [(0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3)]
EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]  # the order of k_0 .. k_5
k = sp.symbols("k_0:6", real=True)


# %% [markdown]
# ## The two stiffness matrices

# %%
@lru_cache(maxsize=None)
def K_fem():
    """12x12 stiffness of the linear tetrahedron in its own frame (positively oriented: z3 > 0)."""
    return fem.element_stiffness("tetra", COORDS, "3d")


# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", K_fem(), rows=slice(0, 6), cols=slice(0, 6),
                what="the linear tetrahedron, nodes 0 and 1")
    show.matrix(r"K_{01}", mss.unit_springs(COORDS, EDGES[:1])[0], rows=slice(0, 6), cols=slice(0, 6),
                what="a unit spring on edge 0-1, nodes 0 and 1")


# %% [markdown]
# ## Normal equations

# %%
@lru_cache(maxsize=None)
def normal_equations():
    """(G, b): G_pq = <K_p, K_q> (geometry only), b_p = <K_p, K_FEM>."""
    return match.normal_equations(mss.unit_springs(COORDS, EDGES), K_fem())


REGULAR = {a: 1, x2: sp.Rational(1, 2), y2: sp.sqrt(3) / 2, x3: sp.Rational(1, 2), y3: sp.sqrt(3) / 6,
           z3: sp.sqrt(sp.Rational(2, 3))}


@lru_cache(maxsize=None)
def regular():
    """The fit on the regular tetrahedron of unit edge (any nu): six equal constants."""
    G, b = (M.subs(REGULAR).applyfunc(sp.radsimp) for M in normal_equations())
    return [sp.factor(sp.radsimp(v)) for v in G.LUsolve(b)]


# %%
if __name__ == "__main__":
    G, b = normal_equations()
    show.matrix("G", G)
    show.math("b_0", b[0])
    show.solution(r"\text{regular, unit edge}", dict(zip(k, regular())))


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    G, b = normal_equations()
    d = Derivation("tetrahedron_lsq", "Tetrahedron of any shape, six springs fitted to its own linear element by "
                                      "least squares (Natsupakpong and Cavusoglu 2010, normal equations)")
    doc = ("of one tetrahedron with nodes (0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3), y2 > 0, z3 > 0 "
           "(positively oriented); edges 0-1, 0-2, 0-3, 1-2, 1-3, 2-3. The per-element spring constants "
           "(N/m, summed over the tetrahedra sharing an edge) solve G k = b.")
    d.formulas += [
        Formula("lsq_tetrahedron_gram", X, {f"G_{p}{q}": G[p, q] for p in range(6) for q in range(p, 6)},
                "Gram matrix G_pq = <K_p, K_q> (upper triangle, dimensionless) of the unit springs " + doc),
        Formula("lsq_tetrahedron_rhs", (E, nu) + X, {f"b_{p}": b[p] for p in range(6)},
                "Right-hand side b_p = <K_p, K_FEM> (N/m) " + doc),
    ]
    reg = regular()
    d.findings += [("regular tetrahedron, edge l", f"k_e = {sp.latex(sp.factor(reg[0] * sp.Symbol('l')))}")]
    d.data.update(regular=reg)
    return d


# %%
if __name__ == "__main__":
    d = show.summary(derive())

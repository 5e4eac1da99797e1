# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Rectangle of any aspect ratio: bilinear plane-stress element against six prestrained springs
#
# Lloyd et al. (2007), Sec. 4.1, match the bilinear square with four edge springs and two diagonal
# springs whose rest lengths are a factor `c` times the rest distance (prestrain), and find
# k_edge = 5/16 E t, k_diag = 7/16 E t, c_edge = 6/5, c_diag = 6/7 at nu = 1/3. Here the element
# is a rectangle with sides `a` (along x) and `b = r a` (along y), every spring family has its own
# constant and rest factor (horizontal edges k_h, c_h; vertical edges k_v, c_v; diagonals k_d, c_d),
# and Poisson's ratio and the aspect ratio are condition symbols: the conditions of an exact match
# come out of the equations. Where no exact match exists, the least-squares optimum (Lloyd's
# criterion, Frobenius distance of the stiffness matrices) is derived in closed form in `r`.
#
# Nodes in VTK order: 0 = (0, 0), 1 = (a, 0), 2 = (a, b), 3 = (0, b).

# %%
from functools import lru_cache

import sympy as sp

from derivations import element_stiffness as fem, lattice, match, mss, show
from derivations.elasticity import E, elasticity_matrix, nu, t
from derivations.records import Derivation, Element, Formula

# what this module derives and which simulator models the generated code feeds (derivations.registry)
ELEMENT = Element("rectangle", cell="quad", models=("lloyd_rectangle",),
                  source="extends Lloyd et al. (2007), Sec. 4.1, to any aspect ratio", extends="square")

a = sp.Symbol("a", positive=True)
r = sp.Symbol("r", positive=True)  # aspect ratio b / a
b = r * a
nu_c = sp.Symbol("nu_c", real=True)  # Poisson's ratio as a condition symbol (any real value)
NU_LLOYD = sp.Rational(1, 3)

FAMILIES = ("h", "v", "d")
EDGES = {"h": [(0, 1), (3, 2)], "v": [(1, 2), (0, 3)], "d": [(0, 2), (1, 3)]}
K_SYM = sp.symbols("k_h k_v k_d", real=True)  # spring constants, per element
C_SYM = sp.symbols("c_h c_v c_d", real=True)  # rest length = c * rest distance
# the at-rest stiffness of a prestrained spring is k [(1 - c) I + c n n^T] = q I + p n n^T:
# linear in p = k c and q = k (1 - c); k = p + q, c = p / (p + q)
P_SYM = sp.symbols("p_h p_v p_d", real=True)
Q_SYM = sp.symbols("q_h q_v q_d", real=True)
COORDS = [(0, 0), (a, 0), (a, b), (0, b)]


def springs(ks, cs=(1, 1, 1)):
    """The six springs of the element: family f has constant ks[f] and rest factor cs[f]."""
    out = []
    for f, kk, cc in zip(FAMILIES, ks, cs):
        out += [mss.spring(i, j, kk, cc, name=f"spring_{f}({i},{j})") for i, j in EDGES[f]]
    return out


def linear_springs(ps, qs):
    """The same springs in the (p, q) parametrisation, in which the stiffness at rest is linear."""
    return springs([p + q for p, q in zip(ps, qs)], [p / (p + q) for p, q in zip(ps, qs)])


@lru_cache(maxsize=None)
def stiffness_fem():
    """8x8 plane-stress bilinear element stiffness, nu free (``nu_c``)."""
    return fem.element_stiffness("quad", COORDS, "plane_stress").subs(nu, nu_c)


@lru_cache(maxsize=None)
def stiffness_mss():
    """Linearised stiffness of the six prestrained springs at rest, in (k, c)."""
    return mss.stiffness_at_rest(springs(K_SYM, C_SYM), COORDS)


@lru_cache(maxsize=None)
def stiffness_mss_linear():
    """The same in (p, q): substituting k = p + q, c = p / (p + q) makes every entry linear."""
    sub = {}
    for k_, c_, p, q in zip(K_SYM, C_SYM, P_SYM, Q_SYM):
        sub.update({k_: p + q, c_: p / (p + q)})
    return stiffness_mss().subs(sub).applyfunc(sp.cancel)


# %% [markdown]
# ## Exact match
#
# Unknowns (k_h, k_v, k_d, c_h, c_v, c_d), conditions (nu, r). A Gröbner basis of the same
# equations (over Q(E, t)) certifies the outcome: for the prestrained springs it is triangular,
# ending in r^4 = 1 and nu = 1/3, so r = 1 (r > 0) is the only aspect ratio; without prestrain it is
# {1}, i.e. the equations are inconsistent for every nu and r.

# %%
@lru_cache(maxsize=None)
def exact():
    return match.match_exact(stiffness_fem(), stiffness_mss(), K_SYM + C_SYM, (nu_c, r))


@lru_cache(maxsize=None)
def exact_without_prestrain():
    K = stiffness_mss().subs({c_: 1 for c_ in C_SYM})
    return match.match_exact(stiffness_fem(), K, K_SYM, (nu_c, r))


@lru_cache(maxsize=None)
def groebner_certificate(prestrain: bool = True):
    """Lex Gröbner basis of the exact-match equations, unknowns before (nu, r)."""
    m = exact() if prestrain else exact_without_prestrain()
    return sp.groebner(m.equations, *(m.unknowns + m.conditions), order="lex", domain=sp.QQ.frac_field(E, t))


@lru_cache(maxsize=None)
def zero_entry_conditions():
    """Without prestrain, the entries where K_mss is structurally zero but K_fem is not: each gives a
    condition on (nu, r) alone."""
    out = []
    for e in exact_without_prestrain().equations:
        if e.free_symbols.isdisjoint(K_SYM):
            cond = sp.factor(e / (E * t))
            if cond not in out and -cond not in out:
                out.append(cond)
    return out


# %%
if __name__ == "__main__":
    show.matrix(r"K_{\text{FEM}}", stiffness_fem())
    show.matrix(r"K_{\text{MSS}}", stiffness_mss(), what="six prestrained springs")
    show.equations(r"K_{\text{FEM}} = K_{\text{MSS}}", exact().equations)
    (s_exact,) = exact().solutions
    show.solution(r"\text{solution}", s_exact)
    show.equations(r"\text{Gröbner basis, last two elements}", groebner_certificate(True).exprs[-2:])
    show.check(r"K_{\text{FEM}} - K_{\text{MSS}} = 0\ \text{at the solution}",
               (stiffness_fem() - stiffness_mss()).subs(s_exact).applyfunc(sp.simplify) == sp.zeros(8, 8))
    show.math(r"\text{Gröbner basis without prestrain}", r"\{" + r",\ ".join(sp.latex(g) for g in groebner_certificate(False).exprs) + r"\}")
    show.equations(r"\text{without prestrain, structural zeros of}\ K_{\text{MSS}}\ \text{demand}", zero_entry_conditions())


# %% [markdown]
# ## Least squares, in a symmetry-adapted frame
#
# The Frobenius distance is invariant under K -> S^T K S with S orthogonal. S below is the
# symmetry-adapted basis of the rectangle's two mirror planes (displacement patterns
# u_x ~ sign(x), u_y ~ sign(y), ... with entries +-1/2): both matrices become block diagonal
# (two 2x2 blocks, two 1x1 blocks, two zero rows of the translations). In that frame the image of
# the six spring parameters misses the FEM matrix in exactly two directions: one combination of the
# block entries (which vanishes for the square), and the difference of the two off-diagonal entries
# (which vanishes at nu = 1/3).
#
# `match.least_squares` simplifies the LU solution of its normal equations, which with symbolic r
# takes over a minute. Orthogonalising the unknowns first (Gram-Schmidt of the basis matrices
# dK/d(unknown), a linear change of unknowns that leaves the minimiser unchanged) makes its Gram
# matrix diagonal, and the engine then solves it in a few seconds.
#
# Equilibrium at rest: a prestrained spring pulls with its tension k (1 - c) L = q L at rest, so the
# element is in equilibrium only if the tensions balance at every node. `mss.forces_at_rest` in
# (p, q) gives that condition, q_h = q_v = -q_d (linear); the least squares is done once freely and
# once restricted to it. A free fit that is not in equilibrium means that a mesh of such elements,
# left alone, does not stay in its rest shape: interior forces of neighbouring elements cancel in a
# regular grid, but the boundary nodes carry unbalanced forces (a residual stress sigma_0 of the
# lattice), so a simulator would see the object deform without load unless it applies the opposite
# boundary forces.

# %%
def _pattern(component, sx, sy):
    v = sp.zeros(8, 1)
    for node, (x, y) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)]):
        v[2 * node + component] = sp.Rational(x**sx * y**sy, 2)
    return v


# columns: (u_x ~ x, u_y ~ y), (u_x ~ y, u_y ~ x), (u_x = 1, u_y ~ xy), (u_y = 1, u_x ~ xy)
SYMMETRY_BASIS = sp.Matrix.hstack(
    _pattern(0, 1, 0), _pattern(1, 0, 1), _pattern(0, 0, 1), _pattern(1, 1, 0),
    _pattern(0, 0, 0), _pattern(1, 1, 1), _pattern(1, 0, 0), _pattern(0, 1, 1))
assert SYMMETRY_BASIS.T * SYMMETRY_BASIS == sp.eye(8)


def to_symmetry_frame(K):
    return (SYMMETRY_BASIS.T * K * SYMMETRY_BASIS).applyfunc(sp.factor)


def _frobenius(A, B):
    return sp.factor(sum(x * y for x, y in zip(A, B)))


def orthogonal_unknowns(K, unknowns, prefix="theta"):
    """Rewrite K (linear and homogeneous in ``unknowns``) as sum_i theta_i B_i with Frobenius-orthogonal
    B_i (Gram-Schmidt). Returns (K(theta), theta, {unknown: linear expression in theta})."""
    basis = [K.applyfunc(lambda e, u=u: sp.diff(e, u)) for u in unknowns]
    assert K.subs({u: 0 for u in unknowns}) == sp.zeros(*K.shape)
    ortho, L = [], sp.eye(len(unknowns))  # basis[i] = sum_j L[i, j] ortho[j]
    for i, B in enumerate(basis):
        Bo = B
        for j, O in enumerate(ortho):
            L[i, j] = sp.factor(_frobenius(B, O) / _frobenius(O, O))
            Bo = Bo - L[i, j] * O
        ortho.append(Bo.applyfunc(sp.factor))
    theta = sp.symbols(f"{prefix}1:{len(unknowns) + 1}", real=True)
    # sum_i u_i basis_i = sum_j theta_j ortho_j  <=>  theta = L^T u
    u_of_theta = (L.T).LUsolve(sp.Matrix(theta)).applyfunc(sp.factor)
    K_theta = sum((th * O for th, O in zip(theta, ortho)), sp.zeros(*K.shape))
    return K_theta, theta, dict(zip(unknowns, u_of_theta))


@lru_cache(maxsize=None)
def forces_linear():
    """Net nodal forces at rest in (p, q): the tension of a spring at rest is k (1 - c) L = q L."""
    return mss.forces_at_rest(linear_springs(P_SYM, Q_SYM), COORDS).applyfunc(sp.cancel)


@lru_cache(maxsize=None)
def equilibrium_condition():
    """Linear conditions on q under which the element is in equilibrium at rest (from the forces)."""
    sol = sp.solve(list(forces_linear()), Q_SYM[:2], dict=True)
    assert len(sol) == 1, sol
    return sol[0]


@lru_cache(maxsize=None)
def least_squares_fit(nu_value=NU_LLOYD, equilibrium=False):
    """Least-squares springs for aspect ratio r at Poisson's ratio ``nu_value`` (a number or nu_c).

    ``equilibrium=True`` restricts the fit to elements in equilibrium at rest. Returns a dict with
    the engine's ``LeastSquares`` (in the orthogonalised unknowns; for a symbolic nu it is fitted to
    K_fem / s with s = E t / (1 - nu^2): the minimiser is linear in K_fem, and dividing out the common
    factor keeps sympy's simplification fast) and p, q, k, c per family, residual, relative residual.
    """
    K_m = stiffness_mss_linear()
    unknowns = list(P_SYM + Q_SYM)
    if equilibrium:
        K_m = K_m.subs(equilibrium_condition()).applyfunc(sp.cancel)
        unknowns = [u for u in unknowns if u not in equilibrium_condition()]
    scale = sp.Integer(1) if sp.sympify(nu_value).is_number else E * t / (1 - nu_value**2)
    F = to_symmetry_frame(stiffness_fem().subs(nu_c, nu_value) / scale)
    M = to_symmetry_frame(K_m)
    M_theta, theta, u_of_theta = orthogonal_unknowns(M, unknowns)
    ls = match.least_squares(F, M_theta, theta)
    pq = {u: sp.factor(scale * e.subs(ls.solution)) for u, e in u_of_theta.items()}
    if equilibrium:
        pq.update({q_: sp.factor(v.subs(pq)) for q_, v in equilibrium_condition().items()})
    p = [pq[s] for s in P_SYM]
    q = [pq[s] for s in Q_SYM]
    k = [sp.factor(pp + qq) for pp, qq in zip(p, q)]
    c = [sp.factor(pp / kk) for pp, kk in zip(p, k)]
    return dict(ls=ls, scale=scale, p=p, q=q, k=k, c=c, pq=pq, residual=sp.factor(scale**2 * ls.residual),
                relative_residual=sp.factor(ls.relative_residual))


def forces(fit):
    """Net nodal forces of one element with the fitted springs, at rest."""
    return forces_linear().subs(fit["pq"]).applyfunc(sp.factor)


def positivity_interval(fit):
    """The interval of r around the square (r = 1, where all are positive) in which every k and c of
    the fit stays positive: bounded by the nearest positive roots of their numerators and denominators."""
    roots = set()
    for e in fit["k"] + fit["c"]:
        for part in sp.fraction(sp.together(e / (E * t) if e.has(E) else e)):
            if part.has(r):
                roots |= {x for x in sp.Poly(part, r).nroots() if x.is_real and x > 0}
    lo = max((x for x in roots if x < 1), default=sp.Integer(0))
    hi = min((x for x in roots if x > 1), default=sp.oo)
    return lo, hi


# %%
if __name__ == "__main__":
    show.matrix(r"S^T K_{\text{FEM}} S", to_symmetry_frame(stiffness_fem()), what="the FEM matrix in the symmetry-adapted frame")
    show.matrix(r"S^T K_{\text{MSS}} S", to_symmetry_frame(stiffness_mss_linear()), what="the springs in (p, q)")
    show.solution(r"\text{equilibrium at rest}", equilibrium_condition())
    for label, eq in ((r"\text{least squares}\ (\nu = 1/3)", False), (r"\text{least squares in equilibrium}\ (\nu = 1/3)", True)):
        fit_ = least_squares_fit(NU_LLOYD, eq)
        show.solution(label, {**dict(zip(K_SYM, fit_["k"])), **dict(zip(C_SYM, fit_["c"]))})
        show.math(r"\epsilon_{\text{rel}}(r)", fit_["relative_residual"])
        show.check(r"\nabla \lVert K_{\text{FEM}} - K_{\text{MSS}} \rVert_F^2 = 0\ \text{at the optimum}",
                   all(sp.simplify(g) == 0 for g in fit_["ls"].gradient))
    show.math(r"f_{\text{rest}}^T\ \text{(free fit)}", forces(least_squares_fit(NU_LLOYD)).T)


# %% [markdown]
# ## Lattice check
#
# Tile the plane with the rectangle (cell volume a b t) and strain it homogeneously. The rectangular
# lattice has inversion symmetry at every node, so the affine deformation is its equilibrium.

# %%
@lru_cache(maxsize=None)
def lattice_linear():
    """(C, sigma0) of the lattice in (p, q); the fits are substituted into it."""
    C, sigma0 = lattice.effective_tensor(linear_springs(P_SYM, Q_SYM), COORDS, a * b * t)
    return C.applyfunc(sp.cancel), sigma0.applyfunc(sp.cancel)


@lru_cache(maxsize=None)
def lattice_check(equilibrium=False):
    fit = least_squares_fit(NU_LLOYD, equilibrium)
    C, sigma0 = lattice_linear()
    return C.subs(fit["pq"]).applyfunc(sp.factor), sigma0.subs(fit["pq"]).applyfunc(sp.factor)


def lattice_agreement(C):
    """Nonzero Voigt entries of the plane-stress matrix at nu = 1/3 that C reproduces for every r,
    and the differences C - D of the others (entries zero in both are left out)."""
    D = elasticity_matrix("plane_stress", E, NU_LLOYD)
    agree, differ = [], {}
    for i in range(3):
        for j in range(i, 3):
            if C[i, j] == 0 and D[i, j] == 0:
                continue
            d = sp.factor(C[i, j] - D[i, j])
            if d == 0:
                agree.append((i, j))
            else:
                differ[(i, j)] = d
    return agree, differ


# %%
if __name__ == "__main__":
    for name, eq in (("least squares", False), ("least squares in equilibrium", True)):
        C_, sigma0_ = lattice_check(eq)
        show.note(f"Lattice of the {name} springs:")
        show.math(r"C_{\text{lattice}}", C_)
        show.math(r"\sigma_0^T", sigma0_.T)
    show.math(r"D_{\text{plane stress}}(\nu = 1/3)", elasticity_matrix("plane_stress", E, NU_LLOYD))


# %% [markdown]
# ## What the module hands on

# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    ex = exact()
    assert len(ex.solutions) == 1, ex.solutions
    s = ex.solutions[0]
    assert not exact_without_prestrain().exists
    fit = least_squares_fit(NU_LLOYD)
    fit_nu = least_squares_fit(nu_c)
    fit_eq = least_squares_fit(NU_LLOYD, equilibrium=True)
    f_rest = forces(fit)
    C, sigma0 = lattice_check()
    agree, differ = lattice_agreement(C)
    C_eq, sigma0_eq = lattice_check(equilibrium=True)
    agree_eq, differ_eq = lattice_agreement(C_eq)
    lo, hi = positivity_interval(fit)

    d = Derivation("rectangle", "Rectangle of aspect ratio r, plane stress, six prestrained springs "
                                "(generalising Lloyd et al. Sec. 4.1)")

    def outputs(f):
        return {**{f"k_{x}": v for x, v in zip(FAMILIES, f["k"])}, **{f"c_{x}": v for x, v in zip(FAMILIES, f["c"])}}

    conventions = ("per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length "
                   "b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c "
                   "times the rest distance). Edge constants add up over the elements sharing the edge.")
    d.formulas.append(Formula(
        "rectangle_least_squares", (E, t, r), outputs(fit),
        "Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, " + conventions
        + f" Exact only for r = 1 (Lloyd's 5/16, 7/16 E t; 6/5, 6/7); k and c are positive only for "
          f"{float(lo):.4f} < r < {float(hi):.4f}, and for r != 1 the element is NOT in equilibrium at rest "
          "(see rectangle_least_squares_equilibrium)."))
    d.formulas.append(Formula(
        "rectangle_least_squares_equilibrium", (E, t, r), outputs(fit_eq),
        "Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, restricted to "
        "elements in equilibrium at rest (spring tensions balance at every node), " + conventions
        + " Equal to rectangle_least_squares at r = 1; k and c are positive for every r."))
    d.formulas.append(Formula(
        "rectangle_least_squares_nu", (E, nu, t, r), {key: v.subs(nu_c, nu) for key, v in outputs(fit_nu).items()},
        "Least-squares springs of an a x b rectangle (r = b/a), plane stress, any Poisson's ratio nu, "
        + conventions + " rectangle_least_squares is its value at nu = 1/3; not in equilibrium at rest."))

    def L(e):  # LaTeX, with the condition symbol nu_c printed as nu
        return sp.latex(sp.sympify(e).subs(nu_c, nu))

    def voigt(i, j):
        return f"C_{{{i + 1}{j + 1}}}"

    gb = groebner_certificate(True)
    d.findings += [
        ("exact match: conditions", f"\\nu = {L(s[nu_c])},\\ r = {L(s[r])}\\ (\\text{{Gröbner basis ends in}}\\ "
                                    f"{L(gb.exprs[-2])} = 0,\\ {L(gb.exprs[-1])} = 0)"),
        ("exact match: springs", ",\\ ".join(f"{L(x)} = {L(s[x])}" for x in K_SYM + C_SYM)),
        ("exact match without prestrain", "\\text{none for any}\\ \\nu, r\\ \\text{(Gröbner basis}\\ \\{1\\}"
         "\\text{); structural zeros of}\\ K_{\\text{MSS}}\\ \\text{demand}\\ "
         + ",\\ ".join(f"{L(cnd)} = 0" for cnd in zero_entry_conditions())),
        ("least squares (ν = 1/3): k", ",\\ ".join(f"k_{x} = {L(v)}" for x, v in zip(FAMILIES, fit["k"]))),
        ("least squares (ν = 1/3): c", ",\\ ".join(f"c_{x} = {L(v)}" for x, v in zip(FAMILIES, fit["c"]))),
        ("least squares (ν = 1/3): positive k and c", f"r \\in \\left({float(lo):.4f},\\ {float(hi):.4f}\\right)"),
        ("least squares (ν = 1/3): residual",
         f"\\lVert K_{{\\text{{FEM}}}} - K_{{\\text{{MSS}}}} \\rVert_F^2 = {L(fit['residual'])}"),
        ("least squares (ν = 1/3): relative residual", f"\\epsilon_{{\\text{{rel}}}}(r) = {L(fit['relative_residual'])}"),
        ("least squares (any ν): relative residual",
         f"\\epsilon_{{\\text{{rel}}}}(r, \\nu) = {L(fit_nu['relative_residual'])}"),
        ("least squares: forces at rest (node 0)",
         f"f_0 = \\left({L(f_rest[0])},\\ {L(f_rest[1])}\\right) \\ne 0\\ \\text{{for}}\\ r \\ne 1"),
        ("lattice (least squares, ν = 1/3)", f"C = {L(C)},\\ \\sigma_0 = {L(sigma0.T)}"),
        ("lattice vs plane stress (least squares)",
         (",\\ ".join(voigt(i, j) for i, j in agree) + " = D;\\ " if agree else "")
         + ",\\ ".join(f"{voigt(i, j)} - D_{{{i + 1}{j + 1}}} = {L(v)}" for (i, j), v in differ.items())),
        ("equilibrium least squares: k", ",\\ ".join(f"k_{x} = {L(v)}" for x, v in zip(FAMILIES, fit_eq["k"]))),
        ("equilibrium least squares: c", ",\\ ".join(f"c_{x} = {L(v)}" for x, v in zip(FAMILIES, fit_eq["c"]))),
        ("equilibrium least squares: relative residual", f"\\epsilon_{{\\text{{rel}}}}(r) = {L(fit_eq['relative_residual'])}"),
        ("lattice (equilibrium least squares)", f"C = {L(C_eq)},\\ \\sigma_0 = {L(sigma0_eq.T)}"),
        ("lattice vs plane stress (equilibrium least squares)",
         (",\\ ".join(voigt(i, j) for i, j in agree_eq) + " = D;\\ " if agree_eq else "")
         + ",\\ ".join(f"{voigt(i, j)} - D_{{{i + 1}{j + 1}}} = {L(v)}" for (i, j), v in differ_eq.items())),
    ]
    d.data.update(exact=s, exact_equations=len(ex.equations), fit=fit, fit_nu=fit_nu, fit_equilibrium=fit_eq,
                  positive_interval=(lo, hi), forces_at_rest=f_rest, lattice=C, lattice_stress=sigma0,
                  lattice_agree=agree, lattice_differ=differ, lattice_equilibrium=C_eq,
                  lattice_equilibrium_stress=sigma0_eq, lattice_equilibrium_agree=agree_eq,
                  lattice_equilibrium_differ=differ_eq)
    return d


# %%
if __name__ == "__main__":
    d = show.summary(derive())
    s = d.data["exact"]
    lloyd = {K_SYM[0]: 5 * E * t / 16, K_SYM[1]: 5 * E * t / 16, K_SYM[2]: 7 * E * t / 16,
             C_SYM[0]: sp.Rational(6, 5), C_SYM[1]: sp.Rational(6, 5), C_SYM[2]: sp.Rational(6, 7)}
    print("  Lloyd eqs. 10-11 recovered at r = 1:", all(sp.simplify(s[x] - v) == 0 for x, v in lloyd.items()))
    fit = d.data["fit"]
    print("  least squares at r = 1 equals the exact match:",
          all(sp.simplify(v.subs(r, 1) - lloyd[x]) == 0 for x, v in zip(K_SYM + C_SYM, fit["k"] + fit["c"])))
    for rv in (sp.Rational(1, 2), 1, 2, 4):
        print(f"  r = {rv}: relative residual {fit['relative_residual'].subs(r, rv)}"
              f" = {float(fit['relative_residual'].subs(r, rv)):.4f};"
              f" equilibrium fit {float(d.data['fit_equilibrium']['relative_residual'].subs(r, rv)):.4f}")

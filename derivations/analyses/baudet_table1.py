# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Unknowns and equations of Baudet's three spring configurations (Baudet et al., Sec. 4, Table 1)
#
# Baudet et al. choose their element by counting: a parallelepiped x0 x y0 x z0 with springs on its
# edges (k_x, k_y, k_z by direction) and diagonal springs in one of three configurations,
#
# - M1: both diagonals of every face (one constant per face orientation: k_f^yz, k_f^xz, k_f^xy),
# - M2: the four inner diagonals (one constant k_d),
# - M3: both, (3 + 4 unknowns),
#
# against the equations of their numerical experiments: three elongations (E and the two Poisson's
# ratios each: 9 equations), six shears (G), one inflation (B, dependent). Table 1 lists the counts.
# Here the engine counts them: the element's second-order Lagrangian per unit volume under a
# homogeneous deformation (its Voigt tensor C, linear in the spring constants) gives every
# experiment's response, so each equation is an explicit function of the unknowns; the ranks say
# which equations are independent and whether the system can be solved. A second reading, Lloyd's
# criterion (equate the 24 x 24 element stiffness matrices of the MSS and of the trilinear
# hexahedron), is counted the same way.

# %%
import itertools
from functools import lru_cache

import sympy as sp

from derivations import elasticity as el
from derivations import element_stiffness as fem, lattice, match, mss, show
from derivations.elasticity import E, nu
from derivations.element_stiffness import _REF
from derivations.records import Derivation

x0, y0, z0 = sp.symbols("x_0 y_0 z_0", positive=True)
a = sp.Symbol("a", positive=True)
nu_c = sp.Symbol("nu_c", real=True)  # Poisson's ratio as a condition symbol (solved for, not assumed)
K_EDGE = sp.symbols("k_x k_y k_z", real=True)
K_FACE = sp.symbols("k_f^yz k_f^xz k_f^xy", real=True)  # by the normal of the face: x, y, z
K_INNER = sp.Symbol("k_d", real=True)
CONFIGURATIONS = ("M1", "M2", "M3")
BOX = (x0, y0, z0)
CUBE = (a, a, a)
AXES = "xyz"


def unknowns(conf):
    return list(K_EDGE) + (list(K_FACE) if conf in ("M1", "M3") else []) + ([K_INNER] if conf in ("M2", "M3") else [])


def coords(L):
    return [tuple((c + 1) * l / 2 for c, l in zip(q, L)) for q in _REF["hexahedron"]]


def kind(i, j):
    """The axes along which hexahedron nodes i and j differ: one (edge), two (face diagonal), three (inner)."""
    return tuple(ax for ax in range(3) if _REF["hexahedron"][i][ax] != _REF["hexahedron"][j][ax])


def terms(conf, symmetric=False):
    """The springs of configuration ``conf`` with Baudet's unknowns (one constant per edge direction
    and per face orientation), or with one constant per kind of spring (``symmetric``: k_e, k_f, k_d)."""
    ts = []
    for i, j in itertools.combinations(range(8), 2):
        ax = kind(i, j)
        if len(ax) == 1:
            k = K_EDGE[0] if symmetric else K_EDGE[ax[0]]
        elif len(ax) == 2 and conf in ("M1", "M3"):
            k = K_FACE[0] if symmetric else K_FACE[3 - sum(ax)]  # the face's normal is the axis not in ax
        elif len(ax) == 3 and conf in ("M2", "M3"):
            k = K_INNER
        else:
            continue
        ts.append(mss.spring(i, j, k))
    return ts


# %% [markdown]
# ## The element's response: its Voigt tensor
#
# A homogeneous deformation of the element (the engine's lattice energy density, per-element
# constants) gives C(k). Nothing else enters Baudet's experiments: an elongation, a shear or an
# inflation is a homogeneous stress, and the strains it causes are S = C^-1 times it.

# %%
@lru_cache(maxsize=None)
def element_tensor(conf, L=BOX):
    """C(k) of the element of edges ``L``; other edges than the symbolic box are substituted into the
    box's C (a rational function of x0, y0, z0, so the substitution is exact)."""
    if L != BOX:
        return element_tensor(conf, BOX).subs(dict(zip(BOX, L)), simultaneous=True).applyfunc(sp.factor)
    C, sigma0 = lattice.effective_tensor(terms(conf), coords(L), sp.prod(L))
    assert sigma0 == sp.zeros(6, 1)  # no prestrain: the element is in equilibrium at rest
    return C


# %%
if __name__ == "__main__":
    for conf in CONFIGURATIONS:
        show.math(f"C_{{\\text{{{conf}}}}}\\ (x_0 = y_0 = z_0 = a)", element_tensor(conf).subs({x0: a, y0: a, z0: a}))


# %% [markdown]
# ## Baudet's equations, one per experiment and measured quantity
#
# Elongation along i (stress sigma e_i): E_i = 1/S_ii and nu_ij = -S_ji/S_ii for the two axes j != i,
# 9 equations E_i = E, nu_ij = nu. Shear of the face normal to n along t (6 ordered pairs n != t):
# G_nt = 1/S_(nt), with S_(nt) the compliance of the engineering shear strain of the plane (n, t).
# Inflation: B = 1/sum_{i,j <= 3} S_ij. The equations are written as numerators (cleared of
# denominators) in the unknowns, with the compliance written out through the adjugate of C.

# %%
VOIGT_SHEAR = {frozenset((1, 2)): 3, frozenset((0, 2)): 4, frozenset((0, 1)): 5}


def _compliance_entries(C):
    """Symbols S_ij for the compliance: the equations are counted on the compliance entries (the
    element's measured response); ``C`` enters only through the map C(k)."""
    return sp.Matrix(6, 6, lambda i, j: sp.Symbol(f"S_{min(i, j) + 1}{max(i, j) + 1}", real=True))


@lru_cache(maxsize=None)
def experiments():
    """The experiments' equations as functions of the compliance entries S_ij:
    {"elongation": [(label, equation)], "shear": [...], "bulk": [...]} (equation = 0)."""
    S = _compliance_entries(None)
    G = el.lame(E, nu)[1]
    elong, shear = [], []
    for i in range(3):
        elong.append((f"E_{AXES[i]} = E", 1 / S[i, i] - E))
        for j in range(3):
            if j != i:
                elong.append((f"nu_{AXES[i]}{AXES[j]} = nu", -S[j, i] / S[i, i] - nu))
    for n, t in itertools.permutations(range(3), 2):
        r = VOIGT_SHEAR[frozenset((n, t))]
        shear.append((f"G_{AXES[n]}{AXES[t]} = G", 1 / S[r, r] - G))
    bulk = [("B = E / (3 (1 - 2 nu))", 1 / sum(S[i, j] for i in range(3) for j in range(3)) - E / (3 * (1 - 2 * nu)))]
    return {"elongation": elong, "shear": shear, "bulk": bulk}


def _generic_rank(M):
    """Rank of a matrix of rational functions at a generic point: every symbol replaced by a distinct
    rational number (exact arithmetic). It equals the rank for all but a measure-zero set of values;
    a coincidence could only lower it, and the ranks are cross-checked at a second point."""
    syms = sorted(M.free_symbols, key=str)
    ranks = []
    for value in (lambda p: sp.Rational(1, p), lambda p: sp.Rational(p, p + 1)):  # never 1/2 or -1 (nu)
        point = {s: value(p) for s, p in zip(syms, sp.primerange(11, 1000))}
        ranks.append(M.subs(point).rank())
    return max(ranks)


def _rank_on(eqs, variables):
    """Rank of the Jacobian of ``eqs`` with respect to ``variables`` at a generic point."""
    if not eqs:
        return 0
    return _generic_rank(sp.Matrix([[sp.diff(e, v) for v in variables] for e in eqs]))


def _distinct(eqs):
    out = []
    for e in eqs:
        num = sp.expand(sp.numer(sp.together(e)))
        if num != 0 and num not in out and -num not in out:
            out.append(num)
    return out


@lru_cache(maxsize=None)
def experiment_counts():
    """How many equations each family of experiments gives: as Baudet counts them (one per experiment and
    measured quantity), distinct ones, and independent ones (rank of their Jacobian with respect to the
    element's compliance entries: the number of conditions they put on the element's response)."""
    ex = experiments()
    S = _compliance_entries(None)
    entries = sorted({S[i, j] for i in range(6) for j in range(6)}, key=str)
    out = {}
    for fam, items in ex.items():
        eqs = [e for _, e in items]
        out[fam] = {"counted": len(eqs), "distinct": len(_distinct(eqs)), "independent": _rank_on(eqs, entries)}
    alle = [e for items in ex.values() for _, e in items]
    no_bulk = [e for fam in ("elongation", "shear") for _, e in ex[fam]]
    out["total"] = {"counted": len(alle), "counted_without_bulk": len(no_bulk), "distinct": len(_distinct(alle)),
                    "independent": _rank_on(alle, entries), "independent_without_bulk": _rank_on(no_bulk, entries)}
    return out


# %%
if __name__ == "__main__":
    for fam, items in experiments().items():
        show.equations(f"\\text{{{fam}}}", [sp.Eq(e, 0) for _, e in items])
    show.note(str(experiment_counts()))


# %% [markdown]
# ## Unknowns per family, and the linear system C(k) = D
#
# An unknown enters a family of experiments when the entries of C that family measures depend on it:
# the normal block C_11 ... C_33 (elongation, inflation) or the shear diagonal C_44, C_55, C_66. All
# equations hold together exactly when C(k) equals the isotropic D(E, nu) (an element whose compliance
# is the isotropic one), and C(k) is linear in k: A k = b, 9 rows (the orthotropic entries C_11, C_22,
# C_33, C_12, C_13, C_23, C_44, C_55, C_66; the other entries vanish for every k). rank A is the number
# of independent combinations of the unknowns the experiments see; the system is solvable where
# rank [A | b] = rank A.

# %%
ORTHO = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2), (3, 3), (4, 4), (5, 5)]
NORMAL, SHEAR = ORTHO[:6], ORTHO[6:]


def _linear_system(conf, L=BOX):
    C = element_tensor(conf, L)
    U = unknowns(conf)
    others = [C[i, j] for i in range(6) for j in range(6) if (min(i, j), max(i, j)) not in ORTHO]
    assert all(sp.simplify(c) == 0 for c in others)  # an orthotropic element for every k
    A = sp.Matrix([[sp.simplify(sp.diff(C[i, j], u)) for u in U] for i, j in ORTHO])
    D = el.elasticity_matrix("3d", E, nu_c)
    b = sp.Matrix([D[i, j] for i, j in ORTHO])
    return A, b, U


def _consistency(A, b):
    """Conditions on nu_c under which A k = b is solvable: w . b = 0 for a basis w of the left null space."""
    W = A.T.nullspace()
    conds = [sp.factor(sp.numer(sp.together((w.T * b)[0, 0]))) for w in W]
    conds = [c for c in conds if c != 0]
    roots = sp.solve(conds, nu_c, dict=True) if conds else [{}]
    return conds, roots


@lru_cache(maxsize=None)
def system(conf, L=BOX, solve=True):
    """Counts and solvability of Baudet's experiments for configuration ``conf`` on the element of
    edges ``L``: unknowns entering the shear and the elongation equations, rank of A and of [A | b]
    (generic nu), the values of nu for which the system is solvable and (``solve``) the solutions there."""
    A, b, U = _linear_system(conf, L)
    in_shear = [u for u, col in zip(U, A[6:, :].T.tolist()) if any(c != 0 for c in col)]
    in_normal = [u for u, col in zip(U, A[:6, :].T.tolist()) if any(c != 0 for c in col)]
    rank_A, rank_Ab = _generic_rank(A), _generic_rank(A.row_join(b))
    conds, roots = _consistency(A, b)
    solutions = []
    solvable_nu = [r[nu_c] for r in roots if nu_c in r]
    for r in roots if solve else []:
        if nu_c not in r:
            continue
        sol = sp.linsolve((A, b.subs(r)), U)
        for s in sol:
            solutions.append((r[nu_c], {u: sp.factor(v) for u, v in zip(U, s)}))
    return {"unknowns": U, "in_shear": in_shear, "in_elongation": in_normal, "edge": [u for u in in_normal if u in K_EDGE],
            "diagonal_in_elongation": [u for u in in_normal if u not in K_EDGE],
            "rank_A": rank_A, "rank_Ab": rank_Ab, "conditions": conds, "solvable_nu": solvable_nu, "solutions": solutions,
            "rank_A_shear": _generic_rank(A[6:, :]), "rank_A_normal": _generic_rank(A[:6, :])}


# %%
if __name__ == "__main__":
    for conf in CONFIGURATIONS:
        for geom, L in (("parallelepiped", BOX), ("cube", CUBE)):
            s = system(conf, L)
            show.note(f"**{conf}, {geom}**: unknowns {len(s['unknowns'])}, in shear {len(s['in_shear'])}, "
                      f"in elongation {len(s['edge'])} + ({len(s['diagonal_in_elongation'])}); rank A = {s['rank_A']}, "
                      f"rank [A | b] = {s['rank_Ab']} for generic nu; solvable for nu = "
                      f"{', '.join(str(v) for v in s['solvable_nu']) or 'no value'}")
            for v, sol in s["solutions"]:
                show.solution(f"\\nu = {sp.latex(v)}", sol)


# %% [markdown]
# Every spring lattice obeys Cauchy's relations (C_12 = C_66, C_13 = C_55, C_23 = C_44: a central
# force between nodes that are centres of symmetry), so C(k) has at most 6 independent entries
# whatever the configuration, while the isotropic D has C_12 = lambda and C_66 = mu: the system is
# solvable only where lambda = mu, i.e. nu = 1/4.

# %% [markdown]
# ## Lloyd's criterion: the element stiffness matrices
#
# Equating the 24 x 24 stiffness matrix of the springs with that of the trilinear hexahedron (cube of
# edge a) gives one equation per matrix entry; :func:`derivations.match._equations` keeps the distinct
# ones (an entry and its negative, and the symmetric entry, once), and equations that differ by a
# constant factor only are counted once. They are linear in the spring constants, so again rank A
# and rank [A | b] decide.

# %%
def _up_to_scale(eqs, gens):
    """The equations (polynomials in ``gens``) that differ by more than a constant factor (a number or
    a power product of E and a): each is divided by its leading coefficient before comparing."""
    out, keys = [], []
    for e in eqs:
        key = sp.expand(sp.cancel(e / sp.Poly(e, *gens).LC()))
        if key not in keys:
            keys.append(key)
            out.append(e)
    return out


@lru_cache(maxsize=None)
def K_fem_cube():
    return fem.element_stiffness("hexahedron", coords(CUBE), "3d").subs(nu, nu_c)


@lru_cache(maxsize=None)
def stiffness_matching(conf, symmetric=False):
    """Distinct equations of K_MSS = K_FEM for the cube, the rank of the linear system and the
    values of nu (if any) for which it is solvable. ``symmetric``: one constant per kind of spring."""
    ts = terms(conf, symmetric)
    K_mss = mss.stiffness_at_rest(ts, coords(CUBE))
    U = sorted(K_mss.free_symbols - {a}, key=str)
    eqs = _up_to_scale(match._equations(K_fem_cube(), K_mss), U + [nu_c])
    A = sp.Matrix([[sp.diff(e, u) for u in U] for e in eqs])
    b = -sp.Matrix([e.subs({u: 0 for u in U}) for e in eqs])
    rank_A, rank_Ab = _generic_rank(A), _generic_rank(A.row_join(b))
    conds, roots = _consistency(A, b)
    return {"unknowns": U, "equations": eqs, "n_equations": len(eqs), "rank_A": rank_A, "rank_Ab": rank_Ab,
            "conditions": conds, "solvable_nu": [r[nu_c] for r in roots if nu_c in r]}


# %%
@lru_cache(maxsize=None)
def table():
    """One row per configuration with the counts Table 1 lists, from the engine."""
    ex = experiment_counts()
    rows = {}
    for conf in CONFIGURATIONS:
        s, c = system(conf, BOX, False), system(conf, CUBE)
        m = stiffness_matching(conf)
        rows[conf] = {
            "unknowns_shear": len(s["in_shear"]), "unknowns_edge": len(s["edge"]),
            "unknowns_diagonal_elongation": len(s["diagonal_in_elongation"]), "unknowns_total": len(s["unknowns"]),
            "equations_elongation": ex["elongation"]["counted"], "equations_elongation_independent": ex["elongation"]["independent"],
            "equations_shear": ex["shear"]["counted"], "equations_shear_independent": ex["shear"]["independent"],
            "equations_bulk_independent_extra": ex["total"]["independent"] - ex["total"]["independent_without_bulk"],
            "equations_total": ex["total"]["counted_without_bulk"], "equations_total_independent": ex["total"]["independent_without_bulk"],
            "rank_A_box": s["rank_A"], "rank_Ab_box": s["rank_Ab"],
            "solvable_nu_box": s["solvable_nu"], "conditions_box": s["conditions"],
            "rank_A_cube": c["rank_A"], "rank_Ab_cube": c["rank_Ab"],
            "solvable_nu_cube": c["solvable_nu"], "solutions_cube": c["solutions"],
            "stiffness_equations": m["n_equations"], "stiffness_rank_A": m["rank_A"], "stiffness_rank_Ab": m["rank_Ab"],
            "stiffness_solvable_nu": m["solvable_nu"],
        }
    return rows


# %%
def derive() -> Derivation:
    d = Derivation("baudet_table1", "Unknowns and equations of Baudet's configurations M1-M3 (Table 1)")
    for conf, r in table().items():
        d.findings.append((f"{conf}: unknowns (shear; elongation; total), rank of the experiments' system",
                           f"{r['unknowns_shear']};\\ {r['unknowns_edge']} + ({r['unknowns_diagonal_elongation']});\\ "
                           f"{r['unknowns_total']},\\ \\operatorname{{rank}} A = {r['rank_A_box']},\\ "
                           f"\\operatorname{{rank}} [A|b] = {r['rank_Ab_box']}"))
    d.data.update(table=table(), experiments=experiment_counts())
    for conf, r in table().items():
        d.checks.update({f"{conf}_unknowns_total": r["unknowns_total"], f"{conf}_rank_A": r["rank_A_box"],
                         f"{conf}_rank_Ab": r["rank_Ab_box"],
                         f"{conf}_consistent": int(r["rank_A_box"] == r["rank_Ab_box"]),
                         f"{conf}_equations_counted": r["equations_total"],
                         f"{conf}_equations_independent": r["equations_total_independent"]})
    return d


# %%
if __name__ == "__main__":
    for conf, r in table().items():
        print(conf, {k: v for k, v in r.items() if not k.startswith("solutions")})

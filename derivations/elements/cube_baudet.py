# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Cube with edge and inner-diagonal springs and an orthogonal correction force (Baudet et al.)
#
# Baudet et al. (2007), configuration M2: 12 edge springs (k_x, k_y, k_z by direction) and 4 inner
# diagonals (k_d), parameterised through the paper's own experiments: a Lagrangian expanded to second
# order in a homogeneous deformation of the element (the engine's lattice energy density) plus the
# work of the applied face loads. Tension gives E and nu, shear gives G, inflation gives B.

# %%
import itertools
from functools import lru_cache

import sympy as sp

from derivations import elasticity as el
from derivations import element_stiffness as fem, lattice, mss, show
from derivations.elasticity import E, nu
from derivations.element_stiffness import _REF
from derivations.records import Derivation, Element, Erratum, Formula

# what this module derives and which simulator models the generated code feeds (derivations.registry)
ELEMENT = Element("cube_baudet", cell="hexahedron", models=("baudet_cube",),
                  source="Baudet et al. (2007), configuration M2")

x0, y0, z0 = sp.symbols("x_0 y_0 z_0", positive=True)
a = sp.Symbol("a", positive=True)
k_x, k_y, k_z, k_d = sp.symbols("k_x k_y k_z k_d", real=True)
alpha = sp.Symbol("alpha", real=True)  # correction force = alpha x elongation force, on each orthogonal face
F, p = sp.symbols("F p", positive=True)


def coords(L):
    return [tuple((c + 1) * l / 2 for c, l in zip(q, L)) for q in _REF["hexahedron"]]


def terms(kxyz, kd):
    ts = []
    for i, j in itertools.combinations(range(8), 2):
        axes = [ax for ax in range(3) if _REF["hexahedron"][i][ax] != _REF["hexahedron"][j][ax]]
        if len(axes) == 1:
            ts.append(mss.spring(i, j, kxyz[axes[0]]))
        elif len(axes) == 3:
            ts.append(mss.spring(i, j, kd))
    return ts


@lru_cache(maxsize=None)
def element_tensor(cube: bool = True):
    """Voigt tensor of the element's second-order Lagrangian per unit volume (a single element under
    homogeneous deformation; the same as the assembled lattice with per-element constants)."""
    L = (a, a, a) if cube else (x0, y0, z0)
    kk = (k_x, k_x, k_x) if cube else (k_x, k_y, k_z)
    C, _ = lattice.effective_tensor(terms(kk, k_d), coords(L), sp.prod(L))
    return C


# %% [markdown]
# ## Shear fixes k_d (eq. 7, and the parallelepiped's three incompatible values)

# %%
@lru_cache(maxsize=None)
def shear():
    G = el.lame()[1]
    C = element_tensor(cube=False)
    per_plane = {name: sp.solve(C[r, r] - G, k_d)[0] for r, name in zip(range(3, 6), ("yz", "xz", "xy"))}
    cube = sp.solve(element_tensor()[3, 3] - G, k_d)[0]
    return per_plane, sp.simplify(cube)


# %% [markdown]
# Baudet et al. match no element matrices: the model is fitted through experiments on one element,
# i.e. through the element's Voigt tensor C (below, for the cube) against the isotropic D.

# %%
if __name__ == "__main__":
    show.math(r"D", el.elasticity_matrix("3d"))
    show.math(r"C_{\text{MSS}}", element_tensor())
    show.math(r"C_{44} = G", sp.Eq(element_tensor()[3, 3], el.lame()[1]))
    per_plane_kd, kd_cube = shear()
    show.solution(r"k_d\ \text{per shear plane (parallelepiped)}", {sp.Symbol(f"k_d^{{{n}}}"): v for n, v in per_plane_kd.items()})
    show.math(r"k_d\ \text{(cube)}", kd_cube)
    show.check(r"k_d = \frac{3 E a}{8 (1 + \nu)}\ \text{(eq. 7)}", sp.simplify(kd_cube - 3 * E * a / (8 * (1 + nu))) == 0)


# %% [markdown]
# ## Tension with the correction force: k_x and the correction amplitude
#
# A tensile force F on the faces normal to z, and correction forces F_perp = alpha F on each face
# normal to x and to y (total per face, equal and opposite on opposite faces). Homogeneous stress
# (alpha F/a^2, alpha F/a^2, F/a^2): solve the Lagrangian's stationarity for the strains, then ask for
# E_eff = E and nu_eff = nu.

# %%
def _strain(C, sigma):
    return C.LUsolve(sigma).applyfunc(sp.simplify)


@lru_cache(maxsize=None)
def tension(face_total: bool = True):
    kd = shear()[1]
    C = element_tensor().subs(k_d, kd)
    s = 1 if face_total else 4  # per-face total, or the same force on each of the face's 4 nodes
    sig = sp.Matrix([s * alpha * F / a**2, s * alpha * F / a**2, F / a**2, 0, 0, 0])
    eps = _strain(C, sig)
    E_eff = sp.simplify(sig[2] / eps[2])
    nu_eff = sp.simplify(-eps[0] / eps[2])
    sol = sp.solve([sp.numer(sp.together(E_eff - E)), sp.numer(sp.together(nu_eff - nu))], [k_x, alpha], dict=True)
    # physical root: a positive edge stiffness that depends on nu (the others are k_x <= 0 for all nu)
    probe = {E: 1, a: 1, nu: sp.Rational(3, 10)}
    sol = [so for so in sol if so[k_x].subs(probe) > 0]
    return [{key: sp.factor(v) for key, v in so.items()} for so in sol], (E_eff, nu_eff)


@lru_cache(maxsize=None)
def inflation():
    """Pressure p on all faces; each face's elongation force induces corrections on the four others."""
    (sol,), _ = tension()
    C = element_tensor().subs({k_d: shear()[1], k_x: sol[k_x]})
    s_i = -p * (1 + 2 * sol[alpha])  # own load plus the corrections from the two other directions
    eps = _strain(C, sp.Matrix([s_i, s_i, s_i, 0, 0, 0]))
    B_with = sp.simplify(-p / (eps[0] + eps[1] + eps[2]))
    eps0 = _strain(C, sp.Matrix([-p, -p, -p, 0, 0, 0]))
    B_without = sp.simplify(-p / (eps0[0] + eps0[1] + eps0[2]))
    return B_with, B_without


# %%
if __name__ == "__main__":
    (sol_t,), (E_eff_t, nu_eff_t) = tension()
    show.math(r"E_{\text{eff}}", E_eff_t)
    show.math(r"\nu_{\text{eff}}", nu_eff_t)
    show.equations(r"E_{\text{eff}} = E,\ \nu_{\text{eff}} = \nu", [sp.numer(sp.together(E_eff_t - E)), sp.numer(sp.together(nu_eff_t - nu))])
    show.solution(r"\text{solution}", sol_t)
    show.check(r"k_x = \frac{E a (4 \nu + 1)}{8 (1 + \nu)}\ \text{(eq. 8)}", sp.simplify(sol_t[k_x] - E * a * (4 * nu + 1) / (8 * (1 + nu))) == 0)
    B_w, B_wo = inflation()
    show.math(r"B_{\text{with correction}}", sp.factor(B_w))
    show.math(r"B_{\text{without correction}}", sp.factor(B_wo))
    show.check(r"B_{\text{with correction}} = \frac{E}{3 (1 - 2 \nu)}", sp.simplify(B_w - E / (3 * (1 - 2 * nu))) == 0)


# %% [markdown]
# ## What an assembled lattice of such cubes does
#
# Inside a body, no external load acts on an element's faces, so no correction force is applied
# there: the interior is the plain spring lattice.

# %%
@lru_cache(maxsize=None)
def assembled_lattice():
    (sol,), _ = tension()
    C = element_tensor().subs({k_d: shear()[1], k_x: sol[k_x]}).applyfunc(sp.simplify)
    E_l, nu_l, G_l, K_l = el.isotropic_moduli_3d(C)
    return C, {"isotropy defect": el.is_isotropic(C), "nu_lattice": sp.factor(nu_l), "C44": sp.simplify(C[3, 3]),
               "uniaxial E along an axis": sp.factor(sp.simplify((C[0, 0] - C[0, 1]) * (C[0, 0] + 2 * C[0, 1]) / (C[0, 0] + C[0, 1])))}


# %%
if __name__ == "__main__":
    C_lat, lat_moduli = assembled_lattice()
    show.math(r"C_{\text{lattice}}", C_lat)
    show.solution(r"\text{the lattice's moduli}", {sp.Symbol(r"C_{11} - C_{12} - 2 C_{44}"): sp.factor(lat_moduli["isotropy defect"]),
                                                   sp.Symbol(r"\nu_{\text{lattice}}"): lat_moduli["nu_lattice"],
                                                   sp.Symbol(r"E_{\text{axis}}"): lat_moduli["uniaxial E along an axis"]})


# %% [markdown]
# ## The lattice under the element reading: its continuum limit
#
# Read at element level, every cube is corrected from the forces acting on it from outside
# (`msslib.terms.ElementBaudetCorrection`): at rest the outside holds each cube against its own
# springs, s_e = -H_e u, so the pair forces solve F_i + c sum_{j != i} F_j = g_i with
# g_i = -mean_{f in i} sum_{a in f} n_f . s_e(a), and the correction puts c F_j n_g / 4 on each node of
# every face g outside pair j. The cube's internal forces are -(I + M) H u; the outside applies
# t = (I + M) H u. Under an affine displacement u = eps X every node of the simple cubic lattice is
# a centre of inversion symmetry (the cubes around a node cancel both their springs' and their
# corrections' forces there), so the affine state is the lattice's equilibrium and the lattice's
# stress is each cube's virial, sigma = (1/V) sum_a t_a X_a^T. Its Voigt matrix is the continuum
# limit of the element-reading lattice.

# %%
def _faces():
    """(pair i, outward unit normal, node indices) of the reference cube's six faces."""
    out = []
    for i in range(3):
        for side in (-1, 1):
            n = sp.zeros(3, 1)
            n[i] = side
            out.append((i, n, [a for a, q in enumerate(_REF["hexahedron"]) if q[i] == side]))
    return out


@lru_cache(maxsize=None)
def element_reading_tensor():
    """(C, sigma antisymmetric part): the Voigt matrix of the lattice of identical cubes under the
    element reading, with the derived constants, and the antisymmetric part of its stress
    (zero when the virial stress is a true stress)."""
    (sol,), _ = tension()
    kx, kd, c = sol[k_x], shear()[1], sol[alpha]
    X = coords((a, a, a))
    H = mss.stiffness_at_rest(terms((kx,) * 3, kd), X)
    faces = _faces()
    # P: g = P s (3 x 24), Q: correction on the nodes = Q F (24 x 3)
    P = sp.zeros(3, 24)
    Q = sp.zeros(24, 3)
    for i, n, nodes in faces:
        for node in nodes:
            for d in range(3):
                P[i, 3 * node + d] -= sp.Rational(1, 2) * n[d]
                for j in range(3):
                    if j != i:
                        Q[3 * node + d, j] += c * n[d] / 4
    A = (1 - c) * sp.eye(3) + c * sp.ones(3, 3)
    M = Q * A.inv() * P
    eps_symbols = lattice.strain_symbols(3)
    eps = lattice.strain_matrix(eps_symbols, 3)
    u = sp.Matrix([v for x in X for v in (eps * sp.Matrix(x))])
    t = ((sp.eye(24) + M) * H * u).applyfunc(sp.expand)
    sigma = sp.zeros(3, 3)
    for node, x in enumerate(X):
        sigma += t[3 * node:3 * node + 3, 0] * sp.Matrix(x).T
    sigma = (sigma / a**3).applyfunc(sp.simplify)
    voigt = sp.Matrix([sigma[i, j] for i, j in el.VOIGT[3]])
    C = voigt.jacobian(sp.Matrix(eps_symbols)).applyfunc(sp.simplify)
    return C, (sigma - sigma.T).applyfunc(sp.simplify)


# %%
if __name__ == "__main__":
    C_el, skew = element_reading_tensor()
    show.math(r"C_{\text{element reading}}", C_el)
    show.check(r"C_{\text{element reading}} = D\ \text{(isotropic: } E, \nu, G \text{ exact)}",
               (C_el - el.elasticity_matrix("3d")).applyfunc(sp.simplify) == sp.zeros(6, 6))
    show.check(r"\sigma = \sigma^T", skew == sp.zeros(3, 3))


# %% [markdown]
# For orientation, the element matrices themselves (24 x 24, dofs x0, y0, z0, x1, ... in VTK order):
# the trilinear hexahedron and the springs with the derived constants (the correction force is a load,
# not a stiffness). Shown: the rows of node 0 against nodes 0 and 1.

# %%
if __name__ == "__main__":
    (sol_t,), _ = tension()
    cube = coords((a, a, a))
    K_hex = fem.element_stiffness("hexahedron", cube, "3d")
    K_springs = mss.stiffness_at_rest(terms((sol_t[k_x],) * 3, shear()[1]), cube).applyfunc(sp.factor)
    show.matrix(r"K_{\text{FEM}}", K_hex, rows=slice(0, 3), cols=slice(0, 6))
    show.matrix(r"K_{\text{MSS}}", K_springs, rows=slice(0, 3), cols=slice(0, 6))


PUBLISHED = {"k_d": 3 * E * a / (8 * (1 + nu)), "k_x": E * a * (4 * nu + 1) / (8 * (1 + nu)),
             "alpha": -(4 * nu - 1) / 16}


# %% [markdown]
# ## Eq. 8 read three ways
#
# The printed amplitude F_perp_i = -(4 nu - 1) F_i / 16 does not say what F_i and F_perp are: a resultant
# on one face, the force on each of a face's four nodes, or the sum over a pair of opposite faces. Each
# reading fixes what the simulator applies as a resultant on each orthogonal face, c F (F: the tensile
# resultant on one loaded face), and hence the derived factor it must equal:
#
# - face: F_i and F_perp are resultants per face (F_i as the paper defines the elongation force, "the
#   projection on the face normal of the sum of all the external forces applied to the considered face");
# - node: F_i per face, F_perp on each of the orthogonal face's four nodes (resultant 4 F_perp);
# - node, pair: F_perp per node, F_i the sum of the magnitudes on both loaded faces (2 F).
#
# For each reading: the factor the tension experiment derives, and E_eff, nu_eff of the tension experiment
# (small strain) if the printed 1/16 is applied under that reading. The paper's Sec. 5.1 reports errors that
# fall with nu (2.7 %, 2 %, 1.5 % on E at 10 % strain for nu = 0.3, 0.4, 0.5) and nu within 5 % for
# nu in [0.3, 0.5] up to 14 % strain; at small strain its errors are smaller still.

# %%
# reading -> (resultant on an orthogonal face per printed unit factor, F_i in units of the face resultant F)
READINGS = {"face": (1, 1), "node": (4, 1), "node, pair": (4, 2)}
PUBLISHED_ERRORS = {sp.Rational(3, 10): sp.Rational(27, 1000), sp.Rational(2, 5): sp.Rational(2, 100),
                    sp.Rational(1, 2): sp.Rational(15, 1000)}  # |E error| at 10 % strain (Baudet Sec. 5.1)


@lru_cache(maxsize=None)
def eq8_readings():
    """For each reading: the derived factor (as printed: F_perp = factor * F_i) and (E_eff, nu_eff) of the
    tension experiment when the printed factor is applied under that reading."""
    (sol,), (E_eff, nu_eff) = tension()
    out = {}
    for name, (n_nodes, fi) in READINGS.items():
        derived = sp.factor(sol[alpha] / (n_nodes * fi))  # resultant alpha F = n_nodes * factor * (fi F)
        applied = n_nodes * fi * PUBLISHED["alpha"]  # resultant factor the printed 1/16 yields
        sub = {k_x: sol[k_x], alpha: applied}
        out[name] = {"derived": derived, "applied": sp.factor(applied),
                     "E_eff": sp.factor(sp.simplify(E_eff.subs(sub))), "nu_eff": sp.factor(sp.simplify(nu_eff.subs(sub)))}
    return out


def _txt(e) -> str:
    """An expression as plain text for an erratum ('16 E (4 nu + 1)/(36 nu + 23)')."""
    return str(e).replace("**", "^").replace("*", " ")


# %%
@lru_cache(maxsize=None)
def derive() -> Derivation:
    per_plane, kd = shear()
    sols, _ = tension(True)
    assert len(sols) == 1, sols
    s = sols[0]
    sols_node, _ = tension(False)
    B_with, B_without = inflation()
    C, lat = assembled_lattice()
    d = Derivation("cube_baudet", "Cube with edge and inner-diagonal springs and orthogonal correction (Baudet et al.)")
    d.formulas.append(Formula(
        "baudet_cube", (E, nu, a),
        {"k_edge": s[k_x], "k_diagonal": kd, "correction_factor": s[alpha]},
        "Per-element constants of a cube of edge a: edge springs (sum over the cubes sharing the edge), inner "
        "diagonals, and the factor c of the correction force F_perp = c F_i applied, as a total per face, on each "
        "face orthogonal to the elongation force F_i (Baudet eqs. 7-8)."))
    d.published.append(Formula(
        "baudet_cube_published", (E, nu, a),
        {"k_edge": PUBLISHED["k_x"], "k_diagonal": PUBLISHED["k_d"], "correction_factor": PUBLISHED["alpha"]},
        "Baudet et al.'s eqs. 7-8 as printed (correction factor -(4 nu - 1)/16)."))
    d.findings += [
        ("k_d per shear plane (parallelepiped)", ",\\ ".join(f"k_d^{{{n}}} = {sp.latex(v)}" for n, v in per_plane.items())),
        ("k_d (cube)", sp.latex(kd)),
        ("k_x", sp.latex(s[k_x])),
        ("correction factor (per-face total)", sp.latex(s[alpha])),
        ("correction factor if applied per node", sp.latex(sols_node[0][alpha]) if sols_node else "no solution"),
        ("bulk modulus with correction", sp.latex(sp.factor(B_with))),
        ("bulk modulus target", sp.latex(sp.factor(E / (3 * (1 - 2 * nu))))),
        ("bulk modulus without correction", sp.latex(sp.factor(B_without))),
        ("assembled lattice (no correction inside)", f"\\text{{isotropy defect}}\\ C_{{11}} - C_{{12}} - 2 C_{{44}} = {sp.latex(sp.factor(lat['isotropy defect']))},\\ "
                                                      f"\\nu_{{\\text{{lattice}}}} = {sp.latex(lat['nu_lattice'])},\\ "
                                                      f"E_{{\\text{{axis}}}} = {sp.latex(lat['uniaxial E along an axis'])}"),
    ]
    d.data.update(solution=s, k_d=kd, per_plane=per_plane, per_node=sols_node, B_with=B_with,
                  B_without=B_without, lattice=C, lattice_moduli=lat)
    C_el, skew = element_reading_tensor()
    defect = (C_el - el.elasticity_matrix("3d")).applyfunc(sp.simplify)
    E_el, nu_el, _, _ = el.isotropic_moduli_3d(C_el)
    G_el = C_el[3, 3]
    d.findings.append(("assembled lattice, element reading (continuum limit)",
                       f"C - D = {'0' if defect == sp.zeros(6, 6) else sp.latex(defect)},\\ "
                       f"E = {sp.latex(sp.factor(sp.simplify(E_el)))},\\ \\nu = {sp.latex(sp.factor(sp.simplify(nu_el)))},\\ "
                       f"G = {sp.latex(sp.factor(sp.simplify(G_el)))}"))
    d.data.update(element_reading_lattice=C_el, element_reading_defect=defect, element_reading_skew=skew)
    rd8 = eq8_readings()
    d.checks.update(k_d_matches_eq7=int(sp.simplify(kd - PUBLISHED["k_d"]) == 0),
                    k_x_matches_eq8=int(sp.simplify(s[k_x] - PUBLISHED["k_x"]) == 0),
                    eq8_readings=len(rd8),
                    eq8_readings_matching_printed=sum(int(sp.simplify(v["derived"] - PUBLISHED["alpha"]) == 0) for v in rd8.values()),
                    bulk_exact_with_correction=int(sp.simplify(B_with - E / (3 * (1 - 2 * nu))) == 0),
                    bulk_exact_without_correction=int(sp.simplify(B_without - E / (3 * (1 - 2 * nu))) == 0))
    d.checks.update(element_reading_isotropic=int(defect == sp.zeros(6, 6) and skew == sp.zeros(3, 3)),
                    boundary_reading_isotropic=int(sp.simplify(lat["isotropy defect"]) == 0),
                    boundary_reading_E_axis_at_nu_0_3=float(lat["uniaxial E along an axis"].subs({E: 1, nu: sp.Rational(3, 10)})))
    rd = eq8_readings()
    d.findings += [(f"eq. 8 read '{n}': derived factor; printed 1/16 applied gives",
                    f"{sp.latex(v['derived'])},\\ E_{{\\text{{eff}}}} = {sp.latex(v['E_eff'])},\\ "
                    f"\\nu_{{\\text{{eff}}}} = {sp.latex(v['nu_eff'])}") for n, v in rd.items()]
    d.data.update(eq8_readings=rd)
    face, node, pair = rd["face"], rd["node"], rd["node, pair"]
    hi = [n for n in PUBLISHED_ERRORS if n > sp.Rational(3, 10)]  # nu = 0.4, 0.5: the clearest cases

    def pct(key, target):
        errs = [abs(v[key] / target - 1).subs({nu: n, a: 1, E: 1}) for v in (face, node) for n in hi]
        return f"{float(min(errs)) * 100:.0f}-{float(max(errs)) * 100:.0f} %"
    published = ", ".join(f"{float(e) * 100:g}" for e in PUBLISHED_ERRORS.values())
    nus = ", ".join(f"{float(n):g}" for n in PUBLISHED_ERRORS)
    d.errata.append(Erratum(
        "Baudet et al. (2007)", "eq. 8, amplitude of the orthogonal correction force (ambiguous: what F_i and F_perp are)",
        r"F_{\perp i} = -\frac{F_i (4\nu - 1)}{16}",
        f"\\text{{face/face: }} F_{{\\perp}} = {sp.latex(face['derived'])}\\, F_i;\\ "
        f"\\text{{node/face: }} {sp.latex(node['derived'])}\\, F_i;\\ "
        f"\\text{{node/pair: }} {sp.latex(pair['derived'])}\\, F_i",
        "Eq. 8 does not say whether F_i and F_perp are face resultants, nodal forces or sums over a pair of faces. "
        "The tension experiment (E and nu exact) fixes only the resultant on each orthogonal face: "
        f"-(4 nu - 1)/2 times the resultant F on a loaded face. Read as resultants per face (F_i as the paper defines "
        f"the elongation force), the factor is {_txt(face['derived'])}, eight times the printed one, and the printed 1/16 would "
        f"give E_eff = {_txt(face['E_eff'])} and nu_eff = {_txt(face['nu_eff'])}. With F_perp on each of a face's four nodes and "
        f"F_i per face it is {_txt(node['derived'])}; the printed 1/16 would give E_eff = {_txt(node['E_eff'])}, "
        f"nu_eff = {_txt(node['nu_eff'])}. The printed {_txt(pair['derived'])} is exact only with F_perp per node and F_i the sum "
        f"over both loaded faces. The paper's own tension numbers (E errors of {published} % at 10 % strain for "
        f"nu = {nus}, falling with nu; nu within 5 % for nu in [0.3, 0.5]) show a simulation that applied the "
        "derived resultant, so of the three readings they support only the last: applied under the first two the "
        "printed 1/16 gives, "
        f"already at small strain and for nu = 0.4, 0.5, errors of {pct('E_eff', E)} in E and {pct('nu_eff', nu)} in "
        "nu, growing with nu. k_d (eq. 7) and k_x (eq. 8) hold under every reading. Inside an assembled body, where no "
        "correction acts, the lattice is cubic-anisotropic with nu = 1/(4 nu + 3) unless nu = 1/4 "
        "(test_baudet_bulk_modulus_and_lattice).",
        "tests/test_derivations.py::test_baudet_eq8_readings"))
    return d


# %%
if __name__ == "__main__":
    show.summary(derive())

# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Cube with edge, face-diagonal and inner-diagonal springs and a volume correction (Golec et al.)
#
# Golec et al. (2017): springs k_e (12 edges), k_f (12 face diagonals), k_c (4 inner diagonals) with
# the ratio A = k_c / k_f, and a correction force from the volume energy with coefficient kappa.
# The lattice of cubes is homogenised (:mod:`derivations.lattice`) with *per-element* constants and
# matched exactly with the isotropic tensor (lambda, mu).

# %%
import itertools
from functools import lru_cache

import sympy as sp

from derivations import elasticity as el
from derivations import lattice, match, mss
from derivations.elasticity import E, nu
from derivations.fem import _REF
from derivations.records import Derivation, Erratum, Formula

a, A = sp.symbols("a A", positive=True)
k_e, k_f, k_c, kappa = sp.symbols("k_e k_f k_c kappa", real=True)
COORDS = [tuple((c + 1) * a / 2 for c in p) for p in _REF["hexahedron"]]


def _kind(i, j):
    return sum(u != v for u, v in zip(_REF["hexahedron"][i], _REF["hexahedron"][j]))  # 1 edge, 2 face, 3 inner


def terms(ke, kf, kc, kap=0):
    ts = [mss.spring(i, j, {1: ke, 2: kf, 3: kc}[_kind(i, j)]) for i, j in itertools.combinations(range(8), 2)]
    if kap != 0:
        ts.append(mss.hex_volume_term(range(8), kap))
    return ts


@lru_cache(maxsize=None)
def lattice_tensor():
    """Voigt tensor of the cube lattice as a function of the per-element constants."""
    C, sigma0 = lattice.effective_tensor(terms(k_e, k_f, k_c, kappa), COORDS, a**3)
    return C, sigma0


# %% [markdown]
# ## Published constants (as printed)

# %%
_den = sp.Rational(10, 3) * A + sp.Rational(5, 2)
PUBLISHED = {k_c: E * a * A / _den, k_f: E * a / _den, k_e: (sp.Rational(8, 3) * A + 1) * E * a / _den}
KAPPA_PUBLISHED = E * (4 * nu - 1) / (2 * (1 + nu) * (1 - 2 * nu))


def moduli(C):
    C = C.applyfunc(sp.simplify)
    return {"isotropy defect C11-C12-2C44": el.is_isotropic(C), "E,nu,G,K": el.isotropic_moduli_3d(C)}


# %% [markdown]
# ## Exact match of the lattice with (lambda, mu), k_c = A k_f

# %%
@lru_cache(maxsize=None)
def exact():
    C, _ = lattice_tensor()
    D = el.elasticity_matrix("3d")
    return match.match_exact(D, C.subs(k_c, A * k_f), (k_e, k_f, kappa))


@lru_cache(maxsize=None)
def derive() -> Derivation:
    C, sigma0 = lattice_tensor()
    sols = exact().solutions
    assert len(sols) == 1, sols
    s = {**sols[0]}
    s[k_c] = sp.simplify(A * s[k_f])
    lam, mu = el.lame()
    # springs alone (kappa = 0): isotropic, nu = 1/4 for every A
    springs_only = moduli(C.subs({kappa: 0, k_e: s[k_e], k_f: s[k_f], k_c: s[k_c]}))
    pub_per_element = moduli(C.subs({kappa: 0, **PUBLISHED}))
    pub_totals = moduli(C.subs({kappa: 0, k_e: PUBLISHED[k_e] / 4, k_f: PUBLISHED[k_f] / 2, k_c: PUBLISHED[k_c]}))
    C_pub = C.subs({kappa: KAPPA_PUBLISHED, k_e: PUBLISHED[k_e] / 4, k_f: PUBLISHED[k_f] / 2, k_c: PUBLISHED[k_c]}).applyfunc(sp.simplify)
    mu_pub = sp.simplify(C_pub[3, 3])
    d = Derivation("cube_golec", "Cube with edge, face and inner springs and volume correction (Golec et al.)")
    d.formulas.append(Formula(
        "golec_cube", (E, nu, a, A),
        {"k_edge": s[k_e], "k_face": s[k_f], "k_inner": s[k_c], "kappa": s[kappa]},
        "Per-element constants of a cube of edge a (sum the edge springs over the up to 4 cubes sharing an "
        "edge, face diagonals over the up to 2 cubes sharing a face) and kappa [Pa] of the volume energy "
        "kappa/(2 V0) (V - V0)^2. The lattice reproduces the isotropic (lambda, mu) exactly."))
    d.published.append(Formula(
        "golec_cube_published", (E, nu, a, A),
        {"k_edge": PUBLISHED[k_e], "k_face": PUBLISHED[k_f], "k_inner": PUBLISHED[k_c], "kappa": KAPPA_PUBLISHED},
        "Golec et al.'s constants as printed (k_edge and k_face are the assembled values of an interior spring)."))
    defect = r"\text{isotropy defect}\ C_{11} - C_{12} - 2 C_{44}"  # zero for an isotropic lattice
    d.findings += [
        ("lattice tensor", f"C = \\frac{{1}}{{3 a}} {sp.latex((3 * a * C).applyfunc(sp.expand))}"),  # entries without nested fractions
        ("residual stress at rest", sp.latex(sigma0.T)),
        ("derived k_e, k_f, k_c", f"k_e = {sp.latex(s[k_e])},\\ k_f = {sp.latex(s[k_f])},\\ k_c = {sp.latex(s[k_c])}"),
        ("derived kappa", f"\\kappa = {sp.latex(sp.factor(s[kappa]))}"),
        ("springs alone", f"{defect} = {sp.latex(springs_only['isotropy defect C11-C12-2C44'])},\\ "
                          f"\\nu_{{\\text{{lattice}}}} = {sp.latex(springs_only['E,nu,G,K'][1])}"),
        ("printed constants read per element", f"{defect} = {sp.latex(pub_per_element['isotropy defect C11-C12-2C44'])},\\ "
                                               f"\\nu_{{\\text{{lattice}}}} = {sp.latex(sp.factor(pub_per_element['E,nu,G,K'][1]))}"),
        ("printed constants read as interior totals", f"{defect} = {sp.latex(pub_totals['isotropy defect C11-C12-2C44'])},\\ "
                                                      f"E_{{\\text{{lattice}}}} = {sp.latex(pub_totals['E,nu,G,K'][0])},\\ \\nu_{{\\text{{lattice}}}} = {sp.latex(pub_totals['E,nu,G,K'][1])}"),
        ("shear modulus with printed constants", f"\\mu = {sp.latex(mu_pub)}\\ \\text{{vs}}\\ {sp.latex(mu)}"),
    ]
    d.data.update(solution=s, lattice=C, springs_only=springs_only, published_per_element=pub_per_element,
                  published_totals=pub_totals, mu_published=mu_pub, C_published=C_pub)
    d.errata += [
        Erratum("Golec et al. (2017)", "spring constants k_e, k_f (Sec. 2)",
                r"k_e = \left(\tfrac{8}{3}A + 1\right)\frac{E l}{\tfrac{10}{3}A + 2.5},\ k_f = \frac{E l}{\tfrac{10}{3}A + 2.5}",
                f"k_e = {sp.latex(s[k_e])},\\ k_f = {sp.latex(s[k_f])}\\ \\text{{(per element)}}",
                "The printed k_e and k_f are the assembled constants of an interior spring (an edge is shared by 4 cubes, "
                "a face diagonal by 2), while k_c (inner diagonal, one cube) is per element. Used per element, as a "
                "simulator summing over elements would, the lattice is anisotropic (C11 - C12 - 2 C44 != 0) and its nu "
                "depends on A; read as interior totals they give an isotropic lattice with nu = 1/4 and the right E. "
                "Boundary springs must get the per-element share only.",
                "tests/test_derivations.py::test_golec_spring_reading"),
        Erratum("Golec et al. (2017)", "spring constants for nu != 1/4",
                r"k \propto E", r"k \propto \tfrac{5}{2}\mu = \tfrac{5 E}{4 (1 + \nu)}",
                "kappa = E(4nu-1)/(2(1+nu)(1-2nu)) is exactly lambda - mu, so it is right only if the springs carry the shear "
                "modulus mu = E/(2(1+nu)). The printed springs scale with E and give mu = 2E/5 whatever nu: 20 % too stiff in "
                "shear at nu -> 1/2, 12 % too soft at nu = 0.1. Replacing E by 5E/(4(1+nu)) in the spring constants makes "
                "the lattice exactly isotropic with the target E and nu.",
                "tests/test_derivations.py::test_golec_exact_lattice"),
        Erratum("Golec et al. (2017)", "correction force (Sec. 2)",
                r"\vec F_{P_2} = \kappa (V - V_0) \frac{\partial V}{\partial P_2}",
                r"\vec F_{P_2} = -\frac{\kappa}{V_0} (V - V_0) \frac{\partial V}{\partial P_2}",
                "With kappa a modulus [Pa], kappa (V - V0) dV/dP has units Pa m^5 = N m^4, not N; the force of the energy "
                "kappa/(2 V0)(V - V0)^2 (density kappa/2 (tr eps)^2, i.e. + kappa on lambda) is -(kappa/V0)(V - V0) dV/dP "
                "(restoring: minus sign). The printed gradient dV/dB is also garbled; the kernel differentiates "
                "V = x . (y x z) exactly.",
                "tests/test_derivations.py::test_golec_correction_dimensions"),
    ]
    return d


# %%
if __name__ == "__main__":
    d = derive()
    print(d.title)
    for label, text in d.findings:
        print(f"  {label}: {text}")

"""The rectangle derivation (derivations/elements/rectangle.py): exact-match conditions, least squares, lattice."""

from __future__ import annotations

import sympy as sp
import pytest

from derivations import match
from derivations.elements import rectangle as R
from derivations.elasticity import E, elasticity_matrix, t

LLOYD = dict(zip(R.K_SYM + R.C_SYM, (5 * E * t / 16, 5 * E * t / 16, 7 * E * t / 16,
                                     sp.Rational(6, 5), sp.Rational(6, 5), sp.Rational(6, 7))))


def _zero(e) -> bool:
    return sp.cancel(sp.sympify(e)) == 0


# ---- exact match ------------------------------------------------------------------------------

def test_exact_match_only_square_at_nu_one_third():
    ex = R.exact()
    assert len(ex.solutions) == 1
    s = ex.solutions[0]
    assert s[R.nu_c] == sp.Rational(1, 3) and s[R.r] == 1
    # Lloyd et al. eqs. 10-11 are the r = 1 case
    assert all(_zero(s[x] - v) for x, v in LLOYD.items())


def test_exact_match_groebner_certificate():
    gb = list(R.groebner_certificate(True).exprs)
    assert R.nu_c - sp.Rational(1, 3) in gb
    assert R.r**4 - 1 in gb  # with r > 0: only the square


def test_no_exact_match_without_prestrain():
    assert not R.exact_without_prestrain().exists
    assert list(R.groebner_certificate(False).exprs) == [1]
    # the structural zeros of the unprestrained K_mss alone are contradictory: r^2 = 1 - nu and r^2 = 1/(1 - nu)
    conds = R.zero_entry_conditions()
    assert sp.solve(conds, [R.nu_c, R.r], dict=True) == []


# ---- least squares ----------------------------------------------------------------------------

@pytest.mark.parametrize("equilibrium", [False, True])
def test_least_squares_optimality(equilibrium):
    ls = R.least_squares_fit(R.NU_LLOYD, equilibrium)["ls"]
    assert all(_zero(g) for g in ls.gradient)
    assert match.is_positive_definite(ls.hessian)


def _objective_pq(r_value, equilibrium=False):
    K_m = R.stiffness_mss_linear()
    unknowns = list(R.P_SYM + R.Q_SYM)
    if equilibrium:
        K_m = K_m.subs(R.equilibrium_condition())
        unknowns = [u for u in unknowns if u not in R.equilibrium_condition()]
    K_f = R.stiffness_fem().subs(R.nu_c, R.NU_LLOYD).subs(R.r, r_value)
    K_m = K_m.subs(R.r, r_value).applyfunc(sp.cancel)
    return K_f, K_m, unknowns


@pytest.mark.parametrize("equilibrium", [False, True])
def test_least_squares_in_original_unknowns_at_r2(equilibrium):
    """Independent of the symmetry frame and the orthogonalised unknowns: the engine's least squares on
    the plain 8x8 matrices in (p, q) at r = 2 has the same optimum, zero gradient, PD Hessian."""
    fit = R.least_squares_fit(R.NU_LLOYD, equilibrium)
    K_f, K_m, unknowns = _objective_pq(2, equilibrium)
    direct = match.least_squares(K_f, K_m, unknowns)
    assert all(_zero(direct.solution[u] - fit["pq"][u].subs(R.r, 2)) for u in unknowns)
    assert match.is_positive_definite(direct.hessian)
    obj = sum((x**2 for x in K_f - K_m), sp.Integer(0))
    at = {u: fit["pq"][u].subs(R.r, 2) for u in unknowns}
    assert all(_zero(sp.diff(obj, u).subs(at)) for u in unknowns)


def test_least_squares_residual_zero_only_for_square():
    fit = R.least_squares_fit()
    rel = fit["relative_residual"]
    assert rel.subs(R.r, 1) == 0 and fit["residual"].subs(R.r, 1) == 0
    assert rel.subs(R.r, 2) == sp.Rational(300, 5203) and rel.subs(R.r, 2) > 0
    assert _zero(rel - rel.subs(R.r, 1 / R.r))  # a b x a rectangle is the same element turned
    eq = R.least_squares_fit(R.NU_LLOYD, True)["relative_residual"]
    assert eq.subs(R.r, 1) == 0 and eq.subs(R.r, 2) > rel.subs(R.r, 2)


@pytest.mark.parametrize("equilibrium", [False, True])
def test_least_squares_is_lloyd_at_r1(equilibrium):
    fit = R.least_squares_fit(R.NU_LLOYD, equilibrium)
    assert all(_zero(v.subs(R.r, 1) - LLOYD[x]) for x, v in zip(R.K_SYM + R.C_SYM, fit["k"] + fit["c"]))


def test_general_nu_fit_reduces_to_one_third():
    a, b = R.least_squares_fit(R.nu_c), R.least_squares_fit()
    assert all(_zero(x.subs(R.nu_c, R.NU_LLOYD) - y) for x, y in zip(a["k"] + a["c"], b["k"] + b["c"]))
    # at r = 1 the general-nu residual vanishes only for nu = 1/3
    assert sp.solve(sp.numer(sp.together(a["relative_residual"].subs(R.r, 1))), R.nu_c) == [sp.Rational(1, 3)]


def test_positivity_interval():
    lo, hi = R.positivity_interval(R.least_squares_fit())
    assert 0.49 < lo < 0.50 and 2.03 < hi < 2.04 and abs(lo * hi - 1) < 1e-9
    fit = R.least_squares_fit()
    assert fit["k"][1].subs({R.r: 3, E: 1, t: 1}) < 0  # outside: a negative spring constant


def test_equilibrium_at_rest():
    assert R.equilibrium_condition() == {R.Q_SYM[0]: -R.Q_SYM[2], R.Q_SYM[1]: -R.Q_SYM[2]}
    f = R.forces(R.least_squares_fit())
    assert f.subs(R.r, 1) == sp.zeros(8, 1)
    assert f.subs(R.r, 2) != sp.zeros(8, 1)
    assert R.forces(R.least_squares_fit(R.NU_LLOYD, True)) == sp.zeros(8, 1)


# ---- lattice ----------------------------------------------------------------------------------

def test_lattice_least_squares():
    C, sigma0 = R.lattice_check()
    D = elasticity_matrix("plane_stress", E, R.NU_LLOYD)
    assert (C.subs(R.r, 1) - D).applyfunc(sp.cancel) == sp.zeros(3, 3)
    assert sigma0.subs(R.r, 1) == sp.zeros(3, 1)
    agree, differ = R.lattice_agreement(C)
    assert agree == [] and set(differ) == {(0, 0), (0, 1), (1, 1), (2, 2)}
    for d in differ.values():  # every nonzero entry is off by a multiple of (r^2 - 1)
        assert sp.rem(sp.numer(sp.together(d)), R.r**2 - 1, R.r) == 0 and d.subs(R.r, 2) != 0
    assert sigma0.subs(R.r, 2) != sp.zeros(3, 1)  # residual stress: not in equilibrium


def test_lattice_equilibrium_least_squares():
    C, sigma0 = R.lattice_check(equilibrium=True)
    assert sigma0 == sp.zeros(3, 1)
    assert (C.subs(R.r, 1) - elasticity_matrix("plane_stress", E, R.NU_LLOYD)).applyfunc(sp.cancel) == sp.zeros(3, 3)
    agree, differ = R.lattice_agreement(C)
    assert agree == [] and all(d.subs(R.r, 2) != 0 for d in differ.values())


# ---- records and generated code ---------------------------------------------------------------

def test_derivation_record_and_codegen():
    from derivations import codegen

    d = R.derive()
    assert d.errata == []
    names = [f.name for f in d.formulas]
    assert names[0] == "rectangle_least_squares" and d.formulas[0].args == (E, t, R.r)
    ns: dict = {}
    exec(codegen.render("rectangle", d), ns)  # noqa: S102 - our own generated code
    got = ns["rectangle_least_squares"](1.0, 1.0, 1.0)
    assert got == pytest.approx([5 / 16, 5 / 16, 7 / 16, 6 / 5, 6 / 5, 6 / 7])
    got2 = ns["rectangle_least_squares_equilibrium"](2.0, 0.5, 1.0)
    assert got2 == pytest.approx([5 / 16, 5 / 16, 7 / 16, 6 / 5, 6 / 5, 6 / 7])
    general = ns["rectangle_least_squares_nu"](1.0, 1 / 3, 1.0, 2.0)
    assert general == pytest.approx(ns["rectangle_least_squares"](1.0, 1.0, 2.0))

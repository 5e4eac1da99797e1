"""Facts that Table 1 reads from ``paper/derivations.json`` agree with numbers worked out here by hand,
independently of the derivation that recorded them."""

from __future__ import annotations

import json
from pathlib import Path

import sympy as sp
from sympy.physics import units as u

ROOT = Path(__file__).resolve().parents[1]


def _checks(module: str) -> dict:
    return json.loads((ROOT / "paper" / "derivations.json").read_text(encoding="utf-8"))[module]["checks"]


def test_golec_correction_force_units():
    """kappa (V - V0) dV/dP with kappa in Pa, V in m^3 and dV/dP in m^2 (V is cubic in the positions)
    is Pa m^5 = N m^3: not a force; dividing by V0 (m^3) gives N."""
    printed = u.convert_to(u.pascal * u.meter**3 * u.meter**2, [u.newton, u.meter])
    assert sp.simplify(printed - u.newton * u.meter**3) == 0
    checks = _checks("cube_golec")
    assert checks["printed_force_is_newton"] == 0
    assert checks["printed_force_extra_length_power"] == 3
    assert checks["corrected_force_is_newton"] == 1


def test_golec_kappa_sign_below_a_quarter():
    """Golec's kappa = E (4 nu - 1) / (2 (1 + nu)(1 - 2 nu)) is negative for nu in ]0, 1/4[."""
    for nu in (0.1, 0.2):
        assert (4 * nu - 1) / (2 * (1 + nu) * (1 - 2 * nu)) < 0
    assert _checks("cube_golec")["kappa_negative_below_quarter"] == 1

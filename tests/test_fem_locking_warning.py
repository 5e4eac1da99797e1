"""Near-incompressible materials: the linear-element FEM references lock, and say so.

A cube of side 1 m clamped at its base and pressed on its top (1 kPa, E = 1 MPa) is solved on 3^3
and 6^3 hexahedra: at nu = 0.3 the top settlement changes by under 2 % between the meshes (converged),
at nu = 0.4999 by a factor over 3 (the coarse mesh locks: far too stiff). Every solve at nu >= 0.45
warns once, naming nu; one at nu = 0.3 does not.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from msslib import fem
from msslib import mesh as M
from msslib.errors import MsslibWarning


def _pressed_cube(n, nu, solve=fem.solve_linear, **options):
    """Mean top settlement (m) of the clamped unit cube on ``n^3`` hexahedra, and the warnings."""
    m = M.hex_grid(1.0, 1.0, 1.0, n, n, n)
    p = m.points
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    fixed[np.isclose(p[:, 2], 0.0)] = True
    top = np.isclose(p[:, 2], 1.0)
    edge = lambda c: np.where(np.isclose(c, 0.0) | np.isclose(c, 1.0), 0.5, 1.0) / n  # noqa: E731
    forces = np.zeros((m.n_nodes, 3))
    forces[top, 2] = -1.0e3 * edge(p[top, 0]) * edge(p[top, 1])  # 1 kPa on the tributary areas
    assert forces.sum() == pytest.approx(-1.0e3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = solve(m, 1.0e6, nu, fixed=fixed, nodal_forces=forces, **options)
    locking = [w for w in caught if issubclass(w.category, MsslibWarning) and "locks" in str(w.message)]
    return -result.displacement[top, 2].mean(), locking


def test_warns_once_per_solve_at_nu_0_4999_and_not_at_0_3():
    _, none = _pressed_cube(3, 0.3)
    assert none == []
    _, (one,) = _pressed_cube(3, 0.4999)
    text = str(one.message)
    assert "linear-element FEM locks near nu = 1/2 (nu = 0.4999" in text and "too small" in text
    _, (again,) = _pressed_cube(2, 0.4999, solve=fem.solve_nonlinear, steps=1)
    assert "nu = 0.4999" in str(again.message)
    _, none = _pressed_cube(2, 0.44, solve=fem.solve_nonlinear, steps=1)
    assert none == []


def test_plane_stress_does_not_lock_and_does_not_warn():
    m = M.quad_grid(1.0, 1.0, 2, 2)
    fixed = np.zeros((m.n_nodes, 2), dtype=bool)
    fixed[np.isclose(m.points[:, 1], 0.0)] = True
    for plane, expected in (("stress", 0), ("strain", 1)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fem.solve_linear(m, 1.0e6, 0.4999, fixed=fixed, plane=plane)
        assert len([w for w in caught if issubclass(w.category, MsslibWarning)]) == expected, plane


def test_the_locking_it_warns_about_is_real():
    (coarse, _), (fine, _) = (_pressed_cube(n, 0.3) for n in (3, 6))
    assert abs(fine / coarse - 1.0) < 0.02  # converged: 0.957 mm and 0.965 mm
    # order of magnitude by hand: a laterally free column, p / E = 1 mm, a little less for the clamp
    assert 0.8e-3 < fine < 1.0e-3
    (coarse, _), (fine, _) = (_pressed_cube(n, 0.4999) for n in (3, 6))
    assert fine / coarse > 3.0  # 0.021 mm and 0.078 mm: the coarse mesh is locked
    # and the fine one still far too stiff: a bonded incompressible block of shape factor S = 1/4
    # (loaded area over free sides) has the apparent modulus E (1 + 2 S^2) (Gent), i.e. settles ~0.9 mm
    assert fine < 0.3 * 1.0e-3

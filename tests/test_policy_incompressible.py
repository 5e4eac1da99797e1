"""Nearly incompressible elasticity goes to a direct solver under linear_solver="auto": the
AMG-preconditioned CG slows down as lambda / mu grows (the quadratic reference of the thick
sphere at nu = 0.4999 took 200 s by CG against 1.6-4 s direct)."""

from __future__ import annotations

import numpy as np
import pytest

from msslib import mesh as M
from msslib.fem import solve_linear
from msslib.solvers import policy


def test_the_rule():
    assert policy.method_for_material("auto", 0.3) == "auto"
    assert policy.method_for_material("auto", 0.4999) == "direct"
    assert policy.method_for_material("auto", np.array([0.3, 0.3, policy.NEARLY_INCOMPRESSIBLE_NU])) == "direct"
    assert policy.method_for_material("cg", 0.4999) == "cg"  # an explicit request is kept
    solver = lambda A, b: b  # noqa: E731
    assert policy.method_for_material(solver, 0.4999) is solver


@pytest.mark.parametrize("nu,expected", [(0.3, "cg"), (0.4999, "direct")])
def test_a_quadratic_solve_takes_the_direct_solver_near_incompressibility(nu, expected):
    mesh = M.tet_grid(1.0, 1.0, 1.0, 6, 6, 6)  # 2 197 quadratic nodes: above the CG threshold
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-9] = True
    forces = np.zeros((mesh.n_nodes, 3))
    forces[mesh.points[:, 2] > 1 - 1e-9, 0] = 1.0
    r = solve_linear(mesh, 1e5, nu, fixed=fixed, nodal_forces=forces, order=2, volumetric="reduced")
    assert expected in r.stats["solver"], r.stats["solver"]
    direct = solve_linear(mesh, 1e5, nu, fixed=fixed, nodal_forces=forces, order=2, volumetric="reduced",
                          linear_solver="direct")
    np.testing.assert_allclose(r.displacement, direct.displacement, rtol=0, atol=1e-6 * np.abs(direct.displacement).max())

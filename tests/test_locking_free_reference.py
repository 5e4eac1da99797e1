"""Near nu = 1/2 linear-element FEM locks; the quadratic reference with the reduced volumetric rule
does not, so plan measures the models and not the reference."""

import warnings

import numpy as np
import pytest

from experiments.examples.incompressible_cube import scene
from msslib import fem
from msslib import mesh as M
from msslib import planning


def _cube(cell, n):
    m = (M.hex_grid if cell == "hexahedron" else M.tet_grid)(1.0, 1.0, 1.0, n, n, n)
    z = m.points[:, 2]
    bf = M.boundary_facets(m)
    return m, z, bf[(np.abs(z[bf] - 1.0) < 1e-9).all(axis=1)]


def _settlement(cell, n, nu, **kw):
    m, z, top = _cube(cell, n)
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    fixed[z < 1e-9] = True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = fem.solve_linear(m, 1e6, nu, fixed=fixed, tractions=[(top, [0.0, 0.0, -1e3])], **kw)
    return -r.displacement[np.abs(z - 1.0) < 1e-9, 2].mean()


def test_linear_hexahedra_lock_the_reduced_quadratic_ones_do_not():
    """Clamped cube at nu = 0.4999: Q1's settlement grows 3.9-fold from 2^3 to 4^3 cells (locking);
    Q2 with the reduced volumetric rule changes by under 3 % (0.3 % measured), and its settlement
    at nu = 0.49 is within 3 % of that at 0.4999 (the response tends smoothly to the
    incompressible limit instead of collapsing)."""
    q1 = [_settlement("hexahedron", n, 0.4999) for n in (2, 4)]
    q2 = [_settlement("hexahedron", n, 0.4999, order=2, volumetric="reduced") for n in (2, 4)]
    assert q1[1] / q1[0] > 3.0
    assert abs(q2[1] / q2[0] - 1.0) < 0.03
    near = _settlement("hexahedron", 4, 0.49, order=2, volumetric="reduced")
    assert abs(near / q2[1] - 1.0) < 0.03


@pytest.mark.parametrize("cell", ["hexahedron", "tetra"])
def test_reduced_quadratic_elements_are_exact_for_uniaxial_stress_at_nu_04999(cell):
    """Rollers on three faces, traction s on z = 1: u_z = -s z / E, u_x = nu s x / E exactly."""
    m, z, top = _cube(cell, 2)
    p = m.points
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    for a in range(3):
        fixed[p[:, a] < 1e-9, a] = True
    nu, s = 0.4999, -1e3
    r = fem.solve_linear(m, 1e6, nu, fixed=fixed, tractions=[(top, [0.0, 0.0, s])], order=2, volumetric="reduced")
    exact = np.column_stack([-nu * s / 1e6 * r.dof_points[:, 0], -nu * s / 1e6 * r.dof_points[:, 1],
                             s / 1e6 * r.dof_points[:, 2]])
    np.testing.assert_allclose(r.dof_displacement, exact, atol=1e-9 * abs(s) / 1e6)


def test_plan_at_nu_04999_reports_no_model_hundreds_of_percent_wrong():
    """Clamped cube at nu = 0.4999, levels 1, 2: the reference is the locking-free one, its own error
    a few per cent; Golec's cube within 30 %; linear FEM (which locks) is the one far off."""
    front = planning.measure_front(scene(0.4999), levels=(1, 2), repeats=1, progress=None,
                                   models=["golec_cube", "fem_linear"])
    assert "locking-free at nu = 0.4999" in front.attrs["reference_model"]
    assert 0 < float(front.attrs["reference_error"]) < 0.1
    golec = front.error_max.sel(model="golec_cube").values
    assert np.all(golec < 0.3), golec
    assert np.all(front.error_max.sel(model="fem_linear").values > 0.5)  # Q1 locks: 2^3 and 4^3 cells


def test_the_p1_reference_is_never_used_near_incompressibility():
    from msslib.planning.reference import nearly_incompressible
    from msslib.scene import load_scene, prepare

    assert nearly_incompressible(prepare(load_scene(scene(0.45)))) == 0.45
    assert nearly_incompressible(prepare(load_scene(scene(0.3)))) is None

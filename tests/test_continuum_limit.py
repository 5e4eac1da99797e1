"""The continuum limit of Baudet's lattice of cubes under the element reading of the correction.

The derivation (derivations/elements/cube_baudet.py, element_reading_tensor) gives the lattice's
Voigt matrix from one cube's virial stress under an affine displacement: exactly the isotropic D(E,
nu), so E, nu and G are all exact and no floor is left (the lattice without the correction inside,
the boundary reading, is cubic-anisotropic). Checked independently with the simulator's own term
(msslib.terms.ElementBaudetCorrection): a block of cubes whose boundary nodes follow an affine
displacement keeps its interior nodes on that affine field, and the boundary reactions give the
stress D eps.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from derivations import elasticity as el
from derivations.elasticity import E, nu
from derivations.elements import cube_baudet as cb


def test_the_element_reading_lattice_is_the_isotropic_material():
    C, skew = cb.element_reading_tensor()
    assert (C - el.elasticity_matrix("3d")).applyfunc(sp.simplify) == sp.zeros(6, 6)
    assert skew == sp.zeros(3, 3)
    # without the correction inside (the boundary reading) the same cubes are not isotropic
    _, lattice = cb.assembled_lattice()
    assert sp.simplify(lattice["isotropy defect"].subs(nu, sp.Rational(3, 10))) != 0
    assert sp.simplify(lattice["uniaxial E along an axis"].subs(nu, sp.Rational(3, 10)) - E) != 0


def _voigt(eps):
    return np.array([eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[1, 2], 2 * eps[0, 2], 2 * eps[0, 1]])


@pytest.mark.parametrize("nu_value", [0.3, 0.45])
def test_a_block_under_an_affine_boundary_displacement_has_the_isotropic_stress(nu_value):
    from msslib.system import Model
    from msslib.scene import load_scene, prepare
    from msslib.solvers import static_solve

    E_value, size, n = 1000.0, 1.0, 4
    scene = {"name": "block", "geometry": {"generator": "hex_grid", "args": {"lx": size, "ly": size, "lz": size,
                                                                            "nx": n, "ny": n, "nz": n}},
             "materials": [{"E": E_value, "nu": nu_value}],
             "model": {"type": "baudet_cube", "correction": "element"},
             "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
             "solver": {"type": "static"}}
    setup = prepare(load_scene(scene))
    mesh = setup.mesh
    X = mesh.points
    boundary = np.any(np.isclose(X, 0.0) | np.isclose(X, size), axis=1)
    eps = 1e-7 * np.array([[1.0, 0.4, -0.3], [0.4, -0.5, 0.2], [-0.3, 0.2, 0.8]])
    affine = X @ eps.T
    fixed = np.repeat(boundary[:, None], 3, axis=1)
    internal = [t for t in setup.model.terms if t.kind in ("springs", "correction")]
    assert {t.kind for t in internal} == {"springs", "correction"}
    model = Model(mesh, internal, fixed=fixed, prescribed=np.where(fixed, affine, 0.0))
    res = static_solve(model, (X + affine * boundary[:, None]).ravel(), tol=1e-12)
    u = res.x.reshape(-1, 3) - X
    np.testing.assert_allclose(u[~boundary], affine[~boundary], rtol=0, atol=1e-9 * np.abs(affine).max())
    reaction = -model.force(res.x, 1.0).reshape(-1, 3)  # what the outside applies at the boundary nodes
    sigma = reaction[boundary].T @ X[boundary] / size**3
    D = np.array(el.elasticity_matrix("3d").subs({E: E_value, nu: nu_value}), dtype=float)
    expected = D @ _voigt(eps)
    got = np.array([sigma[0, 0], sigma[1, 1], sigma[2, 2], sigma[1, 2], sigma[0, 2], sigma[0, 1]])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(sigma, sigma.T, rtol=0, atol=1e-6 * np.abs(expected).max())

"""Least-squares springs of badly shaped tetrahedra (Lloyd Sec. 4.2.1;
experiments/lloyd/studies/tet_shapes.py). Expected values: the regular tetrahedron's six equal
constants with eq. 12's value, and the dihedral angles of the canonical shapes from their geometry."""

import numpy as np
import pytest

from experiments.lloyd.studies import tet_shapes as TS


def test_regular_tetrahedron_gets_six_equal_constants_of_eq12():
    X = TS.positive(TS.shape("regular", 0.1)[None])
    k6, r6 = TS.least_squares_springs(X)
    edge = np.linalg.norm(X[0, 1] - X[0, 0])
    np.testing.assert_allclose(k6[0], 2 * np.sqrt(2) / 25 * TS.E * edge, rtol=1e-10)  # eq. 12 at nu = 1/4
    assert r6[0] == pytest.approx(0.2, abs=1e-3)  # the derivation's residual at nu = 1/4


@pytest.mark.parametrize("name", ["sliver", "cap", "spindle"])
def test_flat_shapes_have_a_large_dihedral_angle_and_a_negative_spring(name):
    X = TS.positive(TS.shape(name, 0.05)[None])
    assert TS.max_dihedral(X)[0] > 160.0
    k6, _ = TS.least_squares_springs(X)
    assert k6.min() < 0 < k6.max()


def test_sliver_dihedral_angle_from_geometry():
    """The sliver's edges (+-1, 0, t) and (0, +-1, -t) carry the dihedral angle 180 - 2 atan(2 t)."""
    for t in TS.T:
        X = TS.positive(TS.shape("sliver", t)[None])
        expected = 180.0 - 2.0 * np.degrees(np.arctan(2.0 * t))
        assert TS.max_dihedral(X)[0] == pytest.approx(max(expected, 90.0), abs=1e-9)

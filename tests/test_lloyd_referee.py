"""Lloyd et al. items a referee asked for: the zero patterns of the element matrices (Figs. 5, 7, 8),
the one-point-quadrature bilinear reference of Sec. 5.3 and the equilateral mesh with the paper's
counts (Sec. 5.1).  Expected values come from closed forms written here (the bilinear square's
stiffness entries, eq. 6 of the paper), not from the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.lloyd.studies import sparsity

E, T = 14630.0, 0.01


def spring_matrix(X, pairs, k, rest_factor=None):
    """Eq. 6 of the paper summed over springs, with the prestrain term of a spring whose rest length
    is c times its length: k (1 - c) I + k c d d^T / l^2 per block."""
    n, d = X.shape
    K = np.zeros((n * d, n * d))
    for s, (i, j) in enumerate(pairs):
        v = X[j] - X[i]
        L = np.linalg.norm(v)
        c = 1.0 if rest_factor is None else rest_factor[s]
        A = k[s] * ((1 - c) * np.eye(d) + c * np.outer(v, v) / L**2)
        for a, b, sign in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[a * d:(a + 1) * d, b * d:(b + 1) * d] += sign * A
    return K


def test_bilinear_square_at_one_third_has_zeros_on_three_antidiagonals():
    # closed form of the plane-stress bilinear square (any side), in units of E t / (1 - nu^2): the
    # diagonal entry is 1/2 - nu/6; the coupling of x at one node with y at its neighbour (3 nu - 1)/8,
    # zero at nu = 1/3
    K = sparsity.simulator("square_fem")
    scale = E * T / (1 - (1 / 3) ** 2)
    assert K[0, 0] == pytest.approx(scale * (1 / 2 - (1 / 3) / 6))
    assert K[0, 3] == pytest.approx(0.0, abs=1e-12 * scale) and K[0, 7] == pytest.approx(0.0, abs=1e-12 * scale)
    zero = ~sparsity.numerical_mask(K)
    i, j = np.nonzero(zero)
    assert zero.sum() == 16
    assert set((i + j + 2).tolist()) == {5, 9, 13}
    # at another nu the same element has no zero
    other = sparsity.fem.element_stiffness("quad", np.array(sparsity.square_coords(0.01), float), E, 0.3, thickness=T)
    assert sparsity.numerical_mask(other).all()


def test_square_springs_match_eq6_with_and_without_prestrain():
    X = np.array(sparsity.square_coords(sparsity.SIDE), float)
    p = sparsity.lloyd_square(E, t=T)
    pairs = sparsity.SQ_EDGES + sparsity.SQ_DIAGONALS
    k = [p.k_edge] * 4 + [p.k_diagonal] * 2
    plain = spring_matrix(X, pairs, k)
    np.testing.assert_allclose(sparsity.simulator("square_mss_plain"), plain, atol=1e-9 * np.abs(plain).max())
    assert sparsity.numerical_mask(plain).sum() == 40  # 4 node blocks full, 8 edge blocks with 1 entry, 4 diagonal-spring blocks full
    c = [p.rest_factor_edge] * 4 + [p.rest_factor_diagonal] * 2
    pre = spring_matrix(X, pairs, k, c)
    np.testing.assert_allclose(sparsity.simulator("square_mss_prestrain"), pre, atol=1e-9 * np.abs(pre).max())
    # eqs. 10-11 are exact: the prestrained springs' matrix is the FEM's at nu = 1/3
    np.testing.assert_allclose(pre, sparsity.simulator("square_fem"), atol=1e-9 * np.abs(pre).max())


def test_regular_tetrahedron_springs_match_eq6_and_eq12():
    X = np.array(sparsity.tet_coords(sparsity.EDGE), float)
    k = 2 * np.sqrt(2) / 25 * sparsity.EDGE * E  # eq. 12
    K = spring_matrix(X, sparsity.TET_PAIRS, [k] * 6)
    np.testing.assert_allclose(sparsity.simulator("tet_mss"), K, atol=1e-9 * np.abs(K).max())
    # the edge 0-1 lies on the x axis: the block K_01 has its xx entry only
    assert np.count_nonzero(np.abs(K[0:3, 3:6]) > 1e-9 * np.abs(K).max()) == 1


def test_generic_orientation_fills_every_matrix():
    for name in ("square_mss_plain", "tet_mss", "tet_fem", "square_fem"):
        R = sparsity.rotation(2 if name.startswith("square") else 3)
        np.testing.assert_allclose(R @ R.T, np.eye(len(R)), atol=1e-12)
        assert sparsity.numerical_mask(sparsity.simulator(name, R)).all(), name

"""Where Lloyd's Sec. 5.2 errors sit and at which nodes Sec. 5.4's coarse error is measured
(experiments/lloyd/studies/error_location.py). Expected values come from the geometry of the
experiment files (the rectangle's corners, the grid spacing) and from the definitions, not from the
study's own output."""

import numpy as np
import pytest

from experiments.lloyd.studies.error_location import corners_part, mean_edge_length, resolutions_part
from msslib.mesh import quad_grid

W, H = 0.072, 0.052  # the Sec. 5.2 rectangle (experiments/lloyd/membrane_arbitrary.yaml)


def test_mean_edge_length_of_a_square_grid_is_its_spacing():
    assert mean_edge_length(quad_grid(0.05, 0.05, 2, 2)) == pytest.approx(0.025, rel=1e-12)
    assert mean_edge_length(quad_grid(0.06, 0.02, 3, 1)) == pytest.approx(0.02, rel=1e-12)


@pytest.fixture(scope="module")
def corners():
    return corners_part(quick=False)


def test_corner_distance_is_measured_from_the_rectangles_corners(corners):
    out, h, size = corners
    np.testing.assert_allclose(size, [W, H], atol=1e-12)
    all_corners = np.array([[0, 0], [W, 0], [0, H], [W, H]])
    top = all_corners[2:]
    for i in range(3):
        for j in range(2):
            p = np.array([out["worst_x"][i, j], out["worst_y"][i, j]])
            assert out["corner_distance"][i, j] == pytest.approx(np.linalg.norm(all_corners - p, axis=1).min(), abs=1e-12)
            assert out["top_corner_distance"][i, j] == pytest.approx(np.linalg.norm(top - p, axis=1).min(), abs=1e-12)
            assert out["corner_distance_edges"][i, j] == pytest.approx(out["corner_distance"][i, j] / h, rel=1e-12)
            assert max(out["near_corner_max"][i, j], out["elsewhere_max"][i, j]) == out["error_max"][i, j]
    assert 0.005 < h < 0.012  # gmsh's element size 1 cm


def test_compression_error_peaks_in_the_middle_of_the_loaded_edge(corners):
    """The loaded edge is y = H; in compression the largest error of both formulas sits on it, far
    from both of its corners; in stretch eq. 8's sits at one of them."""
    out, h, _ = corners
    c = 1  # compression
    for j in range(2):
        assert out["worst_y"][c, j] == pytest.approx(H, abs=1e-12)
        assert out["corner_distance"][c, j] > 3 * h
    s = 0  # stretch, eq. 8
    assert out["top_corner_distance"][s, 0] == pytest.approx(0.0, abs=1e-12)


def test_coarse_error_at_own_nodes_and_at_all_nodes():
    res = resolutions_part(quick=True)
    np.testing.assert_array_equal(res["n_own"], [9, 36])  # 3 x 3 and 6 x 6 nodes
    np.testing.assert_array_equal(res["n_all"], [400, 400])  # the 20 x 20 reference nodes
    assert np.all(res["all_mean"] > 0) and np.all(res["own_mean"] > 0)
    assert np.all(res["all_max"] >= res["all_mean"]) and np.all(res["own_max"] >= res["own_mean"])
    assert res["own_max"][0] > res["own_max"][1]  # the 2 x 2 model errs more than the 5 x 5

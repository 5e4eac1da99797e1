"""Agreement tolerances from the printed digits of Lloyd's published errors
(experiments/lloyd/studies/printed_digits.py): expected intervals worked out by hand."""

import pytest

from experiments.lloyd.studies.printed_digits import half_unit, published_pairs, ratio_interval


def test_half_unit_of_the_last_printed_digit():
    assert half_unit("0.076") == pytest.approx(0.0005)
    assert half_unit("0.0677") == pytest.approx(0.00005)
    assert half_unit("0.100") == pytest.approx(0.0005)  # trailing zeros are printed digits
    assert half_unit("12") == pytest.approx(0.5)


def test_ratio_interval_of_the_square_membrane_in_stretch():
    r, lo, hi = ratio_interval("0.041", "0.076")
    assert r == pytest.approx(0.041 / 0.076)
    assert lo == pytest.approx(0.0405 / 0.0765)
    assert hi == pytest.approx(0.0415 / 0.0755)


def test_pairs_keep_the_texts_of_the_files():
    pairs = {run: (mean, mx) for run, mean, mx in published_pairs()}
    assert pairs["membrane_square/compression/mss"] == ("0.0677", "0.129")
    assert pairs["cylinder_hole/shear/mss"] == ("0.035", "0.100")
    assert pairs["resolutions/shear/mss_19x19"] == ("0.024", "0.078")
    assert len(pairs) == 18

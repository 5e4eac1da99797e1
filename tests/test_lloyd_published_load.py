"""The load at which Lloyd's Sec. 5.3 square MSS reaches the published maximum error
(experiments/lloyd/studies/published_load.py): the published numbers read in metres, the error of
the prestrained square (exact for small strain) quadratic in the load, and the load found gives the
published maximum when the experiment is run there again."""

import pytest
import xarray as xr

from experiments.lloyd.studies import published_load as P
from msslib.experiment import load_experiment


@pytest.fixture(scope="module")
def exp():
    return load_experiment(P.LLOYD / "membrane_square.yaml")


def test_published_maxima_in_metres(exp):
    assert P.published_max(exp, "stretch") == pytest.approx(0.076e-2, rel=1e-12)
    assert P.published_max(exp, "shear") == pytest.approx(0.196e-2, rel=1e-12)


@pytest.mark.parametrize("case", ["stretch", "shear"])
def test_error_is_quadratic_in_small_loads(exp, case):
    e1 = P.error_at(exp, case, 0.01, False)[0]
    e2 = P.error_at(exp, case, 0.02, False)[0]
    assert e2 / e1 == pytest.approx(4.0, rel=0.02)


def test_found_load_reproduces_the_published_maximum(exp, tmp_path):
    out = tmp_path / "published_load.nc"
    P.main(["--out", str(out)])
    with xr.open_dataset(out) as ds:
        ds = ds.load()
    for case in P.CASES:
        f = float(ds.factor.sel(case=case))
        e, d, _ = P.error_at(exp, case, f, False)
        assert e == pytest.approx(P.published_max(exp, case), rel=1e-3)
        assert d == pytest.approx(float(ds.deformation.sel(case=case)), rel=1e-12)
        assert f > 1.0  # our error at the file's load is below the published one

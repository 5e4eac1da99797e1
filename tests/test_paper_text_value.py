"""``{{value FILE VAR fmt=text}}``: a word the results computed (a crossover's "resolved" or
"unresolved"), printed as it is; without ``fmt=text`` a text attribute is not a number."""

import pytest
import xarray as xr

from experiments import paper
from test_paper import make_paper


@pytest.mark.parametrize("word", ["resolved", "unresolved"])
def test_text_attribute_printed_as_computed(tmp_path, word):
    source = make_paper(tmp_path, "The crossover is {{value results/front.nc crossover_status fmt=text}}.\n")
    xr.Dataset(attrs={"crossover_status": word}).to_netcdf(tmp_path / "results" / "front.nc")
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert f"The crossover is {word}." in text


def test_text_attribute_without_fmt_text_is_refused(tmp_path):
    source = make_paper(tmp_path, "The crossover is {{value results/front.nc crossover_status}}.\n")
    xr.Dataset(attrs={"crossover_status": "resolved"}).to_netcdf(tmp_path / "results" / "front.nc")
    with pytest.raises(ValueError):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")

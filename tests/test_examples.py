"""The worked examples in experiments/examples/ run as written and give a choice with the reference's own error."""

import re

import pytest

from experiments.examples import incompressible_cube, liver_plan


@pytest.mark.parametrize("example, budget, nu", [(liver_plan, "0.7", "0.45"), (incompressible_cube, "0.3", "0.49")])
def test_example_plans_a_choice_against_the_locking_free_reference(tmp_path, capsys, example, budget, nu):
    assert example.main(tmp_path, "1,2", budget) == 0
    out = capsys.readouterr().out
    assert f"locking-free at nu = {nu})" in out, out
    choice = re.search(r"choice: \w+ at resolution level \d: max error ([0-9.]+) % <= ([0-9.]+) % "
                       r"\(reference's own error about ([0-9.]+) %", out)
    assert choice, out
    error, allowed, own = (float(g) for g in choice.groups())
    assert error <= allowed == 100 * float(budget) and 0 < own < allowed

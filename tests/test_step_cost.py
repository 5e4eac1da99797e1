"""Study step_cost (experiments/performance/studies/step_cost.py): the parts of a step it times and
the numbers the paper reads from it beside the times."""

from __future__ import annotations

import math

import numpy as np

from experiments.performance.studies import step_cost


def test_diagonal_over_lloyd_is_the_derivations_55_over_48_at_a_quarter():
    # the exact ratio is the symbolic derivation's (tests/test_kikuuwe_tetrahedron.py); here the
    # generated constants of the regular tetrahedron against Lloyd's eq. 12
    assert abs(step_cost.diagonal_over_lloyd(0.25) - 55 / 48) < 1e-12
    assert step_cost.diagonal_over_lloyd(0.45) > step_cost.diagonal_over_lloyd(0.25)


def test_coarsest_level_times_every_part_and_the_same_element_gives_the_same_solution():
    ds = step_cost.measure((0,), 1, progress=lambda _line: None)
    assert float(ds.equal_to_fem_svk.sel(level=0)) < 1e-8
    assert int(ds.n_cells.sel(level=0)) > 100 and int(ds.n_dofs.sel(level=0)) % 3 == 0
    for model in ("kikuuwe_tetrahedron", "fem_svk"):
        t = ds.time_median.sel(model=model, level=0)
        assert np.all(np.isfinite(t.values)) and np.all(t.values >= 0), model
        # a Newton step is its parts: tangent and solve (FEM's tangent call returns its forces too)
        parts = ("tangent", "solve") if model == "fem_svk" else ("force", "tangent", "solve")
        assert math.isclose(float(t.sel(part="newton_step")), sum(float(t.sel(part=p)) for p in parts))
    lloyd = ds.time_median.sel(model="lloyd_tetrahedron", level=0)
    assert np.isnan(float(lloyd.sel(part="element_loop"))) and np.isfinite(float(lloyd.sel(part="force")))
    assert ds.attrs["load_scale"] == step_cost.LOAD_SCALE

"""plan on a mesh file: a gmsh mesh with two physical volumes, refined uniformly into nested levels,
measured against a quadratic reference whose own error is printed beside the choice; budgets
above 1 and below the reference's error are refused."""

import math
import re

import numpy as np
import pytest
import xarray as xr
import yaml

from experiments.examples.liver_plan import SCENE, write_mesh
from msslib import mesh as M
from msslib import planning
from msslib.cli import main as cli
from msslib.planning.reference import solve_setup
from msslib.scene import load_scene, prepare


@pytest.fixture(scope="module")
def liver(tmp_path_factory):
    d = tmp_path_factory.mktemp("liver")
    write_mesh(d / "liver.msh")
    (d / "liver.yaml").write_text(yaml.safe_dump(SCENE, sort_keys=False))
    return d


def test_the_mesh_has_two_physical_volumes_and_the_named_faces(liver):
    m = M.read(liver / "liver.msh")
    assert m.cell_type == "tetra"
    assert {"liver", "inclusion"} <= set(m.cell_groups)
    assert {"base", "capsule"} <= set(m.facet_groups)


def test_quadratic_reference_carries_the_traction_on_the_curved_face(liver):
    """Sum of the reactions of the quadratic reference = - traction x area of the capsule's
    (flat) facets, computed here from the triangle areas."""
    setup = prepare(load_scene(str(liver / "liver.yaml")))
    res = solve_setup(setup, order=2, law=None)
    tri = setup.mesh.facet_groups["capsule"]
    p = setup.mesh.points
    area = 0.5 * np.linalg.norm(np.cross(p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]), axis=1).sum()
    np.testing.assert_allclose(res.reaction.sum(axis=0), [0.0, 0.0, 50.0 * area], atol=1e-9 * 50.0 * area)
    assert res.stats["order"] == 2 and res.dof_points.shape[0] > setup.mesh.n_nodes


def test_plan_on_the_gmsh_mesh_prints_the_reference_error_beside_the_choice(liver, capsys):
    code = cli(["plan", str(liver / "liver.yaml"), "--max-error", "0.7", "--levels", "1,2", "--repeats", "1",
                "--save", str(liver / "front.nc")])
    out = capsys.readouterr().out
    assert code == 0, out
    ref = re.search(r"reference: fem_neohookean \(quadratic elements.*locking-free at nu = 0\.45\)\) on level 2, "
                    r"own error about ([0-9.]+) %", out)
    choice = re.search(r"choice: (\w+) at resolution level (\d): max error ([0-9.]+) % <= 70 % "
                       r"\(reference's own error about ([0-9.]+) %", out)
    assert ref and choice, out
    assert ref.group(1) == choice.group(4)
    front = xr.load_dataset(liver / "front.nc")
    est = float(front.attrs["reference_error"])
    assert 0 < est < 1 and math.isclose(float(ref.group(1)), 100 * est, rel_tol=0.06)
    chosen = front.sel(model=choice.group(1), level=int(choice.group(2)))
    assert float(chosen.error_max) <= 0.7
    # the cheapest: no measured point within the budget is faster
    ok = (front.error_max <= 0.7) & np.isfinite(front.wall_time)
    assert float(chosen.wall_time) == float(front.wall_time.where(ok).min())


@pytest.mark.parametrize("value, meant", [("5", "5 %"), ("30", "30 %")])
def test_a_budget_above_one_is_refused_as_a_percentage(liver, capsys, value, meant):
    code = cli(["plan", str(liver / "liver.yaml"), "--max-error", value])
    err = capsys.readouterr().err
    assert code != 0
    assert f"did you mean {meant}" in err and err.count("\n") == 1, err


def _front(ref_error):
    return xr.Dataset({"wall_time": (("model", "level"), np.array([[0.1, 0.3]])),
                       "error_max": (("model", "level"), np.array([[0.08, 0.02]])),
                       "error_mean": (("model", "level"), np.array([[0.04, 0.01]])),
                       "n_dofs": (("model", "level"), np.array([[10, 80]])),
                       "status": (("model", "level"), np.array([["ok", "ok"]]))},
                      coords={"model": ["m"], "level": [1, 2]},
                      attrs={"reference_model": "r", "reference_level": 2, "reference_error": ref_error,
                             "reference_step_change": 2 * ref_error, "reference_levels": "1,2"})


def test_a_budget_below_the_reference_error_is_refused():
    with pytest.raises(ValueError, match=r"below the reference's own error, about 3 %"):
        planning.choose(_front(0.03), 0.025)
    assert planning.choose(_front(0.03), 0.05) == ("m", 2, 0.3, 0.02)


def test_a_choice_within_the_reference_error_of_the_budget_is_flagged():
    lines = planning.report(_front(0.01), 0.1)
    assert lines[-1].startswith("choice: m at resolution level 1: max error 8 % <= 10 % (reference's own error "
                                "about 1 %)"), lines
    lines = planning.report(_front(0.03), 0.1)
    assert "within the margin: the choice is uncertain" in lines[-1], lines

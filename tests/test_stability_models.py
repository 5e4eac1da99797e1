"""The model columns of the hard-case study (experiments/stability): every mass-spring model of the
registry on tetrahedra or hexahedra runs, Baudet's cube under both readings of its correction
force with the reading recorded, and the stability limit of the dynamic cases recorded; the
speed-against-error fronts run Baudet's cube under the element reading and record it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from experiments.performance import front
from experiments.stability import scenes, study, to_dataset
from experiments.stability.shapes import SHAPES
from msslib import models as registry
from msslib import solvers as S
from msslib.planning.front import at_level
from msslib.scene import load_scene, prepare, run_scene
from msslib.terms import BaudetCorrection, ElementBaudetCorrection

DATA = scenes.load_cases()
ROOT = Path(__file__).resolve().parents[1]


def _only(*columns):
    return {**DATA, "models": {c: DATA["models"][c] for c in columns}}


def test_every_registry_model_of_the_cells_has_a_column_before_the_fem_columns():
    ran = {scenes.model_type(spec) for spec in DATA["models"].values()}
    for cells in ("tetra", "hexahedron"):
        assert set(registry.for_cells(cells, "mss")) <= ran, cells
    assert "kikuuwe_tetrahedron" in DATA["models"] and "lsq_tetrahedron" in DATA["models"]
    kinds = [registry.get(scenes.model_type(s)).kind for s in DATA["models"].values()]
    assert kinds == sorted(kinds, key=lambda k: k == "fem"), kinds  # MSS columns first, then FEM


def test_registry_columns_adds_only_what_no_column_runs():
    columns = {"mine": {"cells": "tetra", "model": {"type": "lloyd_tetrahedron"}},
               "fem_linear": {"cells": "hexahedron", "model": "fem_linear"}}
    out = scenes.registry_columns(columns)
    assert "lloyd_tetrahedron" not in out and list(out)[0] == "mine" and list(out)[-1] == "fem_linear"
    assert out["kikuuwe_tetrahedron"] == {"cells": "tetra", "model": "kikuuwe_tetrahedron"}
    assert out["golec_cube"] == {"cells": "hexahedron", "model": "golec_cube"}


def test_baudet_columns_run_the_reading_they_name():
    assert scenes.reading(DATA["models"]["baudet_cube"]) == "element"
    assert scenes.reading(DATA["models"]["baudet_cube_boundary"]) == "boundary"
    assert scenes.reading(DATA["models"]["golec_derived"]) == ""
    case = DATA["cases"]["nu_0.45"]
    for column, kind in (("baudet_cube", ElementBaudetCorrection), ("baudet_cube_boundary", BaudetCorrection)):
        spec = DATA["models"][column]
        extra = {"traction": -1000.0} if column == "baudet_cube_boundary" else {}
        terms = prepare(load_scene(scenes.scene("nu_0.45", case, spec["cells"], spec["model"], DATA, True,
                                                **extra))).model.terms
        assert [type(t) for t in terms if isinstance(t, (BaudetCorrection, ElementBaudetCorrection))] == [kind]


def test_result_records_the_reading_and_the_stability_limit():
    rec = study.record(ran=True, converged=True, dt_limit=2.5e-4, outcome="ok")
    ds = to_dataset({"c": {"baudet_cube": rec}}, {s: {"k_lloyd": 1.0, "k_lsq": [1.0] * 6, "lsq_residual": 0.0}
                                                  for s in [*SHAPES, "regular"]},
                    ["baudet_cube", "golec_derived"], 1e6, False, readings={"baudet_cube": "element"})
    assert list(ds.reading.values) == ["element", ""]
    assert float(ds.dt_limit.sel(case="c", model="baudet_cube")) == 2.5e-4
    assert ds.dt_limit.attrs["units"] == "s"
    assert math.isnan(float(ds.dt_limit.sel(case="c", model="golec_derived")))


def test_kikuuwe_column_equals_the_svk_element_on_the_same_tetrahedra():
    """Kikuuwe's edge energy is the St Venant-Kirchhoff element's: the hard case's solution at
    nu = 0.49 (10 % compression) is the StVK FEM solution on the same Kuhn mesh, node by node."""
    case = DATA["cases"]["nu_0.49"]
    u = {}
    for column in ("kikuuwe_tetrahedron", "fem_svk_tetra"):
        spec = DATA["models"][column]
        sc = scenes.scene("nu_0.49", case, spec["cells"], spec["model"], DATA, True)
        sc["solver"]["tol"] = 1e-11
        u[column] = run_scene(sc, progress=False)["displacement"].values
    scale = np.abs(u["fem_svk_tetra"]).max()
    assert scale > 0.05 * float(case["size"]) * float(case["strain"])
    assert np.abs(u["kikuuwe_tetrahedron"] - u["fem_svk_tetra"]).max() <= 1e-8 * scale


def test_dynamic_case_records_the_models_stability_limit():
    name = "explicit_2x"
    out = study.dynamic_case(name, DATA["cases"][name], _only("kikuuwe_tetrahedron"), True)
    spec = DATA["models"]["kikuuwe_tetrahedron"]
    system = prepare(load_scene(scenes.scene(name, DATA["cases"][name], spec["cells"], spec["model"], DATA, True,
                                             static=True))).model
    assert out["kikuuwe_tetrahedron"]["dt_limit"] == S.explicit_stability_limit(system, system.x0) > 0
    assert out["kikuuwe_tetrahedron"]["stop_step"] > 0  # at twice the limit the run diverges and is stopped


def test_cantilever_front_runs_baudet_under_the_element_reading():
    path = ROOT / "experiments" / "performance" / "scenes" / "cantilever.yaml"
    raw = yaml.safe_load(path.read_text())
    names = ["baudet_cube", "baudet_cube_linear", "golec_cube", "golec_cube_linear", "fem_linear", "fem_neohookean"]
    assert front.readings(raw, names) == ["element", "element", "", "", "", ""]
    terms = prepare(load_scene(at_level(raw, 1, "baudet_cube"), base_dir=path.parent)).model.terms
    assert any(isinstance(t, ElementBaudetCorrection) for t in terms)
    assert not any(isinstance(t, BaudetCorrection) for t in terms)

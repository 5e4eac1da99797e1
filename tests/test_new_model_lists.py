"""A new model needs no edit of the lists the tests keep: a throw-away family (a model module with a
term of its own) written into a temporary folder is found by the registry, counted by the docs test,
exported and checked against the constants its term declares by the export registry test, and the
scene docstring's table check names the exact row to add for it; ``plan`` compares it on its cells.
"""

from __future__ import annotations

import importlib
import sys
import textwrap

import numpy as np
import pytest

import test_docs
import test_export_registry
from msslib import models

FAMILY = '''
import numpy as np
from msslib.models.lloyd import _tet_rest_volumes, lloyd_tet_springs
from msslib.models.spec import ModelSpec
from msslib.terms.internal import TetVolume


class Bulk(TetVolume):
    """Lloyd's volume energy under a table of its own."""

    export_name = "scratch_bulk"
    cell_constants = (("k_v", "k_v", "J", "a volume constant"), ("V0", "V0", "m3", "rest volume"))


def _build(ctx):
    V0 = _tet_rest_volumes(ctx.mesh)
    return {"springs": lloyd_tet_springs(ctx.mesh, ctx.materials),
            "bulk": [Bulk(ctx.mesh.cells, 0.5 + np.arange(len(V0)), V0)]}


RANK = 91
SPECS = (ModelSpec("scratch_tetrahedron", "scratch", "mss", ("tetra",), 3, "a throw-away model",
                   "a family written for a test", element="tetrahedron", terms=("springs", "bulk"),
                   build=_build),)
'''


@pytest.fixture()
def family(tmp_path, monkeypatch):
    import msslib.scene  # noqa: F401  (its module-level tables of the shipped models are built first)

    fam = tmp_path / "families"
    fam.mkdir()
    (fam / "scratch.py").write_text(textwrap.dedent(FAMILY))
    monkeypatch.setattr(models, "__path__", [*models.__path__, str(fam)])
    for cached in (models.families, models._registry):
        cached.cache_clear()
    monkeypatch.setattr(test_export_registry, "SPECS", models.registry())
    yield models.get("scratch_tetrahedron")
    for cached in (models.families, models._registry):
        cached.cache_clear()
    sys.modules.pop("msslib.models.scratch", None)
    importlib.invalidate_caches()


def test_the_docs_count_takes_the_new_model_and_the_scene_table_names_its_row(family):
    names = models.names()
    assert names[-1] == "scratch_tetrahedron" and len(names) == 16  # the 15 shipped models and this one
    assert len(names) == sum(len(m.SPECS) for m in models.families())  # the docs test's count
    from msslib import planning

    assert planning._models_for("tetra")[-3:] == ["scratch_tetrahedron", "fem_linear", "fem_neohookean"]  # `plan`
    with pytest.raises(pytest.fail.Exception) as failed:
        test_docs.test_scene_docstring_names_every_model()
    assert str(failed.value).endswith("\n    ``scratch_tetrahedron``      tetra        ``springs``, ``bulk``")


def test_the_export_registry_test_checks_the_new_term_by_its_declared_constants(family, tmp_path):
    exp = test_export_registry._build("scratch_tetrahedron", {})
    bulk = next(t for t in exp.model.terms if type(t).__name__ == "Bulk")
    table, columns, conn = test_export_registry._expected_columns(bulk)
    assert table == "scratch_bulk" and list(columns) == ["k_v", "V0"] and conn is bulk.conn
    np.testing.assert_array_equal(columns["k_v"], 0.5 + np.arange(len(bulk)))
    test_export_registry.test_model_exports_to_every_format_and_json_round_trips(tmp_path, "scratch_tetrahedron", {})

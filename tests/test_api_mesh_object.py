"""An in-memory mesh goes to the scene as the object itself: its groups (materials keyed by
group, selections by group) work as from its file, and the result equals the file's."""

import numpy as np
import pytest

import msslib
from experiments.examples.liver_plan import write_mesh

MATERIALS = {"liver": msslib.Material(5e3, 0.25, density=1060.0), "inclusion": msslib.Material(5e4, 0.25, density=1060.0)}
FIXED = {"select": {"group": "base"}, "fix": "all"}
LOADS = {"type": "traction", "select": {"group": "capsule"}, "traction": [0.0, 0.0, -20.0]}


@pytest.fixture(scope="module")
def liver(tmp_path_factory):
    return write_mesh(tmp_path_factory.mktemp("liver") / "liver.msh", 0.03)


def test_mesh_object_with_groups_equals_its_file(liver):
    mesh = msslib.read_mesh(liver)
    assert mesh.cell_groups and mesh.facet_groups
    from_object = msslib.build_model("lloyd_tetrahedron", mesh, MATERIALS, fixed=FIXED, loads=LOADS)
    from_file = msslib.build_model("lloyd_tetrahedron", str(liver), MATERIALS, fixed=FIXED, loads=LOADS)
    a = msslib.solve_static(from_object, progress=False)
    b = msslib.solve_static(from_file, progress=False)
    assert np.array_equal(a["displacement"].values, b["displacement"].values)
    assert "in-memory msslib.mesh.Mesh" in a.attrs["scene"] and str(liver) not in a.attrs["scene"]
    # the reaction balances the traction's resultant (an independent number: traction times area)
    area = msslib.mesh.facet_areas(mesh, mesh.facet_groups["capsule"]).sum()
    total = a["reaction_force"].values.sum(axis=0)
    assert total[2] == pytest.approx(20.0 * area, rel=1e-9)
    assert np.abs(total[:2]).max() < 1e-9 * total[2]


def test_no_temporary_file_is_written(liver, monkeypatch):
    import msslib.mesh as M

    mesh = msslib.read_mesh(liver)

    def refuse(*a, **k):
        raise AssertionError("the in-memory mesh must not go through a file")

    monkeypatch.setattr(M, "write_vtu", refuse)
    setup = msslib.build_model("lloyd_tetrahedron", mesh, MATERIALS, fixed=FIXED)
    assert setup.model.n_nodes == mesh.n_nodes


def test_a_scene_file_cannot_name_an_object(tmp_path):
    with pytest.raises(ValueError, match="scene.geometry.mesh: an in-memory msslib.mesh.Mesh"):
        msslib.load_scene({"geometry": {"mesh": "x"}, "materials": [{"E": 1.0, "nu": 0.3}], "model": "golec_cube"})

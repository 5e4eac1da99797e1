"""A built model is frozen: editing the in-memory mesh (or the arguments) it was built from
afterwards changes neither the model, its spring constants nor its solutions."""

from __future__ import annotations

import numpy as np
import pytest

from msslib.models.golec import golec_cube_springs
import msslib
from msslib.system import Model, frozen_mesh

STEEL = msslib.Material(2.0e11, 0.3)
LOAD = 1.0e6  # Pa on the top face z = 0.1
PRESS = {"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, -LOAD]}


def _cube():
    return msslib.mesh.hex_grid(0.1, 0.1, 0.1, 2, 2, 2)


def _build(mesh, loads=PRESS):
    return msslib.build_model("golec_cube", mesh, STEEL, fixed={"plane": ["z", 0.0]}, loads=loads)


def test_editing_the_mesh_after_building_changes_nothing():
    mesh = _cube()
    model = _build(mesh)
    pristine = _build(_cube())
    mesh.points[...] *= 2.0  # in place: the user's Mesh object now describes a cube twice as large
    mesh.cells[0] = mesh.cells[0][::-1]
    for setup in (model, pristine):
        assert setup.model.mesh.points.max() == pytest.approx(0.1)
    table, reference = msslib.spring_constants(model), msslib.spring_constants(pristine)
    np.testing.assert_array_equal(table.spring_constant, reference.spring_constant)
    np.testing.assert_array_equal(table.rest_length, reference.rest_length)
    result, expected = (msslib.solve_static(s, progress=False) for s in (model, pristine))
    np.testing.assert_array_equal(result["rest_position"].values, expected["rest_position"].values)
    np.testing.assert_array_equal(result["displacement"].values, expected["displacement"].values)
    np.testing.assert_array_equal(result["spring_constant"].values, expected["spring_constant"].values)
    # independent of the code: the clamped face carries the load applied on the top face
    reaction_z = float(result["reaction_force"].isel(axis=2).sum())
    assert reaction_z == pytest.approx(LOAD * 0.1 * 0.1, rel=1e-6)  # the support pushes up
    assert float(result["displacement"].isel(axis=2).min()) < 0  # pressed down


def test_editing_the_load_mapping_after_building_changes_nothing():
    load = {"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, -LOAD]}
    model = _build(_cube(), loads=load)
    load["traction"][2] *= 10.0
    result = msslib.solve_static(model, progress=False)
    assert float(result["reaction_force"].isel(axis=2).sum()) == pytest.approx(LOAD * 0.01, rel=1e-6)


def test_model_keeps_read_only_arrays_of_its_own():
    mesh = _cube()
    terms = golec_cube_springs(mesh, [(1.0e6, 0.3)], A=1.0)
    assert np.may_share_memory(terms[1].conn, mesh.cells)  # the volume term was built on the mesh's cells
    model = Model(mesh, terms, fixed=np.zeros((mesh.n_nodes, 3), dtype=bool))
    x = model.x0 + 1.0e-4 * np.sin(np.arange(model.n_dof))
    force = model.force(x).copy()
    stiffness = model.stiffness(x).toarray()
    for name in ("points", "cells", "material"):
        array = getattr(model.mesh, name)
        assert not np.may_share_memory(array, getattr(mesh, name))
        with pytest.raises(ValueError, match="read-only"):
            array[...] = 0
    assert not any(np.may_share_memory(t.conn, mesh.cells) for t in model.terms)
    mesh.points[...] += 1.0  # the user's mesh, shifted and renumbered in place
    mesh.cells[...] = mesh.cells[::-1]
    np.testing.assert_array_equal(model.force(x), force)
    np.testing.assert_array_equal(model.stiffness(x).toarray(), stiffness)
    # at rest the model is in equilibrium (no load): an independent check that it is intact
    np.testing.assert_allclose(model.force(model.x0), 0.0, atol=1e-9 * np.abs(force).max())


def test_frozen_mesh_copies_groups():
    mesh = msslib.mesh.Mesh(_cube().points, _cube().cells, "hexahedron", node_groups={"bottom": np.arange(9)})
    frozen = frozen_mesh(mesh)
    np.testing.assert_array_equal(frozen.node_groups["bottom"], np.arange(9))
    assert not np.may_share_memory(frozen.node_groups["bottom"], mesh.node_groups["bottom"])
    assert not frozen.node_groups["bottom"].flags.writeable and not frozen.points.flags.writeable

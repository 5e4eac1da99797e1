"""A new cell type is one module: a throw-away cell type written into a temporary folder of the
cell package is found by the registry, accepted by Mesh and CELL_TYPES, and passes every
registry-wide cell test (tests/test_cells.py: faces, measure, flip, gradients, refinement, FEM,
quality, files and results) with no edit of msslib or of the tests."""

from __future__ import annotations

import importlib
import sys
import textwrap

import numpy as np
import pytest
import test_cells
from cell_helpers import example_mesh

from msslib import mesh as M
from msslib.mesh import cells

MODULE = '''
"""A throw-away cell type: the tetrahedron under another name, numbered from another corner."""
import dataclasses

import numpy as np

from msslib.mesh.cells import tetra

RANK = 95
_ORDER = [1, 2, 0, 3]  # the same positively oriented tetrahedron, nodes relabelled
_NEW = {old: new for new, old in enumerate(_ORDER)}


def _renumbered(table):
    return [[_NEW[a] for a in row] for row in table]


def _variants(refinement):
    # virtual nodes as corner sets in the new numbering; children unchanged (they index virtual nodes)
    virtual = tuple(tuple(sorted(_NEW[a] for a in v)) for v in refinement.virtual)
    return dataclasses.replace(refinement, virtual=virtual)


def scratch_tetra_grid(lx, ly, lz, nx, ny, nz):
    from msslib import mesh as M

    grid = M.tet_grid(lx, ly, lz, nx, ny, nz)
    return M.Mesh(grid.points, grid.cells[:, _ORDER], "scratch_tetra")


CELL = dataclasses.replace(
    tetra.CELL, name="scratch_tetra", plural="scratch tetrahedra", reference=tetra.CELL.reference[_ORDER],
    edges=_renumbered(tetra.CELL.edges.tolist()), faces=_renumbered(tetra.CELL.faces),
    flip=(0, 2, 1, 3), refinement=_variants(tetra.CELL.refinement),
    gradients=lambda p: tetra.CELL.gradients(p)[:, _ORDER],
    linear=dataclasses.replace(tetra.CELL.linear, vtk_to_skfem=None),
    quadratic=dataclasses.replace(tetra.CELL.quadratic, vtk_to_skfem=None), generators=(),
    example=(scratch_tetra_grid, {"lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}),
)
'''


@pytest.fixture()
def scratch(tmp_path, monkeypatch):
    folder = tmp_path / "cells"
    folder.mkdir()
    (folder / "scratch_tetra.py").write_text(textwrap.dedent(MODULE))
    monkeypatch.setattr(cells, "__path__", [*cells.__path__, str(folder)])
    cells.clear_cache()
    yield "scratch_tetra"
    cells.clear_cache()
    sys.modules.pop("msslib.mesh.cells.scratch_tetra", None)
    importlib.invalidate_caches()


def test_the_registry_and_the_mesh_take_the_new_cell_type(scratch):
    assert cells.names()[-1] == scratch and len(cells.names()) == len(test_cells.NAMES) + 1
    assert M.CELL_TYPES[scratch] == (3, 4) and scratch in M.CELL_TYPES
    mesh = M.Mesh(np.eye(4, 3), [[0, 1, 2, 3]], scratch)
    assert mesh.cell_type == scratch and mesh.n_cells == 1
    example = example_mesh(scratch, 0.5)  # the registry-wide tests' mesh of it, from its own module
    assert example.cell_type == scratch and example.n_cells == 48
    assert M.check_cells(example).sum() == pytest.approx(0.125, rel=1e-13)


def test_every_cell_test_passes_on_the_new_cell_type(scratch, tmp_path):
    test_cells.test_faces_close_the_surface_and_use_the_edges(scratch)
    for affine in (False, True):
        test_cells.test_the_measure_is_the_volume_of_the_faces_and_the_flip_negates_it(scratch, affine)
    test_cells.test_shape_gradients_reproduce_linear_fields(scratch)
    test_cells.test_refinement_splits_a_cell_into_children_of_equal_measure(scratch)
    for order in (1, 2):
        test_cells.test_the_fem_elements_integrate_the_volume_and_a_uniform_strain_exactly(scratch, order)
    test_cells.test_the_quality_check_is_one_at_rest_and_negative_inside_out(scratch)
    test_cells.test_a_mesh_goes_through_a_vtu_file_and_a_result(scratch, tmp_path)


def test_a_scene_runs_on_the_new_cell_type_from_its_own_generator(scratch):
    """The generator of the new type's example is a scene generator with no edit of msslib.scene: a
    linear FEM scene on it gives the same displacements as on the tetrahedra it renumbers."""
    from msslib.scene import GENERATORS
    from msslib.scene.run import run_scene

    assert GENERATORS["scratch_tetra_grid"] == 3
    args = {"lx": 1.0, "ly": 1.0, "lz": 2.0, "nx": 1, "ny": 1, "nz": 2}
    scene = {"materials": [{"E": 1e6, "nu": 0.3, "density": 1000.0}], "model": "fem_linear",
             "boundary": [{"select": {"box": [[-1, -1, -1], [2, 2, 0.01]]}, "fix": "all"}],
             "loads": [{"type": "gravity", "g": [0.0, 0.0, -9.81]}], "solver": {"type": "static"}}
    new = run_scene({"geometry": {"generator": "scratch_tetra_grid", "args": args}, **scene}, progress=False)
    old = run_scene({"geometry": {"generator": "tet_grid", "args": args}, **scene}, progress=False)
    assert new["cells"].attrs["cell_type"] == scratch and old["cells"].attrs["cell_type"] == "tetra"
    assert float(new["displacement"].min()) < 0
    np.testing.assert_allclose(new["displacement"].values, old["displacement"].values, rtol=1e-10,
                               atol=1e-12 * float(abs(old["displacement"]).max()))


def test_a_wrong_table_of_the_new_cell_type_is_caught(scratch, monkeypatch):
    """The registry tests can fail: a face turned inwards is found by the face test and the volume test."""
    import dataclasses

    assert scratch in cells.names()  # (imports the module)
    module = sys.modules["msslib.mesh.cells.scratch_tetra"]
    bad = dataclasses.replace(module.CELL, faces=[module.CELL.faces[0][::-1], *module.CELL.faces[1:]])
    monkeypatch.setattr(module, "CELL", bad)
    cells.clear_cache()
    with pytest.raises(AssertionError):
        test_cells.test_faces_close_the_surface_and_use_the_edges(scratch)
    with pytest.raises(AssertionError):
        test_cells.test_the_measure_is_the_volume_of_the_faces_and_the_flip_negates_it(scratch, True)

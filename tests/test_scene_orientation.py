"""A scene's mesh (a file or an in-memory mesh) with cells numbered both ways: the loader re-orders
the negatively oriented cells, silently when the whole mesh uses the other convention, with one
warning naming them when only some do (a cell numbered backwards, or a tangled mesh)."""

import warnings

import numpy as np
import pytest

from msslib import mesh as M
from msslib.errors import MsslibWarning
from msslib.scene import run_scene

FLIP = [4, 5, 6, 7, 0, 1, 2, 3]  # a hexahedron's bottom and top faces swapped: the same cell, mirrored numbering
TRACTION = -2.0e4  # Pa on the top face


def _scene(geometry):
    return {"geometry": geometry, "materials": [{"E": 1.0e6, "nu": 0.3}], "model": "golec_cube",
            "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, TRACTION]}]}


def _flipped(mesh, which):
    cells = mesh.cells.copy()
    cells[which] = cells[which][:, FLIP]
    return M.Mesh(mesh.points, cells, mesh.cell_type, mesh.material)


@pytest.fixture(scope="module")
def cube():
    mesh = M.hex_grid(0.1, 0.1, 0.1, 2, 2, 2)
    return mesh, run_scene(_scene({"mesh": mesh}), progress=False)


def _run_quiet_or_warned(scene):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = run_scene(scene, progress=False)
    return ds, [str(w.message) for w in caught if issubclass(w.category, MsslibWarning)
                and "numbered against the others" in str(w.message)]


def test_one_cell_numbered_backwards_is_said_and_reordered(cube):
    mesh, consistent = cube
    flipped = _flipped(mesh, [1])
    assert (M.cell_measures(flipped) < 0).sum() == 1
    ds, said = _run_quiet_or_warned(_scene({"mesh": flipped}))
    assert len(said) == 1
    assert "in-memory mesh has 1 of 8 hexahedron cells" in said[0] and "cell 1)" in said[0]
    # the re-ordered mesh is the consistent one: the same displacement ...
    np.testing.assert_allclose(ds["displacement"].values, consistent["displacement"].values, rtol=0, atol=1e-15)
    # ... and the support carries the load (an independent number: traction times area)
    assert ds["reaction_force"].values[:, 2].sum() == pytest.approx(-TRACTION * 0.1 * 0.1, rel=1e-9)


def test_a_mesh_numbered_the_other_way_throughout_is_reordered_silently(cube):
    mesh, consistent = cube
    ds, said = _run_quiet_or_warned(_scene({"mesh": _flipped(mesh, slice(None))}))
    assert said == []
    np.testing.assert_allclose(ds["displacement"].values, consistent["displacement"].values, rtol=0, atol=1e-15)


def test_a_file_with_a_cell_numbered_backwards_is_named(cube, tmp_path):
    mesh, _ = cube
    path = tmp_path / "mixed.vtu"
    M.write_vtu(path, _flipped(mesh, [2, 5]))
    _, said = _run_quiet_or_warned(_scene({"file": str(path)}))
    assert len(said) == 1 and "mesh file mixed.vtu has 2 of 8 hexahedron cells" in said[0] and "cell 2, 5)" in said[0]

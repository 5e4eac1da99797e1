"""Meshes without cells: a mesh file of points alone is refused as having no cells (meshio's own
failure on such VTK files speaks of arrays and indices), and msslib's VTU export of a model
without springs reads back in meshio and VTK."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

from msslib import cli, export
from msslib.mesh import read

POINTS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@pytest.mark.parametrize("name, cells, options", [
    ("bare.vtu", [], {}),                                                   # no <Cells> at all
    ("empty_lines.vtu", [("line", np.zeros((0, 2), dtype=np.int64))], {}),  # empty compressed arrays
    ("ascii.vtu", [("line", np.zeros((0, 2), dtype=np.int64))], {"binary": False}),
    ("legacy.vtk", [], {}),
    ("legacy_binary.vtk", [], {"binary": True}),
])
def test_points_without_cells_are_refused_as_such(tmp_path, name, cells, options):
    path = tmp_path / name
    meshio.write(path, meshio.Mesh(POINTS, cells), **options)
    with pytest.raises(ValueError, match=rf"^{path}: the mesh has no cells \(3 points\); allowed: .*tetra"):
        read(path)


def test_points_without_cells_on_the_command_line(tmp_path, capsys):
    meshio.write(tmp_path / "points.vtu", meshio.Mesh(POINTS, []))
    scene = {"name": "points", "model": "golec_cube", "geometry": {"file": "points.vtu"},
             "materials": [{"E": 1.0e6, "nu": 0.3}]}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scene))
    code = cli.main(["validate", str(tmp_path / "s.yaml")])
    err = capsys.readouterr().err
    assert code == 1 and err.startswith("msslib: error:") and len(err.splitlines()) == 1
    assert "the mesh has no cells (3 points)" in err and "concatenate" not in err


def _springless_scene():
    scenes = yaml.safe_load((Path(__file__).parent / "data" / "export_scenes.yaml").read_text())
    tet = scenes["lloyd_tet"]
    return {**tet, "name": "volume_only", "model": {"type": tet["model"], "terms": ["volume"]}}


def test_the_vtu_export_of_a_model_without_springs_reads_back(tmp_path, capsys):
    scene = tmp_path / "volume_only.yaml"
    scene.write_text(yaml.safe_dump(_springless_scene()))
    code = cli.main(["export", str(scene), "--out", str(tmp_path / "v"), "--format", "vtu"])
    assert code == 0, capsys.readouterr().err
    exp = export.build(scene)
    assert len(exp.pairs) == 0
    m = meshio.read(tmp_path / "v.vtu")
    assert [c.type for c in m.cells] == ["vertex"]  # one vertex cell per mass, in node order
    np.testing.assert_array_equal(m.cells[0].data[:, 0], np.arange(len(exp.points)))
    np.testing.assert_array_equal(m.points, exp.points)
    np.testing.assert_array_equal(m.point_data["mass"], exp.masses)
    np.testing.assert_array_equal(m.point_data["fixed"][:, :3], exp.fixed.astype(int))
    assert "stiffness" not in m.cell_data  # no springs, no spring data


def test_the_springless_vtu_reads_in_vtk(tmp_path):
    vtk = pytest.importorskip("vtk")
    exp = export.build(_springless_scene())
    from msslib.export import text

    text.write_vtu(tmp_path / "v.vtu", exp)
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "v.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    assert reader.GetErrorCode() == 0
    assert grid.GetNumberOfPoints() == len(exp.points) and grid.GetNumberOfCells() == len(exp.points)
    mass = grid.GetPointData().GetArray("mass")
    np.testing.assert_array_equal([mass.GetValue(i) for i in range(mass.GetNumberOfTuples())], exp.masses)

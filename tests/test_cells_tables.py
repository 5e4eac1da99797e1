"""The per-cell-type tables outside msslib/mesh read the cell registry (msslib/mesh/cells): the
signed measures of msslib.metrics and the cell lists of the SOFA export."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from msslib import export
from msslib import mesh as M
from msslib import metrics
from msslib.export import simulators as export_simulators
from msslib.mesh import cells

_SCENES = yaml.safe_load((Path(__file__).parent / "data" / "export_scenes.yaml").read_text())


def test_cell_volumes_of_a_wedge_mesh_fill_the_box_undeformed_and_stretched():
    mesh = M.wedge_grid(2.0, 1.0, 3.0, 2, 3, 2)
    v = metrics.cell_volumes(mesh)
    np.testing.assert_allclose(v, np.full(mesh.n_cells, 6.0 / mesh.n_cells), rtol=1e-14)
    # a stretch by (1.5, 1, 0.5) scales every volume by 0.75
    u = mesh.points * np.array([0.5, 0.0, -0.5])
    np.testing.assert_allclose(metrics.cell_volumes(mesh, u), 0.75 * v, rtol=1e-14)
    assert metrics.mesh_volume(mesh, u) == pytest.approx(4.5, rel=1e-14)


def test_cell_volumes_follow_the_registry_measure(monkeypatch):
    """A cell type's measure is read from its module: doubling the hexahedron's doubles them."""
    mesh = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2)
    hexa = cells.get("hexahedron")
    doubled = dataclasses.replace(hexa, measure=lambda x: 2.0 * hexa.measure(x))
    table = tuple((n, doubled if n == "hexahedron" else c) for n, c in cells._registry())
    monkeypatch.setattr(cells, "_registry", lambda: table)
    np.testing.assert_allclose(metrics.cell_volumes(mesh), np.full(8, 0.25), rtol=1e-14)


def _sofa_root(tmp_path, scene):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    return ET.fromstring(export_simulators.sofa_text(export.build(path)), parser=parser)


def test_the_sofa_cell_list_is_the_registrys(tmp_path, monkeypatch):
    scene = _SCENES["lloyd_tet"]
    exp = export.build(_write(tmp_path, scene))
    (topo,) = [e for e in _sofa_root(tmp_path, scene).iter("MeshTopology")]
    np.testing.assert_array_equal(np.array(topo.get("tetrahedra").split(), dtype=int), exp.setup.mesh.cells.ravel())
    # a cell type the SOFA export cannot list: no cells, and a comment says so
    tetra = dataclasses.replace(cells.get("tetra"), sofa=None)
    table = tuple((n, tetra if n == "tetra" else c) for n, c in cells._registry())
    monkeypatch.setattr(cells, "_registry", lambda: table)
    root = _sofa_root(tmp_path, scene)
    (topo,) = [e for e in root.iter("MeshTopology")]
    assert set(topo.attrib) == {"name", "position"}
    comments = [c.text for c in root.iter(ET.Comment) if "lists no cells" in c.text]
    assert comments == [" the topology lists no cells: this export writes no tetra cells for SOFA; "
                        "the springs below carry the whole model "]


def _write(tmp_path, scene):
    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    return path


def test_the_scene_generators_are_the_cell_types(monkeypatch):
    """scene.GENERATORS is read from the cell modules: each generator with its type's dimension, and
    a generator a module no longer declares is gone."""
    from msslib.scene import GENERATORS

    assert GENERATORS["triangle_grid_right"] == 2 and GENERATORS["cone_mesh"] == 3 and GENERATORS["wedge_grid"] == 3
    before = len(GENERATORS)
    tetra = dataclasses.replace(cells.get("tetra"), generators=("l_block_tet",))
    table = tuple((n, tetra if n == "tetra" else c) for n, c in cells._registry())
    monkeypatch.setattr(cells, "_registry", lambda: table)
    assert "cone_mesh" not in GENERATORS and GENERATORS["l_block_tet"] == 3 and len(GENERATORS) == before - 3

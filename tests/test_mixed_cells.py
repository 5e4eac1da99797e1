"""Meshes whose cells are of several types (hexahedra with wedges or tetrahedra, triangles with
quads) are refused by msslib.mesh.read in one line naming the types, their counts and the cells
that would be dropped, instead of being cut down to the cells of one type; lower-dimensional
elements (facets, lines, vertices) are no mixed mesh: they carry groups."""

from __future__ import annotations

import re
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.cli import main

gmsh = pytest.importorskip("gmsh")

#: gmsh element type numbers
TRIANGLE, QUAD, TETRA, HEXAHEDRON, WEDGE = 2, 3, 4, 5, 6


def _start(name):
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    for option, value in (("General.Terminal", 0), ("General.NumThreads", 1), ("Mesh.RandomSeed", 0)):
        gmsh.option.setNumber(option, value)
    gmsh.model.add(name)


def _counts(dim) -> dict:
    """Number of elements of each gmsh type of dimension ``dim`` in the current gmsh mesh."""
    types, tags, _ = gmsh.model.mesh.getElements(dim)
    return {int(t): len(g) for t, g in zip(types, tags)}


def _two_squares(occ):
    a, b = occ.addRectangle(0, 0, 0, 1, 1), occ.addRectangle(1, 0, 0, 1, 1)
    occ.fragment([(2, a)], [(2, b)])
    occ.synchronize()
    return a, b


def _hex_and_wedges(path: Path) -> dict:
    """Two unit squares extruded by 1 in z in 2 layers: the left one of transfinite quads gives
    hexahedra, the right one of triangles wedges."""
    _start("hex_wedge")
    try:
        occ = gmsh.model.occ
        quads, triangles = _two_squares(occ)
        gmsh.model.mesh.setTransfiniteSurface(quads)
        gmsh.model.mesh.setRecombine(2, quads)
        for _, curve in gmsh.model.getBoundary([(2, quads)], oriented=False):
            gmsh.model.mesh.setTransfiniteCurve(curve, 3)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
        occ.extrude([(2, quads), (2, triangles)], 0, 0, 1, numElements=[2], recombine=True)
        occ.synchronize()
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
        return _counts(3)
    finally:
        gmsh.finalize()


def _hex_and_tets(path: Path) -> dict:
    """Two unit boxes side by side: one transfinite and recombined (hexahedra), one unstructured
    (tetrahedra)."""
    _start("hex_tet")
    try:
        occ = gmsh.model.occ
        hexes = occ.addBox(0, 0, 0, 1, 1, 1)
        occ.addBox(2, 0, 0, 1, 1, 1)
        occ.synchronize()
        gmsh.model.mesh.setTransfiniteAutomatic([(3, hexes)], recombine=True)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
        return _counts(3)
    finally:
        gmsh.finalize()


def _triangles_and_quads(path: Path) -> dict:
    """Two unit squares, one recombined into quads, one of triangles."""
    _start("tri_quad")
    try:
        quads, _ = _two_squares(gmsh.model.occ)
        gmsh.model.mesh.setRecombine(2, quads)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
        return _counts(2)
    finally:
        gmsh.finalize()


def _hex_box_with_groups(path: Path) -> dict:
    """One transfinite box of hexahedra with physical groups of every lower dimension: the
    surface "base" (quads), the curve "edge" (lines) and the point "corner"."""
    _start("hex_box")
    try:
        occ = gmsh.model.occ
        box = occ.addBox(0, 0, 0, 1, 1, 1)
        occ.synchronize()
        gmsh.model.mesh.setTransfiniteAutomatic([(3, box)], recombine=True)
        gmsh.model.addPhysicalGroup(3, [box], name="body")
        base = [t for _, t in gmsh.model.getEntities(2) if abs(occ.getCenterOfMass(2, t)[2]) < 1e-9]
        gmsh.model.addPhysicalGroup(2, base, name="base")
        gmsh.model.addPhysicalGroup(1, [gmsh.model.getEntities(1)[0][1]], name="edge")
        gmsh.model.addPhysicalGroup(0, [gmsh.model.getEntities(0)[0][1]], name="corner")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
        return _counts(3) | _counts(2)
    finally:
        gmsh.finalize()


def _refusal(path: Path) -> str:
    with pytest.raises(ValueError) as info:
        M.read(path)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path))
    return text


def _expect(text: str, dim: int, counts: dict, kept: str, dropped: str):
    """``counts``: {plural name: number}; the larger first, as the message lists them."""
    (big, n_big), (small, n_small) = sorted(counts.items(), key=lambda item: -item[1])
    assert f"the mesh has {n_big} {big} and {n_small} {small}: its {dim}D cells are of 2 types" in text
    assert re.search(rf"keeping the {kept} cells would drop {counts[dropped]} {dropped};", text), text
    assert f"allowed: {dim}D cells all" in text


def test_gmsh_hexahedra_and_wedges_are_refused(tmp_path):
    counts = _hex_and_wedges(tmp_path / "hw.msh")
    assert counts[HEXAHEDRON] > 0 and counts[WEDGE] > 0 and set(counts) == {HEXAHEDRON, WEDGE}
    text = _refusal(tmp_path / "hw.msh")
    kept, dropped = ("wedge", "hexahedra") if counts[WEDGE] > counts[HEXAHEDRON] else ("hexahedron", "wedges")
    _expect(text, 3, {"hexahedra": counts[HEXAHEDRON], "wedges": counts[WEDGE]}, kept, dropped)


def test_gmsh_hexahedra_and_tetrahedra_are_refused(tmp_path):
    counts = _hex_and_tets(tmp_path / "ht.msh")
    assert counts[HEXAHEDRON] > 0 and counts[TETRA] > 0
    text = _refusal(tmp_path / "ht.msh")
    kept, dropped = ("tetra", "hexahedra") if counts[TETRA] > counts[HEXAHEDRON] else ("hexahedron", "tetrahedra")
    _expect(text, 3, {"hexahedra": counts[HEXAHEDRON], "tetrahedra": counts[TETRA]}, kept, dropped)


def test_gmsh_triangles_and_quads_are_refused(tmp_path):
    counts = _triangles_and_quads(tmp_path / "tq.msh")
    assert counts[TRIANGLE] > 0 and counts[QUAD] > 0
    text = _refusal(tmp_path / "tq.msh")
    kept, dropped = ("triangle", "quads") if counts[TRIANGLE] > counts[QUAD] else ("quad", "triangles")
    _expect(text, 2, {"triangles": counts[TRIANGLE], "quads": counts[QUAD]}, kept, dropped)


def test_meshio_written_mixed_meshes_are_refused(tmp_path):
    hexes, tets = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2), M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)  # 8 and 6 cells
    assert (hexes.n_cells, tets.n_cells) == (8, 6)
    points = np.vstack([hexes.points, tets.points + [1.0, 0.0, 0.0]])
    cells = [("hexahedron", hexes.cells), ("tetra", tets.cells + hexes.n_nodes)]
    for name in ("ht.vtu", "ht.msh", "ht.inp"):
        meshio.write(tmp_path / name, meshio.Mesh(points, cells))
        _expect(_refusal(tmp_path / name), 3, {"hexahedra": 8, "tetrahedra": 6}, "hexahedron", "tetrahedra")
    # two blocks of hexahedra and one of tetrahedra: counted by type, not by block
    cells = [("hexahedron", hexes.cells[:3]), ("tetra", tets.cells + hexes.n_nodes), ("hexahedron", hexes.cells[3:])]
    meshio.write(tmp_path / "blocks.vtu", meshio.Mesh(points, cells))
    _expect(_refusal(tmp_path / "blocks.vtu"), 3, {"hexahedra": 8, "tetrahedra": 6}, "hexahedron", "tetrahedra")

    tri, quad = M.triangle_grid_right(1.0, 1.0, 1, 1), M.quad_grid(1.0, 1.0, 3, 1)  # 2 and 3 cells
    points = np.vstack([tri.points, quad.points + [1.0, 0.0]])
    points = np.hstack([points, np.zeros((len(points), 1))])
    meshio.write(tmp_path / "tq.vtu", meshio.Mesh(points, [("triangle", tri.cells),
                                                           ("quad", quad.cells + tri.n_nodes)]))
    _expect(_refusal(tmp_path / "tq.vtu"), 2, {"triangles": tri.n_cells, "quads": quad.n_cells}, "quad", "triangles")


def test_cells_of_a_type_without_a_model_are_refused(tmp_path):
    """A pyramid (no cell type of msslib) with its boundary triangles: the triangles are facets, not
    a 2D mesh to fall back on; the allowed types are those of the cell registry."""
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]], dtype=float)
    cells = [("pyramid", np.array([[0, 1, 2, 3, 4]])), ("triangle", np.array([[0, 1, 4], [1, 2, 4]]))]
    meshio.write(tmp_path / "pyramid.vtu", meshio.Mesh(points, cells))
    text = _refusal(tmp_path / "pyramid.vtu")
    assert "the mesh has 1 pyramid: msslib has no model for pyramid cells; allowed: 3D cells all tetra or all " \
           "hexahedron or all wedge" in text


def test_lower_dimensional_elements_are_not_a_mixed_mesh(tmp_path):
    counts = _hex_box_with_groups(tmp_path / "box.msh")
    mesh = M.read(tmp_path / "box.msh")
    assert mesh.cell_type == "hexahedron" and mesh.n_cells == counts[HEXAHEDRON]
    assert M.cell_measures(mesh).sum() == pytest.approx(1.0, rel=1e-12)
    assert set(mesh.cell_groups) == {"body"} and set(mesh.facet_groups) == {"base"}
    assert set(mesh.node_groups) == {"edge", "corner"}
    assert M.facet_areas(mesh, mesh.facet_groups["base"]).sum() == pytest.approx(1.0, rel=1e-12)


def test_the_cli_refuses_a_mixed_mesh_in_one_line(tmp_path, capsys):
    counts = _hex_and_wedges(tmp_path / "hw.msh")
    assert counts[WEDGE] > counts[HEXAHEDRON]  # listed first
    scene = {"geometry": {"file": "hw.msh"}, "materials": [{"E": 1.0e6, "nu": 0.3}], "model": "golec_cube",
             "boundary": [{"select": {"plane": ["z", 0.0]}}],
             "loads": [{"type": "traction", "select": {"plane": ["z", 1.0]}, "traction": [0.0, 0.0, -1.0e3]}]}
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene))
    out = tmp_path / "out.nc"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("msslib: error: scene.geometry.file: "), err
    assert f"{counts[WEDGE]} wedges and {counts[HEXAHEDRON]} hexahedra" in err[0]
    assert f"keeping the wedge cells would drop {counts[HEXAHEDRON]} hexahedra" in err[0]  # the more numerous kept
    assert not out.exists()

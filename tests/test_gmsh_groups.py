"""gmsh physical groups of different dimensions with one name: msslib.mesh.read keeps each (meshio
keys the names by name and keeps one), and a scene selects the facet group for boundary conditions
and tractions (with a warning naming the ambiguity) and the cell group for materials.  The loads
are checked against the traction times the area of the loaded face."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.errors import MsslibWarning
from msslib.scene import load_scene, prepare, run_scene

gmsh = pytest.importorskip("gmsh")

MAT = {"E": 1.0e6, "nu": 0.3}
LX, LY, LZ = 2.0, 1.0, 1.0  # the box; its top face z = LZ has the area LX * LY = 2 m^2
TRACTION = np.array([300.0, -200.0, -1.0e3])


def _start(name):
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    for option, value in (("General.Terminal", 0), ("General.NumThreads", 1), ("Mesh.RandomSeed", 0)):
        gmsh.option.setNumber(option, value)
    gmsh.model.add(name)


def _entities_at(dim, axis, value):
    """Tags of the entities of dimension ``dim`` whose centre of mass has coordinate ``value``."""
    return [t for _, t in gmsh.model.getEntities(dim)
            if abs(gmsh.model.occ.getCenterOfMass(dim, t)[axis] - value) < 1e-9]


def _write(path: Path, version: float, binary: bool) -> Path:
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", int(binary))
    gmsh.write(str(path))
    return path


def _box(path: Path, version: float = 4.1, binary: bool = False, all_dims: bool = False) -> Path:
    """The box [0, LX] x [0, LY] x [0, LZ] in tetrahedra: the physical volume "body", the physical
    surface "body" (the top face z = LZ) and the physical surface "base" (z = 0); with
    ``all_dims`` also the physical curve "body" (the top edge y = 0, z = LZ) and the physical
    point "body" (the corner (LX, LY, LZ))."""
    _start("box")
    try:
        occ = gmsh.model.occ
        volume = occ.addBox(0, 0, 0, LX, LY, LZ)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [volume], name="body")
        gmsh.model.addPhysicalGroup(2, _entities_at(2, 2, LZ), name="body")
        gmsh.model.addPhysicalGroup(2, _entities_at(2, 2, 0.0), name="base")
        if all_dims:
            edge = [t for t in _entities_at(1, 2, LZ) if abs(occ.getCenterOfMass(1, t)[1]) < 1e-9]
            gmsh.model.addPhysicalGroup(1, edge, name="body")
            corner = [t for _, t in gmsh.model.getEntities(0)
                      if np.allclose(gmsh.model.getValue(0, t, []), [LX, LY, LZ])]
            gmsh.model.addPhysicalGroup(0, corner, name="body")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        return _write(path, version, binary)
    finally:
        gmsh.finalize()


def _plate(path: Path) -> Path:
    """The 2D plate [0, 2] x [0, 1] in triangles: the physical surface "plate", the physical
    curve "plate" (the right edge x = 2, length 1) and the physical curve "left" (x = 0)."""
    _start("plate")
    try:
        occ = gmsh.model.occ
        surface = occ.addRectangle(0, 0, 0, 2.0, 1.0)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(2, [surface], name="plate")
        gmsh.model.addPhysicalGroup(1, _entities_at(1, 0, 2.0), name="plate")
        gmsh.model.addPhysicalGroup(1, _entities_at(1, 0, 0.0), name="left")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(2)
        return _write(path, 4.1, False)
    finally:
        gmsh.finalize()


def _scene_file(tmp_path: Path, mesh_file: str, select: str = "body") -> Path:
    data = {"geometry": {"file": mesh_file}, "materials": {"body": MAT}, "model": "fem_linear",
            "boundary": [{"select": {"group": "base"}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"group": select}, "traction": TRACTION.tolist()}]}
    out = tmp_path / "scene.yaml"
    out.write_text(yaml.safe_dump(data, sort_keys=False))
    return out


@pytest.mark.parametrize("version, binary", [(4.1, False), (4.1, True), (2.2, False)])
def test_surface_and_volume_of_one_name_are_both_kept(tmp_path, version, binary):
    mesh = M.read(_box(tmp_path / "box.msh", version, binary))
    assert mesh.cell_type == "tetra"
    assert set(mesh.cell_groups) == {"body"} and set(mesh.facet_groups) == {"body", "base"}
    np.testing.assert_array_equal(mesh.cell_groups["body"], np.arange(mesh.n_cells))
    top = mesh.facet_groups["body"]
    np.testing.assert_allclose(mesh.points[top][..., 2], LZ, atol=1e-12)
    assert M.facet_areas(mesh, top).sum() == pytest.approx(LX * LY, rel=1e-12)
    assert M.cell_measures(mesh).sum() == pytest.approx(LX * LY * LZ, rel=1e-12)


def test_traction_on_the_surface_of_a_shared_name_loads_that_face_alone(tmp_path):
    """The reaction at the clamped base balances the traction on the top face (2 m^2), not on the
    whole boundary of the volume of the same name (10 m^2)."""
    _box(tmp_path / "box.msh")
    scene = load_scene(_scene_file(tmp_path, "box.msh"))
    with pytest.warns(MsslibWarning, match=r"loads\[0\]\.select\.group: 'body' names a group of cells and a group "
                                           r"of boundary facets of the mesh .*the group of boundary facets is "
                                           r"selected, materials take the group of cells"):
        setup = prepare(scene)
    np.testing.assert_allclose(setup.surface_forces.sum(axis=0), TRACTION * LX * LY, rtol=1e-12)
    loaded = np.flatnonzero(np.abs(setup.surface_forces).sum(axis=1) > 0)
    np.testing.assert_allclose(setup.mesh.points[loaded, 2], LZ, atol=1e-12)
    np.testing.assert_array_equal(setup.mesh.material, 0)  # materials: the cell group, every cell

    with pytest.warns(MsslibWarning, match="'body' names a group of cells and a group of boundary facets"):
        ds = run_scene(scene, progress=False)
    z = setup.mesh.points[:, 2]
    reaction = ds["reaction_force"].values
    np.testing.assert_allclose(reaction[np.abs(z) < 1e-12].sum(axis=0), -TRACTION * LX * LY, rtol=1e-6,
                               atol=1e-6 * np.abs(TRACTION).max())
    np.testing.assert_allclose(reaction[np.abs(z) > 1e-12], 0.0, atol=1e-9)


def test_groups_of_dimension_0_to_3_of_one_name(tmp_path):
    """A point, a curve, a surface and a volume all called "body": the cells, the facets of the
    surface and the nodes of the point and the curve; a selection takes the facets."""
    mesh = M.read(_box(tmp_path / "box.msh", all_dims=True))
    assert set(mesh.cell_groups) == {"body"} and set(mesh.facet_groups) == {"body", "base"}
    assert set(mesh.node_groups) == {"body"}
    nodes = mesh.points[mesh.node_groups["body"]]
    np.testing.assert_allclose(nodes[:, 2], LZ, atol=1e-12)  # the top edge y = 0 and the corner (LX, LY)
    assert np.all((np.abs(nodes[:, 1]) < 1e-12) | np.all(np.abs(nodes - [LX, LY, LZ]) < 1e-12, axis=1))
    assert np.any(np.all(np.abs(nodes - [LX, LY, LZ]) < 1e-12, axis=1))
    assert M.facet_areas(mesh, mesh.facet_groups["body"]).sum() == pytest.approx(LX * LY, rel=1e-12)

    scene = load_scene(_scene_file(tmp_path, "box.msh"))
    with pytest.warns(MsslibWarning, match=r"'body' names a group of cells and a group of boundary facets and a "
                                           r"group of nodes of the mesh .*the group of boundary facets is selected"):
        setup = prepare(scene)
    np.testing.assert_allclose(setup.surface_forces.sum(axis=0), TRACTION * LX * LY, rtol=1e-12)

    data = yaml.safe_load((tmp_path / "scene.yaml").read_text())
    data["boundary"].append({"select": {"group": "body"}, "fix": ["x"]})
    with pytest.warns(MsslibWarning) as record:
        fixed = prepare(load_scene(data, base_dir=tmp_path)).fixed
    said = [str(w.message) for w in record]
    assert any(re.search(r"boundary\[1\]\.select\.group: 'body' names .*boundary facets is selected", s) for s in said)
    top_nodes = np.unique(mesh.facet_groups["body"])
    base_nodes = np.unique(mesh.facet_groups["base"])
    np.testing.assert_array_equal(np.flatnonzero(fixed[:, 0]), np.union1d(top_nodes, base_nodes))


def test_2d_surface_and_curve_of_one_name(tmp_path):
    """The traction on the curve "plate" (length 1 m, thickness 0.01 m), not on the whole outline of
    the surface "plate" (6 m)."""
    _plate(tmp_path / "plate.msh")
    data = {"geometry": {"file": "plate.msh"}, "thickness": 0.01, "materials": {"plate": MAT}, "model": "fem_linear",
            "boundary": [{"select": {"group": "left"}}],
            "loads": [{"type": "traction", "select": {"group": "plate"}, "traction": [1.0e4, 500.0]}]}
    scene = load_scene(data, base_dir=tmp_path)
    with pytest.warns(MsslibWarning, match="'plate' names a group of cells and a group of boundary facets"):
        setup = prepare(scene)
    np.testing.assert_allclose(setup.surface_forces.sum(axis=0), [1.0e4 * 0.01, 500.0 * 0.01], rtol=1e-12)
    loaded = np.flatnonzero(np.abs(setup.surface_forces).sum(axis=1) > 0)
    np.testing.assert_allclose(setup.mesh.points[loaded, 0], 2.0, atol=1e-12)
    with pytest.warns(MsslibWarning, match="'plate' names"):
        ds = run_scene(scene, progress=False)
    x = setup.mesh.points[:, 0]
    np.testing.assert_allclose(ds["reaction_force"].values[np.abs(x) < 1e-12].sum(axis=0), [-100.0, -5.0],
                               rtol=1e-6)


def test_materials_of_a_name_that_is_only_a_facet_group_are_refused(tmp_path):
    """Materials take cell groups only: "base" is a surface, not a group of cells."""
    _box(tmp_path / "box.msh")
    data = yaml.safe_load(_scene_file(tmp_path, "box.msh").read_text())
    data["materials"] = {"base": MAT}
    with pytest.raises(ValueError, match=r"scene\.materials\.base: the mesh has no cell group 'base'"):
        prepare(load_scene(data, base_dir=tmp_path))


# ---- groups that share elements: gmsh 4 gives an element every group of its entity ----------------

STIFF_T = np.array([0.0, 0.0, -40.0])  # Pa on the end face x = LX (1 m^2)


def _overlapping(path: Path, version: float = 4.1, binary: bool = False, shared_volume: bool = True) -> Path:
    """The box [0, LX] x [0, LY] x [0, LZ] as two volumes x < 1 and x > 1; every physical group
    shares its elements with another, in every dimension, and the later group is the one meshio
    drops: the volume "stiff" (x > 1) inside the volume "body" (both); the surface "stiff" (the end
    face x = LX, 1 m^2) inside the surface "tip" (that face and the top faces, 3 m^2); the surface
    "base" (x = 0); the curves "edge" and "rim" (the end face's top edge); the points "corner" and
    "pin" (the corner (LX, LY, LZ)).  Without ``shared_volume``, no volume "stiff"."""
    _start("overlap")
    try:
        occ = gmsh.model.occ
        occ.fragment([(3, occ.addBox(0, 0, 0, 1.0, LY, LZ))], [(3, occ.addBox(1.0, 0, 0, 1.0, LY, LZ))])
        occ.synchronize()
        volumes = [t for _, t in gmsh.model.getEntities(3)]
        right = [t for t in volumes if occ.getCenterOfMass(3, t)[0] > 1.0]
        end, top = _entities_at(2, 0, LX), _entities_at(2, 2, LZ)
        edge = [t for t in _entities_at(1, 0, LX) if abs(occ.getCenterOfMass(1, t)[2] - LZ) < 1e-9]
        corner = [t for _, t in gmsh.model.getEntities(0) if np.allclose(gmsh.model.getValue(0, t, []), [LX, LY, LZ])]
        assert len(right) == 1 and len(end) == 1 and len(top) == 2 and len(edge) == 1 and len(corner) == 1
        gmsh.model.addPhysicalGroup(3, volumes, name="body")
        if shared_volume:
            gmsh.model.addPhysicalGroup(3, right, name="stiff")
        gmsh.model.addPhysicalGroup(2, end + top, name="tip")
        gmsh.model.addPhysicalGroup(2, end, name="stiff")
        gmsh.model.addPhysicalGroup(2, _entities_at(2, 0, 0.0), name="base")
        gmsh.model.addPhysicalGroup(1, edge, name="edge")
        gmsh.model.addPhysicalGroup(1, edge, name="rim")
        gmsh.model.addPhysicalGroup(0, corner, name="corner")
        gmsh.model.addPhysicalGroup(0, corner, name="pin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
        gmsh.model.mesh.generate(3)
        return _write(path, version, binary)
    finally:
        gmsh.finalize()


def test_the_entities_groups_in_every_gmsh_4_encoding(tmp_path):
    """The physical groups of each entity read alike from ASCII and binary gmsh 4.1 and ASCII 4.0
    (which meshio reads only for some meshes): the end face carries "tip" and "stiff"."""
    from msslib.mesh.gmsh_file import entity_groups

    lists = [entity_groups(_overlapping(tmp_path / f"o{i}.msh", v, b))
             for i, (v, b) in enumerate([(4.1, False), (4.1, True), (4.0, False)])]
    assert lists[0] == lists[1] == lists[2]
    assert sorted(len(tags) for tags in lists[0].values() if len(tags) > 1) == [2, 2, 2, 2]
    assert entity_groups(_overlapping(tmp_path / "o2.msh", 2.2)) is None


@pytest.mark.parametrize("version, binary", [(4.1, False), (4.1, True), (2.2, False)])
def test_groups_that_share_elements_are_all_kept(tmp_path, version, binary):
    """gmsh 4 lists the groups of each entity; gmsh 2 writes an element once for each of its groups
    (the tetrahedra of "stiff" twice): both read as one cell in every group."""
    mesh = M.read(_overlapping(tmp_path / "overlap.msh", version, binary))
    assert set(mesh.cell_groups) == {"body", "stiff"}
    assert set(mesh.facet_groups) == {"tip", "stiff", "base"} and set(mesh.node_groups) == {"edge", "rim", "corner",
                                                                                             "pin"}
    np.testing.assert_array_equal(mesh.cell_groups["body"], np.arange(mesh.n_cells))
    centroids = mesh.points[mesh.cells].mean(axis=1)
    np.testing.assert_array_equal(mesh.cell_groups["stiff"], np.flatnonzero(centroids[:, 0] > 1.0))
    measures = M.cell_measures(mesh)
    assert measures[mesh.cell_groups["stiff"]].sum() == pytest.approx(1.0 * LY * LZ, rel=1e-12)
    assert M.facet_areas(mesh, mesh.facet_groups["stiff"]).sum() == pytest.approx(LY * LZ, rel=1e-12)
    np.testing.assert_allclose(mesh.points[mesh.facet_groups["stiff"]][..., 0], LX, atol=1e-12)
    assert M.facet_areas(mesh, mesh.facet_groups["tip"]).sum() == pytest.approx(LY * LZ + LX * LY, rel=1e-12)
    np.testing.assert_array_equal(mesh.node_groups["edge"], mesh.node_groups["rim"])
    edge = mesh.points[mesh.node_groups["edge"]]
    np.testing.assert_allclose(edge[:, [0, 2]], np.tile([LX, LZ], (len(edge), 1)), atol=1e-12)
    assert np.ptp(edge[:, 1]) == pytest.approx(LY)
    for name in ("corner", "pin"):
        np.testing.assert_allclose(mesh.points[mesh.node_groups[name]], [[LX, LY, LZ]], atol=1e-12)


@pytest.mark.parametrize("version", [4.1, 2.2])
def test_a_traction_on_a_surface_that_shares_its_triangles_loads_that_surface(tmp_path, version):
    """The reaction at the clamped base balances 40 Pa on the 1 m^2 of the surface "stiff" (40 N),
    not on the 5 m^2 outline of the volume "stiff" (meshio's single tag keeps the triangles in
    "tip" alone, and the selection then took the volume's faces)."""
    _overlapping(tmp_path / "overlap.msh", version)
    data = {"geometry": {"file": "overlap.msh"}, "materials": {"body": MAT}, "model": "fem_linear",
            "boundary": [{"select": {"group": "base"}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"group": "stiff"}, "traction": STIFF_T.tolist()}]}
    scene = load_scene(data, base_dir=tmp_path)
    with pytest.warns(MsslibWarning, match="'stiff' names a group of cells and a group of boundary facets"):
        ds = run_scene(scene, progress=False)
    x = ds["rest_position"].transpose("node", "axis").values[:, 0]
    reaction = ds["reaction_force"].transpose("node", "axis").values
    np.testing.assert_allclose(reaction[np.abs(x) < 1e-12].sum(axis=0), -STIFF_T * LY * LZ, rtol=1e-6, atol=1e-6)


def test_a_gmsh_2_file_keeps_shared_facets_curves_and_points(tmp_path):
    """gmsh 2 writes an element once for each of its groups: the lower dimensions keep them all."""
    mesh = M.read(_overlapping(tmp_path / "overlap.msh", 2.2, shared_volume=False))
    assert set(mesh.cell_groups) == {"body"} and set(mesh.facet_groups) == {"tip", "stiff", "base"}
    assert M.facet_areas(mesh, mesh.facet_groups["stiff"]).sum() == pytest.approx(LY * LZ, rel=1e-12)
    assert M.facet_areas(mesh, mesh.facet_groups["tip"]).sum() == pytest.approx(LY * LZ + LX * LY, rel=1e-12)
    np.testing.assert_array_equal(mesh.node_groups["edge"], mesh.node_groups["rim"])
    np.testing.assert_array_equal(mesh.node_groups["corner"], mesh.node_groups["pin"])
    assert len(mesh.node_groups["corner"]) == 1


def test_a_gmsh_2_file_keeps_the_volumes_of_shared_cells_as_one_mesh(tmp_path):
    """The gmsh 2 file of two volume groups sharing tetrahedra reads as the gmsh 4 file does: the
    same cells once each, the same groups."""
    two = M.read(_overlapping(tmp_path / "o2.msh", 2.2))
    four = M.read(_overlapping(tmp_path / "o4.msh", 4.1))
    text = (tmp_path / "o2.msh").read_text()
    n_file = int(text.split("$Elements\n", 1)[1].split("\n", 1)[0])
    assert two.n_cells == four.n_cells and n_file > two.n_cells  # the file repeats the "stiff" tetrahedra
    np.testing.assert_array_equal(two.points, four.points)
    np.testing.assert_array_equal(two.cells, four.cells)
    for name in ("body", "stiff"):
        np.testing.assert_array_equal(two.cell_groups[name], four.cell_groups[name])


def test_a_gmsh_2_file_with_a_cell_repeated_in_another_node_order_is_refused(tmp_path):
    """Copies of an element are one cell only when they are the same element: a repeated
    tetrahedron with two nodes swapped (an inverted copy) is refused naming both cells."""
    path = _overlapping(tmp_path / "overlap.msh", 2.2)
    head, rest = path.read_text().split("$Elements\n", 1)
    lines = rest.split("\n")
    n = int(lines[0])
    rows = [line.split() for line in lines[1:n + 1]]
    tets = [r for r in rows if r[1] == "4"]
    tail = tets[-1]  # the last copy of a shared tetrahedron (its group "stiff" comes after "body")
    assert sum(r[-4:] == tail[-4:] for r in tets) == 2
    tail[-4:] = [tail[-3], tail[-4], tail[-2], tail[-1]]
    lines[1:n + 1] = [" ".join(r) for r in rows]
    path.write_text(head + "$Elements\n" + "\n".join(lines))
    with pytest.raises(ValueError, match=r"overlap.msh: tetra cells \d+ and \d+ have the same nodes \(1 duplicate "
                                         r"cell\(s\)\); allowed: each cell once \(copies of one gmsh 2 element"):
        M.read(path)


@pytest.mark.parametrize("version", [4.1, 2.2])
def test_a_named_physical_group_without_elements_is_refused(tmp_path, version):
    path = _box(tmp_path / "box.msh", version)
    text = path.read_text()
    count = int(text.split("$PhysicalNames\n", 1)[1].split("\n", 1)[0])
    path.write_text(text.replace(f"$PhysicalNames\n{count}\n", f'$PhysicalNames\n{count + 1}\n2 99 "ghost"\n', 1))
    with pytest.raises(ValueError, match=r"box.msh: the physical group 'ghost' \(dimension 2, tag 99\) has no "
                                         r"elements in the file; allowed: physical groups with elements"):
        M.read(path)

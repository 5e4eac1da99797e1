"""The mesh of a scene: building (or reading) the mesh with its materials and regions (the
selections on it live in :mod:`msslib.mesh.selection`)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from msslib import mesh as _mesh
from msslib.scene.schema import Scene, _check_size, _generator_function
from msslib.mesh.selection import group_names, in_box, missing_group_message
from msslib.scene.validate import _fail


def _oriented(mesh: _mesh.Mesh, what: str) -> _mesh.Mesh:
    """``mesh`` with every cell positively oriented (:func:`msslib.mesh.orient`).  A mesh numbered
    the other way throughout (another convention) is re-ordered silently; one whose cells disagree
    (some negative, some positive: a cell numbered backwards, or a tangled mesh, whose re-ordered
    cells would overlap) is re-ordered with a :class:`msslib.errors.MsslibWarning` naming them."""
    measures = _mesh.cell_measures(mesh)
    negative = np.flatnonzero(measures < 0)
    if not len(negative):
        return mesh
    if len(negative) < mesh.n_cells:
        from msslib.errors import MsslibWarning

        shown = ", ".join(str(c) for c in negative[:3]) + (", ..." if len(negative) > 3 else "")
        warnings.warn(f"scene.geometry: {what} has {len(negative)} of {mesh.n_cells} {mesh.cell_type} cells numbered "
                      f"against the others (negative measure; cell {shown}); they were re-ordered. Right if only "
                      f"their node order is reversed; a tangled mesh (a node moved through a neighbour) stays wrong",
                      MsslibWarning, stacklevel=4)
    return _mesh.orient(mesh)


def _build_mesh(scene: Scene) -> _mesh.Mesh:
    geo = scene.geometry
    if "file" in geo:
        try:
            mesh = _mesh.read(geo["file"], coincident_nodes=scene.checks.get("coincident_nodes", "merge"))
        except ValueError as exc:
            _fail("scene.geometry.file", str(exc))
        _check_size("scene", geo, scene.model, scene.solver, scene.output, scene.checks, n_nodes=mesh.n_nodes,
                    dim=mesh.dim)
        mesh = _oriented(mesh, f"the mesh file {geo['file'].name}")
    elif "mesh" in geo:  # an in-memory mesh (the API): used as given, oriented like a file's
        mesh = geo["mesh"]
        _check_size("scene", geo, scene.model, scene.solver, scene.output, scene.checks, n_nodes=mesh.n_nodes,
                    dim=mesh.dim)
        mesh = _oriented(mesh, "the in-memory mesh")
    else:
        fn = _generator_function(geo["generator"])
        try:
            mesh = fn(**geo["args"])
        except (ValueError, TypeError) as exc:
            _fail("scene.geometry", f"{geo['generator']}: {exc}")
    if geo.get("refine"):
        from msslib.mesh.refine import uniform

        mesh = uniform(mesh, geo["refine"])
    if scene.thickness is not None and mesh.dim == 3:
        _fail("scene.thickness", "applies to 2D meshes only; the mesh is 3D")
    groups = scene.material_groups
    if groups is not None:
        if not mesh.cell_groups:
            what = (f"the mesh file {geo['file'].name}" if "file" in geo else "the in-memory mesh" if "mesh" in geo
                    else f"the generated mesh ({geo['generator']})")
            _fail("scene.materials", f"keyed by mesh group ({', '.join(groups)}), but {what} has no groups of its "
                  f"{mesh.cell_type} cells (its groups: {group_names(mesh)}); allowed: a list of materials, or a "
                  f"mesh file with physical groups or cell sets of its cells")
        for key in groups:
            if key not in mesh.cell_groups:
                _fail(f"scene.materials.{key}", missing_group_message(mesh, key, "cell"))
        try:
            material = _mesh.materials_from_groups(mesh, groups, source="scene.materials")
        except ValueError as exc:
            raise ValueError(str(exc)) from None
    else:
        material = mesh.material.copy()
        if len(scene.materials) > 1 and mesh.cell_groups and not scene.regions and not material.any():
            shown = ", ".join(f"{k} ({len(v)} cells)" for k, v in sorted(mesh.cell_groups.items()))
            names = sorted(mesh.cell_groups)
            example = ", ".join([f"{names[0]}: {{E: ..., nu: ...}}"] + [f"{k}: {{...}}" for k in names[1:3]])
            _fail("scene.materials", f"{len(scene.materials)} materials listed, but the mesh gives every cell "
                  f"material 0 (the file has no 'material' cell data, or only zeros) and has the cell groups "
                  f"{shown}; key the materials by group, e.g. materials: {{{example}}}, or assign them with scene.regions")
    if scene.regions:
        centroids = mesh.points[mesh.cells].mean(axis=1)
        for i, region in enumerate(scene.regions):
            inside = in_box(f"scene.regions[{i}].box", centroids, region["box"], mesh.dim, 1e-12)
            material[inside] = region["material"]
    if mesh.n_cells and material.max() >= len(scene.materials):
        _fail("scene.materials", f"the mesh uses material index {int(material.max())}, "
              f"only {len(scene.materials)} material(s) given")
    if mesh.n_cells and material.min() < 0:
        _fail("scene.geometry", f"the mesh has a negative material index {int(material.min())}")
    return replace(mesh, material=material)  # the groups stay


def _check_dim(path, vec, dim):
    if len(vec) != dim:
        _fail(path, f"expected {dim} values on a {dim}D mesh, got {len(vec)}: {vec!r}")
    return np.asarray(vec, dtype=float)

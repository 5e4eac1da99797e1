"""Node and facet selections on a mesh: by plane, box and mesh group, and the boundary facets a
traction acts on (the scene's selection syntax, also taken by :class:`msslib.Simulator`).  Every
refusal raises one ``ValueError`` naming the path of the selection."""

from __future__ import annotations

import difflib
import warnings

import numpy as np

from msslib import mesh as _mesh
from msslib.mesh import cells as _cells

AXES = ("x", "y", "z")


def _fail(path: str, message: str):
    raise ValueError(f"{path}: {message}")


def group_names(mesh) -> str:
    """The groups of a mesh, by kind, for messages."""
    parts = [f"{', '.join(sorted(groups))} ({kind})" for kind, groups in
             (("cells", mesh.cell_groups), ("boundary facets", mesh.facet_groups), ("nodes", mesh.node_groups))
             if groups]
    return "; ".join(parts) if parts else "none"


def missing_group_message(mesh, key, kind=None) -> str:
    """The message for a group ``key`` the mesh lacks (``kind`` "cell": among its cell groups)."""
    pool = list(mesh.cell_groups) if kind == "cell" else [*mesh.facet_groups, *mesh.node_groups, *mesh.cell_groups]
    hint = difflib.get_close_matches(key, pool, n=1)
    did = f" (did you mean {hint[0]!r}?)" if hint else ""
    if not (mesh.cell_groups or mesh.facet_groups or mesh.node_groups):
        return (f"the mesh has no group {key!r}: it has no groups at all (generated meshes have none; a mesh file "
                f"gives its gmsh physical groups, cell sets and node sets)")
    return f"the mesh has no {'cell ' if kind == 'cell' else ''}group {key!r}{did}; its groups: {group_names(mesh)}"


def _group_members(path, mesh, key):
    """``(kind, members, nodes)`` of the group ``key`` for a selection: its boundary facets
    (``kind`` "facets", ``members`` the facets), else its nodes ("nodes", None), else its cells
    ("cells", the cell indices); ``nodes`` the sorted nodes.  A name that is a group of more than
    one kind (gmsh physical groups of different dimensions with one name) takes the first of
    facets, nodes, cells, with a warning naming the kinds (materials take the group of cells)."""
    kinds = [kind for kind, groups in (("boundary facets", mesh.facet_groups), ("nodes", mesh.node_groups),
                                       ("cells", mesh.cell_groups)) if key in groups]
    if not kinds:
        _fail(path, missing_group_message(mesh, key))
    if len(kinds) > 1:
        from msslib.errors import MsslibWarning

        named = [kind for kind in ("cells", "boundary facets", "nodes") if kind in kinds]
        cells = ", materials take the group of cells" if "cells" in kinds else ""
        warnings.warn(f"{path}: {key!r} names a group of {' and a group of '.join(named)} of the mesh (groups of "
                      f"different dimensions with one name); the group of {kinds[0]} is selected{cells}",
                      MsslibWarning, stacklevel=3)
    if kinds[0] == "boundary facets":
        facets = mesh.facet_groups[key]
        return "facets", facets, np.unique(facets.ravel())
    if kinds[0] == "nodes":
        return "nodes", None, mesh.node_groups[key]
    cells = mesh.cell_groups[key]
    return "cells", cells, np.unique(mesh.cells[cells])


def in_box(path, x, box, dim, tol):
    keep = np.ones(len(x), dtype=bool)
    for corner, sign in zip(box, (1.0, -1.0)):
        if corner is None:
            continue
        if len(corner) != dim:
            _fail(path, f"box corners need {dim} coordinates on a {dim}D mesh, got {list(corner)!r}")
        for d, b in enumerate(corner):
            if b is not None:
                keep &= sign * (x[:, d] - b) >= -tol
    return keep


def select_nodes(path, mesh, sel, default_tol, group=None):
    """Sorted ids of the selected nodes (``group``: the :func:`_group_members` of ``sel["group"]``
    if already looked up)."""
    if sel.get("all"):
        return np.arange(mesh.n_nodes)
    if "group" in sel:
        group = _group_members(f"{path}.group", mesh, sel["group"]) if group is None else group
        if "plane" not in sel and "box" not in sel:
            return group[2]
        nodes = np.intersect1d(select_nodes(path, mesh, {k: v for k, v in sel.items() if k != "group"}, default_tol),
                               group[2])
        if len(nodes) == 0:
            where = " and ".join(f"plane [{sel['plane'][0]}, {sel['plane'][1]:g}]" if k == "plane" else f"box {sel[k]}"
                                 for k in ("plane", "box") if k in sel)
            _fail(path, f"group {sel['group']!r} ({len(group[2])} nodes) has no node in {where}")
        return nodes
    tol = sel.get("tol", default_tol)
    if "plane" in sel and AXES.index(sel["plane"][0]) >= mesh.dim:
        _fail(f"{path}.plane", f"axis {sel['plane'][0]!r} does not exist on a {mesh.dim}D mesh")
    if "box" in sel:
        for i, corner in enumerate(sel["box"]):
            if corner is not None and len(corner) != mesh.dim:
                _fail(f"{path}.box[{i}]", f"needs {mesh.dim} coordinates on a {mesh.dim}D mesh, got {corner!r}")
    try:
        return _mesh.select_nodes(mesh, box=sel.get("box"), plane=sel.get("plane"), tol=tol)
    except ValueError:
        shown = {k: v for k, v in sel.items()}
        lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
        _fail(path, f"selects no node: {shown} (tol {tol:.3g} m; the mesh spans {np.round(lo, 6).tolist()} to "
              f"{np.round(hi, 6).tolist()})")


def loaded_facets(path, mesh, sel, default_tol, cache, load: str = "traction"):
    """The facets a ``load`` (a traction or a pressure: the word its refusals use) acts on: the facets of a facet group (each must be a boundary facet),
    the boundary facets of the cells of a cell group, else the boundary facets whose nodes are all
    selected; with plane and/or box, only those whose nodes are all in them too.  A ``(k, nodes)``
    array, for a cell type with facets of one type (a ValueError naming the ``load`` for others;
    see :func:`loaded_facets_by_type`)."""
    kinds = _cells.get(mesh.cell_type).facet_types
    if len(set(kinds)) > 1:
        one = ", ".join(n for n, c in _cells.registry().items() if c.single_facet_type is not None)
        _fail(path, f"a {load} on {mesh.cell_type} cells, whose facets are of several types "
              f"({', '.join(sorted(set(kinds)))}), is not supported; allowed: a {load} on meshes of {one} cells")
    (facets,) = loaded_facets_by_type(path, mesh, sel, default_tol, cache, load).values()
    return facets


def loaded_facets_by_type(path, mesh, sel, default_tol, cache, load: str = "traction") -> dict:
    """:func:`loaded_facets` of any cell type, by facet type: facet type -> ``(k, nodes)`` facets,
    the types with no loaded facet left out (a wedge mesh's triangles and quads)."""
    if "boundary_by_type" not in cache:
        cache["boundary_by_type"] = _mesh.boundary_facets_by_type(mesh)
    by_type = dict(cache["boundary_by_type"])
    group = None
    if "group" in sel:
        group = _group_members(f"{path}.group", mesh, sel["group"])
        kind, members, _ = group
        if kind == "facets":
            counts = _mesh.facet_cell_counts(mesh, members)
            bad = np.flatnonzero(counts != 1)
            if len(bad):
                f = members[bad[0]]
                where = "is a face of no cell" if counts[bad[0]] == 0 else "lies between two cells"
                centroid = np.round(mesh.points[f].mean(axis=0), 6).tolist()
                _fail(f"{path}.group", f"{len(bad)} of the {len(members)} facets of group {sel['group']!r} are not on "
                      f"the boundary of the mesh: the facet of nodes {f.tolist()} at {centroid} {where}; allowed: a "
                      f"{load} on boundary facets")
            by_type = {_cells.facet_type(members.shape[1], mesh.dim): (members, None)}
        elif kind == "cells":
            by_type = {k: (c[np.isin(fc, members)], None) for k, (c, fc) in by_type.items()}
    nodes = select_nodes(path, mesh, sel, default_tol, group)
    selected = np.zeros(mesh.n_nodes, dtype=bool)
    selected[nodes] = True
    out = {}
    for k, (candidates, _) in by_type.items():
        on = selected[candidates].all(axis=1) if len(candidates) else np.zeros(0, dtype=bool)
        if on.any():
            out[k] = candidates[on]
    if not out:
        of = f" of group {sel['group']!r}" if "group" in sel else ""
        _fail(path, f"no boundary facet{of} has all its nodes selected ({len(nodes)} node(s) selected)")
    return out

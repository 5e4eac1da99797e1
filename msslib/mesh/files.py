"""Mesh files: :func:`read` (any mesh file meshio reads; every failure one ValueError naming the
file; keeps the file's physical groups, cell sets and node sets), :func:`write_vtu`,
:func:`readable_suffixes` and :func:`check_mesh_suffix`.  meshio is imported when a file is read
or written, not with this module.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import numpy as np

from . import cells as _cells
from .cells import RegistryView as _RegistryView
from .core import CELL_TYPES, COINCIDENT_POLICIES, COINCIDENT_RTOL, Mesh, _fmt_point
from .gmsh_file import entity_groups, physical_names
from .hygiene import resolve_coincident_nodes


def readable_suffixes() -> list[str]:
    """The file suffixes meshio knows (``.msh``, ``.vtu``, ...), sorted; compound ones such as
    ``.vol.gz`` included."""
    import meshio

    return sorted(meshio.extension_to_filetypes)


def check_mesh_suffix(path) -> None:
    """Raise ValueError naming ``path`` and the suffixes meshio knows when its suffix is not one
    of them (meshio would otherwise give up on the file with :class:`SystemExit` or an error)."""
    path = Path(path)
    known = set(readable_suffixes())
    suffixes = [s.lower() for s in path.suffixes]
    if not any("".join(suffixes[i:]) in known for i in range(len(suffixes))):
        shown = repr(path.suffix) if path.suffix else "(none)"
        raise ValueError(f"{path}: unknown mesh file suffix {shown}; allowed: the suffixes meshio reads, "
                         f"{' '.join(sorted(known))}")


def _vtk_points_without_cells(path: Path) -> int | None:
    """The number of points of a VTK file (XML ``.vtu`` or legacy ``.vtk`` unstructured grid) that
    declares no cells, else None.  meshio fails on such files with messages about arrays and
    indices; this is what they are."""
    import re

    suffix = path.suffix.lower()
    if suffix not in (".vtu", ".vtk"):
        return None
    try:
        data = path.read_bytes()
    except OSError:
        return None
    if suffix == ".vtu":
        pieces = re.findall(rb"<Piece\b[^>]*>", data)
        if not pieces:
            return None
        points, cells = 0, 0
        for piece in pieces:
            n_points = re.search(rb'NumberOfPoints\s*=\s*"(\d+)"', piece)
            n_cells = re.search(rb'NumberOfCells\s*=\s*"(\d+)"', piece)
            if n_points is None:
                return None
            points += int(n_points.group(1))
            cells += int(n_cells.group(1)) if n_cells else 0
        return points if cells == 0 else None
    if not re.search(rb"DATASET\s+UNSTRUCTURED_GRID", data):
        return None
    n_points = re.search(rb"(?m)^\s*POINTS\s+(\d+)", data)
    n_cells = re.search(rb"(?m)^\s*CELL_TYPES\s+(\d+)", data)  # (CELLS counts offsets in format 5)
    if n_points is None or (n_cells is not None and int(n_cells.group(1)) > 0):
        return None
    return int(n_points.group(1))


def _meshio_read(path: Path):
    """``meshio.read`` that never exits the interpreter: any failure (meshio calls ``sys.exit``
    for some files and raises anything from ``struct.error`` to ``UnicodeDecodeError`` for others)
    becomes one ValueError naming the file.  What meshio says is collected for this thread alone
    (:func:`msslib.mesh.meshio_output.collected`; ``sys.stdout`` and ``sys.stderr`` are never
    replaced, so threads may read at once): part of the message on failure; on success returned
    with the mesh, ``(mesh, said)``, for :func:`read` to pass on once the mesh has passed its own
    checks."""
    import meshio

    from .meshio_output import collected

    with collected() as messages:
        try:
            m = meshio.read(path)
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - every failure of a reader is bad input
            points = _vtk_points_without_cells(path)
            if points is not None:  # meshio cannot read a VTK file without cells: say what it is
                raise ValueError(f"{path}: the mesh has no cells ({points} points); allowed: "
                                 f"{', '.join(CELL_TYPES)} cells") from None
            said = " ".join(" ".join(messages).replace("Error:", " ").split())
            if isinstance(exc, UnicodeDecodeError):
                detail = (f"not UTF-8 text where the {path.suffix or 'chosen'} reader expects text "
                          f"({exc.reason} at byte {exc.start})")
            elif isinstance(exc, SystemExit):
                detail = said or "meshio gave up on it"
            else:
                text = " ".join(str(exc).split())
                detail = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
                if said and said not in detail:
                    detail += f" ({said})"
            if "Incompatible cell data 'gmsh:physical'" in str(exc):
                detail += (" (meshio reads gmsh physical groups only when every element is in one: save without "
                           "Mesh.SaveAll, or put every entity in a physical group)")
            if len(detail) > 300:
                detail = detail[:297] + "..."
            raise ValueError(f"{path}: cannot read mesh: {detail}; allowed: a valid mesh file in a format meshio "
                             f"reads, chosen by its suffix") from None
    return m, " ".join(" ".join(messages).split())


def read(path, material_key: str = "material", coincident_nodes: str = "merge",
         coincident_rtol: float = COINCIDENT_RTOL) -> Mesh:
    """Read any mesh file meshio can read.

    The cells are the elements of the highest dimension in the file, which must all be of one
    supported type (a type of :mod:`msslib.mesh.cells`: ``tetra``, ``hexahedron`` or ``wedge`` in
    3D, ``triangle`` or ``quad`` in 2D); blocks of that type are concatenated.  A mixed mesh
    (hexahedra with wedges or tetrahedra, triangles with quads) or cells of another type
    (pyramids, quadratic cells) are refused, naming
    the types, their counts and the cells that would be dropped; lower-dimensional elements
    (facets, lines, vertices) are not cells of the mesh: they carry groups.  Nodes no chosen cell
    uses are dropped (the others keep their order).  For 2D cells the z coordinate must be constant and is
    dropped.  ``cell_data[material_key]`` (one integer per cell), when present, becomes
    ``material``; otherwise every cell has material 0, also when the file has groups (the scenes
    assign materials by group, :func:`materials_from_groups`).  Two cells on the same nodes are
    an error, except the copies a gmsh 2 file writes of an element for each of its physical groups
    (same nodes in the same order, same material): they are one cell in all those groups.

    Groups (:class:`Mesh`): the gmsh physical groups (named by the file's ``$PhysicalNames`` with
    their dimension, since meshio's ``field_data`` ``{name: [tag, dim]}`` keeps one group of each
    name; a group without a name is known by its tag, ``"3"``): in a gmsh 4 file every group of an
    element's entity, from the file's ``$Entities`` (meshio's ``cell_data["gmsh:physical"]`` keeps
    the first only, and a group whose elements are also in another would vanish); in a gmsh 2 file,
    which repeats an element for each of its groups, ``gmsh:physical``.  A physical group of the
    file without elements is an error naming it.  Also meshio's
    ``cell_sets`` (gmsh 4 named groups, Abaqus ELSET, ...; sets named ``gmsh:...`` are meshio's bookkeeping and are
    skipped) become ``cell_groups`` for elements of the chosen cell type, ``facet_groups`` for
    elements of its facet types (lines in 2D, triangles for tetra, quads for hexahedron cells,
    triangles and quads for wedge cells: a group of one type each; a group holding both is read
    as a node group, with a :class:`msslib.errors.MsslibWarning`) and ``node_groups`` (the
    nodes of the elements) for other lower-dimensional elements (gmsh physical points and curves
    of a 3D mesh, triangles of a hexahedron mesh); meshio's
    ``point_sets`` (Abaqus NSET, Exodus node sets) become ``node_groups``.  A group of the same
    name from both sources is their union.  Groups of different dimensions with one name (a
    physical surface and a physical volume both called ``body``) are kept apart, one group of each
    kind: a scene's ``select: {group: body}`` (boundary conditions, tractions) takes the facet
    group, else the node group, with a :class:`msslib.errors.MsslibWarning` naming the ambiguity,
    and materials keyed by ``body`` take the cell group.  A facet or node group on a node no chosen
    cell uses is dropped with a :class:`msslib.errors.MsslibWarning` naming it (it could not carry
    its load or support).  VTU files hold no sets (meshio writes them as cell data it cannot split
    back reliably): their groups come from a ``gmsh:physical`` cell data array, by number.

    Coincident nodes (closer than ``coincident_rtol`` times the bounding-box diagonal, see
    :func:`resolve_coincident_nodes`) are merged with a :class:`msslib.errors.MsslibWarning`
    (``coincident_nodes="merge"``, the default), refused (``"error"``) or kept (``"keep"``); the
    messages give node numbers of the file.

    Raises FileNotFoundError for a missing file, and a one-line ValueError naming the file for
    everything else: a directory, an unknown suffix (listing the suffixes meshio knows), an empty
    or unreadable file (whatever meshio raises, :class:`SystemExit` included), no cells, no
    supported cell type or cells of several types (naming the types found), cells referring to
    nodes that do not exist, non-finite coordinates, material values that are not integers, duplicate cells, a cell
    collapsed by merging.
    """
    if coincident_nodes not in COINCIDENT_POLICIES:
        raise ValueError(f"coincident_nodes must be one of {', '.join(COINCIDENT_POLICIES)}, got {coincident_nodes!r}")
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path}: is a directory; allowed: a mesh file")
    if not path.exists():
        raise FileNotFoundError(f"mesh file not found: {path}")
    if not path.is_file():
        raise ValueError(f"{path}: not a regular file; allowed: a mesh file")
    check_mesh_suffix(path)
    if path.stat().st_size == 0:
        raise ValueError(f"{path}: cannot read mesh: the file is empty; allowed: a mesh file with cells")
    m, said = _meshio_read(path)
    try:
        mesh, used, notes = _mesh_from_meshio(path, m, material_key)
    except (ValueError, TypeError, IndexError, KeyError) as exc:  # one line naming the file, whatever it is
        text = " ".join(str(exc).split()) or type(exc).__name__
        if not text.startswith(str(path)):
            text = f"{path}: cannot read mesh: {type(exc).__name__}: {text}"
        if said:  # what meshio printed while reading explains the problem
            text += f"; meshio said: {said[:200]}"
        raise ValueError(text) from None
    import warnings

    if said:
        from msslib.errors import MsslibWarning

        warnings.warn(f"{path}: meshio says: {said}", MsslibWarning, stacklevel=2)
    if notes:
        from msslib.errors import MsslibWarning

        for note in notes:
            warnings.warn(f"{path}: {note}", MsslibWarning, stacklevel=2)
    hint = " (coincident_nodes: merge merges them)" if coincident_nodes == "error" else ""
    return resolve_coincident_nodes(mesh, coincident_nodes, coincident_rtol, source=str(path), node_ids=used,
                                    hint=hint)


def _mesh_from_meshio(path: Path, m, material_key: str):
    """The :class:`Mesh` of :func:`read` from a meshio mesh, the file numbers of its nodes, and the
    notes on dropped groups to warn about."""
    allowed = f"allowed: {', '.join(CELL_TYPES)} cells"
    blocks_all = [b for b in m.cells if len(b.data)]
    if not blocks_all:
        raise ValueError(f"{path}: the mesh has no cells ({len(m.points)} points); {allowed}")
    found = [block.type for block in blocks_all]
    supported = [t for t in CELL_TYPES if t in found]
    if not supported:
        raise ValueError(f"{path}: no supported cell type; found {sorted(set(found))}, supported {sorted(CELL_TYPES)}")
    cell_type = _one_cell_type(path, blocks_all)
    dim = CELL_TYPES[cell_type][0]
    blocks = [k for k, b in enumerate(m.cells) if b.type == cell_type and len(b.data)]
    cells = np.concatenate([np.asarray(m.cells[k].data).reshape(len(m.cells[k].data), -1) for k in blocks])
    points = np.asarray(m.points, dtype=float)
    if points.ndim != 2 or not 2 <= points.shape[1] <= 3:
        raise ValueError(f"{path}: points have shape {points.shape}; allowed: 2 or 3 coordinates per point")
    n_file = len(points)
    outside = (cells < 0) | (cells >= n_file)
    if outside.any():
        c = int(np.flatnonzero(outside.any(axis=1))[0])
        node = int(cells[c][outside[c]][0])
        raise ValueError(f"{path}: {cell_type} cell {c} refers to node {node}, which does not exist; "
                         f"allowed: nodes 0 to {n_file - 1}")
    cells = cells.astype(np.int64)
    material = None
    if material_key in m.cell_data:
        values = np.concatenate([np.asarray(m.cell_data[material_key][k]).reshape(len(m.cells[k].data), -1)
                                 for k in blocks])
        if values.shape[1] != 1:
            raise ValueError(f"{path}: cell data {material_key!r} has {values.shape[1]} values per cell; "
                             f"allowed: one integer material index per cell")
        values = values[:, 0]
        if not np.issubdtype(values.dtype, np.number) or np.issubdtype(values.dtype, np.complexfloating):
            raise ValueError(f"{path}: cell data {material_key!r} has type {values.dtype}; allowed: integers")
        bad = np.flatnonzero(~np.isfinite(values) | (values != np.rint(values)))
        if len(bad):
            raise ValueError(f"{path}: cell data {material_key!r} of cell {int(bad[0])} is {values[bad[0]].item()!r}; "
                             f"allowed: integer material indices")
        material = np.rint(values).astype(np.int64)
    names_in_file, entities = physical_names(path), entity_groups(path)
    # a gmsh 2 file (no $Entities) writes an element once for each physical group it is in
    gmsh2 = names_in_file is not None and entities is None and "gmsh:physical" in (m.cell_data or {})
    repeats = _check_duplicate_cells(path, cells, cell_type, material if gmsh2 else False)
    used = np.unique(cells)  # file numbers of the nodes the cells use, ascending
    groups, notes = _file_groups(m, cell_type, blocks, used, names_in_file, entities, source=str(path))
    if repeats is not None:  # one cell for each repeated element, in every group of its copies
        kept, new_index = repeats
        cells = cells[kept]
        material = None if material is None else material[kept]
        groups["cell_groups"] = {name: np.unique(new_index[idx]) for name, idx in groups["cell_groups"].items()}
    points = points[used]
    cells = np.searchsorted(used, cells)
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if len(bad):
        raise ValueError(f"{path}: node {int(used[bad[0]])} has coordinates {_fmt_point(points[bad[0]])} "
                         f"({len(bad)} node(s) with NaN or infinite coordinates); allowed: finite coordinates")
    if points.shape[1] < dim:
        points = np.pad(points, ((0, 0), (0, dim - points.shape[1])))
    if dim == 2 and points.shape[1] == 3:
        z = points[:, 2]
        scale = max(np.ptp(points[:, :2], axis=0).max(initial=0.0), 1e-300)
        if len(z) and np.ptp(z) > 1e-9 * scale:
            raise ValueError(f"{path}: {cell_type} cells are not in a plane z = const; cannot make a 2D mesh")
        points = points[:, :2]
    return Mesh(points, cells, cell_type, material, **groups), used, notes


#: plural of the cell types in messages
_PLURAL = _RegistryView(lambda c: c.plural, "cell type -> its plural",
                        extra={"wedge": "wedges", "pyramid": "pyramids", "polygon": "polygons"})


def _one_cell_type(path: Path, blocks) -> str:
    """The cell type of the mesh: the type of the cells of the highest dimension in the file (the
    lower-dimensional elements carry groups).  Cells of that dimension of two or more types (a
    mixed mesh: hexahedra with wedges or tetrahedra, triangles with quads), or of a type msslib
    has no cell type for (pyramids, quadratic cells), are a ValueError naming the types, how
    many cells of each there are and how many would be dropped."""
    counts = {}
    for block in blocks:
        bdim = _block_dim(block.type)
        if bdim is not None:
            counts.setdefault(bdim, {})
            counts[bdim][block.type] = counts[bdim].get(block.type, 0) + len(block.data)
    dim = max(counts)
    of_dim = sorted(counts[dim].items(), key=lambda item: (-item[1], item[0]))
    kept = [t for t, _ in of_dim if t in CELL_TYPES]
    if len(of_dim) == 1 and kept:
        return kept[0]
    shown = " and ".join(f"{n} {_PLURAL.get(t, t + ' cells') if n != 1 else t}" for t, n in of_dim)
    allowed = " or all ".join(t for t in CELL_TYPES if CELL_TYPES[t][0] == dim) if dim in (2, 3) else "one type"
    if kept:
        dropped = " and ".join(f"{n} {_PLURAL.get(t, t + ' cells') if n != 1 else t}" for t, n in of_dim
                               if t != kept[0])
        what = (f"its {dim}D cells are of {len(of_dim)} types; msslib's meshes and models have cells of one type, "
                f"so keeping the {kept[0]} cells would drop {dropped}")
    else:
        what = f"msslib has no model for {' or '.join(t for t, _ in of_dim)} cells"
    raise ValueError(f"{path}: the mesh has {shown}: {what}; allowed: {dim}D cells all {allowed} (lower-dimensional "
                     f"elements carry groups)")


def _check_duplicate_cells(path: Path, cells: np.ndarray, cell_type: str, repeats=False):
    """Two cells on the same nodes (in any order) are a ValueError naming both, except, with
    ``repeats`` not False (a gmsh 2 file, which writes an element once for each of its physical
    groups; ``repeats`` is then its materials or None), copies with the same nodes in the same order
    and the same material: then ``(kept, new_index)``, the first copy of each cell (ascending) and
    the index among those of every cell, for the groups of the copies to become the groups of the
    one cell.  None when no cell is repeated."""
    if len(cells) < 2:
        return None
    keys = np.sort(cells, axis=1)
    _, first, inverse, counts = np.unique(keys, axis=0, return_index=True, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    dup = np.flatnonzero(counts[inverse] > 1)
    dup = dup[dup != first[inverse[dup]]]
    if len(dup):
        original = first[inverse]  # the first copy of every cell
        if repeats is not False:
            same = (cells[dup] == cells[original[dup]]).all(axis=1)
            if repeats is not None:
                same &= repeats[dup] == repeats[original[dup]]
            if same.all():
                kept = np.flatnonzero(original == np.arange(len(cells)))
                return kept, np.searchsorted(kept, original)
            dup = dup[~same]
        c = int(dup[0])
        hint = ("copies of one gmsh 2 element in several physical groups, nodes in the same order and of one "
                "material, are one cell" if repeats is not False else
                "a gmsh 2 file repeats an element for every physical group it belongs to: it is read as one cell")
        raise ValueError(f"{path}: {cell_type} cells {int(first[inverse[c]])} and {c} have the same nodes ({len(dup)} "
                         f"duplicate cell(s)); allowed: each cell once ({hint})")


#: topological dimension of meshio cell types that are no cell type of the registry and may carry
#: groups (the registry's own types have their dimension; others are looked up in meshio)
_TOPOLOGICAL_DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle6": 2, "quad8": 2, "quad9": 2, "polygon": 2,
                    "tetra10": 3, "hexahedron20": 3, "hexahedron27": 3, "pyramid": 3}

#: the element types of the facets of each cell type (a wedge has triangles and quads)
_FACET_TYPES = _RegistryView(lambda c: frozenset(c.facet_types), "cell type -> its facet types")


def _block_dim(cell_type: str) -> int | None:
    for cell in _cells.registry().values():
        if cell.meshio == cell_type:
            return cell.dim
    if cell_type in _TOPOLOGICAL_DIM:
        return _TOPOLOGICAL_DIM[cell_type]
    try:
        from meshio._mesh import topological_dimension
    except ImportError:  # pragma: no cover - depends on meshio's internals
        return None
    return topological_dimension.get(cell_type)


def _file_groups(m, cell_type: str, blocks: list, used: np.ndarray, physical_names: dict | None = None,
                 entity_groups: dict | None = None, source: str = "mesh") -> tuple[dict, list]:
    """The groups of a meshio mesh (see :func:`read`) as keyword arguments of :class:`Mesh` (cell
    indices into the concatenated ``blocks``, node indices into ``used``), and the notes on the
    groups dropped because they touch nodes no chosen cell uses.  ``physical_names``: the
    ``{(dim, tag): name}`` of a gmsh file (:func:`msslib.mesh.gmsh_file.physical_names`), which
    name the physical groups that meshio's ``field_data`` lost.  ``entity_groups``: the physical
    groups of each entity of a gmsh 4 file (:func:`msslib.mesh.gmsh_file.entity_groups`): an
    element is in every group of its entity (``gmsh:geometrical``), where meshio keeps the first.  A physical group of the file with
    no element is a ValueError naming it."""
    dim = CELL_TYPES[cell_type][0]
    offsets = {}
    start = 0
    for k in blocks:
        offsets[k] = start
        start += len(m.cells[k].data)
    names = {}  # (dim, tag) -> name, from gmsh's $PhysicalNames
    for name, value in (m.field_data or {}).items():
        value = np.asarray(value).ravel()
        if value.size == 2 and value.dtype.kind in "iu":
            names[(int(value[1]), int(value[0]))] = str(name)
    names.update(physical_names or {})  # the file's own list: meshio keeps one group of each name
    physical = (m.cell_data or {}).get("gmsh:physical")
    geometrical = (m.cell_data or {}).get("gmsh:geometrical") if entity_groups is not None else None
    cell_sets = {str(k): v for k, v in (m.cell_sets or {}).items() if not str(k).startswith("gmsh:")}
    if geometrical is not None:  # meshio's cell sets of a gmsh 4 file: its copy of the physical groups
        cell_sets = {}

    def physical_members(k, bdim, n):
        """(dim, tag, element indices in block k) of every physical group of block k's elements."""
        out = []
        tags = None
        if physical is not None and k < len(physical):
            tags = np.asarray(physical[k]).reshape(n, -1)[:, 0]
            if tags.dtype.kind not in "iuf":
                tags = None
        if geometrical is not None and k < len(geometrical) and bdim is not None:
            entities = np.asarray(geometrical[k]).reshape(n, -1)[:, 0]
            for entity in np.unique(entities):
                idx = np.flatnonzero(entities == entity)
                listed = entity_groups.get((bdim, int(entity)))
                if listed is None:  # not in $Entities: meshio's tag
                    listed = [] if tags is None else [int(t) for t in np.unique(tags[idx]) if t == int(t)]
                    out += [(bdim, t, idx[tags[idx] == t]) for t in listed]
                else:
                    out += [(bdim, int(t), idx) for t in listed]
            return out
        if tags is not None:
            out += [(bdim, int(t), np.flatnonzero(tags == t)) for t in np.unique(tags) if t == int(t)]
        return out

    declared = set(physical_names or {})
    for (d, _), tags in (entity_groups or {}).items():
        declared |= {(d, int(t)) for t in tags}
    found = set()
    for k, block in enumerate(m.cells):
        if len(block.data):
            found |= {(d, t) for d, t, idx in physical_members(k, _block_dim(block.type), len(block.data)) if len(idx)}
    empty = sorted(declared - found)
    if empty:
        d, t = empty[0]
        name = names.get((d, t), str(t))
        raise ValueError(f"{source}: the physical group {name!r} (dimension {d}, tag {t}) has no elements in the file"
                         f"{f' ({len(empty)} such groups)' if len(empty) > 1 else ''}; allowed: physical groups with "
                         f"elements (mesh its entities, or remove the group)")
    cells_acc, facets_acc, nodes_acc = {}, {}, {}
    for k, block in enumerate(m.cells):
        n = len(block.data)
        if n == 0:
            continue
        bdim = _block_dim(block.type)
        if block.type == cell_type:
            if k not in offsets:
                continue
            target = cells_acc
        elif bdim is None or bdim >= dim:
            continue  # another cell type of the same or a higher dimension: not in the mesh
        else:
            target = facets_acc if (bdim == dim - 1 and block.type in _FACET_TYPES[cell_type]) else nodes_acc
        members = [(names.get((d, t), str(t)), idx) for d, t, idx in physical_members(k, bdim, n)]
        for name, per_block in cell_sets.items():
            if k < len(per_block) and per_block[k] is not None and len(per_block[k]):
                members.append((name, np.asarray(per_block[k], dtype=np.int64).ravel()))
        data = np.asarray(block.data)
        for name, idx in members:
            if target is cells_acc:
                cells_acc.setdefault(name, []).append(offsets[k] + idx)
            elif target is facets_acc:
                facets_acc.setdefault(name, []).append(data[idx].reshape(len(idx), -1))
            else:
                nodes_acc.setdefault(name, []).append(data[idx].ravel())
    for name, nodes in (m.point_sets or {}).items():
        if not str(name).startswith("gmsh:") and len(nodes):
            nodes_acc.setdefault(str(name), []).append(np.asarray(nodes, dtype=np.int64).ravel())

    notes = []

    def to_mesh_nodes(kind, name, file_nodes):
        """File node numbers -> mesh node indices; None (and a note) if one is not a mesh node."""
        file_nodes = np.asarray(file_nodes, dtype=np.int64)
        pos = np.clip(np.searchsorted(used, file_nodes), 0, len(used) - 1)
        missing = used[pos] != file_nodes
        if missing.any():
            notes.append(f"{kind} group {name!r} dropped: {int(missing.sum())} of its node entries (e.g. node "
                         f"{int(file_nodes[missing].ravel()[0])}) belong to no {cell_type} cell, so it could not "
                         f"carry its loads or supports")
            return None
        return pos

    facet_groups, node_groups = {}, {}
    for name, parts in list(facets_acc.items()):
        if len({p.shape[1] for p in parts}) > 1:  # a group of facets holds facets of one type
            notes.append(f"facet group {name!r} has facets of several types "
                         f"({', '.join(sorted({_cells.facet_type(p.shape[1], dim) for p in parts}))}): read as a node group "
                         f"(a facet group holds facets of one type)")
            nodes_acc.setdefault(name, []).extend(p.ravel() for p in parts)
            del facets_acc[name]
    for name, parts in facets_acc.items():
        facets = to_mesh_nodes("facet", name, np.concatenate(parts))
        if facets is not None:
            _, first = np.unique(np.sort(facets, axis=1), axis=0, return_index=True)
            facet_groups[name] = facets[np.sort(first)]  # a facet in the group twice (two sources) once
    for name, parts in nodes_acc.items():
        nodes = to_mesh_nodes("node", name, np.unique(np.concatenate(parts)))
        if nodes is not None:
            node_groups[name] = nodes
    cell_groups = {name: np.unique(np.concatenate(parts)) for name, parts in cells_acc.items()}
    return {"cell_groups": cell_groups, "facet_groups": facet_groups, "node_groups": node_groups}, notes


def _pad_columns(a: np.ndarray, dim: int) -> np.ndarray:
    if dim == 2 and a.ndim == 2 and a.shape[1] == 2:
        return np.pad(a, ((0, 0), (0, 1)))
    return a


def write_vtu(path, mesh: Mesh, point_data: dict | None = None, cell_data: dict | None = None) -> Path:
    """Write ``mesh`` as a VTK unstructured grid (.vtu) that ParaView opens.

    2D points get ``z = 0``; on a 2D mesh, data arrays of shape ``(n, 2)`` (vectors) are padded
    to 3 components as well.  ``point_data`` arrays have ``n_nodes`` rows, ``cell_data`` arrays
    ``n_cells`` rows; ``material`` is always written as cell data.  The file is written to a
    temporary file in the same directory and moved into place with :func:`os.replace`, so a
    reader never sees a partial file.  Returns the path.
    """
    import meshio

    path = Path(path)
    point_data = {} if point_data is None else dict(point_data)
    cell_data = {} if cell_data is None else dict(cell_data)
    pdata, cdata = {}, {"material": [mesh.material]}
    for name, values in point_data.items():
        values = np.asarray(values)
        if len(values) != mesh.n_nodes:
            raise ValueError(f"point_data[{name!r}] has {len(values)} rows, the mesh {mesh.n_nodes} nodes")
        pdata[name] = _pad_columns(values, mesh.dim)
    for name, values in cell_data.items():
        values = np.asarray(values)
        if len(values) != mesh.n_cells:
            raise ValueError(f"cell_data[{name!r}] has {len(values)} rows, the mesh {mesh.n_cells} cells")
        cdata[name] = [_pad_columns(values, mesh.dim)]
    points = _pad_columns(mesh.points, mesh.dim)
    out = meshio.Mesh(points, [(_cells.get(mesh.cell_type).meshio, mesh.cells)], point_data=pdata, cell_data=cdata)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        meshio.write(tmp, out, file_format="vtu")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path

"""Named groups and node selections: the material index of every cell from cell groups
(:func:`materials_from_groups`), the nodes inside a box or on a plane (:func:`select_nodes`), and
the facet and node groups carried along when nodes are renumbered.
"""

from __future__ import annotations

import numpy as np

from .core import Mesh, _fmt_point

_AXES = {"x": 0, "y": 1, "z": 2}


def _renumbered_groups(mesh: Mesh, node_map: np.ndarray, source: str) -> dict:
    """The facet and node groups of ``mesh`` with node ``i`` renumbered ``node_map[i]`` (-1: the
    node is dropped), as keyword arguments of :class:`Mesh`; the cell groups are unchanged.

    Nodes that are dropped leave their node groups; a facet that loses a node, or whose corners
    become one node, and a node group left empty, are a ValueError naming the group."""
    facet_groups, node_groups = {}, {}
    for name, facets in mesh.facet_groups.items():
        new = node_map[facets]
        ordered = np.sort(new, axis=1)
        bad = np.flatnonzero((new < 0).any(axis=1) | (ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
        if len(bad):
            f = facets[bad[0]]
            raise ValueError(f"{source}: facet group {name!r}: {len(bad)} facet(s) lose a node or collapse when "
                             f"nodes are merged or dropped, e.g. the facet of nodes {f.tolist()}; allowed: facets on "
                             f"nodes of the cells with distinct corners")
        facet_groups[name] = new
    for name, nodes in mesh.node_groups.items():
        new = node_map[nodes]
        new = new[new >= 0]
        if len(new) == 0:
            raise ValueError(f"{source}: node group {name!r}: none of its {len(nodes)} node(s) is used by a cell; "
                             f"allowed: groups of nodes of the cells")
        node_groups[name] = new
    return {"facet_groups": facet_groups, "node_groups": node_groups}


def _fmt_names(names) -> str:
    return ", ".join(sorted(names)) if names else "none"


def materials_from_groups(mesh: Mesh, keys, source: str = "materials") -> np.ndarray:
    """Material index of every cell from cell groups: ``material[c] = i`` for the cells of
    ``mesh.cell_groups[keys[i]]``.

    Every cell must be in exactly one of the groups: a group the mesh lacks (naming the cell
    groups it has), cells in none of them or in two of them (counted, with an example cell and
    its centroid) are a ValueError starting with ``source``.
    """
    keys = [str(k) for k in keys]
    groups = mesh.cell_groups
    for key in keys:
        if key not in groups:
            import difflib

            hint = difflib.get_close_matches(key, list(groups), n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise ValueError(f"{source}: the mesh has no cell group {key!r}{did}; its cell groups: "
                             f"{_fmt_names(groups)}")
    count = np.zeros(mesh.n_cells, dtype=np.int64)
    material = np.zeros(mesh.n_cells, dtype=np.int64)
    for i, key in enumerate(keys):
        count[groups[key]] += 1
        material[groups[key]] = i

    def contains(cells, c):  # cells sorted
        return bool(len(cells)) and cells[min(np.searchsorted(cells, c), len(cells) - 1)] == c

    def example(c):
        others = [name for name, cells in groups.items() if name not in keys and contains(cells, c)]
        where = f" (in the group(s) {_fmt_names(others)})" if others else ""
        centroid = mesh.points[mesh.cells[c]].mean(axis=0)
        return f"cell {c} at {_fmt_point(centroid)}{where}"

    many = np.flatnonzero(count > 1)
    if len(many):
        c = int(many[0])
        which = [key for key in keys if contains(groups[key], c)]
        raise ValueError(f"{source}: {len(many)} of {mesh.n_cells} cell(s) are in two or more of the groups "
                         f"{', '.join(keys)}, e.g. {example(c)} in {', '.join(which)}; allowed: every cell in "
                         f"exactly one of them")
    none = np.flatnonzero(count == 0)
    if len(none):
        raise ValueError(f"{source}: {len(none)} of {mesh.n_cells} cell(s) are in none of the groups "
                         f"{', '.join(keys)}, e.g. {example(int(none[0]))}; allowed: every cell in exactly one of "
                         f"them (the mesh's cell groups: {_fmt_names(groups)})")
    return material


def select_nodes(mesh: Mesh, box=None, plane=None, tol: float = 1e-9) -> np.ndarray:
    """Sorted ids of the nodes inside ``box`` and on ``plane`` (both optional; both -> intersection).

    ``box = ((xmin, ymin[, zmin]), (xmax, ymax[, zmax]))`` in metres, any bound may be None
    (unbounded), and either corner may be None.  ``plane = (axis, value)`` with axis "x", "y",
    "z" or 0, 1, 2, e.g. ``("z", 0.0)``.  Bounds are widened by ``tol`` metres.  With neither,
    every node is selected.  Raises ValueError if nothing is selected.
    """
    x = mesh.points
    keep = np.ones(len(x), dtype=bool)
    if box is not None:
        lower, upper = box
        for bounds, sign in ((lower, 1.0), (upper, -1.0)):
            if bounds is None:
                continue
            if len(bounds) != mesh.dim:
                raise ValueError(f"box corners need {mesh.dim} coordinates, got {bounds!r}")
            for d, b in enumerate(bounds):
                if b is not None:
                    keep &= sign * (x[:, d] - b) >= -tol
    if plane is not None:
        axis, value = plane
        d = _AXES.get(axis, axis) if isinstance(axis, str) else int(axis)
        if not isinstance(d, int) or not 0 <= d < mesh.dim:
            raise ValueError(f"plane axis {axis!r} is not an axis of a {mesh.dim}D mesh")
        keep &= np.abs(x[:, d] - value) <= tol
    ids = np.flatnonzero(keep)
    if len(ids) == 0:
        raise ValueError(f"no node selected by box={box!r}, plane={plane!r} (tol={tol})")
    return ids

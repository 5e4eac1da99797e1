"""What the model builders of the families share: material tables, parameter functions called per cell, spring
constants summed over the cells sharing a node pair, and the checks of the mesh."""

from __future__ import annotations

from functools import partial

import numpy as np

from msslib import mesh as _mesh
from msslib.mesh.core import LOCAL_EDGES
from msslib.models.checks import poisson, positive, same_shape, warn_nu
from msslib.terms import Springs


def material_arrays(mesh, materials) -> tuple[np.ndarray, np.ndarray]:
    """``(E, nu)`` per cell from ``materials`` (list of ``(E, nu)``) and ``mesh.material``."""
    materials = [tuple(m) for m in materials]
    if not materials:
        raise ValueError("materials is empty")
    if any(len(m) != 2 for m in materials):
        raise ValueError("materials must be a list of (E, nu) pairs")
    if mesh.n_cells and (mesh.material.min() < 0 or mesh.material.max() >= len(materials)):
        raise ValueError(f"mesh.material refers to materials up to {mesh.material.max()}, only {len(materials)} given")
    table = np.asarray(materials, dtype=float)
    return table[mesh.material, 0], table[mesh.material, 1]


def _field(result, name):
    """Field ``name`` of a parameters result (a dataclass), or the result itself if it is a number."""
    if hasattr(result, name):
        return getattr(result, name)
    if np.ndim(result) == 0 and not hasattr(result, "__dataclass_fields__"):
        return result
    raise AttributeError(f"{type(result).__name__} has no field {name!r}")


def _per_cell(fn, fields, E, **named):
    """Call a parameters function ``fn(E, **named)`` on per-cell arrays (its arguments past ``E``
    are keyword-only); returns one float array per field.

    Tries one vectorised call; if the function only takes scalars, calls it cell by cell
    (genuine errors, e.g. an invalid nu, are then raised by the scalar call)."""
    names = list(named)
    arrays = [np.asarray(a, dtype=float) for a in (E, *named.values())]
    m = max((a.size for a in arrays if a.ndim), default=1)
    arrays = [np.broadcast_to(a, (m,)) for a in arrays]

    def call(values):
        return fn(values[0], **dict(zip(names, values[1:])))

    try:
        res = call(arrays)
        out = [np.broadcast_to(np.asarray(_field(res, f), dtype=float), (m,)).copy() for f in fields]
        return out
    except (TypeError, ValueError, AttributeError):
        pass
    out = [np.empty(m) for _ in fields]
    cache = {}
    for i in range(m):
        key = tuple(float(a[i]) for a in arrays)
        if key not in cache:
            res = call(key)
            cache[key] = [float(_field(res, f)) for f in fields]
        for o, v in zip(out, cache[key]):
            o[i] = v
    return out


def _pairs_of(mesh, pair_kind):
    if isinstance(pair_kind, _mesh.NodePairs):
        return pair_kind
    table = {
        "edges": _mesh.unique_edges,
        "face_diagonals": _mesh.face_diagonals,
        "inner_diagonals": _mesh.inner_diagonals,
    }
    if pair_kind not in table:
        raise ValueError(f"pair_kind must be one of {sorted(table)} or a NodePairs, got {pair_kind!r}")
    return table[pair_kind](mesh)


def _combine(pairs: _mesh.NodePairs, k_inc, rest_inc):
    """Sum per-incidence constants per pair; the rest length is the k-weighted mean (exact: the sum
    of springs on one pair equals one spring of that constant and rest length, up to a constant)."""
    n_pairs = len(pairs.pairs)
    owner = np.repeat(np.arange(n_pairs), pairs.counts)
    k = np.bincount(owner, weights=k_inc, minlength=n_pairs)
    if rest_inc is None:
        return k, None
    with np.errstate(invalid="ignore", divide="ignore"):
        rest = np.bincount(owner, weights=k_inc * rest_inc, minlength=n_pairs) / k
    return k, rest


def _springs_from(mesh, pairs, k, rest, signed=False):
    length = np.linalg.norm(mesh.points[pairs.pairs[:, 1]] - mesh.points[pairs.pairs[:, 0]], axis=1)
    return Springs(pairs.pairs, k, length if rest is None else rest, mesh.dim, signed=signed)


def assemble_springs(mesh, pair_kind, k_per_cell_fn, signed: bool = False) -> Springs:
    """Springs on the node pairs of ``mesh`` with constants summed over the cells sharing a pair.

    ``pair_kind``: ``"edges"``, ``"face_diagonals"``, ``"inner_diagonals"`` or a
    :class:`msslib.mesh.NodePairs`.  ``k_per_cell_fn(cell_ids, node_pairs)`` receives, for every
    (pair, cell) incidence, the cell id (m,) and the node pair (m, 2), and returns the constant
    contributed by that cell (m,), or a tuple ``(k, rest_length)``.  The spring of a pair gets
    ``k = sum`` of its contributions and the rest length: the distance of its nodes, or with
    explicit rest lengths their k-weighted mean.  Raises ValueError (from :class:`Springs`) if a
    summed constant is not positive, unless ``signed`` (the caller checks the lattice itself).
    """
    pairs = _pairs_of(mesh, pair_kind)
    node_pairs = np.repeat(pairs.pairs, pairs.counts, axis=0)
    res = k_per_cell_fn(pairs.cells, node_pairs)
    if isinstance(res, tuple):
        k_inc, rest_inc = (np.broadcast_to(np.asarray(v, dtype=float), (len(node_pairs),)) for v in res)
    else:
        k_inc, rest_inc = np.broadcast_to(np.asarray(res, dtype=float), (len(node_pairs),)), None
    k, rest = _combine(pairs, k_inc, rest_inc)
    return _springs_from(mesh, pairs, k, rest, signed)


def _merge_springs(springs: list[Springs]) -> Springs:
    """One Springs term from several on disjoint pair sets (e.g. edges and diagonals)."""
    return Springs(np.concatenate([s.pairs for s in springs]), np.concatenate([s.k for s in springs]),
                   np.concatenate([s.rest_length for s in springs]), springs[0].dim)


def _require(mesh, cell_type):
    if mesh.cell_type != cell_type:
        raise ValueError(f"this model needs {cell_type} cells, got {mesh.cell_type}")
    return _mesh.check_cells(mesh)


def _pair_lengths(mesh, node_pairs):
    return np.linalg.norm(mesh.points[node_pairs[:, 1]] - mesh.points[node_pairs[:, 0]], axis=1)


def _cube_edges(mesh, rtol=1e-6):
    """Edge length ``a`` per hexahedron; ValueError unless every cell is a cube (within rtol)."""
    x = mesh.points[mesh.cells]
    edges = LOCAL_EDGES["hexahedron"]
    lengths = np.linalg.norm(x[:, edges[:, 1]] - x[:, edges[:, 0]], axis=2)  # (m, 12)
    a = lengths.mean(axis=1)
    diag = np.linalg.norm(x[:, [6, 7, 4, 5]] - x[:, [0, 1, 2, 3]], axis=2)
    bad = np.flatnonzero((np.abs(lengths - a[:, None]).max(axis=1) > rtol * a)
                         | (np.abs(diag - np.sqrt(3.0) * a[:, None]).max(axis=1) > rtol * a))
    if len(bad):
        shown = ", ".join(f"cell {i} (edges {lengths[i].min():.4g}..{lengths[i].max():.4g} m)" for i in bad[:5])
        raise ValueError(f"{len(bad)} hexahedra are not cubes (rtol {rtol}): {shown}")
    return a


def cube_constants(mesh, materials, parameters, fields, published: bool = False, **named) -> list[np.ndarray]:
    """Per-cube constants on a mesh of cubes: ``fields`` of ``parameters(E, nu=nu, a=a, **named,
    published=published)``, ``E`` and ``nu`` from ``materials``, ``a`` each cube's edge; one float
    array per field (see :func:`_per_cell`).  ValueError unless the cells are cubes."""
    _require(mesh, "hexahedron")
    a = _cube_edges(mesh)
    E, nu = material_arrays(mesh, materials)
    return _per_cell(partial(parameters, published=published), fields, E, nu=nu, a=a, **named)


def cube_springs(mesh, constants) -> Springs:
    """One Springs term from per-cube spring constants: ``constants`` is a sequence of
    ``(pair_kind, k)``, ``k`` one value per cell, summed over the cubes sharing a pair
    (:func:`assemble_springs`); the pairs of the kinds in the order given."""
    def per_cell(k):
        return lambda cells, _pairs: k[cells]

    return _merge_springs([assemble_springs(mesh, kind, per_cell(k)) for kind, k in constants])


def check_material(E, nu, model, valid_nu):
    """Validate E > 0 and -1 < nu < 1/2 (ValueError naming the value) and warn
    (``FormulaValidityWarning``) when ``model`` is exact or optimal only at ``valid_nu[model]``."""
    positive("E", E)
    poisson(nu)
    same_shape("check_material", E=E, nu=nu)
    if model in valid_nu:
        warn_nu(nu, valid_nu[model], model)

"""The error of one result against another: ``msslib compare RESULT.nc REFERENCE.nc``.

:func:`compare_results` measures the final displacement of a result (a mass-spring system, an FEM
run, anything :func:`msslib.results.netcdf.write_result` wrote) against a reference result:

* on the **same mesh** (equal rest positions, node for node) the per-node error is
  ``|u_i - u_ref_i|``;
* on **another mesh of the same body** (a coarse result against a finer reference, nested or
  not) the reference displacement is evaluated at the result's nodes with the reference's own
  shape functions (:func:`interpolate`), and the error is taken there.  Nodes of the result that
  lie outside the reference mesh (a curved boundary meshed at another resolution) take the
  displacement of the nearest reference node; how many there are and how far they lie is part of
  the comparison.

Meshes that do not cover the same body are refused, checked both ways: a node of the result
farther from the reference mesh, or a boundary node of the reference farther from the result mesh,
than :data:`OUTSIDE_TOLERANCE` times the element size (the largest distance between two nodes of
one cell, of the coarser of the two meshes).  A curved boundary meshed at two resolutions stays
within that (its chords lie about ``h^2 / 8R`` inside); a reference that extends beyond the result
(a longer bar that contains it) or a result that extends beyond the reference does not.  Rest
positions whose extent is 1000 or 100 times the other's are named as millimetres or centimetres.
:func:`reference_at` is that one measurement: ``msslib compare``, ``msslib experiment compare``
and the studies all take the reference displacement through it (or :func:`interpolate`).

The statistics (:class:`Comparison`) are the mean, standard deviation and maximum of the per-node
Euclidean error, in the result's unit (metres), and the same divided by the largest reference
displacement (the convention of the papers).  :func:`write_error_field` writes the result's mesh
with the error field for ParaView.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Comparison", "compare_results", "reference_at", "interpolate", "element_size", "write_error_field",
           "OUTSIDE_TOLERANCE"]

#: the farthest a node of one mesh may lie outside the other mesh, relative to the element size
#: (:func:`element_size`, the larger of the two meshes'), before the two are taken for different bodies
OUTSIDE_TOLERANCE = 0.25
#: extents this many times the other's: the rest positions are in that unit, not metres
UNIT_FACTORS = ((1000.0, "millimetres"), (100.0, "centimetres"))
#: points located at once in the reference mesh (bounds the element finder's memory)
PROBE_BLOCK = 256


def _probe(ref_mesh, ref_u, points):
    """Shape-function values of the reference at ``points``: (values, inside mask).

    Points on a reference node (a nested refinement, or the same nodes) take that node's value,
    which is what the interpolating shape functions give there; points farther from every node
    than :func:`element_size` lie in no cell; the others are located element by element in blocks (:data:`PROBE_BLOCK` points at a time: scikit-fem's element finder holds
    arrays of points x candidate elements)."""
    from scipy.spatial import cKDTree
    from skfem import Basis

    from msslib.fem import to_skfem

    out = np.empty((len(points), ref_u.shape[1]))
    inside = np.ones(len(points), dtype=bool)
    nodes = np.asarray(ref_mesh.points, dtype=float)
    tol = 1e-10 * max(float(np.ptp(nodes, axis=0).max()), 1e-300)
    distance, nearest = cKDTree(nodes).query(points)
    on_node = distance <= tol
    out[on_node] = ref_u[nearest[on_node]]
    # farther from every node than the largest cell is wide: in no cell (not located one by one)
    beyond = distance > (1.0 + 1e-9) * element_size(ref_mesh)
    inside[beyond] = False
    out[beyond] = ref_u[nearest[beyond]]
    rest = np.flatnonzero(~on_node & ~beyond)
    if not len(rest):
        return out, inside
    skmesh, elem = to_skfem(ref_mesh)
    basis = Basis(skmesh, elem)

    def probe(pts):
        P = basis.probes(pts.T)
        return np.column_stack([P @ ref_u[:, d] for d in range(ref_u.shape[1])])

    for start in range(0, len(rest), PROBE_BLOCK):
        block = rest[start:start + PROBE_BLOCK]
        try:
            out[block] = probe(points[block])
            continue
        except ValueError:  # some points lie outside: probe one by one
            pass
        for i in block:
            try:
                out[i] = probe(points[i][None, :])[0]
            except ValueError:
                inside[i] = False
    return out, inside


def element_size(mesh) -> float:
    """The largest distance between two nodes of one cell of ``mesh`` [m] (0 without cells)."""
    cells = np.asarray(mesh.cells)
    if not len(cells):
        return 0.0
    X = np.asarray(mesh.points, dtype=float)
    k = cells.shape[1]
    return float(max(np.linalg.norm(X[cells[:, a]] - X[cells[:, b]], axis=1).max()
                     for a in range(k) for b in range(a + 1, k)))


def _segment_distance(p, a, b):
    """Distance of points ``p`` to segments ``a``-``b`` (broadcast over leading axes)."""
    ab = b - a
    t = np.einsum("...i,...i", p - a, ab) / np.maximum(np.einsum("...i,...i", ab, ab), 1e-300)
    return np.linalg.norm(p - (a + np.clip(t, 0.0, 1.0)[..., None] * ab), axis=-1)


def _triangle_distance(p, a, b, c):
    """Distance of points ``p`` to triangles ``a b c`` in 3D (broadcast over leading axes)."""
    n = np.cross(b - a, c - a)
    nn = np.einsum("...i,...i", n, n)
    ok = nn > 0
    h = np.einsum("...i,...i", p - a, n) / np.where(ok, nn, 1.0)
    q = p - h[..., None] * n  # projection onto the triangle's plane
    inside = ok.copy()
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("...i,...i", np.cross(v - u, q - u), n) >= 0
    edges = np.minimum(np.minimum(_segment_distance(p, a, b), _segment_distance(p, b, c)), _segment_distance(p, c, a))
    return np.where(inside, np.abs(h) * np.sqrt(np.where(ok, nn, 0.0)), edges)


def _distance_to_mesh(mesh, points, candidates: int = 16, tol: float | None = None):
    """Distance [m] of ``points`` (outside ``mesh``) to the boundary of ``mesh``, over the boundary
    facets nearest to each point: exact where those are shown to hold the closest, else over all
    facets.  With ``tol``, that search over all facets is made only where it decides whether the
    distance exceeds ``tol`` (elsewhere the value may be an upper bound at most ``tol``, or
    a value above a lower bound that already exceeds ``tol``)."""
    from scipy.spatial import cKDTree

    from msslib.mesh import boundary_facets

    points = np.asarray(points, dtype=float)
    if not len(points):
        return np.zeros(0)
    X = np.asarray(mesh.points, dtype=float)
    facets = boundary_facets(mesh)
    if not len(facets):
        return cKDTree(X).query(points)[0]
    corners = X[facets]  # (f, k, dim)
    if corners.shape[1] == 4:  # quadrilaterals: two triangles each
        corners = np.concatenate([corners[:, [0, 1, 2]], corners[:, [0, 2, 3]]])

    def dist(p, c):  # p (m, 1, dim), c (m or 1, f, k, dim) -> (m, f)
        if c.shape[-2] == 2:
            return _segment_distance(p, c[..., 0, :], c[..., 1, :])
        return _triangle_distance(p, c[..., 0, :], c[..., 1, :], c[..., 2, :])

    centre = corners.mean(axis=1)
    radius = float(np.linalg.norm(corners - centre[:, None, :], axis=2).max())
    k = min(candidates, len(corners))
    dc, near = cKDTree(centre).query(points, k=k)
    dc, near = dc.reshape(len(points), k), near.reshape(len(points), k)
    out = dist(points[:, None, :], corners[near]).min(axis=1)
    if k < len(corners):  # a facet beyond the k nearest centres could be closer: check against all
        lower = dc[:, -1] - radius
        unsure = out > lower
        if tol is not None:
            unsure &= (out > tol) & (lower <= tol)
        for i in np.flatnonzero(unsure):
            out[i] = dist(points[i][None, None, :], corners[None]).min()
    return out


def _interpolate(ref_mesh, ref_u, points, tol: float | None = None):
    """(values, inside mask, distance of each point to the reference mesh [m], 0 inside; with
    ``tol`` as :func:`_distance_to_mesh` gives it)."""
    from scipy.spatial import cKDTree

    ref_u = np.asarray(ref_u, dtype=float)
    points = np.asarray(points, dtype=float)
    out, inside = _probe(ref_mesh, ref_u, points)
    distance = np.zeros(len(points))
    if not inside.all():
        distance[~inside] = _distance_to_mesh(ref_mesh, points[~inside], tol=tol)
        out[~inside] = ref_u[cKDTree(ref_mesh.points).query(points[~inside])[1]]
    return out, inside, distance


def _fmt_point(x) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in x) + ")"


def _unit_hint(X, Xr, result_name, reference_name) -> str:
    """The unit of rest positions whose extent is 1000 or 100 times the other's (or ``""``)."""
    ext, ext_ref = np.ptp(X, axis=0), np.ptp(Xr, axis=0)
    use = (ext > 0) & (ext_ref > 0)
    if not use.any() or (ext > 0).tolist() != (ext_ref > 0).tolist():
        return ""
    ratio = ext[use] / ext_ref[use]
    for factor, unit in UNIT_FACTORS:
        for r, name, other in ((ratio, result_name, reference_name), (1.0 / ratio, reference_name, result_name)):
            if np.all(np.abs(r / factor - 1.0) < 0.05):
                return (f"the rest positions of {name} span {float(factor):g} times those of {other}: they look like "
                        f"{unit}; results are compared in metres (give the mesh in metres, or scale it)")
    return ""


def reference_at(ref_mesh, ref_u, at, *, result_name: str = "result", reference_name: str = "reference"):
    """The reference displacement ``ref_u`` (one row per node of ``ref_mesh``) at the nodes of the
    result mesh ``at`` (a :class:`~msslib.mesh.Mesh`; or only its node positions, then only the
    result's side is checked), with the reference's shape functions: ``(values, relation,
    n_outside, outside_distance)``.

    The one measurement behind every comparison.  Raises ValueError naming both when the two are
    not meshes of the same body (see the module docstring): a result node outside the reference,
    or a boundary node of the reference outside the result, farther than
    :data:`OUTSIDE_TOLERANCE` times the element size; rest positions in millimetres or
    centimetres are named as such."""
    from scipy.spatial import cKDTree

    mesh = None if isinstance(at, np.ndarray) or not hasattr(at, "points") else at
    X = np.asarray(at.points if mesh is not None else at, dtype=float)
    Xr = np.asarray(ref_mesh.points, dtype=float)
    ref_u = np.asarray(ref_u, dtype=float)
    if X.ndim != 2 or X.shape[1] != Xr.shape[1]:
        raise ValueError(f"{result_name} has {X.shape[-1] if X.ndim == 2 else '?'}D points and {reference_name} "
                         f"{Xr.shape[1]}D: a result can only be compared with a reference of its own dimension")
    size = float(np.linalg.norm(np.ptp(Xr, axis=0))) if len(Xr) else 0.0
    if X.shape == Xr.shape and np.allclose(X, Xr, rtol=0.0, atol=1e-12 * max(size, float(np.abs(Xr).max()))):
        return ref_u, "same mesh", 0, 0.0
    h = max(element_size(ref_mesh), element_size(mesh) if mesh is not None else 0.0)
    tol = OUTSIDE_TOLERANCE * h

    def refuse(detail):
        unit = _unit_hint(X, Xr, result_name, reference_name)
        raise ValueError(f"{result_name} and {reference_name} are not meshes of the same body: "
                         f"{unit or detail}")

    if len(X) and len(Xr):
        unit = _unit_hint(X, Xr, result_name, reference_name)
        if unit:
            refuse(unit)
    values, inside, distance = _interpolate(ref_mesh, ref_u, X, tol=tol)
    far = float(distance.max(initial=0.0))
    if far > tol:
        worst = int(np.argmax(distance))
        far = float(_distance_to_mesh(ref_mesh, X[worst][None, :])[0])  # exact, for the message
        refuse(f"node {worst} of {result_name} at {_fmt_point(X[worst])} lies {far:.3g} m outside the reference "
               f"mesh (allowed: {OUTSIDE_TOLERANCE:g} of the element size {h:.3g} m, {tol:.3g} m)")
    if mesh is not None and len(X):
        from msslib.mesh import boundary_facets

        edge = np.unique(boundary_facets(ref_mesh)) if len(np.asarray(ref_mesh.cells)) else np.arange(len(Xr))
        d_node = cKDTree(X).query(Xr[edge])[0]
        check = edge[d_node > tol]  # nearer than tol to a result node: within tol of the result
        if len(check):
            _, located = _probe(mesh, np.zeros((len(X), 1)), Xr[check])
            check = check[~located]
        if len(check):
            d = _distance_to_mesh(mesh, Xr[check], tol=tol)
            if d.max() > tol:
                worst = int(np.argmax(d))
                d[worst] = _distance_to_mesh(mesh, Xr[check[worst]][None, :])[0]  # exact, for the message
                refuse(f"the reference extends beyond the result: node {int(check[worst])} of {reference_name} at "
                       f"{_fmt_point(Xr[check[worst]])} lies {float(d[worst]):.3g} m outside the mesh of {result_name} "
                       f"(allowed: {OUTSIDE_TOLERANCE:g} of the element size {h:.3g} m, {tol:.3g} m)")
    return values, "interpolated", int((~inside).sum()), far


def interpolate(ref_mesh, ref_u, points):
    """Reference displacement ``ref_u`` (one row per node of ``ref_mesh``) at ``points`` (or at the
    nodes of a mesh: then the reference is checked against it both ways), with the reference mesh's
    shape functions: :func:`reference_at`'s values.
    Points outside the reference mesh, within its tolerance, take the displacement of the nearest
    reference node; farther ones (and, given a mesh, a reference beyond it) are a ValueError."""
    return reference_at(ref_mesh, ref_u, points)[0]


@dataclass(frozen=True, eq=False)
class Comparison:
    """The error of ``result`` against ``reference`` (see the module docstring).

    ``relation`` is ``"same mesh"`` or ``"interpolated"``; ``models`` the two results' model names; ``n_outside`` result nodes lie outside
    the reference mesh, the farthest ``outside_distance`` metres away.  ``u`` and ``u_ref`` are the
    result's displacement and the reference's at the result's nodes; ``error`` the per-node
    :class:`msslib.metrics.DisplacementError`.
    """

    result: str
    reference: str
    relation: str
    models: tuple[str, str]
    mesh: object
    u: np.ndarray
    u_ref: np.ndarray
    error: object
    reference_max: float
    n_outside: int
    outside_distance: float

    @property
    def n_nodes(self) -> int:
        return len(self.u)

    def rows(self) -> list[tuple[str, str, str]]:
        """(statistic, absolute value with unit, relative value) rows of the table."""
        e = self.error

        def pc(v):
            return "-" if not np.isfinite(v) else f"{100 * v:.4g} %"

        return [("mean", f"{e.mean:.6g} m", pc(e.rel_mean)),
                ("SD", f"{e.std:.6g} m", pc(e.rel_std)),
                ("max", f"{e.max:.6g} m", pc(e.rel_max))]

    def table(self) -> str:
        """The comparison as a Markdown table with a header saying what was compared how."""
        how = ("on the same mesh" if self.relation == "same mesh" else
               "at the result's nodes, the reference interpolated with its own shape functions")
        (a, b), (ma, mb) = (self.result, self.reference), self.models
        lines = [f"error of {a}{f' ({ma})' if ma else ''} against {b}{f' ({mb})' if mb else ''}: "
                 f"{self.n_nodes} nodes, {how}", ""]
        if self.n_outside:
            lines += [f"{self.n_outside} result nodes lie outside the reference mesh (at most "
                      f"{self.outside_distance:.3g} m away) and take the nearest reference node's displacement", ""]
        scale = f"largest reference displacement {self.reference_max:.6g} m"
        lines += ["| per-node error | absolute | relative |", "|---|---|---|"]
        lines += [f"| {name} | {absolute} | {relative} |" for name, absolute, relative in self.rows()]
        lines += ["", f"relative: divided by the {scale}" if self.reference_max > 0 else
                  "relative: not defined (the reference does not move)"]
        return "\n".join(lines) + "\n"


def _final_state(ds, name):
    from msslib.results import mesh_from_result

    if "displacement" not in ds or "rest_position" not in ds:
        raise ValueError(f"{name} has no displacement and rest positions: not an msslib result with a mesh")
    unit = ds["displacement"].attrs.get("units", "m")
    if unit != "m":
        raise ValueError(f"{name}: displacement in {unit!r}; compare needs metres")
    u = np.asarray(ds["displacement"].transpose("node", "axis").values, dtype=float)
    return mesh_from_result(ds), u


def compare_results(result, reference, *, result_name: str = "result",
                    reference_name: str = "reference") -> Comparison:
    """The error of ``result`` against ``reference`` (datasets as :func:`msslib.results.netcdf.read_result`
    returns them, or paths to result files).  Raises ValueError naming the problem when they
    cannot be compared (another dimension, different bodies, not a result with a mesh)."""
    from msslib.results import read_result
    from msslib.metrics import displacement_error

    if isinstance(result, (str, Path)):
        result_name, result = str(result), read_result(result)
    if isinstance(reference, (str, Path)):
        reference_name, reference = str(reference), read_result(reference)
    mesh, u = _final_state(result, result_name)
    ref_mesh, u_ref = _final_state(reference, reference_name)
    if mesh.dim != ref_mesh.dim:
        raise ValueError(f"{result_name} is {mesh.dim}D and {reference_name} {ref_mesh.dim}D: "
                         f"a result can only be compared with a reference of its own dimension")
    ur, relation, n_outside, far = reference_at(ref_mesh, u_ref, mesh, result_name=result_name,
                                                reference_name=reference_name)
    reference_max = float(np.linalg.norm(u_ref, axis=1).max())
    error = displacement_error(u, ur, relative_to=reference_max if reference_max > 0 else None)
    models = (str(result.attrs.get("model", "")), str(reference.attrs.get("model", "")))
    return Comparison(result=result_name, reference=reference_name, relation=relation, models=models, mesh=mesh, u=u,
                      u_ref=ur, error=error, reference_max=reference_max, n_outside=n_outside,
                      outside_distance=far)


def error_point_data(comparison: Comparison) -> dict:
    """The fields :func:`write_error_field` writes, one row per node of the result."""
    c = comparison
    return {"displacement": c.u, "reference_displacement": c.u_ref, "error": c.u - c.u_ref,
            "error_magnitude": c.error.per_node, "relative_error": c.error.per_node_relative}


def write_error_field(path, comparison: Comparison) -> Path:
    """Write the result's mesh with the displacement, the reference's displacement at its nodes,
    the error vector, its magnitude [m] and the relative error as one VTU file for ParaView."""
    from msslib.mesh import write_vtu

    return write_vtu(path, comparison.mesh, point_data=error_point_data(comparison))

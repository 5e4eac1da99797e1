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
  the comparison.  Meshes that do not cover the same body (a node farther from the reference than
  :data:`MAX_OUTSIDE` of its bounding-box diagonal) are refused.

The statistics (:class:`Comparison`) are the mean, standard deviation and maximum of the per-node
Euclidean error, in the result's unit (metres), and the same divided by the largest reference
displacement (the convention of the papers).  :func:`write_error_field` writes the result's mesh
with the error field for ParaView.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Comparison", "compare_results", "interpolate", "write_error_field", "MAX_OUTSIDE"]

#: the farthest a result node may lie outside the reference mesh, relative to the reference's
#: bounding-box diagonal, before the two are taken for different bodies
MAX_OUTSIDE = 0.05
#: points located at once in the reference mesh (bounds the element finder's memory)
PROBE_BLOCK = 256


def _probe(ref_mesh, ref_u, points):
    """Shape-function values of the reference at ``points``: (values, inside mask).

    Points on a reference node (a nested refinement, or the same nodes) take that node's value,
    which is what the interpolating shape functions give there; the others are located element by
    element in blocks (:data:`PROBE_BLOCK` points at a time: scikit-fem's element finder holds
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
    rest = np.flatnonzero(~on_node)
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


def _interpolate(ref_mesh, ref_u, points):
    from scipy.spatial import cKDTree

    out, inside = _probe(ref_mesh, np.asarray(ref_u, dtype=float), np.asarray(points, dtype=float))
    distance = np.zeros(len(points))
    if not inside.all():
        distance[~inside], nearest = cKDTree(ref_mesh.points).query(points[~inside])
        out[~inside] = ref_u[nearest]
    return out, inside, distance


def interpolate(ref_mesh, ref_u, points):
    """Reference displacement ``ref_u`` (one row per node of ``ref_mesh``) at ``points``, with the
    reference mesh's shape functions; points outside the reference mesh take the displacement of
    the nearest reference node."""
    return _interpolate(ref_mesh, ref_u, points)[0]


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
    X, Xr = mesh.points, ref_mesh.points
    size = float(np.linalg.norm(Xr.max(axis=0) - Xr.min(axis=0)))
    n_outside, far = 0, 0.0
    if X.shape == Xr.shape and np.allclose(X, Xr, rtol=0.0, atol=1e-12 * max(size, np.abs(Xr).max())):
        relation, ur = "same mesh", u_ref
    else:
        relation = "interpolated"
        ur, inside, distance = _interpolate(ref_mesh, u_ref, X)
        n_outside, far = int((~inside).sum()), float(distance.max(initial=0.0))
        if far > MAX_OUTSIDE * size:
            worst = int(np.argmax(distance))
            raise ValueError(
                f"{result_name} and {reference_name} are not meshes of the same body: node {worst} of "
                f"{result_name} at {tuple(np.round(X[worst], 6))} lies {far:.3g} m from the reference mesh "
                f"(allowed: {MAX_OUTSIDE:g} of its size, {MAX_OUTSIDE * size:.3g} m)")
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

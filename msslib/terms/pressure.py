"""Pressure loads on boundary facets: :class:`Pressure` (dead or follower) and
:func:`pressure_nodal_forces`, the consistent nodal forces of a uniform pressure.

A pressure ``p`` (Pa) acts on facets with outward normal ``n``: the force per area is ``-p n``
(positive pushes into the body).  The nodal forces are the consistent ones of linear facets,
``f_a = -p integral N_a n dA``: two-node edges in 2D (per unit thickness, times ``thickness``),
triangles, bilinear quads.  Every facet is a bilinear map of its nodes' positions, so the integral is
a sum ``f_a = sum_{b, c} C_abc x_b x x_c`` (3D; ``C`` a few numbers per facet type, exact with one
point on triangles and 2 x 2 Gauss points on quads) and ``f_a = -p t / 2 R (x_1 - x_0)`` in 2D
(``R`` the quarter turn that takes the edge direction to its outward normal ``(dy, -dx)``).

Two readings: *dead* (``follow=False``), constant forces on the reference surface; *follower*
(``follow=True``), the same integral on the current positions, whose derivative in the positions
(the load stiffness) enters Newton's tangent: ``K_ab = d f_a / d x_b = sum_c (C_acb - C_abc)
[x_c]_x``, non-symmetric in general.  On a closed surface the follower forces are minus the
gradient of ``p V(x)``, ``V`` the enclosed volume (area in 2D, times the thickness).
"""

from __future__ import annotations

import numpy as np

from .base import ElementTerm, Table, _as_flat, make_column
from .external import ExternalForce

__all__ = ["Pressure", "pressure_nodal_forces", "outward_facets"]

# reference facets: corner shape functions and their derivatives at the quadrature points
_QUAD_SU = np.array([-1.0, 1.0, 1.0, -1.0])
_QUAD_SV = np.array([-1.0, -1.0, 1.0, 1.0])


def _coefficients(nf: int) -> np.ndarray:
    """``C`` (nf, nf, nf) of unit pressure: ``f_a = sum_bc C_abc x_b x x_c`` (3D facets)."""
    C = np.zeros((nf, nf, nf))
    if nf == 3:
        du = np.array([-1.0, 1.0, 0.0])
        dv = np.array([-1.0, 0.0, 1.0])
        # integral of N_a over the reference triangle is 1/6 for each corner; x_u x x_v is constant
        C[:] = -np.einsum("a,b,c->abc", np.full(3, 1.0 / 6.0), du, dv)
        return C
    if nf == 4:
        g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
        for u in g:
            for v in g:
                n = 0.25 * (1 + _QUAD_SU * u) * (1 + _QUAD_SV * v)
                du = 0.25 * _QUAD_SU * (1 + _QUAD_SV * v)
                dv = 0.25 * _QUAD_SV * (1 + _QUAD_SU * u)
                C -= np.einsum("a,b,c->abc", n, du, dv)
        return C
    raise ValueError(f"facets must have 2 (2D), 3 or 4 (3D) nodes, got {nf}")


def _pairs(C):
    """``[(b, c, A[:, b, c])]`` for ``b < c`` with ``A_abc = C_abc - C_acb`` not all zero (the cross
    product is antisymmetric, so the pairs ``b < c`` hold the whole sum)."""
    nf = C.shape[0]
    return [(b, c, C[:, b, c] - C[:, c, b]) for b in range(nf) for c in range(b + 1, nf)
            if np.any(C[:, b, c] - C[:, c, b] != 0)]


def _facet_forces(X, p, thickness):
    """Forces ``(k, nf, dim)`` on the nodes of facets at positions ``X`` (k, nf, dim); ``p`` (k,)."""
    k, nf, dim = X.shape
    if dim == 2:
        d = X[:, 1] - X[:, 0]
        normal = np.stack([d[:, 1], -d[:, 0]], axis=1)  # outward normal times the length
        f = -(0.5 * thickness * p)[:, None] * normal
        return np.repeat(f[:, None, :], 2, axis=1)
    X = X - X[:, :1]  # the sum is the same about any origin (sum_b C_abc = 0); about a corner it rounds less
    out = np.zeros((k, nf, 3))
    for b, c, a_bc in _pairs(_coefficients(nf)):
        cross = np.cross(X[:, b], X[:, c])
        out += a_bc[None, :, None] * cross[:, None, :]
    return out * p[:, None, None]


def _skew(y):
    """``[y]_x`` (k, 3, 3): ``[y]_x z = y x z``."""
    s = np.zeros(y.shape[:-1] + (3, 3))
    s[..., 0, 1], s[..., 0, 2] = -y[..., 2], y[..., 1]
    s[..., 1, 0], s[..., 1, 2] = y[..., 2], -y[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -y[..., 1], y[..., 0]
    return s


def _facet_stiffness(X, p, thickness):
    """``K`` (k, nf, nf, dim, dim): ``K[e, a, b] = d f_a / d x_b`` of facet ``e``."""
    k, nf, dim = X.shape
    if dim == 2:
        R = np.array([[0.0, 1.0], [-1.0, 0.0]])
        K = np.zeros((k, 2, 2, 2, 2))
        s = (0.5 * thickness * p)[:, None, None]
        for a in range(2):
            K[:, a, 0] = s * R
            K[:, a, 1] = -s * R
        return K
    C = _coefficients(nf)
    D = np.transpose(C, (0, 2, 1)) - C  # D[a, m, c] = C_acm - C_amc
    S = _skew(X - X[:, :1])  # (k, nf, 3, 3); about a corner, as the forces
    K = np.einsum("amc,ecij->eamij", D, S)
    return K * p[:, None, None, None, None]


def _checked_facets(points, facets):
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise ValueError(f"points must have shape (n, 2) or (n, 3), got {points.shape}")
    dim = points.shape[1]
    facets = np.asarray(facets)
    want = "(k, 2)" if dim == 2 else "(k, 3) or (k, 4)"
    if (facets.ndim != 2 or facets.dtype.kind not in "iu"
            or facets.shape[1] not in ((2,) if dim == 2 else (3, 4))):
        raise ValueError(f"facets must be whole node ids of shape {want} on a {dim}D mesh, got shape "
                         f"{facets.shape} ({facets.dtype})")
    facets = facets.astype(np.int64)
    if facets.size and (facets.min() < 0 or facets.max() >= len(points)):
        bad = int(facets[(facets < 0) | (facets >= len(points))][0])
        raise ValueError(f"facets: node ids must lie in 0..{len(points) - 1}, got {bad}")
    return points, facets


def _checked_pressure(pressure, k):
    p = np.asarray(pressure, dtype=float)
    if p.ndim > 1 or (p.ndim == 1 and p.shape != (k,)):
        raise ValueError(f"pressure must be a number (Pa) or one per facet ({k}), got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"pressure must be finite (Pa), got {float(p) if p.ndim == 0 else p.tolist()!r}")
    return np.broadcast_to(p, (k,)).astype(float)


def _checked_thickness(thickness, dim):
    t = float(thickness)
    if not np.isfinite(t) or t <= 0:
        raise ValueError(f"thickness must be a finite number > 0 (m), got {thickness!r}")
    if dim == 3 and t != 1.0:
        raise ValueError(f"thickness applies to 2D meshes only, got {thickness!r} on a 3D mesh")
    return t


def pressure_nodal_forces(points, facets, pressure, thickness: float = 1.0) -> np.ndarray:
    """Consistent nodal forces ``(n, dim)`` (N) of a pressure ``pressure`` (Pa, a number or one per
    facet; positive pushes into the body) on ``facets`` ``(k, 2|3|4)``, outward oriented (as
    :func:`msslib.mesh.boundary_facets` gives them), at node positions ``points`` ``(n, dim)``:
    ``f_a = -p integral N_a n dA``.  2D facets are edges of a body ``thickness`` thick (m)."""
    points, facets = _checked_facets(points, facets)
    dim = points.shape[1]
    p = _checked_pressure(pressure, len(facets))
    t = _checked_thickness(thickness, dim)
    out = np.zeros_like(points)
    if len(facets):
        f = _facet_forces(points[facets], p, t)
        for d in range(dim):
            out[:, d] = np.bincount(facets.ravel(), weights=f[:, :, d].ravel(), minlength=len(points))
    return out


def outward_facets(mesh, facets, boundary=None) -> np.ndarray:
    """``facets`` (node ids ``(k, nodes per facet)`` of boundary facets of ``mesh`` in any node order,
    e.g. a gmsh facet group's) as the mesh's boundary lists them: outward oriented, corners in the
    order of their cell's facet (:func:`msslib.mesh.boundary_facets`; ``boundary``: its result, if
    at hand).  A ValueError in one line for a wrong shape, an empty list, a node id off the mesh or a
    facet that is not on the boundary."""
    from msslib import mesh as _mesh

    if boundary is None:
        boundary = _mesh.boundary_facets(mesh)
    nf = boundary.shape[1]
    a = np.asarray(facets)
    if a.ndim != 2 or a.shape[1] != nf or a.dtype.kind not in "iu" or not len(a):
        raise ValueError(f"facets must be node ids of shape (k, {nf}) with k >= 1 (the facets of the mesh's "
                         f"{mesh.cell_type} cells), got {facets!r:.120}")
    if a.min() < 0 or a.max() >= mesh.n_nodes:
        raise ValueError(f"facets: node ids must lie in 0..{mesh.n_nodes - 1}, got "
                         f"{int(a[(a < 0) | (a >= mesh.n_nodes)][0])}")
    index = {tuple(sorted(f)): i for i, f in enumerate(boundary.tolist())}
    found = [index.get(tuple(sorted(f)), -1) for f in a.tolist()]
    bad = [i for i, j in enumerate(found) if j < 0]
    if bad:
        raise ValueError(f"facets: {len(bad)} of {len(a)} facets are not on the boundary of the mesh (facet "
                         f"{bad[0]}, nodes {a[bad[0]].tolist()}); allowed: boundary facets")
    return boundary[found]


class Pressure(ExternalForce):
    """A uniform pressure ``pressure`` (Pa, positive into the body) on the outward oriented
    boundary ``facets`` of ``mesh``, scaled by the load factor.

    ``follow=False``: dead, the constant nodal forces of the reference surface
    (:func:`pressure_nodal_forces` at the mesh's points; energy ``-f . x``).  ``follow=True``
    (default): a follower load, the forces of the current surface with their load stiffness in the
    tangent (non-symmetric: the model tells the solvers so; non-conservative: no energy).  2D meshes
    take ``thickness`` (m).  ``nodal``: the forces at rest at unit load, in either reading.
    Calling ``Pressure(...)`` with ``follow=True`` makes a :class:`FollowerPressure`.
    """

    kind = "external"
    export_label = "pressure"
    export_energy = "-f . x (f: the nodal forces at rest, table PRESSURE_forces)"
    follow = False

    def __new__(cls, *args, **kwargs):
        # Pressure(...) with follow (default True) makes the follower reading; a copy (no arguments)
        # keeps its class
        follow = args[3] if len(args) > 3 else kwargs.get("follow", True)
        if cls is Pressure and (args or kwargs) and follow:
            cls = FollowerPressure
        return super().__new__(cls)

    def __init__(self, mesh, facets, pressure, follow=True, thickness: float = 1.0, name: str = ""):
        points, facets = _checked_facets(mesh.points, facets)
        if not isinstance(follow, (bool, np.bool_)):
            raise ValueError(f"follow must be true or false, got {follow!r}")
        if not len(facets):
            raise ValueError("facets: a pressure needs at least one facet, got none")
        if np.ndim(pressure) != 0:
            raise ValueError(f"pressure must be one number (Pa), got shape {np.shape(pressure)}")
        self.pressure = float(_checked_pressure(pressure, len(facets))[0])
        self.thickness = _checked_thickness(thickness, points.shape[1])
        self.facets = facets
        #: the name of its export table (e.g. ``pressure_2`` for the scene's ``loads[2]``)
        self.export_name = name
        super().__init__(pressure_nodal_forces(points, facets, self.pressure, self.thickness), points.shape[1])

    def export_count(self) -> int:
        return int(len(self.facets))

    def export_entry(self) -> dict:
        entry = super().export_entry()
        energy = None if self.export_energy is None else self.export_energy.replace("PRESSURE", self.export_name)
        entry.update(follow=bool(self.follow), pressure=self.pressure, count=self.export_count(), energy=energy)
        return entry

    def export_tables(self, mesh) -> list[Table]:
        nf = self.facets.shape[1]
        how = ("a follower load: the forces of the current surface, -p n dA" if self.follow else
               "a dead load: constant forces normal to the reference surface")
        cols = [make_column("facet", None, np.arange(len(self.facets)), "facet index", int),
                *[make_column(f"node_{a}", None, self.facets[:, a], f"node {a} of the facet (outward oriented)", int)
                  for a in range(nf)],
                make_column("pressure", "Pa", np.full(len(self.facets), self.pressure),
                            "pressure at load factor 1, positive into the body"),
                make_column("follow", None, np.full(len(self.facets), int(self.follow)),
                            "1: follower (normal to the current surface), 0: dead", int)]
        if self.dim == 2:
            cols.append(make_column("thickness", "m", np.full(len(self.facets), self.thickness), "thickness"))
        on = np.flatnonzero(np.any(self.nodal != 0, axis=1))
        axes = "xyz"[:self.dim]
        forces = [make_column("node", None, on, "node index", int),
                  *[make_column(f"f_{a}", "N", self.nodal[on, i], f"force at rest, {a}") for i, a in enumerate(axes)]]
        return [Table(self.export_name, f"pressure on boundary facets, {how}", cols),
                Table(f"{self.export_name}_forces", f"nodal forces of the pressure at rest at load factor 1"
                      f"{' (they follow the surface as it deforms)' if self.follow else ''}", forces)]

    def export_forces(self):
        return [(self.export_name, self.nodal, f"pressure forces (N) at load factor 1 ({self.export_name})")]

    def export_note(self, fmt: str) -> str:
        return (f"the follower pressure {self.pressure:g} Pa on {len(self.facets)} facets (table {self.export_name}: "
                f"a load that follows the deforming surface)")


class FollowerPressure(Pressure, ElementTerm):
    """The follower reading of :class:`Pressure` (see there)."""

    follow = True
    conservative = False
    symmetric = False
    export_energy = None  # non-conservative on an open surface
    export_formats = ("csv", "json")

    def __init__(self, mesh, facets, pressure, follow=True, thickness: float = 1.0, name: str = ""):
        super().__init__(mesh, facets, pressure, follow, thickness, name)
        self.conn = self.facets
        self._n_local = (self.facets.shape[1] * self.dim) ** 2
        self._p = np.array([self.pressure])
        self._q = np.array([self.thickness])
        self._loops = (None, None, _follower_hessian)

    def __len__(self):
        return len(self.facets)

    def max_node(self) -> int:
        return self.n_nodes - 1

    def forces_at(self, x) -> np.ndarray:
        """Nodal forces ``(n, dim)`` at unit load at the positions ``x`` (flat or (n, dim))."""
        X = _as_flat(x).reshape(-1, self.dim)
        return pressure_nodal_forces(X, self.facets, self.pressure, self.thickness)

    def energy(self, x):
        return None

    def gradient(self, x) -> np.ndarray:
        return -self.forces_at(x).ravel()

    def export_forces(self):
        return []  # not constant: the formats that carry only constant forces say they cannot carry it


def _follower_hessian(x, conn, p, q, out):
    """Dense blocks ``-d f / d x`` (m, (nf dim)^2), row-major, of the facets ``conn`` (the loop
    signature of :class:`msslib.terms.base.ElementTerm`; ``p``: the pressure, ``q``: the thickness)."""
    m, nf = conn.shape
    dim = int(round(np.sqrt(out.shape[1]))) // nf
    X = x.reshape(-1, dim)[conn]
    K = _facet_stiffness(X, np.full(m, p[0]), float(q[0]))  # (m, a, b, i, j)
    out[:] = -np.transpose(K, (0, 1, 3, 2, 4)).reshape(m, -1)

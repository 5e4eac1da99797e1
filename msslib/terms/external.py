"""External (dead) loads, scaled by the load factor: nodal forces, gravity, tractions."""

from __future__ import annotations

import numpy as np

from .base import Term, _as_flat, _connectivity


class ExternalForce(Term):
    """A constant (dead) nodal force ``f`` (N, flat ``(n_dof,)``) at unit load.

    Energy ``-f . x``, gradient ``-f``, zero Hessian.  ``scales_with_load``: a model multiplies
    it by the load factor.
    """

    scales_with_load = True
    #: the scene states its loads and gravity itself: the exporters read them from the scene's setup
    kind = "external"
    export_formats = ("csv", "json", "vtu", "mjcf", "sofa", "c")

    def __init__(self, forces, dim: int):
        forces = np.asarray(forces, dtype=float)
        if forces.ndim != 2 or forces.shape[1] != dim:
            raise ValueError(f"forces must have shape (n_nodes, {dim}), got {forces.shape}")
        if not np.isfinite(forces).all():
            raise ValueError("forces must be finite")
        self.dim = dim
        self.nodal = forces
        self.vector = forces.ravel().copy()

    @property
    def n_nodes(self) -> int:
        return len(self.nodal)

    def max_node(self) -> int:
        return self.n_nodes - 1

    @property
    def total(self) -> np.ndarray:
        """Resultant force (N), ``(dim,)``."""
        return self.nodal.sum(axis=0)

    def energy(self, x) -> float:
        return -float(self.vector @ _as_flat(x))

    def gradient(self, x) -> np.ndarray:
        return -self.vector.copy()

    def abs_row_sums(self, x, scale, isq, out) -> bool:
        return type(self).hessian_values is Term.hessian_values  # a dead load has no stiffness


class NodalForces(ExternalForce):
    """Dead nodal loads ``f`` of shape ``(n_nodes, dim)`` (N)."""

    def __init__(self, forces):
        forces = np.asarray(forces, dtype=float)
        super().__init__(forces, forces.shape[1] if forces.ndim == 2 else 0)


class Gravity(ExternalForce):
    """Weight ``m_i g`` of every node: ``masses`` (n,) in kg, ``g`` (dim,) in m/s^2.

    Energy ``-sum_i m_i g . x_i``; constant force, zero Hessian.
    """

    def __init__(self, masses, g):
        masses = np.asarray(masses, dtype=float)
        g = np.asarray(g, dtype=float).ravel()
        if masses.ndim != 1:
            raise ValueError(f"masses must have shape (n_nodes,), got {masses.shape}")
        self.g = g
        super().__init__(masses[:, None] * g[None, :], len(g))


def _traction_nodal(points, facets, thickness):
    """Consistent nodal weights ``w`` (f, nodes): the force on node a of facet e is
    ``w[e, a] * traction[e]`` (reference configuration)."""
    x = points[facets]
    nf = facets.shape[1]
    if nf == 2:
        length = np.linalg.norm(x[:, 1] - x[:, 0], axis=1) * thickness
        return np.repeat(length[:, None] / 2.0, 2, axis=1)
    if nf == 3:
        area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
        return np.repeat(area[:, None] / 3.0, 3, axis=1)
    if nf == 4:
        # bilinear quad on [-1, 1]^2, corners counter-clockwise; 2 x 2 Gauss of N_a |dX/du x dX/dv|
        w = np.zeros((len(facets), 4))
        su = np.array([-1.0, 1.0, 1.0, -1.0])
        sv = np.array([-1.0, -1.0, 1.0, 1.0])
        for u in np.array([-1.0, 1.0]) / np.sqrt(3.0):
            for v in np.array([-1.0, 1.0]) / np.sqrt(3.0):
                du = 0.25 * ((x[:, 1] - x[:, 0]) * (1 - v) + (x[:, 2] - x[:, 3]) * (1 + v))
                dv = 0.25 * ((x[:, 3] - x[:, 0]) * (1 - u) + (x[:, 2] - x[:, 1]) * (1 + u))
                jac = np.linalg.norm(np.cross(du, dv), axis=1)
                n = 0.25 * (1 + su * u) * (1 + sv * v)
                w += jac[:, None] * n[None, :]
        return w
    raise ValueError(f"facets must have 2, 3 or 4 nodes, got {nf}")


class Traction(ExternalForce):
    """A traction (Pa) on boundary facets turned into consistent nodal dead loads.

    ``mesh`` gives the reference node positions; ``facets`` (f, 2|3|4) node ids (e.g. from
    :func:`msslib.mesh.boundary_facets`); ``traction`` (dim,) or (f, dim) in Pa, a fixed vector
    (not a follower pressure).  Two-node facets (2D edges) carry ``traction * length * thickness``
    (thickness in metres, 2D only) split in halves, triangles a third of ``traction * area`` per
    node, quads the exact consistent forces ``integral N_a traction dA`` of the bilinear facet
    (2 x 2 Gauss; exact for parallelograms).  ``total`` is the resultant.
    """

    def __init__(self, mesh, facets, traction, thickness: float = 1.0):
        facets = np.asarray(facets, dtype=np.int64)
        if facets.ndim != 2:
            raise ValueError(f"facets must have shape (f, 2|3|4), got {facets.shape}")
        facets = _connectivity("facets", facets, facets.shape[1])
        dim = mesh.dim
        if dim == 3 and thickness != 1.0:
            raise ValueError("thickness applies to 2D meshes only")
        if (dim == 2) != (facets.shape[1] == 2):
            raise ValueError(f"{dim}D meshes need {'2-node' if dim == 2 else '3- or 4-node'} facets")
        traction = np.broadcast_to(np.asarray(traction, dtype=float), (len(facets), dim))
        w = _traction_nodal(mesh.points, facets, float(thickness))
        nodal = np.zeros((mesh.n_nodes, dim))
        for d in range(dim):
            nodal[:, d] = np.bincount(facets.ravel(), weights=(w * traction[:, d:d + 1]).ravel(),
                                      minlength=mesh.n_nodes)
        self.facets = facets
        self.traction = np.array(traction)
        super().__init__(nodal, dim)


def sum_external_forces(terms, n_nodes: int, dim: int) -> np.ndarray:
    """Sum of the nodal forces ``(n_nodes, dim)`` at unit load of the :class:`ExternalForce`
    terms in ``terms`` (other terms are ignored)."""
    total = np.zeros((n_nodes, dim))
    for t in terms:
        if isinstance(t, ExternalForce):
            if t.nodal.shape != total.shape:
                raise ValueError(f"external term {type(t).__name__} has shape {t.nodal.shape}, expected {total.shape}")
            total += t.nodal
    return total

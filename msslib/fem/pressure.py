"""Pressure loads of the FEM references: consistent dof forces of a uniform pressure on boundary
facets, integrated with scikit-fem facet forms on the element's own facets (for quadratic elements
the quadratic facets, mid-side dofs included), dead or follower, and the follower's load stiffness.

A pressure ``p`` (Pa) pushes into the body: the force per current area is ``-p n``, ``n`` the
outward normal.  By Nanson's formula ``n da = cof(F) N dA`` (``N`` the outward reference normal,
``cof(F) = det(F) F^-T``), so the dof forces are

    ``f_(a,i) = -p w integral_facets phi_a cof(F)_(iJ) N_J dA``

on the reference facets (``w`` the thickness in 2D, 1 in 3D).  *Dead* (``follow=False``):
``F = I``, constant forces.  *Follower* (``follow=True``): ``F = I + grad u`` of the element at the
facet's quadrature points (``cof(F) N`` depends on the tangential derivatives only: it is the
current area-weighted normal of the facet's image), and the load stiffness

    ``d f_(a,i) / d u_(b,j) = -p w integral phi_a  d cof(F)_(iJ) / d F_(jK)  N_J  dphi_b/dX_K dA``

with ``cof(F)_(iJ) = e_ij e_JK F_jK`` in 2D and ``1/2 e_ijk e_JKL F_jK F_kL`` in 3D; it is not
symmetric in general.  For linear elements the forces equal
:func:`msslib.terms.pressure.pressure_nodal_forces` (the tests check it).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Levi-Civita symbols
_E2 = np.array([[0.0, 1.0], [-1.0, 0.0]])
_E3 = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _E3[_i, _j, _k], _E3[_i, _k, _j] = 1.0, -1.0


def check_pressures(pressures, mesh) -> list:
    """``pressures`` as a list of ``(facets (k, nf) int64, p float, follow bool)``; ValueError in one
    line naming the argument, the value and what is allowed for a malformed entry, an empty facet
    array, a non-finite pressure, facets that are not boundary facets of ``mesh`` or a facet listed
    twice."""
    from msslib.mesh import boundary_facets

    try:
        items = list(pressures)
    except TypeError:
        raise ValueError(f"pressures must be a sequence of (facets, pressure, follow) tuples, got "
                         f"{type(pressures).__name__}") from None
    out = []
    boundary = None
    if not items:  # (no facets to find without pressures)
        return out
    try:
        nf = boundary_facets(mesh).shape[1]
    except ValueError:  # facets of several types (wedges): no facet forms for them here
        raise ValueError(f"pressures: the FEM references take pressures on meshes whose facets are of one type "
                         f"(triangle, quad, tetra or hexahedron cells), got {mesh.cell_type} cells") from None
    for n, item in enumerate(items):
        if not isinstance(item, (tuple, list)) or len(item) != 3:
            raise ValueError(f"pressures[{n}] must be a tuple (facets, pressure, follow), got {item!r:.80}")
        facets, p, follow = item
        facets = np.asarray(facets)
        if facets.ndim != 2 or facets.dtype.kind not in "iu" or facets.shape[1] != nf:
            raise ValueError(f"pressures[{n}]: facets must be node ids of shape (k, {nf}) (the mesh's boundary facets), "
                             f"got shape {facets.shape} ({facets.dtype})")
        if facets.shape[0] == 0:
            raise ValueError(f"pressures[{n}]: facets is empty; a pressure needs at least one boundary facet")
        try:
            pv = float(p)
        except (TypeError, ValueError):
            raise ValueError(f"pressures[{n}]: pressure must be a finite number (Pa), got {p!r:.40}") from None
        if not np.isfinite(pv):
            raise ValueError(f"pressures[{n}]: pressure must be a finite number (Pa), got {pv}")
        if not isinstance(follow, (bool, np.bool_)):
            raise ValueError(f"pressures[{n}]: follow must be True (follower) or False (dead), got {follow!r:.40}")
        facets = facets.astype(np.int64)
        if facets.min() < 0 or facets.max() >= mesh.n_nodes:
            bad = int(facets[(facets < 0) | (facets >= mesh.n_nodes)][0])
            raise ValueError(f"pressures[{n}]: facets: node ids must lie in 0..{mesh.n_nodes - 1}, got {bad}")
        if boundary is None:
            boundary = {tuple(sorted(r)) for r in boundary_facets(mesh).tolist()}
        seen = set()
        for r in facets.tolist():
            key = tuple(sorted(r))
            if key not in boundary:
                raise ValueError(f"pressures[{n}]: facet of nodes {r} is not a boundary facet of the mesh; a pressure "
                                 "acts on boundary facets only (msslib.mesh.boundary_facets)")
            if key in seen:  # it would carry the pressure twice
                raise ValueError(f"pressures[{n}]: facet of nodes {r} is listed twice; give each loaded facet once")
            seen.add(key)
        out.append((facets, pv, bool(follow)))
    return out


class FacetPressure:
    """One uniform pressure on boundary facets of the FEM space ``geo``
    (:class:`msslib.fem.space._Geometry`), at load factor 1: :meth:`forces` and, for a follower,
    :meth:`stiffness` at a displacement ``u`` of all the dofs (flat, interleaved)."""

    def __init__(self, geo, facets, pressure: float, follow: bool, thickness: float = 1.0):
        import skfem

        self.geo, self.p, self.follow = geo, float(pressure), bool(follow)
        self.w = float(thickness) if geo.dim == 2 else 1.0
        index = {tuple(sorted(r)): i for i, r in enumerate(np.asarray(geo.skmesh.facets).T.tolist())}
        ids = np.array([index[tuple(sorted(r))] for r in np.asarray(facets).tolist()], dtype=np.int64)
        # exact for phi_a cof(F) N and for x times it (the torque) on simplices and Q1, Q2 facets
        fb = skfem.FacetBasis(geo.skmesh, geo.elem, facets=ids, intorder=3 * geo.order + 1)
        nb, d = fb.Nbfun, geo.dim
        self.phi = np.stack([np.asarray(fb.basis[a][0]) for a in range(nb)])  # (nb, k, q)
        self.dphi = np.stack([np.asarray(fb.basis[a][0].grad) for a in range(nb)])  # (nb, d, k, q)
        self.N = np.asarray(fb.normals)  # (d, k, q), outward, reference
        self.dx = np.asarray(fb.dx)  # (k, q)
        nodes = geo._sk_to_ours[np.asarray(fb.element_dofs)]  # (nb, k)
        self.nodes = nodes
        self.edofs = (nodes.T[:, :, None] * d + np.arange(d)[None, None, :]).reshape(len(ids), nb * d)
        self._dead = self._assemble(np.einsum("akq,Jkq,kq->kaJ", self.phi, self.N, self.dx))

    def _assemble(self, fe):
        """Flat dof vector of facet forces ``fe`` (k, nb, d) times ``-p w``."""
        return np.bincount(self.edofs.ravel(), weights=(-self.p * self.w * fe).ravel(), minlength=self.geo.n_dofs)

    def _F(self, u):
        ue = np.asarray(u, dtype=float).reshape(-1, self.geo.dim)[self.nodes]  # (nb, k, d)
        H = np.einsum("aki,aJkq->iJkq", ue, self.dphi)
        return H + np.eye(self.geo.dim)[:, :, None, None]

    def forces(self, u=None) -> np.ndarray:
        """Dof forces (flat, ``n_dofs``) at the displacement ``u`` (dead: the same for every ``u``)."""
        if not self.follow or u is None:
            return self._dead
        F = self._F(u)
        if self.geo.dim == 2:
            m = np.einsum("ij,JK,jKkq,Jkq->ikq", _E2, _E2, F, self.N)
        else:
            m = 0.5 * np.einsum("ijl,JKL,jKkq,lLkq,Jkq->ikq", _E3, _E3, F, F, self.N, optimize=True)
        return self._assemble(np.einsum("akq,ikq,kq->kai", self.phi, m, self.dx))

    def stiffness(self, u) -> sp.csr_matrix:
        """``d forces / d u`` (``n_dofs`` square, CSR; zero for a dead load), not symmetric in general."""
        n, d = self.geo.n_dofs, self.geo.dim
        if not self.follow:
            return sp.csr_matrix((n, n))
        if d == 2:
            D = np.einsum("ij,JK,Jkq->ijKkq", _E2, _E2, self.N)
        else:
            D = np.einsum("ijl,JKL,lLkq,Jkq->ijKkq", _E3, _E3, self._F(u), self.N, optimize=True)
        ke = -self.p * self.w * np.einsum("akq,ijKkq,bKkq,kq->kaibj", self.phi, D, self.dphi, self.dx, optimize=True)
        k, nb = ke.shape[0], ke.shape[1]
        ke = ke.reshape(k, nb * d, nb * d)
        rows = np.repeat(self.edofs, nb * d, axis=1).ravel()
        cols = np.tile(self.edofs, (1, nb * d)).ravel()
        return sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()


def facet_pressures(geo, pressures, thickness: float) -> list[FacetPressure]:
    """The :class:`FacetPressure` of every checked ``(facets, p, follow)`` on the space ``geo``."""
    return [FacetPressure(geo, f, p, follow, thickness) for f, p, follow in pressures]

"""scikit-fem conversion, the scalar element basis of a mesh, vectorised assembly, boundary
conditions and loads of the FEM references."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from msslib.mesh import Mesh, check_cells
from msslib.mesh import cells as _cells
from msslib.mesh.cells import RegistryView as _RegistryView

#: column permutation taking a VTK hexahedron to scikit-fem's ``MeshHex1`` node order.
HEX_VTK_TO_SKFEM = np.array(_cells.get("hexahedron").linear.vtk_to_skfem)

# The elements and their quadrature are the cell types' (msslib.mesh.cells): 1 point for P1
# simplices, 2x2(x2) Gauss for Q1, a rule of its own for the wedge; for quadratic elements exact for
# the linear-elastic stiffness on straight-sided simplices (degree 2), and 3x3(x3) Gauss for Q2.
_INTORDER = _RegistryView(lambda c: c.linear.intorder, "cell type -> quadrature order of its linear element")
_INTORDER_ORDER = {1: _INTORDER, 2: _RegistryView(lambda c: c.quadratic.intorder, "cell type -> quadrature order "
                                                  "of its quadratic element", only=lambda c: c.quadratic is not None)}
#: element orders: 1 linear (P1/Q1), 2 quadratic (P2/Q2, scikit-fem's ElementTriP2 ... ElementHex2)
ORDERS = (1, 2)
_ORDER2 = _RegistryView(lambda c: c.quadratic.element, "cell type -> scikit-fem quadratic element",
                        only=lambda c: c.quadratic is not None)


def element_of(cell_type: str, order: int = 1):
    """The :class:`msslib.mesh.cells.FemElement` of ``order`` of ``cell_type``; ValueError in one
    line where the type has none (no quadratic wedge in scikit-fem)."""
    cell = _cells.get(cell_type)
    element = cell.linear if order == 1 else cell.quadratic
    if element is None:
        have = ", ".join(n for n, c in _cells.registry().items() if c.quadratic is not None)
        raise ValueError(f"order must be 1 for {cell_type} cells (scikit-fem has no quadratic {cell_type} element), "
                         f"got {order!r}; quadratic elements exist for {have} cells")
    return element


def _quadrature(element, intorder):
    """Keyword arguments of ``skfem.Basis`` for ``element``: its own rule, else ``intorder``."""
    if intorder is None and element.rule is not None:
        points, weights = element.rule
        return {"quadrature": (np.asarray(points, dtype=float), np.asarray(weights, dtype=float))}
    return {"intorder": element.intorder if intorder is None else intorder}


def to_skfem(mesh: Mesh):
    """Convert a :class:`Mesh` to ``(skfem_mesh, scalar_element)``.

    Node indices are kept (``skfem_mesh.p[:, a] == mesh.points[a]``); only the order of the
    nodes inside each cell changes where scikit-fem's numbering differs from VTK's.
    """
    import skfem

    p = np.ascontiguousarray(mesh.points.T)
    t = mesh.cells
    element = element_of(mesh.cell_type)
    if element.vtk_to_skfem is not None:
        t = t[:, np.array(element.vtk_to_skfem)]
    return getattr(skfem, element.mesh)(p, np.ascontiguousarray(t.T)), getattr(skfem, element.element)()


class _Geometry:
    """Scalar basis data of a mesh with Lagrange elements of ``order`` 1 (P1/Q1) or 2 (P2, Q2):
    shape functions and gradients at the quadrature points, the scalar dofs (``nodes``, shape
    ``(nb, m)``: the mesh's nodes come first, with their numbers, then the edge, face and cell
    dofs of quadratic elements), where they sit (``points``) and ``interp``, the sparse
    ``(n_scalar, n_nodes)`` matrix of the linear (P1/Q1) interpolant at them (identity for
    order 1): prescribed nodal values are carried to every dof by it, and dof forces back to the
    nodes by its transpose (which keeps their sum)."""

    def __init__(self, mesh: Mesh, order: int = 1, intorder: int | None = None, quadrature=None, curved=()):
        import skfem

        if order not in ORDERS:
            raise ValueError(f"order must be 1 (linear elements) or 2 (quadratic elements), got {order!r}")
        check_cells(mesh)  # ValueError naming inverted or degenerate cells (else a singular matrix)
        self.mesh, self.order = mesh, order
        self.dim = mesh.dim
        element = element_of(mesh.cell_type, order)
        self.skmesh, elem1 = to_skfem(mesh)
        # ``curved``: pairs (boundary facets, project): the quadratic dofs of those facets moved onto
        # the surface by ``project`` (isoparametric elements, see curved_mesh)
        self.curved = check_curved(curved, mesh, order)
        if self.curved:
            self.skmesh = curved_mesh(self.skmesh, self.curved)
            if intorder is None and quadrature is None and mesh.cell_type in ("triangle", "tetra"):
                # on a curved simplex grad(phi) dx = adj(J) grad_ref(phi) dxi is of degree d: a rule of
                # that degree integrates a constant stress's forces exactly (the patch test)
                intorder = max(element.intorder, mesh.dim)
        self.elem = elem1 if order == 1 else getattr(skfem, element.element)()
        # ``quadrature``: an explicit rule ``(points (dim, q), weights (q,))`` on the reference cell
        # (scikit-fem takes at least 2 points per direction from ``intorder``); without one, the
        # element's own rule where it has one, else ``intorder`` (by default the element's)
        self.basis = (skfem.Basis(self.skmesh, self.elem, quadrature=quadrature) if quadrature is not None
                      else skfem.Basis(self.skmesh, self.elem, **_quadrature(element, intorder)))
        nb = self.basis.Nbfun
        nodal = np.asarray(self.basis.nodal_dofs).ravel()
        n_sk = nodal.size  # scikit-fem drops trailing unused nodes
        if n_sk > mesh.n_nodes or not np.array_equal(nodal, np.arange(n_sk)):
            raise RuntimeError("unexpected scikit-fem dof numbering: scalar dofs are not the node indices")
        gap = mesh.n_nodes - n_sk  # our numbering: every node first, then the higher-order dofs
        sk = np.asarray(self.basis.element_dofs)
        self.nodes = np.where(sk < n_sk, sk, sk + gap)  # (nb, m)
        self.n_scalar = int(self.basis.N) + gap
        self._sk_to_ours = np.concatenate([np.arange(n_sk), np.arange(n_sk, int(self.basis.N)) + gap])
        self.points = np.empty((self.n_scalar, self.dim))
        self.points[: mesh.n_nodes] = mesh.points
        self.points[self._sk_to_ours] = np.asarray(self.basis.doflocs).T
        self.phi = np.stack([np.asarray(self.basis.basis[a][0]) for a in range(nb)])  # (nb, m, q)
        self.dphi = np.stack([np.asarray(self.basis.basis[a][0].grad) for a in range(nb)])  # (nb, d, m, q)
        self.dx = np.asarray(self.basis.dx)  # (m, q), includes quadrature weights
        d = self.dim
        # interleaved global dofs of the local (node, component) pairs, shape (m, nb*d)
        self.edofs = (self.nodes.T[:, :, None] * d + np.arange(d)[None, None, :]).reshape(len(mesh.cells), nb * d)
        self.n_dofs = self.n_scalar * d
        if order == 1:
            self.interp = sp.identity(mesh.n_nodes, format="csr")
        else:  # the linear shape functions at the reference locations of the quadratic dofs
            local = np.stack([elem1.lbasis(self.elem.doflocs.T, a)[0] for a in range(len(mesh.cells[0]))], axis=1)
            vertices = np.asarray(self.skmesh.t)  # (nv, m) mesh nodes in scikit-fem's local order
            dofs, first = np.unique(self.nodes.ravel(), return_index=True)  # one cell per dof
            j, cell = np.unravel_index(first, self.nodes.shape)
            rows = np.repeat(dofs, local.shape[1])
            cols = vertices[:, cell].T.ravel()
            vals = local[j].ravel()
            keep = vals != 0.0
            self.interp = sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(self.n_scalar, mesh.n_nodes))

    def facet_ids(self, facets) -> np.ndarray:
        """scikit-fem's facet numbers of ``facets`` (node ids, ``(k, nodes per facet)``)."""
        return _facet_ids(self.skmesh, facets)

    def to_ours(self, v_sk: np.ndarray) -> np.ndarray:
        """A scalar vector in scikit-fem's dof numbering, in ours."""
        out = np.zeros(self.n_scalar)
        out[self._sk_to_ours] = v_sk
        return out

    def traction_load(self, facets, traction, thickness: float) -> np.ndarray:
        """Consistent dof loads ``(n_scalar, d)`` of a dead ``traction`` (Pa) on the boundary
        ``facets`` (``(k, nodes per facet)`` node indices), integrated with the element's own
        shape functions (2D: times ``thickness``)."""
        import skfem

        facets = np.asarray(facets, dtype=np.int64)
        index = {tuple(sorted(r)): i for i, r in enumerate(np.asarray(self.skmesh.facets).T.tolist())}
        try:
            ids = np.array([index[tuple(sorted(r))] for r in facets.tolist()], dtype=np.int64)
        except KeyError as exc:
            raise ValueError(f"a loaded facet of nodes {list(exc.args[0])} is no facet of the mesh") from None
        fb = skfem.FacetBasis(self.skmesh, self.elem, facets=ids, intorder=2 * self.order)

        @skfem.LinearForm
        def ones(v, _w):
            return v

        s = self.to_ours(ones.assemble(fb)) * (thickness if self.dim == 2 else 1.0)
        return s[:, None] * np.asarray(traction, dtype=float)[None, :]

    def assemble_matrix(self, ke: np.ndarray) -> sp.csr_matrix:
        """Assemble element matrices ``(m, nb*d, nb*d)`` into a sparse (interleaved) matrix."""
        m, k, _ = ke.shape
        rows = np.repeat(self.edofs, k, axis=1).ravel()
        cols = np.tile(self.edofs, (1, k)).ravel()
        return sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(self.n_dofs, self.n_dofs)).tocsr()

    def assemble_vector(self, fe: np.ndarray) -> np.ndarray:
        return np.bincount(self.edofs.ravel(), weights=fe.ravel(), minlength=self.n_dofs)

    def displacement_gradient(self, u_nodes: np.ndarray) -> np.ndarray:
        """``H = grad u = F - I`` at the quadrature points, shape ``(d, d, m, q)``."""
        ue = u_nodes[self.nodes]  # (nb, m, d)
        return np.einsum("ami,aJmq->iJmq", ue, self.dphi)

    def body_load(self, body_force, thickness: float) -> np.ndarray:
        """Consistent dof loads ``(n_scalar, d)`` of a body force per unit (reference) volume."""
        d, m = self.dim, len(self.mesh.cells)
        b = np.asarray(body_force, dtype=float)
        if b.shape == (d,):
            b = np.broadcast_to(b, (m, d))
        elif b.shape != (m, d):
            raise ValueError(f"body_force must have shape ({d},) or ({m}, {d}), got {b.shape}")
        w = thickness if d == 2 else 1.0
        fe = np.einsum("amq,mq,mi->mai", self.phi, self.dx, b) * w  # (m, nb, d)
        return self.assemble_vector(fe.reshape(m, -1)).reshape(-1, d)


#: the scikit-fem mesh of each linear one whose quadratic (mid-side, face and cell) nodes are its own
_QUADRATIC_MESH = {"MeshTri1": "MeshTri2", "MeshQuad1": "MeshQuad2", "MeshTet1": "MeshTet2", "MeshHex1": "MeshHex2"}


def _facet_ids(skmesh, facets) -> np.ndarray:
    index = {tuple(sorted(r)): i for i, r in enumerate(np.asarray(skmesh.facets).T.tolist())}
    try:
        return np.array([index[tuple(sorted(r))] for r in np.asarray(facets).tolist()], dtype=np.int64)
    except KeyError as exc:
        raise ValueError(f"a facet of nodes {list(exc.args[0])} is no facet of the mesh") from None


def check_curved(curved, mesh: Mesh, order: int) -> tuple:
    """``curved`` as a tuple of ``(facets (k, nf) int64, project)``; ValueError in one line for an
    entry that is no pair of boundary facets and a callable, or for linear elements (``order=1``:
    their facets are straight)."""
    from msslib.mesh import boundary_facets

    try:
        items = list(curved)
    except TypeError:
        raise ValueError(f"curved must be a sequence of (facets, project) pairs, got {type(curved).__name__}") from None
    if not items:
        return ()
    if order != 2:
        raise ValueError(f"curved: only quadratic elements (order=2) place nodes on a curved surface, got order={order!r}")
    boundary = {tuple(sorted(r)) for r in boundary_facets(mesh).tolist()}
    out = []
    for n, item in enumerate(items):
        if not isinstance(item, (tuple, list)) or len(item) != 2 or not callable(item[1]):
            got = (f"project of type {type(item[1]).__name__}" if isinstance(item, (tuple, list)) and len(item) == 2
                   else f"a {type(item).__name__}" + (f" of length {len(item)}" if isinstance(item, (tuple, list)) else ""))
            raise ValueError(f"curved[{n}] must be a pair (facets, project) with project a function of points "
                             f"(k, dim) -> (k, dim), got {got}")
        facets = np.asarray(item[0])
        if facets.ndim != 2 or facets.dtype.kind not in "iu" or facets.shape[0] == 0:
            raise ValueError(f"curved[{n}]: facets must be a non-empty array of node ids (k, nodes per facet), got "
                             f"shape {facets.shape} ({facets.dtype})")
        for r in facets.tolist():
            if tuple(sorted(r)) not in boundary:
                raise ValueError(f"curved[{n}]: facet of nodes {r} is not a boundary facet of the mesh; only boundary "
                                 "facets lie on a surface (msslib.mesh.boundary_facets)")
        out.append((facets.astype(np.int64), item[1]))
    return tuple(out)


def curved_mesh(skmesh, curved):
    """The quadratic scikit-fem mesh (``MeshTri2``, ``MeshQuad2``, ``MeshTet2``, ``MeshHex2``) of
    the linear ``skmesh`` with the quadratic nodes of each ``(facets, project)`` of ``curved``
    (their mid-side nodes and, on quadrilateral facets, the face centres) placed at
    ``project(points)`` (``(k, dim) -> (k, dim)``, e.g. the closest point of a circle or sphere);
    the mesh's own nodes stay where they are, every other quadratic node on its straight side.
    Elements on it are isoparametric: their sides follow the surface to ``O(h^3)`` instead of the
    ``O(h^2)`` of straight sides, which is what the quadratic element needs for its third order
    in L2 on a curved body."""
    import dataclasses

    import skfem

    quadratic = getattr(skfem, _QUADRATIC_MESH[type(skmesh).__name__])
    m2 = quadratic.from_mesh(skmesh)
    n_vertices = skmesh.p.shape[1]
    doflocs = np.array(m2.doflocs)
    for n, (facets, project) in enumerate(curved):
        dofs = np.unique(np.asarray(m2.dofs.get_facet_dofs(_facet_ids(m2, facets))).ravel())
        dofs = dofs[dofs >= n_vertices]
        moved = np.asarray(project(doflocs[:, dofs].T.copy()), dtype=float)
        if moved.shape != (dofs.size, m2.dim()) or not np.all(np.isfinite(moved)):
            raise ValueError(f"curved[{n}]: project must map points (k, {m2.dim()}) to finite points of the same shape, "
                             f"got shape {moved.shape}" + ("" if moved.shape != (dofs.size, m2.dim()) else
                                                           " with non-finite values"))
        doflocs[:, dofs] = moved.T
    return dataclasses.replace(m2, doflocs=doflocs)


def _linear_stiffness(geo: _Geometry, lam_c: np.ndarray, mu_c: np.ndarray) -> sp.csr_matrix:
    """Linear-elastic stiffness, vectorised over cells from the scalar basis gradients.

    ``Ke[(a,i),(b,k)] = lam G[a,i,b,k] + mu G[a,k,b,i] + mu delta_ik sum_J G[a,J,b,J]`` with
    ``G[a,J,b,L] = int dN_a/dX_J dN_b/dX_L`` (Lame constants are constant per cell). Several times
    faster than a Python form evaluated per pair of vector basis functions; the result equals
    :func:`_skfem_linear_stiffness` to round-off (checked in the tests).
    """
    G = np.einsum("aJmq,bLmq,mq->maJbL", geo.dphi, geo.dphi, geo.dx, optimize=True)
    m, nb, d = G.shape[0], G.shape[1], G.shape[2]
    lam = lam_c[:, None, None, None, None]
    mu = mu_c[:, None, None, None, None]
    trG = np.einsum("maJbJ->mab", G)
    ke = lam * G + mu * np.swapaxes(G, 2, 4)
    ke += mu * trG[:, :, None, :, None] * np.eye(d)[None, None, :, None, :]
    return geo.assemble_matrix(ke.reshape(m, nb * d, nb * d))


def _skfem_linear_stiffness(geo: _Geometry, lam_c: np.ndarray, mu_c: np.ndarray) -> sp.csr_matrix:
    """Linear-elastic stiffness assembled with scikit-fem (``ElementVector``), interleaved dofs."""
    import skfem
    from skfem.helpers import ddot, sym_grad, trace

    vb = skfem.Basis(geo.skmesh, skfem.ElementVector(geo.elem), **_quadrature(element_of(geo.mesh.cell_type), None))
    nq = vb.X.shape[-1]

    @skfem.BilinearForm
    def elasticity(u, v, w):
        eu, ev = sym_grad(u), sym_grad(v)
        return w.lam * trace(eu) * trace(ev) + 2.0 * w.mu * ddot(eu, ev)

    K = elasticity.assemble(
        vb,
        lam=np.repeat(lam_c[:, None], nq, axis=1),
        mu=np.repeat(mu_c[:, None], nq, axis=1),
    )
    nodal = np.asarray(vb.nodal_dofs)  # (d, n): skfem dof of (component, node)
    d, n = nodal.shape
    ours = np.empty(nodal.size, dtype=np.int64)  # skfem dof -> interleaved dof
    ours[nodal] = np.arange(n)[None, :] * d + np.arange(d)[:, None]
    K = K.tocoo()
    return sp.coo_matrix((K.data, (ours[K.row], ours[K.col])), shape=(geo.n_dofs, geo.n_dofs)).tocsr()


# --------------------------------------------------------------------------------------------
# boundary conditions and loads
# --------------------------------------------------------------------------------------------


def _boundary(mesh: Mesh, fixed, prescribed, nodal_forces, body_force, geo: _Geometry, thickness: float,
              tractions=()):
    """Constrained dofs, prescribed values and external forces on the dofs of ``geo``.

    ``fixed``, ``prescribed`` and ``nodal_forces`` are given at the mesh's nodes. With quadratic
    elements a higher-order dof is held in a component when it lies on a boundary facet all of
    whose nodes are held in it, at the linear interpolant of the nodes' prescribed values; nodal
    forces act at the nodes (point loads); body forces and ``tractions`` (pairs of boundary
    facets and traction vector) are integrated with the element's shape functions."""
    n, d = mesh.n_nodes, mesh.dim
    fixed = np.asarray(fixed, dtype=bool)
    if fixed.shape != (n, d):
        raise ValueError(f"fixed must have shape ({n}, {d}), got {fixed.shape}")
    presc = np.zeros((n, d)) if prescribed is None else np.asarray(prescribed, dtype=float)
    if presc.shape != (n, d):
        raise ValueError(f"prescribed must have shape ({n}, {d}), got {presc.shape}")
    presc = np.where(fixed, presc, 0.0)
    fn = np.zeros((n, d)) if nodal_forces is None else np.array(nodal_forces, dtype=float)
    if fn.shape != (n, d):
        raise ValueError(f"nodal_forces must have shape ({n}, {d}), got {fn.shape}")
    f = np.zeros((geo.n_scalar, d))
    f[:n] = fn
    if body_force is not None:
        f = f + geo.body_load(body_force, thickness)
    for facets, traction in tractions:
        f = f + geo.traction_load(facets, traction, thickness)
    # nodes used by no cell carry no stiffness: hold them at their prescribed value (0 by default)
    used = np.zeros(n, dtype=bool)
    used[mesh.cells.ravel()] = True
    constrained = np.zeros((geo.n_scalar, d), dtype=bool)
    constrained[:n] = fixed | ~used[:, None]
    if geo.order > 1:
        from msslib.mesh import boundary_facets

        bf = boundary_facets(mesh)
        index = {tuple(sorted(r)): i for i, r in enumerate(np.asarray(geo.skmesh.facets).T.tolist())}
        for i in range(d):
            held = bf[fixed[bf, i].all(axis=1)]
            if len(held):
                ids = np.array([index[tuple(sorted(r))] for r in held.tolist()], dtype=np.int64)
                sk = np.asarray(geo.basis.get_dofs(facets=ids).all()).ravel()
                constrained[geo._sk_to_ours[sk], i] = True
    presc_all = np.where(constrained, geo.interp @ presc, 0.0)
    return constrained.ravel(), presc_all.ravel(), f.ravel()

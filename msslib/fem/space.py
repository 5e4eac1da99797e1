"""scikit-fem conversion, the scalar element basis of a mesh, vectorised assembly, boundary
conditions and loads of the FEM references."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from msslib.mesh import Mesh, check_cells

#: column permutation taking a VTK hexahedron to scikit-fem's ``MeshHex1`` node order.
HEX_VTK_TO_SKFEM = np.array([0, 4, 3, 1, 7, 5, 2, 6])

# quadrature order per cell type: 1 point for P1 simplices, 2x2(x2) Gauss for Q1.
_INTORDER = {"triangle": 1, "tetra": 1, "quad": 2, "hexahedron": 2}


def to_skfem(mesh: Mesh):
    """Convert a :class:`Mesh` to ``(skfem_mesh, scalar_element)``.

    Node indices are kept (``skfem_mesh.p[:, a] == mesh.points[a]``); only the order of the
    nodes inside each cell changes where scikit-fem's numbering differs from VTK's.
    """
    import skfem

    p = np.ascontiguousarray(mesh.points.T)
    t = mesh.cells
    ct = mesh.cell_type
    if ct == "triangle":
        return skfem.MeshTri1(p, np.ascontiguousarray(t.T)), skfem.ElementTriP1()
    if ct == "quad":
        return skfem.MeshQuad1(p, np.ascontiguousarray(t.T)), skfem.ElementQuad1()
    if ct == "tetra":
        return skfem.MeshTet1(p, np.ascontiguousarray(t.T)), skfem.ElementTetP1()
    if ct == "hexahedron":
        return skfem.MeshHex1(p, np.ascontiguousarray(t[:, HEX_VTK_TO_SKFEM].T)), skfem.ElementHex1()
    raise ValueError(f"unsupported cell_type {ct!r}")


class _Geometry:
    """Scalar basis data of a mesh: shape functions and gradients at the quadrature points."""

    def __init__(self, mesh: Mesh):
        import skfem

        check_cells(mesh)  # ValueError naming inverted or degenerate cells (else a singular matrix)
        self.mesh = mesh
        self.dim = mesh.dim
        self.skmesh, self.elem = to_skfem(mesh)
        self.basis = skfem.Basis(self.skmesh, self.elem, intorder=_INTORDER[mesh.cell_type])
        nb = self.basis.Nbfun
        # global node of local basis function a in cell e (skfem's local order)
        self.nodes = np.asarray(self.basis.element_dofs)  # (nb, m); scalar P1/Q1 dofs == nodes
        n_sk = np.asarray(self.basis.nodal_dofs).size  # scikit-fem drops trailing unused nodes
        if n_sk > mesh.n_nodes or not np.array_equal(np.asarray(self.basis.nodal_dofs).ravel(), np.arange(n_sk)):
            raise RuntimeError("unexpected scikit-fem dof numbering: scalar dofs are not the node indices")
        self.phi = np.stack([np.asarray(self.basis.basis[a][0]) for a in range(nb)])  # (nb, m, q)
        self.dphi = np.stack([np.asarray(self.basis.basis[a][0].grad) for a in range(nb)])  # (nb, d, m, q)
        self.dx = np.asarray(self.basis.dx)  # (m, q), includes quadrature weights
        d = self.dim
        # interleaved global dofs of the local (node, component) pairs, shape (m, nb*d)
        self.edofs = (self.nodes.T[:, :, None] * d + np.arange(d)[None, None, :]).reshape(len(mesh.cells), nb * d)
        self.n_dofs = mesh.n_nodes * d

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
        """Consistent nodal loads ``(n_nodes, d)`` of a body force per unit (reference) volume."""
        d, m = self.dim, len(self.mesh.cells)
        b = np.asarray(body_force, dtype=float)
        if b.shape == (d,):
            b = np.broadcast_to(b, (m, d))
        elif b.shape != (m, d):
            raise ValueError(f"body_force must have shape ({d},) or ({m}, {d}), got {b.shape}")
        w = thickness if d == 2 else 1.0
        fe = np.einsum("amq,mq,mi->mai", self.phi, self.dx, b) * w  # (m, nb, d)
        return self.assemble_vector(fe.reshape(m, -1)).reshape(-1, d)


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

    vb = skfem.Basis(geo.skmesh, skfem.ElementVector(geo.elem), intorder=_INTORDER[geo.mesh.cell_type])
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


def _boundary(mesh: Mesh, fixed, prescribed, nodal_forces, body_force, geo: _Geometry, thickness: float):
    n, d = mesh.n_nodes, mesh.dim
    fixed = np.asarray(fixed, dtype=bool)
    if fixed.shape != (n, d):
        raise ValueError(f"fixed must have shape ({n}, {d}), got {fixed.shape}")
    presc = np.zeros((n, d)) if prescribed is None else np.asarray(prescribed, dtype=float)
    if presc.shape != (n, d):
        raise ValueError(f"prescribed must have shape ({n}, {d}), got {presc.shape}")
    presc = np.where(fixed, presc, 0.0)
    f = np.zeros((n, d)) if nodal_forces is None else np.array(nodal_forces, dtype=float)
    if f.shape != (n, d):
        raise ValueError(f"nodal_forces must have shape ({n}, {d}), got {f.shape}")
    if body_force is not None:
        f = f + geo.body_load(body_force, thickness)
    # nodes used by no cell carry no stiffness: hold them at their prescribed value (0 by default)
    used = np.zeros(n, dtype=bool)
    used[mesh.cells.ravel()] = True
    constrained = fixed | ~used[:, None]
    return constrained.ravel(), presc.ravel(), f.ravel()


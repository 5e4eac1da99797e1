"""FEM references (scikit-fem) on the same :class:`~msslib.mesh.Mesh` objects the mass-spring models use.

Public functions
----------------
* :func:`solve_linear` -- small-strain isotropic linear elasticity (2D plane stress/strain, 3D).
* :func:`solve_nonlinear` -- total-Lagrangian finite-strain reference (St Venant-Kirchhoff or
  compressible neo-Hookean), dead loads, Newton with load stepping and step halving.
* :func:`element_stiffness` -- numeric stiffness matrix of one element, dofs interleaved by node
  ``(n0_x, n0_y, [n0_z], n1_x, ...)`` in the VTK node order of the given coordinates.

Conventions
-----------
Displacements, forces and reactions are ``(n_nodes, dim)`` arrays. Internally the global dof of
node ``a``, component ``i`` is ``a * dim + i`` (interleaved by node).

Elements: triangle P1 (``ElementTriP1``), quad Q1 (``ElementQuad1``), tetra P1 (``ElementTetP1``),
hexahedron Q1 (``ElementHex1``). Quadrature: one point for simplices (exact for the constant
strains and for the linear load integrands), 2x2 / 2x2x2 Gauss for Q1.

Assembly: scikit-fem provides the meshes, reference mappings, quadrature and basis functions.
:func:`element_stiffness` and ``solve_linear(..., assembly="skfem")`` assemble with a scikit-fem
``BilinearForm`` on ``ElementVector``; the default ``assembly="fast"`` and the non-linear solver
build the element matrices with vectorised ``numpy.einsum`` from the scalar basis gradients (about
10x faster on large meshes; the two agree to round-off, see the tests). Linear systems are solved
with SuperLU (``scipy.sparse.linalg.spsolve``) after removing the constrained dofs.

Node orders (checked against the volumes of a unit square/box in the tests):

* triangle, tetra, quad: scikit-fem accepts the VTK order as is (``MeshTri`` sorts the node
  indices of each triangle, which does not change P1 results; ``MeshQuad1`` numbers its corners
  counter-clockwise 0-1-2-3 like VTK).
* hexahedron: ``MeshHex1`` numbers the corners of the unit cube
  (0,0,0), (0,0,1), (0,1,0), (1,0,0), (0,1,1), (1,0,1), (1,1,0), (1,1,1); the VTK order is
  (0,0,0), (1,0,0), (1,1,0), (0,1,0), (0,0,1), (1,0,1), (1,1,1), (0,1,1). Hence
  ``skfem_cells = vtk_cells[:, [0, 4, 3, 1, 7, 5, 2, 6]]`` (:data:`HEX_VTK_TO_SKFEM`).

2D finite strain: ``plane="strain"`` keeps ``F33 = 1``. ``plane="stress"`` is the exact plane
stress of the 3D law: at every quadrature point the out-of-plane stretch ``F33`` is solved from
``P33 = 0`` (closed form for St Venant-Kirchhoff, a local Newton iteration for neo-Hookean) and the
tangent is statically condensed. For St Venant-Kirchhoff this is identical to the 2D SVK law with
the plane-stress Lame constant ``lambda* = 2 lambda mu / (lambda + 2 mu)``. Integrals are taken
over the reference thickness (nominal quantities), so thickness changes are accounted for exactly.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .mesh import CELL_TYPES, Mesh, check_cells
from .models.fem import warn_locking

__all__ = [
    "FemResult",
    "HEX_VTK_TO_SKFEM",
    "element_stiffness",
    "lame",
    "solve_linear",
    "solve_nonlinear",
    "to_skfem",
]

#: column permutation taking a VTK hexahedron to scikit-fem's ``MeshHex1`` node order.
HEX_VTK_TO_SKFEM = np.array([0, 4, 3, 1, 7, 5, 2, 6])

# quadrature order per cell type: 1 point for P1 simplices, 2x2(x2) Gauss for Q1.
_INTORDER = {"triangle": 1, "tetra": 1, "quad": 2, "hexahedron": 2}


@dataclass(frozen=True)
class FemResult:
    """Result of an FEM solve.

    ``displacement`` and ``reaction`` are ``(n_nodes, dim)``; ``reaction`` is ``K u - f`` (linear) or
    ``f_int(u) - f_ext`` (non-linear) on the constrained dofs and zero elsewhere. ``strain_energy``
    in J (per unit thickness times ``thickness`` in 2D). ``stats`` holds at least ``n_dofs``,
    ``wall_time`` and ``solver``.
    """

    displacement: np.ndarray
    reaction: np.ndarray
    strain_energy: float
    stats: dict = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# materials
# --------------------------------------------------------------------------------------------


def lame(E, nu, plane: str | None = None):
    """Lame constants ``(lambda, mu)``; with ``plane="stress"`` the 2D plane-stress ``lambda*``."""
    E = np.asarray(E, dtype=float)
    nu = np.asarray(nu, dtype=float)
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    return lam, mu


def _per_material(value, name: str, n_mat: int) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(max(n_mat, 1), float(arr))
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1D sequence indexed by material, got shape {arr.shape}")
    if arr.size < n_mat:
        raise ValueError(f"{name} has {arr.size} values but the mesh uses material indices up to {n_mat - 1}")
    return arr


def _cell_materials(mesh: Mesh, E, nu) -> tuple[np.ndarray, np.ndarray]:
    """Validated per-cell ``(E, nu)`` arrays."""
    if mesh.material.size and mesh.material.min() < 0:
        raise ValueError("material indices must be non-negative")
    n_mat = int(mesh.material.max()) + 1 if mesh.material.size else 1
    E_m = _per_material(E, "E", n_mat)
    nu_m = _per_material(nu, "nu", n_mat)
    for k, e in enumerate(E_m):
        if not (np.isfinite(e) and e > 0):
            raise ValueError(f"Young's modulus E={float(e)!r} of material {k} must be > 0")
    for k, v in enumerate(nu_m):
        if not (np.isfinite(v) and -1.0 < v < 0.5):
            raise ValueError(f"Poisson's ratio nu={float(v)!r} of material {k} must satisfy -1 < nu < 0.5")
    return E_m[mesh.material], nu_m[mesh.material]


def _check_plane(plane: str, dim: int) -> None:
    if plane not in ("stress", "strain"):
        raise ValueError(f"plane must be 'stress' or 'strain', got {plane!r}")


# --------------------------------------------------------------------------------------------
# scikit-fem conversion and bases
# --------------------------------------------------------------------------------------------


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


_SOLVER = "scipy.sparse.linalg.spsolve (SuperLU, MMD_AT_PLUS_A ordering)"


def _solve_sparse(K: sp.spmatrix, rhs: np.ndarray) -> np.ndarray:
    """Direct sparse solve; the minimum-degree ordering on K + K^T suits the symmetric stiffness
    matrices here (about twice as fast as the default COLAMD on 3D meshes)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", spla.MatrixRankWarning)
        try:
            x = np.atleast_1d(spla.spsolve(K.tocsc(), rhs, permc_spec="MMD_AT_PLUS_A"))
        except (spla.MatrixRankWarning, RuntimeError) as exc:
            raise np.linalg.LinAlgError(f"singular stiffness matrix (are rigid-body modes constrained?): {exc}") from exc
    if not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError("singular stiffness matrix (are rigid-body modes constrained?)")
    return x


# --------------------------------------------------------------------------------------------
# linear elasticity
# --------------------------------------------------------------------------------------------


def solve_linear(
    mesh: Mesh,
    E,
    nu,
    *,
    fixed,
    prescribed=None,
    nodal_forces=None,
    body_force=None,
    thickness: float = 1.0,
    plane: str = "stress",
    assembly: str = "fast",
) -> FemResult:
    """Small-strain isotropic linear elasticity on ``mesh``.

    ``E``, ``nu``: scalars or sequences indexed by ``mesh.material``. ``fixed`` (n_nodes, dim) bool
    marks constrained dofs, ``prescribed`` their displacements (default 0). ``nodal_forces`` in N,
    ``body_force`` in N/m^3, shape ``(dim,)`` or ``(n_cells, dim)``. In 2D the stiffness and the body
    load are multiplied by ``thickness`` and ``plane`` selects plane stress (default) or strain.
    ``assembly="fast"`` (default) assembles the stiffness with vectorised element matrices built from
    scikit-fem's scalar basis; ``"skfem"`` uses a scikit-fem ``BilinearForm`` on ``ElementVector``
    (same matrix, several times slower on large meshes).
    """
    t0 = time.perf_counter()
    _check_plane(plane, mesh.dim)
    if thickness <= 0:
        raise ValueError(f"thickness={thickness!r} must be > 0")
    E_c, nu_c = _cell_materials(mesh, E, nu)
    warn_locking(mesh, nu_c, plane)
    lam_c, mu_c = lame(E_c, nu_c, plane if mesh.dim == 2 else None)
    geo = _Geometry(mesh)
    w = thickness if mesh.dim == 2 else 1.0
    if assembly == "fast":
        K = _linear_stiffness(geo, lam_c, mu_c) * w
    elif assembly == "skfem":
        K = _skfem_linear_stiffness(geo, lam_c, mu_c) * w
    else:
        raise ValueError(f"assembly must be 'fast' or 'skfem', got {assembly!r}")
    cons, presc, f = _boundary(mesh, fixed, prescribed, nodal_forces, body_force, geo, thickness)
    t1 = time.perf_counter()

    u = presc.copy()
    free = ~cons
    if free.any():
        Kff = K[free][:, free]
        rhs = f[free] - K[free][:, cons] @ presc[cons]
        u[free] = _solve_sparse(Kff, rhs)
    t2 = time.perf_counter()

    Ku = K @ u
    reaction = np.where(cons, Ku - f, 0.0)
    d = mesh.dim
    stats = {
        "n_dofs": int(u.size),
        "n_free_dofs": int(free.sum()),
        "assembly_time": t1 - t0,
        "solve_time": t2 - t1,
        "wall_time": time.perf_counter() - t0,
        "solver": _SOLVER,
        "assembly": assembly,
        "plane": plane if d == 2 else None,
    }
    return FemResult(
        displacement=u.reshape(-1, d),
        reaction=reaction.reshape(-1, d),
        strain_energy=float(0.5 * u @ Ku),
        stats=stats,
    )


def element_stiffness(cell_type: str, coords, E: float, nu: float, thickness: float = 1.0, plane: str = "stress") -> np.ndarray:
    """Stiffness matrix of a single element with node coordinates ``coords`` (VTK order).

    Dofs are interleaved by node: ``(node0_x, node0_y, [node0_z], node1_x, ...)``.
    """
    if cell_type not in CELL_TYPES:
        raise ValueError(f"unknown cell_type {cell_type!r}")
    dim, nv = CELL_TYPES[cell_type]
    coords = np.asarray(coords, dtype=float)
    if coords.shape != (nv, dim):
        raise ValueError(f"coords must have shape ({nv}, {dim}) for {cell_type}, got {coords.shape}")
    _check_plane(plane, dim)
    mesh = Mesh(coords, np.arange(nv)[None, :], cell_type)
    E_c, nu_c = _cell_materials(mesh, E, nu)
    lam_c, mu_c = lame(E_c, nu_c, plane if dim == 2 else None)
    geo = _Geometry(mesh)
    w = thickness if dim == 2 else 1.0
    return (_skfem_linear_stiffness(geo, lam_c, mu_c) * w).toarray()


# --------------------------------------------------------------------------------------------
# finite strain
# --------------------------------------------------------------------------------------------


def _det1m(H):
    """``det(I + H) - 1`` for ``(3, 3, ...)`` arrays without cancellation for small ``H``."""
    i1 = np.einsum("ii...->...", H)
    i2 = 0.5 * (i1**2 - np.einsum("ij...,ji...->...", H, H))
    i3 = np.linalg.det(np.moveaxis(H, (0, 1), (-2, -1)))
    return i1 + i2 + i3


def _law3d(H, lam, mu, law: str, tangent: bool = True):
    """Response to the displacement gradient ``H = F - I`` of shape ``(3, 3, ...)``.

    Returns the first Piola stress ``P`` (3,3,...), the tangent ``A = dP/dF`` (3,3,3,3,...) or
    ``None``, and the energy density ``W``. Strain measures are formed from ``H`` directly so that
    tiny deformations keep full relative precision (``F^T F - I`` would cancel).
    """
    ex = (1,) * (H.ndim - 2)
    I = np.eye(3).reshape((3, 3) + ex)
    F = H + I
    if law == "svk":
        Eg = 0.5 * (H + np.swapaxes(H, 0, 1) + np.einsum("kI...,kJ...->IJ...", H, H))
        trE = np.einsum("ii...->...", Eg)
        S = lam * trE * I + 2.0 * mu * Eg
        P = np.einsum("iK...,KJ...->iJ...", F, S)
        W = 0.5 * lam * trE**2 + mu * np.einsum("IJ...,IJ...->...", Eg, Eg)
        if not tangent:
            return P, None, W
        b = np.einsum("iK...,kK...->ik...", F, F)
        A = (
            np.einsum("ik,JL...->iJkL...", np.eye(3), S)
            + lam * np.einsum("iJ...,kL...->iJkL...", F, F)
            + mu * np.einsum("ik...,JL->iJkL...", b, np.eye(3))
            + mu * np.einsum("iL...,kJ...->iJkL...", F, F)
        )
        return P, A, W
    if law == "neohookean":
        Jm1 = _det1m(H)
        if np.any(~(Jm1 > -1.0)):
            raise FloatingPointError("non-positive Jacobian det F")
        lnJ = np.log1p(Jm1)
        Finv = np.moveaxis(np.linalg.inv(np.moveaxis(F, (0, 1), (-2, -1))), (-2, -1), (0, 1))
        FinvT = np.swapaxes(Finv, 0, 1)
        # F - F^-T = (F F^T - I) F^-T with F F^T - I = H + H^T + H H^T
        bm1 = H + np.swapaxes(H, 0, 1) + np.einsum("iK...,kK...->ik...", H, H)
        P = mu * np.einsum("ik...,kJ...->iJ...", bm1, FinvT) + lam * lnJ * FinvT
        trC_3 = 2.0 * np.einsum("ii...->...", H) + np.einsum("iJ...,iJ...->...", H, H)
        W = 0.5 * mu * trC_3 - mu * lnJ + 0.5 * lam * lnJ**2
        if not tangent:
            return P, None, W
        A = (
            mu * np.einsum("ik,JL->iJkL", np.eye(3), np.eye(3)).reshape((3, 3, 3, 3) + ex)
            + (mu - lam * lnJ) * np.einsum("Li...,Jk...->iJkL...", Finv, Finv)
            + lam * np.einsum("Ji...,Lk...->iJkL...", Finv, Finv)
        )
        return P, A, W
    raise ValueError(f"law must be 'svk' or 'neohookean', got {law!r}")


def _law(H, lam, mu, law: str, plane: str | None, tangent: bool = True):
    """Material response for ``H = F - I`` of shape ``(d, d, ...)``; 2D: plane strain or exact plane stress."""
    d = H.shape[0]
    if d == 3:
        return _law3d(H, lam, mu, law, tangent)
    H3 = np.zeros((3, 3) + H.shape[2:])
    H3[:2, :2] = H
    if plane == "stress":
        if law == "svk":
            # S33 = lam tr(E) + 2 mu E33 = 0 is linear in E33 = h33 + h33^2 / 2
            E2 = 0.5 * (H + np.swapaxes(H, 0, 1) + np.einsum("kI...,kJ...->IJ...", H, H))
            E33 = -lam * (E2[0, 0] + E2[1, 1]) / (lam + 2.0 * mu)
            if np.any(~(1.0 + 2.0 * E33 > 0)):
                raise FloatingPointError("plane-stress SVK: out-of-plane stretch not real")
            H3[2, 2] = 2.0 * E33 / (1.0 + np.sqrt(1.0 + 2.0 * E33))  # sqrt(1 + 2 E33) - 1
        else:
            h = np.zeros(H.shape[2:])
            for _ in range(60):
                H3[2, 2] = h
                P, A, _ = _law3d(H3, lam, mu, law, True)
                dh = -P[2, 2] / A[2, 2, 2, 2]
                h = h + dh
                if np.any(~(h > -1.0)):
                    raise FloatingPointError("plane-stress: out-of-plane stretch not positive")
                if np.max(np.abs(dh), initial=0.0) < 1e-15:
                    break
            H3[2, 2] = h
    P, A, W = _law3d(H3, lam, mu, law, tangent or plane == "stress")
    P2 = P[:2, :2]
    if not tangent:
        return P2, None, W
    A2 = A[:2, :2, :2, :2]
    if plane == "stress":
        A2 = A2 - np.einsum("ij...,kl...->ijkl...", A[:2, :2, 2, 2], A[2, 2, :2, :2]) / A[2, 2, 2, 2]
    return P2, A2, W


def solve_nonlinear(
    mesh: Mesh,
    E,
    nu,
    *,
    fixed,
    prescribed=None,
    nodal_forces=None,
    body_force=None,
    law: str = "svk",
    steps: int = 10,
    tol: float = 1e-8,
    max_iter: int = 30,
    thickness: float = 1.0,
    plane: str = "stress",
    progress: Callable[[int, int], None] | None = None,
    max_halvings: int = 8,
) -> FemResult:
    """Geometrically non-linear (total Lagrangian) reference solution with dead loads.

    ``law``: ``"svk"`` (St Venant-Kirchhoff, Green-Lagrange strain) or ``"neohookean"``
    (``W = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2``). Loads and prescribed displacements are
    applied in ``steps`` equal load-factor increments, solved by the Newton iteration of the
    mass-spring models (:func:`msslib.solvers.static_solve` through
    :mod:`msslib.solvers.displacement`; no line search, direct linear solves): converged when the
    residual force norm on the free dofs is at most ``max(tol * F_ref, floor)``
    (:func:`msslib.solvers.convergence_threshold`), ``F_ref`` the norm of the external load on the
    free dofs (for pure displacement control, of the linear reaction of the prescribed motion),
    ``floor`` the round-off floor :func:`msslib.solvers.roundoff_floor` of
    ``|| |K| |u| + sum_e |f_e| + |load| ||`` on the free dofs at the current iterate (the size of
    what the internal force sums: the displacement gradient differences nodal displacements,
    each element force sums stresses), so that a problem whose ``tol * F_ref`` lies below the
    round-off converges at the floor instead of iterating on it (an increment accepted there is
    listed in ``stats``). A failed increment (no convergence in ``max_iter`` iterations, or an
    inverted element) is halved, at most ``max_halvings`` times in a row and never below
    ``1 / (steps * 2**max_halvings)``; then :class:`msslib.errors.ConvergenceError` (a
    RuntimeError) names the step and the residual.
    2D: ``plane="stress"`` (default, as in :func:`solve_linear`; exact plane stress of the 3D law, see
    the module docstring) or ``"strain"`` (``F33 = 1``). ``progress(step, n_steps)`` is called after every converged nominal step.

    ``stats``: ``iterations`` (Newton iterations per converged increment), ``residuals`` (residual
    history per increment, relative to ``F_ref``; ``force_scale`` is ``F_ref``), ``load_factors`` (after each converged increment), ``n_halvings``,
    ``n_dofs``, ``wall_time``, ``solver``, ``tol``, ``roundoff_floor`` and ``threshold`` (of the
    last converged increment, absolute), ``roundoff_steps`` (increments accepted at the floor,
    1-based) and ``messages``.
    """
    from msslib.solvers.displacement import SOLVER, DisplacementProblem, solve_displacement

    t0 = time.perf_counter()
    d = mesh.dim
    if d == 2:
        _check_plane(plane, d)
    if law not in ("svk", "neohookean"):
        raise ValueError(f"law must be 'svk' or 'neohookean', got {law!r}")
    if steps < 1:
        raise ValueError(f"steps={steps!r} must be >= 1")
    if thickness <= 0:
        raise ValueError(f"thickness={thickness!r} must be > 0")
    E_c, nu_c = _cell_materials(mesh, E, nu)
    warn_locking(mesh, nu_c, plane)
    lam_c, mu_c = lame(E_c, nu_c)  # 3D constants; plane stress handled inside the law
    geo = _Geometry(mesh)
    w = thickness if d == 2 else 1.0
    cons, presc, f_ext = _boundary(mesh, fixed, prescribed, nodal_forces, body_force, geo, thickness)
    free = ~cons
    nq = geo.dx.shape[1]
    lam_q = np.repeat(lam_c[:, None], nq, axis=1)
    mu_q = np.repeat(mu_c[:, None], nq, axis=1)
    pl = plane if d == 2 else None
    m, nb = geo.dphi.shape[2], geo.dphi.shape[0]

    def internal(u, tangent=True):
        H = geo.displacement_gradient(u.reshape(-1, d))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # divergence is detected by the caller
            P, A, W = _law(H, lam_q, mu_q, law, pl, tangent)
        fe = np.einsum("iJmq,aJmq,mq->mai", P, geo.dphi, geo.dx).reshape(m, nb * d) * w
        fint = geo.assemble_vector(fe)
        energy = float(np.sum(W * geo.dx) * w)
        if not tangent:
            return fint, None, energy, None
        fabs = geo.assemble_vector(np.abs(fe))  # the size of what fint sums: its round-off scale
        ke = np.einsum("aJmq,iJkLmq,bLmq,mq->maibk", geo.dphi, A, geo.dphi, geo.dx, optimize=True)
        K = geo.assemble_matrix(ke.reshape(m, nb * d, nb * d) * w)
        return fint, K, energy, fabs

    problem = DisplacementProblem(internal, f_ext, cons, presc)
    u, newton = solve_displacement(problem, steps=steps, tol=tol, max_iter=max_iter, max_halvings=max_halvings,
                                   progress=progress)
    fint, _, energy, _ = internal(u, tangent=False)
    r = fint - f_ext
    reaction = np.where(cons, r, 0.0)
    stats = {"n_dofs": int(u.size), "n_free_dofs": int(free.sum()), **newton, "law": law, "plane": pl,
             "wall_time": time.perf_counter() - t0, "solver": SOLVER}
    return FemResult(displacement=u.reshape(-1, d), reaction=reaction.reshape(-1, d), strain_energy=energy, stats=stats)

"""Higher-order FEM reference solutions of a prepared scene (scikit-fem quadratic elements).

:func:`solve` takes a :class:`msslib.scene.Setup` (mesh, fixed dofs, loads built by
:func:`msslib.scene.prepare`) and solves small-strain linear elasticity (``law=None``) or the
total-Lagrangian St Venant-Kirchhoff / neo-Hookean problem (``law="svk"`` / ``"neohookean"``, the
material laws of :mod:`msslib.fem`, 2D exact plane stress) with Lagrange elements of ``order`` 1
(``P1``/``Q1``, as :mod:`msslib.fem`) or 2 (``ElementTriP2``, ``ElementTetP2``, ``ElementQuad2``,
``ElementHex2``). The displacement of the mesh's nodes (the vertex dofs) is returned, so a solution
on a nested fine mesh is read at the nodes of every coarser mesh without interpolation.

Loads are integrated with the element's own shape functions: gravity over the cells, a traction
over the loaded boundary facets (those whose nodes are all selected, as the scene does) with a
scikit-fem ``FacetBasis``. Fixed dofs are the dofs whose location matches the scene's
``boundary`` selections (``plane`` and ``box``; prescribed displacements must be zero). Newton's
method runs over the scene's load steps to a relative residual of ``tol`` with SuperLU solves.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from msslib.fem import _law, _solve_sparse, lame, to_skfem

_ORDER2 = {"triangle": "ElementTriP2", "tetra": "ElementTetP2", "quad": "ElementQuad2", "hexahedron": "ElementHex2"}
_INTORDER = {(1, "triangle"): 1, (1, "tetra"): 1, (1, "quad"): 2, (1, "hexahedron"): 2,
             (2, "triangle"): 2, (2, "tetra"): 2, (2, "quad"): 4, (2, "hexahedron"): 4}
AXES = {"x": 0, "y": 1, "z": 2}


DIRECT_MAX = 6000  # free dofs up to which SuperLU is used; above, CG preconditioned by smoothed aggregation


def _rigid_modes(x: np.ndarray) -> np.ndarray:
    """Rigid-body modes (n d, 3 or 6) of points ``x`` (n, d), interleaved dofs, for the AMG hierarchy."""
    n, d = x.shape
    c = x - x.mean(axis=0)
    modes = [np.kron(np.ones(n), np.eye(d)[i]) for i in range(d)]
    for i, j in ((0, 1),) if d == 2 else ((0, 1), (1, 2), (2, 0)):
        r = np.zeros((n, d))
        r[:, i], r[:, j] = -c[:, j], c[:, i]
        modes.append(r.ravel())
    return np.column_stack(modes)


def linear_solve(K, rhs, points, tol: float = 1e-13):
    """``K^-1 rhs``: SuperLU for small systems, else pyamg smoothed aggregation (rigid-body near-null
    space) as a CG preconditioner to a relative residual of ``tol``."""
    if K.shape[0] <= DIRECT_MAX or points is None:
        return _solve_sparse(K, rhs)
    import pyamg
    import scipy.sparse.linalg as spla

    K = K.tocsr()
    ml = pyamg.smoothed_aggregation_solver(K, B=_rigid_modes(points), symmetry="symmetric")
    x, info = spla.cg(K, rhs, M=ml.aspreconditioner(cycle="V"), rtol=tol, atol=0.0, maxiter=2000)
    if info != 0 or not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError(f"AMG-preconditioned CG did not converge (info {info})")
    return x


class Space:
    """Scalar Lagrange basis of ``order`` on a mesh, with interleaved vector dofs (dof ``a d + i``)."""

    def __init__(self, mesh, order: int):
        import skfem

        if order not in (1, 2):
            raise ValueError(f"order must be 1 or 2, got {order!r}")
        self.mesh, self.order, self.dim = mesh, order, mesh.dim
        self.skmesh, elem = to_skfem(mesh)
        if order == 2:
            elem = getattr(skfem, _ORDER2[mesh.cell_type])()
        self.elem = elem
        self.basis = skfem.Basis(self.skmesh, elem, intorder=_INTORDER[order, mesh.cell_type])
        nodal = np.asarray(self.basis.nodal_dofs).ravel()
        if not np.array_equal(nodal, np.arange(mesh.n_nodes)):
            raise RuntimeError("unexpected scikit-fem numbering: the vertex dofs are not the node indices")
        self.n_scalar = int(self.basis.N)
        self.x = np.asarray(self.basis.doflocs).T  # (n_scalar, d): where each scalar dof sits
        self.nodes = np.asarray(self.basis.element_dofs)  # (nb, m)
        nb = self.nodes.shape[0]
        self.phi = np.stack([np.asarray(self.basis.basis[a][0]) for a in range(nb)])  # (nb, m, q)
        self.dphi = np.stack([np.asarray(self.basis.basis[a][0].grad) for a in range(nb)])  # (nb, d, m, q)
        self.dx = np.asarray(self.basis.dx)
        d = self.dim
        self.edofs = (self.nodes.T[:, :, None] * d + np.arange(d)).reshape(self.nodes.shape[1], nb * d)
        self.n_dofs = self.n_scalar * d

    def matrix(self, ke):
        k = ke.shape[1]
        rows = np.repeat(self.edofs, k, axis=1).ravel()
        cols = np.tile(self.edofs, (1, k)).ravel()
        return sp.coo_matrix((ke.ravel(), (rows, cols)), shape=(self.n_dofs, self.n_dofs)).tocsr()

    def vector(self, fe):
        return np.bincount(self.edofs.ravel(), weights=fe.ravel(), minlength=self.n_dofs)


def _select(x, sel, tol):
    """Points of ``x`` matched by a scene selection with ``plane`` and/or ``box``."""
    unknown = set(sel) - {"plane", "box", "tol"}
    if unknown:
        raise ValueError(f"the reference understands plane and box selections, not {sorted(unknown)}")
    tol = sel.get("tol") or tol
    keep = np.ones(len(x), dtype=bool)
    if sel.get("box") is not None:
        for bounds, sign in zip(sel["box"], (1.0, -1.0)):
            for i, b in enumerate(bounds or ()):
                if b is not None:
                    keep &= sign * (x[:, i] - b) >= -tol
    if sel.get("plane") is not None:
        axis, value = sel["plane"]
        keep &= np.abs(x[:, AXES[axis] if isinstance(axis, str) else int(axis)] - value) <= tol
    return keep


def _constraints(space, setup, tol):
    d = space.dim
    fixed = np.zeros((space.n_scalar, d), dtype=bool)
    for b in setup.scene.boundary:
        if b["displacement"] is not None and any(v not in (None, 0.0) for v in b["displacement"]):
            raise ValueError("the reference supports zero prescribed displacements only")
        axes = range(d) if b["fix"] is None else [AXES[a] for a in b["fix"]]
        on = _select(space.x, b["select"], tol)
        for a in axes:
            fixed[on, a] = True
    if not np.array_equal(fixed[: setup.mesh.n_nodes], setup.fixed):
        raise ValueError("the reference's fixed nodes differ from the scene's (a selection it reads differently)")
    return fixed.ravel()


def _loads(space, setup, tol):
    import skfem

    from msslib.mesh import boundary_facets

    d, mesh = space.dim, setup.mesh
    w = setup.thickness if d == 2 else 1.0
    f = np.zeros(space.n_dofs)
    if setup.gravity is not None:
        b = setup.cell_density[:, None] * setup.gravity[None, :]  # (m, d) N/m^3
        fe = np.einsum("amq,mq,mi->mai", space.phi, space.dx, b) * w
        f += space.vector(fe.reshape(len(mesh.cells), -1))
    facets = None
    for load in setup.scene.loads:
        if load["type"] == "gravity":
            continue
        if load["type"] != "traction":
            raise ValueError(f"the reference supports gravity and traction loads, not {load['type']}")
        if facets is None:
            bf = boundary_facets(mesh)
            index = {tuple(sorted(r)): i for i, r in enumerate(space.skmesh.facets.T.tolist())}
        on = _select(mesh.points, load["select"], tol)
        loaded = bf[on[bf].all(axis=1)]
        ids = np.array([index[tuple(sorted(r))] for r in loaded.tolist()])
        fb = skfem.FacetBasis(space.skmesh, space.elem, facets=ids, intorder=2 * space.order)

        @skfem.LinearForm
        def ones(v, _w):
            return v

        s = ones.assemble(fb) * w  # integral of each scalar basis function over the loaded facets
        t = np.asarray(load["traction"], dtype=float)
        f += (s[:, None] * t[None, :]).ravel()
    return f


def at_points(info, points, rtol: float = 1e-9):
    """The dof values of a solution at ``points`` that coincide with its dofs (KeyError-like
    ValueError if one does not): the nodes of the once-refined mesh for quadratic elements."""
    from scipy.spatial import cKDTree

    x = info["x_dofs"]
    dist, idx = cKDTree(x).query(points)
    size = float(np.linalg.norm(np.ptp(x, axis=0)))
    if dist.max(initial=0.0) > rtol * size:
        raise ValueError(f"a point is no dof location (nearest dof {dist.max():.3g} m away)")
    return info["u_dofs"][idx]


def solve(setup, *, order: int = 2, law: str | None = None, steps: int | None = None, tol: float = 1e-10,
          max_iter: int = 30):
    """Solve the prepared scene; returns ``(u_nodes (n_nodes, d), info)`` with ``info`` holding
    ``n_dofs``, ``wall_time``, ``iterations`` (Newton iterations per load step), ``order`` and the
    displacement ``u_dofs`` at every scalar dof, located at ``x_dofs`` (for quadratic elements the
    vertices, edge midpoints and, for ``ElementQuad2``/``ElementHex2``, face and cell centres:
    exactly the nodes of the mesh refined once, :func:`at_points`)."""
    t0 = time.perf_counter()
    mesh, scene = setup.mesh, setup.scene
    space = Space(mesh, order)
    d = space.dim
    size = float(np.linalg.norm(np.ptp(mesh.points, axis=0)))
    stol = max(1e-8 * size, 1e-15)  # the scene's default selection tolerance
    cons = _constraints(space, setup, stol)
    free = ~cons
    f_ext = _loads(space, setup, stol)
    node_free = free.reshape(-1, d)
    # the points of the free nodes, for the AMG near-null space (partly fixed nodes: direct solver)
    xf = space.x[node_free.all(axis=1)] if np.array_equal(node_free.all(axis=1), node_free.any(axis=1)) else None
    E = np.array([m.E for m in scene.materials])[mesh.material]
    nu = np.array([m.nu for m in scene.materials])[mesh.material]
    w = setup.thickness if d == 2 else 1.0
    plane = scene.model_options.get("plane", "stress") if d == 2 else None
    m, nb = len(mesh.cells), space.nodes.shape[0]
    nq = space.dx.shape[1]
    u = np.zeros(space.n_dofs)
    iterations = []
    if law is None:
        lam, mu = lame(E, nu, plane)
        G = np.einsum("aJmq,bLmq,mq->maJbL", space.dphi, space.dphi, space.dx, optimize=True)
        trG = np.einsum("maJbJ->mab", G)
        ke = lam[:, None, None, None, None] * G + mu[:, None, None, None, None] * np.swapaxes(G, 2, 4)
        ke += mu[:, None, None, None, None] * trG[:, :, None, :, None] * np.eye(d)[None, None, :, None, :]
        K = space.matrix(ke.reshape(m, nb * d, nb * d) * w)
        u[free] = linear_solve(K[free][:, free], f_ext[free], xf)
    else:
        lam, mu = lame(E, nu)
        lam_q, mu_q = np.repeat(lam[:, None], nq, axis=1), np.repeat(mu[:, None], nq, axis=1)
        n_steps = steps or scene.solver.get("load_steps", 1)
        for k in range(1, n_steps + 1):
            target = k / n_steps * f_ext
            ref = max(np.linalg.norm(target[free]), np.finfo(float).tiny)
            for it in range(max_iter + 1):
                H = np.einsum("ami,aJmq->iJmq", u.reshape(-1, d)[space.nodes], space.dphi)
                P, A, _ = _law(H, lam_q, mu_q, law, plane, True)
                fe = np.einsum("iJmq,aJmq,mq->mai", P, space.dphi, space.dx).reshape(m, nb * d) * w
                r = space.vector(fe) - target
                if np.linalg.norm(r[free]) <= tol * ref:
                    break
                if it == max_iter:
                    raise RuntimeError(f"reference Newton did not converge in load step {k} of {n_steps}: "
                                       f"relative residual {np.linalg.norm(r[free]) / ref:.2e}")
                ke = np.einsum("aJmq,iJkLmq,bLmq,mq->maibk", space.dphi, A, space.dphi, space.dx, optimize=True)
                K = space.matrix(ke.reshape(m, nb * d, nb * d) * w)
                u[free] -= linear_solve(K[free][:, free], r[free], xf)
            iterations.append(it)
    info = {"n_dofs": int(space.n_dofs), "wall_time": time.perf_counter() - t0, "iterations": iterations,
            "order": order, "law": law or "linear", "u_dofs": u.reshape(-1, d).copy(), "x_dofs": space.x.copy()}
    return u.reshape(-1, d)[: mesh.n_nodes].copy(), info

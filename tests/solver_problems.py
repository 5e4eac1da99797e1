"""Small self-contained problems for the solver tests (the problem protocol of msslib.solvers)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

# ---------------------------------------------------------------------------------------------
# toy problems
# ---------------------------------------------------------------------------------------------


class SpringNetwork:
    """Springs with energy k/2 s^2 + k3/4 s^4, s = |x_j - x_i| - L, plus a constant external force."""

    def __init__(self, points, edges, k, rest=None, k3=0.0, fixed_nodes=(), f_ext=None, mass=1.0,
                 damping=None):
        points = np.asarray(points, dtype=float)
        if points.ndim == 1:
            points = points[:, None]
        self.n_nodes, self.dim = points.shape
        self.n_dof = points.size
        self.points = points
        self.edges = np.asarray(edges, dtype=np.int64)
        d = points[self.edges[:, 1]] - points[self.edges[:, 0]]
        self.rest = np.linalg.norm(d, axis=1) if rest is None else np.broadcast_to(np.asarray(rest, float), len(self.edges)).copy()
        self.k = float(k)
        self.k3 = float(k3)
        self.free = np.ones(self.n_dof, dtype=bool)
        for node in fixed_nodes:
            self.free[self.dim * node:self.dim * node + self.dim] = False
        self.f_ext = np.zeros(self.n_dof) if f_ext is None else np.asarray(f_ext, dtype=float)
        self.mass = np.full(self.n_dof, float(mass))
        if damping is not None:
            self.damping = damping

    def _geometry(self, x):
        p = x.reshape(-1, self.dim)
        d = p[self.edges[:, 1]] - p[self.edges[:, 0]]
        length = np.linalg.norm(d, axis=1)
        return d, length, length - self.rest

    def energy(self, x, load=1.0):
        _, _, s = self._geometry(x)
        return float(np.sum(0.5 * self.k * s**2 + 0.25 * self.k3 * s**4) - load * self.f_ext @ x)

    def force(self, x, load=1.0):
        d, length, s = self._geometry(x)
        tension = self.k * s + self.k3 * s**3
        fe = (tension / length)[:, None] * d  # force pulling node j back towards i
        f = np.zeros((self.n_nodes, self.dim))
        np.add.at(f, self.edges[:, 0], fe)
        np.add.at(f, self.edges[:, 1], -fe)
        return f.reshape(-1) + load * self.f_ext

    def stiffness(self, x, load=1.0):
        d, length, s = self._geometry(x)
        dim = self.dim
        n = d / length[:, None]
        tension = self.k * s + self.k3 * s**3
        dtension = self.k + 3 * self.k3 * s**2
        nn = n[:, :, None] * n[:, None, :]
        ke = dtension[:, None, None] * nn + (tension / length)[:, None, None] * (np.eye(dim) - nn)
        rows, cols, vals = [], [], []
        a, b = np.meshgrid(np.arange(dim), np.arange(dim), indexing="ij")
        for p, q, sign in ((0, 0, 1.0), (1, 1, 1.0), (0, 1, -1.0), (1, 0, -1.0)):
            rows.append((dim * self.edges[:, p])[:, None, None] + a)
            cols.append((dim * self.edges[:, q])[:, None, None] + b)
            vals.append(sign * ke)
        rows, cols, vals = (np.concatenate([r.reshape(-1) for r in arr]) for arr in (rows, cols, vals))
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_dof, self.n_dof))

    def x0(self):
        return self.points.reshape(-1).copy()


def chain(n_springs, dim, *, k=1.0, k3=0.0, rest=1.0, end_force=0.0, zigzag=0.0, prestretch=1.0, **kw):
    """Chain of springs along x, node 0 fixed, force ``end_force`` along +x on the last node."""
    pts = np.zeros((n_springs + 1, dim))
    pts[:, 0] = np.arange(n_springs + 1) * rest * prestretch
    if dim > 1:
        pts[1::2, 1] = zigzag * rest
    edges = np.column_stack([np.arange(n_springs), np.arange(1, n_springs + 1)])
    f = np.zeros(pts.size)
    f[dim * n_springs] = end_force
    return SpringNetwork(pts, edges, k, rest=rest, k3=k3, fixed_nodes=(0,), f_ext=f, **kw)


class LinearProblem:
    """force = load * f - K (x - x_ref), a fixed SPD K."""

    def __init__(self, K, f, x_ref):
        self.K = sp.csr_matrix(K)
        self.f = np.asarray(f, float)
        self.x_ref = np.asarray(x_ref, float)
        self.n_dof = len(f)
        self.free = np.ones(self.n_dof, bool)
        self.mass = np.ones(self.n_dof)

    def force(self, x, load=1.0):
        return load * self.f - self.K @ (x - self.x_ref)

    def stiffness(self, x, load=1.0):
        return self.K

    def energy(self, x, load=1.0):
        u = x - self.x_ref
        return 0.5 * u @ (self.K @ u) - load * self.f @ x


class Circulatory:
    """Non-conservative: f(u) = load*P - k*(atan(u - a) - atan(-a)) - load*c*J u, J = 90-degree rotation.

    The circulatory term load*c*J u has no potential, so there is no energy and the stiffness is
    non-symmetric. With a shift ``a`` the atan springs are soft at u = 0 and stiff near u = a, which
    throws a plain Newton iteration started at 0 far away (the classic atan divergence)."""

    symmetric = False
    n_dof = 2
    free = np.ones(2, bool)
    mass = np.ones(2)
    J = np.array([[0.0, -1.0], [1.0, 0.0]])

    def __init__(self, P, k=1.0, c=0.5, a=0.0):
        self.P, self.k, self.c, self.a = np.asarray(P, float), k, c, a

    def force(self, x, load=1.0):
        return load * self.P - self.k * (np.arctan(x - self.a) - np.arctan(-self.a)) - load * self.c * self.J @ x

    def stiffness(self, x, load=1.0):
        return sp.csr_matrix(np.diag(self.k / (1 + (x - self.a) ** 2)) + load * self.c * self.J)

    def energy(self, x, load=1.0):
        return None


def hardening_stretch(k, k3, force):
    roots = np.roots([k3, 0.0, k, -force]) if k3 else np.array([force / k])
    return float(np.real(roots[np.argmin(np.abs(roots.imag))]))


def lattice_system(n=8):
    """The free-dof block matrix of a clamped Golec lattice of n^3 cubes at a perturbed state, its
    rigid-body modes and the solver context (the AMG and speed-path tests' system)."""
    from msslib import mesh as M
    from msslib.system import Model
    from msslib.models.golec import golec_cube_springs
    from msslib.solvers.amg import _rigid_body_modes
    from msslib.solvers.context import linear_solve_context
    from msslib.solvers.submatrices import _submatrix_bsr

    mesh = M.hex_grid(0.01 * n, 0.01 * n, 0.01 * n, n, n, n)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    model = Model(mesh, golec_cube_springs(mesh, [(1e4, 0.3)], 1.0), fixed=fixed)
    x = model.x0 + 2e-4 * np.random.default_rng(7).standard_normal(model.n_dof)
    ctx = linear_solve_context(model, x, model.free)
    A = _submatrix_bsr(model.stiffness(x), ctx["node_free"], 3)
    A.sort_indices()
    return A, _rigid_body_modes(ctx["coords"], 3), ctx

"""Set-up of the smoothed-aggregation AMG preconditioner (pyamg, with a compiled finest level)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .amg_cycle import _BlockGaussSeidel, _compiled_smoothers, _matvec_of, _VCycle  # noqa: F401
from .amg_kernels import (
    _block_diag,
    _block_diag_inverse,
    _block_rows_times,
    _galerkin_numeric,
    _mirror_lower,
    _smoothed_prolongator,
)


def _rigid_body_modes(coords, dim):
    """Near-null space of elasticity on free nodes: ``dim`` translations and the rotations about
    the centroid, ``(n_nodes * dim, 3 | 6)``, dofs interleaved by node."""
    c = coords - coords.mean(axis=0)
    nn = len(c)
    if dim == 2:
        B = np.zeros((2 * nn, 3))
        B[0::2, 0] = B[1::2, 1] = 1.0
        B[0::2, 2], B[1::2, 2] = -c[:, 1], c[:, 0]
        return B
    B = np.zeros((3 * nn, 6))
    B[0::3, 0] = B[1::3, 1] = B[2::3, 2] = 1.0
    B[1::3, 3], B[2::3, 3] = -c[:, 2], c[:, 1]
    B[0::3, 4], B[2::3, 4] = c[:, 2], -c[:, 0]
    B[0::3, 5], B[1::3, 5] = -c[:, 1], c[:, 0]
    scale = np.abs(B[:, dim:]).max()
    if scale > 0:
        B[:, dim:] /= scale
    return B


_SA_SMOOTHERS = (("block_gauss_seidel", {"sweep": "forward", "iterations": 1}),
                 ("block_gauss_seidel", {"sweep": "backward", "iterations": 1}))
_SA_OPTIONS = dict(strength=("symmetric", {"theta": 0.0}),
                   smooth=("jacobi", {"omega": 4.0 / 3.0, "weighting": "block"}), improve_candidates=None,
                   max_coarse=500, coarse_solver="splu", presmoother=_SA_SMOOTHERS[0],
                   postsmoother=_SA_SMOOTHERS[1])


def _block_jacobi_radius(A, dinv, steps: int = 15, seed: int = 0) -> float:
    """Largest eigenvalue of ``D^-1 A`` (``D`` the block diagonal of the SPD ``A``) by Lanczos
    in the ``D`` inner product, where ``D^-1 A`` is self-adjoint: the largest Ritz value after
    ``steps`` matrix-vector products (a slight underestimate, as pyamg's Arnoldi estimate)."""
    n = A.shape[0]
    v = np.random.default_rng(seed).standard_normal(n)
    dblocks = _block_diag(A.indptr, A.indices, A.data)  # D itself, for the D inner product
    matvec = _matvec_of(A)

    def dmul(w):
        return _block_rows_times(dblocks, w)

    v /= np.sqrt(v @ dmul(v))
    v_prev = np.zeros(n)
    beta = 0.0
    alphas, betas = [], []
    for _ in range(min(steps, n)):
        u = matvec(v)
        alpha = float(v @ u)
        w = _block_rows_times(dinv, u) - alpha * v - beta * v_prev
        beta = float(np.sqrt(max(w @ dmul(w), 0.0)))
        alphas.append(alpha)
        if beta <= 1e-12 * abs(alpha):
            break
        betas.append(beta)
        v_prev, v = v, w / beta
    k = len(alphas)
    Tk = np.diag(alphas) + np.diag(betas[:k - 1], 1) + np.diag(betas[:k - 1], -1)
    return float(np.linalg.eigvalsh(Tk)[-1])


def _galerkin(A, P):
    """Coarse matrix ``P^T A P`` (BSR, blocks ``(m, m)``) of a symmetric BSR ``A`` (square
    blocks, sorted indices) and a BSR prolongator ``P`` (blocks ``(d, m)``).  The block
    pattern comes from products of the block patterns (cheap: one scalar per block); the values
    from :func:`_galerkin_numeric`, which computes the upper block triangle only (the product
    is symmetric) without forming ``A P`` (several times larger than ``A``: 290 MB at 3e5 dofs
    with scipy's product), 3x faster than scipy's block products at 1e5 dofs."""
    nb = A.indptr.shape[0] - 1
    d, m = P.blocksize
    nc = P.shape[1] // m
    A.sort_indices()
    Ab = sp.csr_matrix((np.ones(A.indices.shape[0]), A.indices, A.indptr), shape=(nb, nb))
    Pb = sp.csr_matrix((np.ones(P.indices.shape[0]), P.indices, P.indptr), shape=(nb, nc))
    Cb = (Pb.T.tocsr() @ (Ab @ Pb)).tocsr()
    Cb.sort_indices()
    data = np.zeros((Cb.indices.shape[0], m, m))
    _galerkin_numeric(A.indptr, A.indices, A.data, P.indptr, P.indices, P.data, Cb.indptr, Cb.indices, data)
    _mirror_lower(Cb.indptr, Cb.indices, data)
    A_c = sp.bsr_matrix((data, Cb.indices, Cb.indptr), shape=(nc * m, nc * m), copy=False)
    A_c.has_sorted_indices = True
    return A_c


def _sa_solver(A, B, dim):
    """pyamg smoothed aggregation on the BSR ``A`` (``dim x dim`` blocks) with near-null space
    ``B``, as ``pyamg.smoothed_aggregation_solver(A, B, **_SA_OPTIONS)`` builds it, except that
    the finest level (by far the largest) is built here with less memory and time: the
    prolongator ``P = T - (omega / rho) D^-1 A T`` is formed block row by block row in one
    compiled pass (:func:`_smoothed_prolongator`; pyamg forms ``D^-1 A`` and its scaled copy,
    two more matrices of the size of ``A``, and ``A T`` with scipy's block product), ``rho``
    comes from Lanczos in the ``D`` inner product (15 products with ``A``, instead of Arnoldi on
    ``D^-1 A``), and the coarse matrix from the compiled :func:`_galerkin`.  Coarser levels are
    pyamg's.  Returns None when ``A`` does not fit (pyamg is then
    used as is)."""
    import pyamg
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers
    from pyamg.strength import symmetric_strength_of_connection

    if A.shape[0] // dim <= _SA_OPTIONS["max_coarse"]:
        return None
    C = symmetric_strength_of_connection(A, theta=_SA_OPTIONS["strength"][1]["theta"])
    AggOp, _ = standard_aggregation(C)
    T, B_c = fit_candidates(AggOp, B)
    T = T.tobsr(blocksize=(dim, B.shape[1]))
    try:
        dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    except np.linalg.LinAlgError:  # a singular diagonal block
        return None
    if not np.all(np.isfinite(dinv)):
        return None
    rho = _block_jacobi_radius(A, dinv)
    if not (np.isfinite(rho) and rho > 0):
        return None
    omega = _SA_OPTIONS["smooth"][1]["omega"]
    m, nc = B.shape[1], T.shape[1] // B.shape[1]
    p_ptr = np.empty(A.indptr.shape[0], dtype=np.int64)
    args = (A.indptr, A.indices, A.data, dinv, T.indptr, T.indices, T.data, -omega / rho, nc, p_ptr)
    if not _smoothed_prolongator(*args, np.empty(0, dtype=np.int64), np.empty((0, dim, m))):
        return None
    p_ind = np.empty(p_ptr[-1], dtype=A.indices.dtype)
    p_data = np.empty((p_ptr[-1], dim, m))
    _smoothed_prolongator(*args, p_ind, p_data)
    P = sp.bsr_matrix((p_data, p_ind, p_ptr.astype(A.indices.dtype)), shape=(A.shape[0], T.shape[1]), copy=False)
    P.has_sorted_indices = True
    R = _LazyTranspose(P)  # the compiled V-cycle needs no R; pyamg's cycle gets it on first use
    A_c = _galerkin(A, P)
    A_c.symmetry = "symmetric"
    coarse = pyamg.smoothed_aggregation_solver(A_c.tobsr(blocksize=(B.shape[1], B.shape[1])), B=B_c, **_SA_OPTIONS)
    top = MultilevelSolver.Level()
    top.A, top.B, top.P, top.R = A, B, P, R
    ml = MultilevelSolver([top] + coarse.levels, coarse_solver=_SA_OPTIONS["coarse_solver"])
    pre, post = _SA_SMOOTHERS
    change_smoothers(ml, [(pre[0], dict(pre[1], Dinv=dinv))] + [pre] * (len(ml.levels) - 2),
                     [(post[0], dict(post[1], Dinv=dinv))] + [post] * (len(ml.levels) - 2))
    return _compiled_smoothers(ml, dinv)


class _LazyTranspose:
    """``P^T`` as pyamg's restriction ``R``, formed on the first product (the compiled V-cycle
    restricts with ``P`` itself: no transposed copy of the finest prolongator is made)."""

    def __init__(self, P):
        self.P = P
        self.shape = (P.shape[1], P.shape[0])
        self.dtype = P.dtype
        self._T = None

    def __matmul__(self, v):
        if self._T is None:
            self._T = self.P.T.tobsr()
        return self._T @ v

    def tocsr(self):
        return self.P.T.tocsr()


def _amg_preconditioner(A, context):
    """pyamg smoothed aggregation; with node-aligned free dofs (``context['dim']`` and
    ``context['coords']`` of the free nodes) it works on dim x dim blocks (BSR) with the rigid
    body modes as near-null space, which is what makes it scale on elasticity; otherwise scalar
    with the constant vector.

    Options (``_SA_OPTIONS``): prolongation smoothing weighted by the inverse diagonal blocks;
    one forward block Gauss-Seidel sweep before and one backward sweep after the coarse
    correction, a symmetric V-cycle (CG needs it) at half the cost of symmetric sweeps; the
    coarsest level by sparse LU (pyamg's default dense pseudo-inverse costs O(n^3) and took
    minutes on the ~10^4-unknown coarse levels of 10^5-dof lattices).  The finest level of the
    block case is built by :func:`_sa_solver`; the cycle is applied by :class:`_VCycle` when
    every level fits it (pyamg's ``aspreconditioner`` otherwise).  pyamg is a dependency of
    msslib."""
    import pyamg

    dim = context.get("dim") if context else None
    coords = context.get("coords") if context else None
    if not (sp.issparse(A) and A.format == "bsr" and dim and A.blocksize == (dim, dim)):
        A = sp.csr_matrix(A)
    if dim and coords is not None and A.shape[0] == dim * len(coords) and len(coords) > 0:
        A = A.tobsr(blocksize=(dim, dim))  # no copy when it already is
        B = _rigid_body_modes(coords, dim)
        ml = _sa_solver(A, B, dim)
        if ml is None:
            ml = _compiled_smoothers(pyamg.smoothed_aggregation_solver(A, B=B, **_SA_OPTIONS))
    else:
        ml = pyamg.smoothed_aggregation_solver(A, max_coarse=500, coarse_solver="splu")
    cycle = _VCycle.build(ml)
    return cycle if cycle is not None else ml.aspreconditioner(cycle="V")


def _preconditioner(A, context=None):
    """The preconditioner of a CG solve: smoothed-aggregation AMG (:func:`_amg_preconditioner`)."""
    return _amg_preconditioner(A, context)

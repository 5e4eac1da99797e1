"""The compiled V-cycle of a smoothed-aggregation hierarchy and its block Gauss-Seidel smoother."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import amg_kernels as kernels
from .submatrices import _same_readonly


class _BlockGaussSeidel:
    """A pyamg level smoother ``(A, x, b)``: one block Gauss-Seidel sweep, compiled; the same
    sweep as pyamg's ``block_gauss_seidel`` at a third of its cost (its block loops are generic
    in the block size at run time)."""

    def __init__(self, dinv, forward: bool):
        self.dinv, self.forward = dinv, forward

    def __call__(self, A, x, b):
        if x.ndim != 1 or not x.flags.c_contiguous or x.dtype != np.float64:
            raise TypeError("block Gauss-Seidel needs a contiguous float64 vector")
        kernels._block_gauss_seidel_sweep(A.indptr, A.indices, A.data, self.dinv, x,
                                  np.ascontiguousarray(b, dtype=np.float64).ravel(), self.forward)


def _compiled_smoothers(ml, dinv0=None):
    """Replace the smoothers of the square-block BSR levels of a pyamg hierarchy (all but the
    coarsest) by the compiled block Gauss-Seidel: forward before the coarse correction,
    backward after (a symmetric V-cycle, as the options in ``_SA_SMOOTHERS``)."""
    for k, lvl in enumerate(ml.levels[:-1]):
        A = lvl.A
        if not (sp.issparse(A) and A.format == "bsr" and A.blocksize[0] == A.blocksize[1]):
            continue
        try:
            dinv = dinv0 if (k == 0 and dinv0 is not None) else kernels._block_diag_inverse(A.indptr, A.indices, A.data)
        except np.linalg.LinAlgError:  # a singular diagonal block: pyamg's smoother stays
            continue
        if not np.all(np.isfinite(dinv)):
            continue
        lvl.presmoother = _BlockGaussSeidel(dinv, True)
        lvl.postsmoother = _BlockGaussSeidel(dinv, False)
    return ml


# The finest level of the compiled V-cycle reads its matrix and prolongator in single precision
# (the arithmetic stays double): the cycle is then exactly the V-cycle of the rounded matrices,
# a symmetric preconditioner as good as the unrounded one (relative changes ~6e-8 of the
# entries), and the finest level, memory-bound at large sizes, reads half the bytes.
VCYCLE_SINGLE = True


class _VCycle:
    """The V-cycle of a smoothed-aggregation hierarchy as a preconditioner (``M @ r``), compiled
    level by level: the same cycle as pyamg's ``aspreconditioner(cycle="V")`` with the
    smoothers of :func:`_compiled_smoothers` (forward block Gauss-Seidel from zero, residual,
    restriction ``P^T``, coarse correction, prolongation, backward sweep), but

    * without the two residual norms of the finest level that pyamg's ``solve`` computes around
      each cycle (two products with the finest matrix of the about seven per application);
    * the forward sweep from zero reads only the blocks left of the diagonal, and the residual
      after it only the others (it is zero on the part the sweep solved), fused with the
      restriction ``P^T r`` (no ``R`` is needed);
    * compiled products with the BSR matrices.

    Work vectors are kept per level, so one operator must not be applied concurrently."""

    def __init__(self, ml, dinvs, single=False):
        self.ml = ml
        self.levels = []
        for k, (lvl, dinv) in enumerate(zip(ml.levels[:-1], dinvs)):
            A, P = lvl.A, lvl.P
            f32 = single and k == 0
            self.levels.append({"A": A, "P": P, "dinv": dinv, "s": np.empty(A.shape[0]),
                                "bc": np.empty(P.shape[1]), "xc": np.empty(P.shape[1]),
                                "a_data": A.data.astype(np.float32) if f32 else A.data,
                                "p_data": P.data.astype(np.float32) if f32 else P.data})
        self.single = bool(single)
        self.coarse_A = ml.levels[-1].A
        self.coarse_solver = ml.coarse_solver
        self.shape = ml.levels[0].A.shape
        self.dtype = np.dtype(float)

    @classmethod
    def build(cls, ml, single=None):
        """The compiled V-cycle of ``ml``, or None when a level does not fit (a non-BSR or
        non-square-block matrix, a prolongator whose block rows differ, or no compiled
        smoother).  ``single`` (default ``VCYCLE_SINGLE``): the finest level's matrix and
        prolongator are read in single precision (see :data:`VCYCLE_SINGLE`)."""
        if len(ml.levels) < 2:
            return None
        dinvs = []
        for lvl in ml.levels[:-1]:
            A, P = lvl.A, getattr(lvl, "P", None)
            sm = lvl.presmoother
            if not (sp.issparse(A) and A.format == "bsr" and A.blocksize[0] == A.blocksize[1]
                    and sp.issparse(P) and P.format == "bsr" and P.blocksize[0] == A.blocksize[0]
                    and isinstance(sm, _BlockGaussSeidel) and isinstance(lvl.postsmoother, _BlockGaussSeidel)
                    and A.dtype == np.float64 and P.dtype == np.float64):
                return None
            A.sort_indices()
            dinvs.append(sm.dinv)
        return cls(ml, dinvs, VCYCLE_SINGLE if single is None else single)

    def update(self, A):
        """Take the values of ``A`` (the next Newton matrix, same pattern as the finest level's)
        for the finest level's smoothing and residual, as the kept hierarchy does with a matrix
        refilled in place; the prolongator, the inverse diagonal blocks and the coarse levels
        stay.  Returns False (nothing changed) when ``A`` has another pattern."""
        L = self.levels[0]
        A0 = L["A"]
        if not (sp.issparse(A) and A.format == "bsr" and A.shape == A0.shape and A.blocksize == A0.blocksize
                and A.data.shape == L["a_data"].shape):
            return False
        if not (A.indices is A0.indices or _same_readonly(A.indices, A0.indices)
                or (A.indptr.shape == A0.indptr.shape and np.array_equal(A.indices, A0.indices)
                    and np.array_equal(A.indptr, A0.indptr))):
            return False
        if L["a_data"] is not A.data:
            if L["a_data"].dtype == A.data.dtype and L["a_data"] is A0.data:
                L["a_data"] = A.data  # double precision: read the new matrix itself
            else:
                np.copyto(L["a_data"], A.data, casting="same_kind")
        L["A"] = A
        return True

    def refresh_diagonal(self):
        """Invert the finest level's diagonal blocks anew, from the matrix of the last
        :meth:`update`.  The sweeps assume that they solve the diagonal blocks exactly: with the
        inverses of an older matrix the cycle is not symmetric, and CG with it stalled (the
        cylinder scene, 2 568 dofs: no convergence in 1 013 iterations at the first solve of the
        next load step; 4 iterations with the inverses refreshed).
        False (nothing changed) when a diagonal block is singular."""
        A = self.levels[0]["A"]
        try:
            dinv = kernels._block_diag_inverse(A.indptr, A.indices, A.data)
        except np.linalg.LinAlgError:
            return False
        if not np.all(np.isfinite(dinv)):
            return False
        self.levels[0]["dinv"] = dinv
        return True

    def _cycle(self, k, b, x):
        if k == len(self.levels):
            x[:] = np.asarray(self.coarse_solver(self.coarse_A, b), dtype=float).ravel()
            return
        L = self.levels[k]
        A, P, dinv, a, p = L["A"], L["P"], L["dinv"], L["a_data"], L["p_data"]
        three = A.blocksize[0] == 3
        forward, residual = ((kernels._gs3_forward_from_zero, kernels._residual3_restrict) if three
                             else (kernels._gs_forward_from_zero, kernels._residual_restrict))
        forward(A.indptr, A.indices, a, dinv, b, x, L["s"])
        bc, xc = L["bc"], L["xc"]
        bc.fill(0.0)
        residual(A.indptr, A.indices, a, x, L["s"], P.indptr, P.indices, p, bc)
        self._cycle(k + 1, bc, xc)
        kernels._prolong_add(P.indptr, P.indices, p, xc, x)
        if three:
            kernels._gs3_backward(A.indptr, A.indices, a, dinv, x, b)
        else:
            kernels._block_gauss_seidel_sweep(A.indptr, A.indices, a, dinv, x, b, False)

    def __matmul__(self, b):
        b = np.ascontiguousarray(np.asarray(b, dtype=np.float64).ravel())
        x = np.empty_like(b)
        self._cycle(0, b, x)
        return x

    matvec = __matmul__


def _matvec_of(A):
    """A function ``v -> A v``: compiled for float64 BSR matrices, else ``A @ v``."""
    if sp.issparse(A) and A.format == "bsr" and A.dtype == np.float64:
        kernel = kernels._bsr3_matvec if A.blocksize == (3, 3) else kernels._bsr_matvec

        def mv(v):
            y = np.empty(A.shape[0])
            kernel(A.indptr, A.indices, A.data, np.ascontiguousarray(v, dtype=np.float64), y)
            return y
        return mv
    return lambda v: np.asarray(A @ v, dtype=float).ravel()

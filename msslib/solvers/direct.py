"""Direct factorisations of the Newton systems: banded Cholesky (banded LU once the tangent is
found indefinite) in a bandwidth-reducing ordering, else SuperLU.  The blocked banded
factorisations run on one BLAS thread (:mod:`msslib.solvers.blas_threads`)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from msslib.solvers.blas_threads import BLOCKED_BANDWIDTH, one_blas_thread

from . import submatrices as _plans
from .submatrices import _plans_of, _same_readonly
from .protocol import TINY

BAND_PLAN_MAX_DOFS = 50_000  # no bandwidth-reducing ordering is computed above this size
BAND_COST_MAX = 4e8  # n * (bandwidth + 1)^2 above which the banded Cholesky is not tried


def _bandwidth(A, perm):
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    return int(np.max(np.abs(inv[rows] - inv[A.indices]))) if A.nnz else 0


def _band_plan(A, context):
    """Ordering and scatter map of the banded (LAPACK ``pbtrf``) Cholesky of a symmetric CSR
    matrix with sorted indices, computed once per sparsity pattern.  Candidate orderings:
    reverse Cuthill-McKee, and, for node-aligned dofs with known coordinates, slices across the
    longest side of the bounding box (node by node, dofs of a node together).  The one with the
    smallest bandwidth wins.  Returns None when the estimated cost ``n (b + 1)^2`` exceeds
    ``BAND_COST_MAX``.  The plan is kept in the :class:`~msslib.solvers.submatrices.PlanCache` of
    ``context`` (a solver context), if it has one, and in the process-wide memo of plans
    (:data:`msslib.solvers.memo.PLANS`), keyed by everything it is computed from: the pattern,
    the free-node coordinates, the dimension and the cost limit.  Each context gets its own copy
    of the plan dict (a factorisation adds its LU map to it)."""
    cache = _plans_of(context)
    for entry in (cache.bands if cache is not None else ()):
        if _same_readonly(entry["indices"], A.indices) and _same_readonly(entry["indptr"], A.indptr):
            return entry["plan"]
        if (entry["indices"].shape == A.indices.shape and entry["indptr"].shape == A.indptr.shape
                and np.array_equal(entry["indices"], A.indices) and np.array_equal(entry["indptr"], A.indptr)):
            return entry["plan"]
    dim = context.get("dim") if context else None
    coords = context.get("coords") if context else None
    arrays = (A.indptr, A.indices) + (() if coords is None else (np.ascontiguousarray(coords),))
    plan = _plans.PLANS.get_or_compute("band", arrays, lambda: _new_band_plan(A, dim, coords),
                                       (dim, BAND_COST_MAX))
    plan = None if plan is None else dict(plan)
    if cache is not None:
        cache.add_band({"indices": A.indices, "indptr": A.indptr, "plan": plan})
    return plan


def _new_band_plan(A, dim, coords):
    """The band plan of :func:`_band_plan`, computed."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    n = A.shape[0]
    pattern = sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    candidates = [np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), dtype=np.int64)]
    if dim and coords is not None and n == dim * len(coords) and len(coords):
        ext = np.ptp(coords, axis=0)
        axes = np.argsort(ext)  # shortest first: lexsort's last key is the primary one
        nodes = np.lexsort(tuple(np.round(coords[:, a] / max(ext.max(), TINY), 9) for a in axes))
        candidates.append((dim * nodes[:, None] + np.arange(dim)).ravel())
    widths = [_bandwidth(A, p) for p in candidates]
    k = int(np.argmin(widths))
    perm, bw = candidates[k], widths[k]
    if n * (bw + 1.0) ** 2 > BAND_COST_MAX:
        return None
    inv = np.empty_like(perm)
    inv[perm] = np.arange(n)
    rows = inv[np.repeat(np.arange(n), np.diff(A.indptr))]
    cols = inv[A.indices]
    lower = np.flatnonzero(rows >= cols)
    # LAPACK lower band storage: ab[i - j, j] = A[i, j] (i, j in the permuted numbering);
    # general band storage (for the LU fallback): ab[bw + i - j, j] = A[i, j]; both arrays
    # in Fortran order (LAPACK's), as flat positions (a C-ordered array would be copied on
    # every call)
    return {"perm": perm, "bw": bw, "src": lower,
            "dst": (rows[lower] - cols[lower]) + cols[lower] * (bw + 1),
            "dst_full": (bw + rows - cols) + cols * (2 * bw + 1)}


def _banded_cholesky_solve(A, b, context):
    """Solve with the banded Cholesky of ``A`` (symmetric, CSR); None when ``A`` is not
    positive definite or its bandwidth is too large (the caller then uses SuperLU)."""
    from scipy.linalg import LinAlgError, cho_solve_banded, cholesky_banded, lapack

    if A.shape[0] > BAND_PLAN_MAX_DOFS or not (sp.issparse(A) and A.format == "csr" and A.has_canonical_format):
        return None
    plan = _band_plan(A, context)
    if plan is None:
        return None
    n, bw, perm = A.shape[0], plan["bw"], plan["perm"]
    bp = np.asarray(b, dtype=float)[perm]
    y = None
    state = context if context is not None else {}
    if not state.get("band_indefinite"):
        # the band array is kept in the context (a solve's Newton iterations, a run's time
        # steps) and refilled: no new pages per factorisation
        ab = state.get("band_ab")
        if ab is None or ab.shape != (bw + 1, n):
            ab = state["band_ab"] = np.zeros((bw + 1, n), order="F")
        else:
            ab.fill(0.0)
        flat = ab.reshape(-1, order="F")  # a view (Fortran-contiguous)
        flat[plan["dst"]] = A.data[plan["src"]]
        try:
            with one_blas_thread(bw >= BLOCKED_BANDWIDTH):  # msslib.solvers.blas_threads: shared cores
                cb = cholesky_banded(ab, lower=True, overwrite_ab=True, check_finite=False)
                y = cho_solve_banded((cb, True), bp, check_finite=False)
        except LinAlgError:  # not positive definite: banded LU (partial pivoting) from now on
            state["band_indefinite"] = True
    if y is None:
        if 2.0 * n * (bw + 1.0) * (2 * bw + 1.0) > 2 * BAND_COST_MAX:
            return None
        # LAPACK gbtrf/gbtrs on a band array kept in the context and refilled, with the bw rows
        # of room for the pivoting fill that gbtrf needs (solve_banded would allocate the band
        # array and then copy it into a larger one on every call)
        rows = 3 * bw + 1
        ab = state.get("band_lu")
        if ab is None or ab.shape != (rows, n):
            ab = state["band_lu"] = np.zeros((rows, n), order="F")
        else:
            ab.fill(0.0)
        dst = plan.get("dst_lu")
        if dst is None:  # general band storage with kl extra rows: ab[2 bw + i - j, j] = A[i, j]
            full = plan["dst_full"]
            dst = plan["dst_lu"] = (full // (2 * bw + 1)) * rows + full % (2 * bw + 1) + bw
        ab.reshape(-1, order="F")[dst] = A.data
        with one_blas_thread(bw >= BLOCKED_BANDWIDTH):
            lu, piv, info = lapack.dgbtrf(ab, bw, bw, overwrite_ab=1)
            if info == 0:
                y, info = lapack.dgbtrs(lu, bw, bw, bp, piv, overwrite_b=1)
        if info != 0:  # exactly singular (info > 0 from gbtrf) or bad input
            return None
    x = np.empty(n)
    x[perm] = y
    return x if np.all(np.isfinite(x)) else None


def _direct_solve(A, b, symmetric, context=None, factorisation="superlu"):
    """``factorisation``: the one :func:`msslib.solvers.policy.choose_factorisation` takes
    (``"pardiso"`` or ``"superlu"``), after a banded Cholesky where one is cheap.  Symmetric:
    banded Cholesky in a bandwidth-reducing ordering when it is cheap and the matrix is positive
    definite; above ``PARDISO_MIN_DOFS`` MKL Pardiso (symmetric indefinite, its analysis kept in
    ``context`` for the later matrices of the pattern; :mod:`msslib.solvers.pardiso`) where it
    is installed; otherwise SuperLU with the minimum-degree ordering of A^T + A (less fill than
    the default COLAMD on lattice stiffnesses).  Non-symmetric: above ``PARDISO_MIN_DOFS`` MKL
    Pardiso (real non-symmetric, its analysis kept likewise) where it is installed, otherwise
    SuperLU with COLAMD."""
    if symmetric:
        x = _banded_cholesky_solve(A, b, context)
        if x is not None:
            return x
    if factorisation == "pardiso":
        from .pardiso import PardisoFactor

        state = context if context is not None else {}
        key = "pardiso" if symmetric else "pardiso_nonsymmetric"
        factor = state.get(key)
        if factor is None:
            factor = state[key] = PardisoFactor(symmetric)
        try:
            x = factor.solve(A, b)
        except RuntimeError:  # a (nearly) singular tangent: SuperLU's pivoting decides, as before
            x = None
        if x is not None:
            state["direct_solver"] = "pardiso" if symmetric else "pardiso (non-symmetric)"
            if factor.inertia is not None and factor.inertia[1] > 0:
                state["indefinite"] = True  # CG is not tried again on this problem's tangents
            return x
    spec = "MMD_AT_PLUS_A" if symmetric else "COLAMD"
    return spla.splu(sp.csc_matrix(A), permc_spec=spec).solve(np.asarray(b, dtype=float))

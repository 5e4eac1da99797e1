"""The linear-solver policy: which solver takes a Newton system, decided in one place
(:func:`choose_linear_solver`, and :func:`choose_factorisation` for the direct ones), for the
static Newton systems, their node-block assembly, the linearised runs, the FEM references and
the implicit time steps alike.

``"auto"`` takes the direct solver up to ``ITERATIVE_THRESHOLD`` free dofs, and above it while the
banded Cholesky is cheap (``n (b + 1)^2 <= BAND_AUTO_COST`` for the bandwidth ``b`` of the best
ordering found; never above ``BAND_PLAN_MAX_DOFS``, where no ordering is computed), else
AMG-preconditioned CG for symmetric systems -- except for a problem whose tangent was found
indefinite when MKL Pardiso is installed: direct from then on.  The direct solver itself picks
the factorisation (:func:`msslib.solvers.direct._direct_solve`): banded Cholesky when a band plan
exists and the matrix is positive definite, banded LU once it is found indefinite, else MKL
Pardiso for systems of ``PARDISO_MIN_DOFS`` unknowns or more where it is installed
(:mod:`msslib.solvers.pardiso`; symmetric indefinite or real non-symmetric), else SuperLU.

A system declared non-symmetric whose matrix is symmetric to round-off (:func:`as_symmetric`,
relative ``SYMMETRY_RTOL``) is symmetrised and takes the symmetric way: a model whose terms cannot
promise symmetry (the element reading of Baudet's cube) is not sent to a non-symmetric
factorisation for entries of 1e-16.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .direct import BAND_PLAN_MAX_DOFS, _band_plan
from .submatrices import _bsr_entry, _eccentricity, submatrix

ITERATIVE_THRESHOLD = 2_000  # free dofs above which "auto" may use preconditioned CG (symmetric)
BAND_AUTO_COST = 1.5e8  # ... unless the banded Cholesky costs at most this n (b + 1)^2
# Measured on the gravity-loaded Golec cube lattice (benchmarks/statics.py), single thread, whole
# static solves: 1944 dofs banded Cholesky 0.033 s vs AMG-CG 0.040 s; 3630 dofs SuperLU 0.44 s
# (banded too wide) vs AMG-CG 0.083 s; 6084 dofs 1.37 s vs 0.16 s.  SuperLU's fill grows like
# n^(4/3..2) in 3D; slender bodies keep a narrow band and stay direct.

LINEAR_SOLVERS = ("auto", "direct", "cg")
PARDISO_MIN_DOFS = 5_000  # symmetric systems from this size are factorised by MKL Pardiso, if installed
#: from this Poisson ratio "auto" solves elasticity systems directly: the AMG-preconditioned CG
#: needs ever more iterations as lambda / mu grows (quadratic reference of the thick sphere, 13 k
#: dofs, nu = 0.4999: CG 200 s, direct 1.6-4 s; the 2.5 k-dof octant: 8.5 s against 3.6 s, where
#: at nu = 0.3 CG takes 0.84 s and direct 1.02 s)
NEARLY_INCOMPRESSIBLE_NU = 0.45
# Measured on the quadratic neo-Hookean reference's first tangent (benchmarks/fem_solvers.py),
# single thread: 13,104 dofs Pardiso 0.21 s (a refactorisation with the kept analysis 0.12 s)
# against SuperLU's 0.91 s; 94,176 dofs 6.4 s (SuperLU: minutes).  AMG-CG stays ahead on
# positive definite systems (94,176 dofs: 2.3 s set-up, 4.2 s CG to 1e-8).


# Measured on the stiffness at rest of Baudet's cube under the element reading (cantilever scene,
# numerically symmetric, max|K - K^T| / max|K| = 4.5e-16, but not structurally symmetric), single
# thread: 55,488 dofs SuperLU COLAMD 47.5 s (fill 1.7e8), SuperLU MMD_AT_PLUS_A 15.8 s, Pardiso
# real non-symmetric 2.6 s; 7,776 dofs 0.25 s, 0.36 s, 0.21 s.
SYMMETRY_RTOL = 1e-12  # max|A - A^T| <= this max|A|: symmetric to round-off


def as_symmetric(A, symmetric: bool):
    """``(A, symmetric)`` for the solve of ``A x = b``: a matrix declared non-symmetric whose
    entries are symmetric to round-off (``max|A - A^T| <= SYMMETRY_RTOL max|A|``, measured) is
    replaced by its symmetric part ``(A + A^T) / 2`` (canonical CSR) and declared symmetric;
    anything else is returned as given.  Costs a transposition of ``A``."""
    if symmetric or not sp.issparse(A) or A.shape[0] != A.shape[1] or A.nnz == 0:
        return A, symmetric
    A = sp.csr_matrix(A)
    scale = float(abs(A).max())
    if not np.isfinite(scale) or scale == 0.0:
        return A, symmetric
    At = A.T.tocsr()
    if float(abs(A - At).max()) > SYMMETRY_RTOL * scale:
        return A, False
    S = ((A + At) * 0.5).tocsr()
    S.sum_duplicates()
    S.sort_indices()
    return S, True


def method_for_material(method, nu):
    """The linear-solver request of an elasticity solve with Poisson ratios ``nu`` (a number or
    one per cell): ``"auto"`` becomes ``"direct"`` from :data:`NEARLY_INCOMPRESSIBLE_NU`; any
    other request is kept."""
    if isinstance(method, str) and method == "auto":
        nu = np.asarray(nu, dtype=float)
        if nu.size and float(np.nanmax(nu)) >= NEARLY_INCOMPRESSIBLE_NU:
            return "direct"
    return method


def choose_factorisation(n: int, symmetric: bool) -> str:
    """The direct factorisation of a system of ``n`` unknowns that no band plan takes:
    ``"pardiso"`` (MKL, at least ``PARDISO_MIN_DOFS`` unknowns, where pypardiso is installed:
    symmetric indefinite for symmetric systems, real non-symmetric otherwise) or ``"superlu"``."""
    if n >= PARDISO_MIN_DOFS:
        from .pardiso import available

        if available():
            return "pardiso"
    return "superlu"


def choose_linear_solver(method, n: int, symmetric: bool, band_is_cheap: Callable[[], bool] | None = None,
                         indefinite: bool = False) -> str:
    """The solver of a Newton system of ``n`` unknowns: ``"user"`` (``method`` is a callable),
    ``"cg"`` or ``"direct"``.

    ``method``: ``"auto"``, ``"direct"``, ``"cg"`` or a callable.  ``symmetric``: whether the
    tangent is symmetric (CG is never chosen by ``"auto"`` otherwise).  ``band_is_cheap()``:
    asked only for ``"auto"`` between ``ITERATIVE_THRESHOLD`` and ``BAND_PLAN_MAX_DOFS`` free
    dofs, whether the banded Cholesky is cheap (None: it is not).  ``indefinite``: an earlier
    tangent of the problem was found indefinite (CG met negative curvature, the factorisation's
    inertia had negative eigenvalues) and a symmetric indefinite factorisation is at hand
    (``choose_factorisation`` gives ``"pardiso"``): ``"auto"`` then goes direct."""
    if callable(method):
        return "user"
    if method not in LINEAR_SOLVERS:
        raise ValueError(f"linear_solver must be 'auto', 'direct', 'cg' or a callable, got {method!r}")
    if method != "auto":
        return method
    if not symmetric or n <= ITERATIVE_THRESHOLD or indefinite:
        return "direct"
    if n > BAND_PLAN_MAX_DOFS or band_is_cheap is None:
        return "cg"
    return "direct" if band_is_cheap() else "cg"


def _band_surely_wide(entry, dim) -> bool:
    """True when no ordering can make the banded Cholesky cheap, from a bound that costs one
    breadth-first search: a graph of ``n`` vertices and diameter ``D`` has bandwidth at least
    ``(n - 1) / D``, and ``D <= 2 e`` for the eccentricity ``e`` of any vertex (the dofs of a
    node are neighbours, so the dof graph has the diameter of the node graph).  Spares compact
    bodies the bandwidth-reducing orderings, which cost more than the whole solve there."""
    e = int(_eccentricity(entry["bptr"], entry["bind"]))
    if e <= 0:
        return False
    n = dim * (len(entry["bptr"]) - 1)
    b = (n - 1) / (2.0 * e)
    return n * (b + 1.0) ** 2 > BAND_AUTO_COST


def banded_cholesky_is_cheap(A, context):
    """Whether the banded Cholesky of the free-dof matrix ``A`` (canonical CSR) is cheap."""
    if A.shape[0] > BAND_PLAN_MAX_DOFS or not (sp.issparse(A) and A.format == "csr" and A.has_canonical_format):
        return False
    plan = _band_plan(A, context)
    return plan is not None and A.shape[0] * (plan["bw"] + 1.0) ** 2 <= BAND_AUTO_COST


def _wants_blocks(full_tangent, free, method, symmetric, context, block_tangent=None):
    """Whether the Newton systems go to AMG-CG as BSR node blocks: symmetric, whole free nodes,
    and CG chosen by :func:`choose_linear_solver`.  ``full_tangent()`` gives the full stiffness
    when the decision needs its pattern (mid sizes only); ``block_tangent()`` (optional) the free
    node blocks or None: when their graph alone shows the band too wide, the full tangent is not
    formed."""
    if not (symmetric and method in ("auto", "cg") and context.get("dim") and "node_free" in context):
        return False

    def band_is_cheap():
        Kb = block_tangent() if block_tangent is not None else None
        if Kb is not None and _band_surely_wide({"bptr": Kb.indptr, "bind": Kb.indices}, context["dim"]):
            return False
        K_full = full_tangent()
        entry = _bsr_entry(K_full, context["node_free"], context["dim"], context)
        if entry is not None and _band_surely_wide(entry, context["dim"]):
            return False
        return banded_cholesky_is_cheap(submatrix(K_full, free, plans=context), context)

    return choose_linear_solver(method, int(free.sum()), symmetric, band_is_cheap) == "cg"

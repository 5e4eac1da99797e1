"""Large symmetric systems are factorised by MKL Pardiso where it is installed (symmetric
indefinite, its analysis kept for the later matrices of a pattern), SuperLU elsewhere; the
choice by size and definiteness is the policy's (msslib.solvers.policy)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from msslib.solvers import pardiso, policy
from msslib.solvers.linear import solve_linear_system
from msslib.solvers.protocol import NewtonFailure

needs_pardiso = pytest.mark.skipif(not pardiso.available(), reason="pypardiso (MKL) not installed here")


def _indefinite(n, shift):
    """A 3D Laplacian-like SPD matrix shifted by ``shift``: indefinite for shift above its smallest eigenvalue."""
    k = round(n ** (1 / 3))
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(k, k))
    eye = sp.identity(k)
    L = (sp.kron(sp.kron(one, eye), eye) + sp.kron(sp.kron(eye, one), eye) + sp.kron(sp.kron(eye, eye), one)).tocsr()
    return (L - shift * sp.identity(L.shape[0])).tocsr()


def test_the_factorisation_is_chosen_by_size_and_symmetry(monkeypatch):
    monkeypatch.setattr(pardiso, "available", lambda: True)
    assert policy.choose_factorisation(policy.PARDISO_MIN_DOFS, True) == "pardiso"
    assert policy.choose_factorisation(policy.PARDISO_MIN_DOFS - 1, True) == "superlu"
    # non-symmetric systems too (real non-symmetric Pardiso), by the same size
    assert policy.choose_factorisation(10 * policy.PARDISO_MIN_DOFS, False) == "pardiso"
    assert policy.choose_factorisation(policy.PARDISO_MIN_DOFS - 1, False) == "superlu"
    monkeypatch.setattr(pardiso, "available", lambda: False)
    assert policy.choose_factorisation(10 * policy.PARDISO_MIN_DOFS, True) == "superlu"
    # an indefinite tangent goes direct under "auto" only where the indefinite factorisation exists
    assert policy.choose_linear_solver("auto", 50_000, True, None, indefinite=True) == "direct"
    assert policy.choose_linear_solver("auto", 50_000, True, None, indefinite=False) == "cg"


@needs_pardiso
def test_pardiso_solves_an_indefinite_system_as_superlu_and_keeps_its_analysis():
    A = _indefinite(22**3, 0.5)  # 10,648 unknowns, some eigenvalues negative
    b = np.random.default_rng(0).normal(size=A.shape[0])
    ctx = {}
    x = solve_linear_system(A, b, "direct", True, [], ctx)
    ref = spla.splu(A.tocsc()).solve(b)
    assert np.abs(x - ref).max() <= 1e-8 * np.abs(ref).max()
    factor = ctx["pardiso"]
    assert factor.inertia[1] > 0 and ctx["indefinite"]
    # the next matrix of the same pattern: a numerical factorisation only
    A2 = A.copy()
    A2.data *= 1.5
    x2 = solve_linear_system(A2, b, "direct", True, [], ctx)
    assert np.abs(x2 - ref / 1.5).max() <= 1e-8 * np.abs(ref).max()
    assert (factor.analyses, factor.factorisations) == (1, 2)


@needs_pardiso
def test_a_singular_system_is_refused_not_answered():
    A = _indefinite(18**3, 0.0).tolil()
    A[0, :] = 0.0
    A[:, 0] = 0.0
    with pytest.raises(NewtonFailure, match="singular"):
        solve_linear_system(A.tocsr(), np.ones(A.shape[0]), "direct", True, [], {})


@needs_pardiso
def test_after_negative_curvature_the_problem_goes_direct():
    """CG meets negative curvature on an indefinite tangent and falls back; the next solve of the
    same problem skips CG (no second fallback message)."""
    A = _indefinite(18**3, 0.5)
    b = np.ones(A.shape[0])
    messages, ctx = [], {}
    solve_linear_system(A, b, "auto", True, messages, ctx)
    assert len(messages) == 1 and "negative curvature" in messages[0] and ctx["indefinite"]
    x = solve_linear_system(A, b, "auto", True, messages, ctx)
    assert len(messages) == 1
    assert np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)


def test_a_matrix_pardiso_refuses_goes_to_superlu(monkeypatch):
    """A nearly singular tangent that Pardiso refuses (perturbed pivots) is solved by SuperLU's
    pivoting, as before Pardiso was used."""
    monkeypatch.setattr(pardiso, "available", lambda: True)

    class Refusing:
        inertia = None

        def solve(self, A, b):
            raise RuntimeError("MKL Pardiso: singular matrix (1 pivots perturbed)")

    A = _indefinite(18**3, 0.5)
    b = np.ones(A.shape[0])
    x = solve_linear_system(A, b, "direct", True, [], {"pardiso": Refusing()})
    assert np.abs(x - spla.splu(A.tocsc()).solve(b)).max() <= 1e-10 * np.abs(x).max()

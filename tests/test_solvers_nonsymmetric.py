"""Systems declared non-symmetric: a matrix symmetric to round-off (the stiffness of a model whose
terms cannot promise symmetry) is symmetrised and takes the symmetric way; a genuinely
non-symmetric one (a follower pressure's tangent) is factorised by MKL Pardiso's real
non-symmetric factorisation from PARDISO_MIN_DOFS unknowns where it is installed, its analysis
kept for the later matrices of the pattern, else by SuperLU."""

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import yaml

from msslib.solvers import pardiso, policy
from msslib.solvers.linear import solve_linear_system

needs_pardiso = pytest.mark.skipif(not pardiso.available(), reason="pypardiso (MKL) not installed here")
CANTILEVER = Path(__file__).resolve().parents[1] / "experiments" / "performance" / "scenes" / "cantilever.yaml"


def _laplacian(k):
    """The SPD 7-point Laplacian of a k x k x k grid plus the identity (k^3 unknowns)."""
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(k, k))
    eye = sp.identity(k)
    L = sp.kron(sp.kron(one, eye), eye) + sp.kron(sp.kron(eye, one), eye) + sp.kron(sp.kron(eye, eye), one)
    return (L + sp.identity(k**3)).tocsr()


def _pattern_asymmetric(A, eps):
    """``A`` plus entries of relative size ``eps`` on one side of the diagonal only, at places
    outside A's pattern: structurally non-symmetric, ``max|A - A^T| = eps max|A|``."""
    n = A.shape[0]
    i = np.arange(0, n - 7, 5)
    E = sp.csr_matrix((np.full(i.size, eps * abs(A).max()), (i, i + 7)), shape=A.shape)
    assert (abs(A).multiply(abs(E)) != 0).nnz == 0  # outside the pattern
    return (A + E).tocsr()


def _nonsymmetric(k):
    """A convection-diffusion matrix: the Laplacian plus a one-sided difference along x (no
    symmetric part can stand in for it)."""
    A = _laplacian(k)
    one = sp.diags([-1.0, 1.0], [-1, 0], shape=(k, k))
    eye = sp.identity(k)
    return (A + 0.8 * sp.kron(sp.kron(one, eye), eye)).tocsr()


def test_a_matrix_symmetric_to_roundoff_is_symmetrised():
    A = _pattern_asymmetric(_laplacian(8), 1e-16)
    assert (abs(A) > 0).astype(int).__ne__((abs(A.T) > 0).astype(int)).nnz > 0
    S, symmetric = policy.as_symmetric(A, False)
    assert symmetric
    assert abs(S - S.T).max() == 0.0  # exactly symmetric
    assert abs(S - A).max() <= 1e-16 * abs(A).max()
    assert S.has_canonical_format
    # above the tolerance, and a genuinely non-symmetric matrix: left as they are
    B = _pattern_asymmetric(_laplacian(8), 1e-9)
    assert policy.as_symmetric(B, False)[1] is False
    C = _nonsymmetric(8)
    assert policy.as_symmetric(C, False)[1] is False
    # a matrix declared symmetric is not looked at
    assert policy.as_symmetric(B, True)[0] is B


def test_a_numerically_symmetric_system_goes_the_symmetric_way():
    """Declared non-symmetric but symmetric to round-off: the banded Cholesky takes it (it keeps
    its band array in the context), where SuperLU took it before."""
    A = _pattern_asymmetric(_laplacian(8), 1e-16)  # 512 unknowns: banded Cholesky
    b = np.random.default_rng(1).normal(size=A.shape[0])
    ctx = {}
    x = solve_linear_system(A, b, "direct", False, [], ctx)
    assert "band_ab" in ctx
    assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)


@needs_pardiso
def test_a_large_numerically_symmetric_system_takes_symmetric_pardiso():
    A = _pattern_asymmetric(_laplacian(18), 1e-16)  # 5,832 unknowns: no band plan is cheap here
    b = np.random.default_rng(2).normal(size=A.shape[0])
    ctx = {"band_indefinite": True}  # past the banded Cholesky: the factorisation chosen by size
    x = solve_linear_system(A, b, "direct", False, [], ctx)
    assert "pardiso" in ctx and "pardiso_nonsymmetric" not in ctx
    assert ctx["pardiso"].inertia == (A.shape[0], 0)
    assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)


@needs_pardiso
def test_a_non_symmetric_system_is_solved_by_non_symmetric_pardiso_keeping_its_analysis():
    A = _nonsymmetric(18)  # 5,832 unknowns
    assert A.shape[0] >= policy.PARDISO_MIN_DOFS
    b = np.random.default_rng(3).normal(size=A.shape[0])
    ctx = {}
    x = solve_linear_system(A, b, "auto", False, [], ctx)
    factor = ctx["pardiso_nonsymmetric"]
    assert not factor.symmetric and "pardiso" not in ctx
    assert ctx["direct_solver"] == "pardiso (non-symmetric)"
    assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)
    # its transpose is a different system: the solve is not of the symmetric part
    assert np.linalg.norm(A.T @ x - b) > 1e-3 * np.linalg.norm(b)
    A2 = A.copy()
    A2.data *= 2.0
    x2 = solve_linear_system(A2, b, "auto", False, [], ctx)
    assert np.abs(x2 - x / 2.0).max() <= 1e-10 * np.abs(x).max()
    assert (factor.analyses, factor.factorisations) == (1, 2)


def test_a_non_symmetric_system_falls_back_to_superlu_without_pardiso(monkeypatch):
    monkeypatch.setattr(pardiso, "available", lambda: False)
    A = _nonsymmetric(18)
    b = np.random.default_rng(4).normal(size=A.shape[0])
    ctx = {}
    x = solve_linear_system(A, b, "auto", False, [], ctx)
    assert "pardiso_nonsymmetric" not in ctx and "pardiso" not in ctx and "band_ab" not in ctx
    assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)


def test_baudet_cube_stiffness_is_symmetric_to_roundoff_and_solved_as_symmetric():
    """The case that needed it: Baudet's cube under the element reading declares its terms
    non-symmetric; its stiffness at rest is symmetric to round-off but not in pattern."""
    from msslib.planning.front import at_level
    from msslib.scene import load_scene, prepare

    raw = yaml.safe_load(CANTILEVER.read_text())
    model = prepare(load_scene(at_level(raw, 1, "baudet_cube"), base_dir=CANTILEVER.parent)).model
    assert not all(t.symmetric for t in model.terms)
    K = model.stiffness(model.x0, 1.0).tocsr()
    A = K[model.free][:, model.free].tocsr()
    assert (abs(A) > 0).astype(int).__ne__((abs(A.T) > 0).astype(int)).nnz > 0
    S, symmetric = policy.as_symmetric(A, False)
    assert symmetric and abs(S - A).max() <= 1e-12 * abs(A).max()


@needs_pardiso
def test_a_follower_pressure_scene_solved_by_non_symmetric_pardiso_equals_superlu(monkeypatch):
    """A follower pressure on an open face (a genuinely non-symmetric tangent, 5,400 free dofs):
    every Newton system goes to non-symmetric Pardiso, and the solution equals SuperLU's."""
    from msslib.scene import load_scene, run_scene
    from msslib.solvers import direct as solvers_direct
    from msslib.solvers import linear as solvers_linear

    n = 9
    scene = {"name": "flat", "geometry": {"generator": "hex_grid", "args": {"lx": 1.0, "ly": 1.0, "lz": 2.0,
                                                                           "nx": n, "ny": n, "nz": 2 * n}},
             "materials": [{"E": 1e6, "nu": 0.3, "density": 1000.0}], "model": "golec_cube",
             "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
             "loads": [{"type": "pressure", "select": {"plane": ["x", 1.0]}, "pressure": 2e3, "follow": True}],
             "solver": {"type": "static", "load_steps": 2}}
    calls = []
    real = solvers_direct._direct_solve

    def spy(A, b, symmetric, context=None, factorisation="superlu"):
        calls.append((symmetric, factorisation, A.shape[0]))
        return real(A, b, symmetric, context, factorisation)

    monkeypatch.setattr(solvers_linear, "_direct_solve", spy)
    u = run_scene(load_scene(scene), progress=False)["displacement"].values
    assert calls and {c[:2] for c in calls} == {(False, "pardiso")} and calls[0][2] >= policy.PARDISO_MIN_DOFS
    calls.clear()
    monkeypatch.setattr(solvers_linear, "choose_factorisation", lambda n, s: "superlu")
    u_lu = run_scene(load_scene(scene), progress=False)["displacement"].values
    assert {c[:2] for c in calls} == {(False, "superlu")}
    assert np.abs(u).max() > 1e-3 and np.abs(u - u_lu).max() <= 1e-10 * np.abs(u_lu).max()

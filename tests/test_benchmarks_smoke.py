"""Smoke test of the benchmark command (no timing assertions) and the fast spring kernel."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from msslib.models.golec import golec_cube_springs
from msslib import mesh as M
from msslib.system import Model
from msslib.terms import Springs
from msslib.terms.loops import _spring3d_hessian_loop

ROOT = Path(__file__).resolve().parents[1]

FIGURES = [
    "spring_force_numpy_bincount", "spring_force_numba_plain", "spring_force_fast",
    "spring_force_fast_rel_error", "stream_copy_bandwidth", "spring_force_bandwidth_limit",
    "spring_force_fraction_of_bandwidth_limit", "hessian_assembly_scipy_coo", "hessian_assembly_fast",
    "hessian_assembly_rel_error", "cantilever_static_baudet", "cantilever_static_golec",
    "golec_sample_explicit_wall", "golec_sample_step_cost", "golec_sample_error_vs_reference",
    "golec_sample_final_error_vs_reference", "golec_sample_reference_wall", "golec_sample_explicit_wall_double",
    "golec_sample_single_vs_double",
    "static_solve_scaling_exponent_warm", "static_solve_scaling_exponent_cold", "static_solve_superlu_scaling_exponent",
]


def test_benchmarks_quick_writes_every_figure(tmp_path):
    out = tmp_path / "tmp.json"
    proc = subprocess.run([sys.executable, "-m", "benchmarks", "--quick", "--out", str(out)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads(out.read_text())
    figs = data["figures"]
    for name in FIGURES:
        assert name in figs, name
        assert np.isfinite(figs[name]["value"])
        assert f"{name}:" in proc.stdout and "ratio to baseline" in proc.stdout
    assert any(k.startswith("static_solve_") and k.endswith("_dofs") for k in figs)
    assert data["meta"]["threads_blas"] == 1 and data["meta"]["threads_numba"] == 1


def _random_springs(seed=0):
    rng = np.random.default_rng(seed)
    n, s = 60, 400
    pairs = rng.integers(0, n, size=(s, 2))
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    x = rng.standard_normal(3 * n)
    L = np.linalg.norm(x.reshape(-1, 3)[pairs[:, 1]] - x.reshape(-1, 3)[pairs[:, 0]], axis=1)
    k = rng.uniform(0.5, 2.0, len(pairs))
    rest = L * rng.uniform(0.8, 1.2, len(pairs))
    return Springs(pairs, k, rest, 3), x


def test_fast_spring_kernel_equals_generated_kernel():
    springs, x = _random_springs()
    g, g_ref = springs.gradient(x), springs.gradient_reference(x)
    assert np.abs(g - g_ref).max() <= 1e-12 * np.abs(g_ref).max()
    e_ref = float(type(springs).__mro__[1].energy(springs, x))
    assert abs(springs.energy(x) - e_ref) <= 1e-12 * abs(e_ref)
    # on a lattice near rest (cancellation-prone) too
    mesh = M.hex_grid(0.05, 0.04, 0.03, 5, 4, 3)
    sp_ = golec_cube_springs(mesh, [(1e4, 0.3)], 1.0)[0]
    xl = mesh.points.ravel() + 1e-6 * np.random.default_rng(1).standard_normal(mesh.n_nodes * 3)
    g, g_ref = sp_.gradient(xl), sp_.gradient_reference(xl)
    assert np.abs(g - g_ref).max() <= 1e-12 * np.abs(g_ref).max()


def test_fast_csr_stiffness_equals_coo_assembly():
    import scipy.sparse as sp

    box = M.hex_grid(0.03, 0.03, 0.03, 3, 3, 3)
    terms = golec_cube_springs(box, [(1e4, 0.3)], 1.0)
    model = Model(box, terms)
    xb = box.points.ravel() + 1e-3 * np.random.default_rng(3).standard_normal(box.n_nodes * 3)
    K = model.stiffness(xb).toarray()
    K_ref = np.zeros_like(K)
    for t in terms:
        r, c = t.hessian_pattern()
        if isinstance(t, Springs):
            v = np.empty((len(t.conn), 36))
            _spring3d_hessian_loop(xb, t.conn, t.k, t.rest_length, v)
            v = v.ravel()
        else:
            v = t.hessian_values(xb)
        K_ref += sp.coo_matrix((v, (r, c)), shape=K.shape).toarray()
    assert np.abs(K - K_ref).max() <= 1e-12 * np.abs(K_ref).max()

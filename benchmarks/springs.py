"""1-2: spring force evaluation and sparse Hessian assembly on a cube lattice."""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from msslib.models.golec import golec_cube_springs
from msslib import mesh as M
from msslib import system as MD
from msslib.terms import loops

from .common import median_time


def lattice(n: int, E: float = 1e4, nu: float = 0.25):
    """n^3 cubes of 1 cm, springs on edges, face and inner diagonals (Golec's constants at
    nu = 1/4, where his volume term vanishes: the springs alone are the model)."""
    mesh = M.hex_grid(0.01 * n, 0.01 * n, 0.01 * n, n, n, n)
    springs = golec_cube_springs(mesh, [(E, nu)], 1.0)[0]
    return mesh, springs


def numpy_gradient(x, a, b, k, L0, n_dof):
    """Baseline: vectorised numpy with np.bincount scatter."""
    p = x.reshape(-1, 3)
    d = p[a] - p[b]
    l = np.sqrt(np.einsum("ij,ij->i", d, d))
    f = d * (k * (L0 - l) / l)[:, None]
    g = np.empty((n_dof // 3, 3))
    for c in range(3):
        g[:, c] = np.bincount(b, weights=f[:, c], minlength=n_dof // 3) - np.bincount(a, weights=f[:, c], minlength=n_dof // 3)
    return g.ravel()


def stream_bandwidth(nbytes: int = 64_000_000, repeat: int = 15) -> float:
    """numpy copy bandwidth (bytes read + written per second), large arrays (out of cache): the
    best of ``repeat`` copies, since it serves as a limit."""
    a = np.random.default_rng(0).random(nbytes // 8)
    b = np.empty_like(a)
    np.copyto(b, a)
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        np.copyto(b, a)
        ts.append(time.perf_counter() - t)
    return 2 * a.nbytes / min(ts)


def run(res, quick: bool):
    n = 15 if quick else 30
    mesh, springs = lattice(n)
    s = len(springs.conn)
    x = mesh.points.ravel() + 1e-4 * np.random.default_rng(1).standard_normal(mesh.n_nodes * 3)
    rep = 7 if quick else 15
    a, b = springs.conn[:, 0].copy(), springs.conn[:, 1].copy()
    t_np = median_time(lambda: numpy_gradient(x, a, b, springs.k, springs.rest_length, x.size), repeat=3)
    t_ref = median_time(lambda: springs.gradient_reference(x), repeat=rep)
    t_fast = median_time(lambda: springs.gradient(x), repeat=rep)
    g, g_ref = springs.gradient(x), springs.gradient_reference(x)
    err = float(np.abs(g - g_ref).max() / np.abs(g_ref).max())
    tag = f"lattice {n}^3 cubes, {s} springs"
    res.add("spring_force_numpy_bincount", s / t_np / 1e6, "M springs/s", 1.0, "itself", tag)
    res.add("spring_force_numba_plain", s / t_ref / 1e6, "M springs/s", t_np / t_ref, "numpy_bincount")
    res.add("spring_force_fast", s / t_fast / 1e6, "M springs/s", t_ref / t_fast, "numba_plain",
            "msslib Springs.gradient", target=(">=", 150, "value"))
    res.add("spring_force_fast_rel_error", err, "(max |g - g_generated| / max |g|)", None, None,
            "against the generated scalar kernel", target=("<=", 1e-12, "value"))
    # bandwidth bound: bytes one pass must move (node-ordered layout)
    _, rowptr, ib, k, L0 = springs.node_layout()
    nbytes = ib.nbytes + k.nbytes + L0.nbytes + rowptr.nbytes + x.nbytes + 2 * x.nbytes  # x read, g read+write
    bw = stream_bandwidth()
    limit = s / (nbytes / bw)
    res.add("stream_copy_bandwidth", bw / 1e9, "GB/s", None, None, "numpy copy, read+write bytes")
    res.add("spring_force_bandwidth_limit", limit / 1e6, "M springs/s", None, None,
            f"{nbytes / s:.1f} bytes/spring per pass at the copy bandwidth")
    res.add("spring_force_fraction_of_bandwidth_limit", (s / t_fast) / limit, "", None, None)

    # ---- Hessian assembly
    model = MD.Model(mesh, [springs])
    model.stiffness(x)  # warm-up (compilation)
    rows, cols = springs.hessian_pattern()
    vals = np.empty((s, 36))

    def coo():
        loops._spring3d_hessian_loop(x, springs.conn, springs.k, springs.rest_length, vals)
        return sp.coo_matrix((vals.ravel(), (rows, cols)), shape=(x.size, x.size)).tocsr()

    # interleaved rounds: the baseline and the fills are timed side by side, so that a change of
    # machine speed during the run (shared hosts) affects both alike
    K_out = model.stiffness(x)
    rounds = 3 if quick else 7
    t_coo_all, t_fill_all, t_refill_all = [], [], []
    for _ in range(rounds):
        t_coo_all.append(median_time(coo, repeat=1, warmup=0))
        t_fill_all.append(median_time(lambda: model.stiffness(x), repeat=3, warmup=0))
        t_refill_all.append(median_time(lambda: model.stiffness(x, out=K_out), repeat=3, warmup=0))
    t_coo, t_fill, t_refill = (float(np.median(t)) for t in (t_coo_all, t_fill_all, t_refill_all))
    K, Kc = model.stiffness(x), coo()
    herr = float(abs(K - Kc).max() / abs(Kc).max())
    res.add("hessian_assembly_scipy_coo", t_coo * 1e3, "ms", 1.0, "itself",
            f"values (numba loop) + COO->CSR, nnz {Kc.nnz}; median of {rounds} rounds interleaved with the fills")
    res.add("hessian_assembly_fast", t_fill * 1e3, "ms", t_coo / t_fill, "scipy_coo",
            "Model.stiffness(x): precomputed CSR pattern, new value array (page faults of a fresh "
            f"{K.data.nbytes / 1e6:.0f} MB allocation included)")
    res.add("hessian_assembly_fast_refill", t_refill * 1e3, "ms", t_coo / t_refill, "scipy_coo",
            "Model.stiffness(x, out=K): precomputed CSR pattern, values refilled in place (as in "
            "Newton iterations)", target=(">=", 30, "ratio"))
    # bandwidth bound of the refill: the value array written (and read for ownership), the
    # layout arrays read once, at the copy bandwidth measured above
    _, rowptr2, nb2, k2, L02 = springs.symmetric_layout()
    nptr, diag_pos, fills = model._block
    moved = 2 * K.data.nbytes + sum(a.nbytes for a in (rowptr2, nb2, k2, L02, fills[0][1], nptr, diag_pos, x))
    t_floor = moved / bw
    res.add("hessian_refill_bandwidth_floor", t_floor * 1e3, "ms", t_coo / t_floor, "scipy_coo",
            f"{moved / 1e6:.0f} MB moved per refill at the best copy bandwidth of this run: an "
            "estimate of the fastest a refill can be")
    res.add("hessian_refill_fraction_of_bandwidth_limit", t_floor / t_refill, "", None, None)
    write = np.empty_like(K.data)
    t_write = median_time(lambda: write.fill(1.0), repeat=rep)
    res.add("hessian_value_array_write", t_write * 1e3, "ms", t_coo / t_write, "scipy_coo",
            "floor: writing the value array once (np.fill), no arithmetic")
    res.add("hessian_assembly_rel_error", herr, "", None, None, "against the COO matrix",
            target=("<=", 1e-12, "value"))

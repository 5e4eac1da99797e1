"""5: Golec's 1,000-element sample (10 x 10 x 10 cubes) for 10 s of simulated time.

Scheme: explicit symplectic Euler (the scheme of ``solvers.integrate(method="symplectic_euler")``)
with mass-proportional damping, at 0.9 x the stability limit 2/omega_max, every step in numba.
Explicit because with a diagonal mass matrix a step costs one force evaluation (~30 us here),
while any implicit step needs a sparse solve of ~3,600 dofs (>= 1 ms with SuperLU/banded
Cholesky, even with the factorisation reused) and would have to take > 30x longer steps to win.

Two kernels, same scheme and physics:

* "after": :class:`msslib.fastexplicit.LatticeExplicit`, structured-lattice kernels
  (structure-of-arrays state, springs grouped by the 13 lattice directions as shifted contiguous
  slices, hexahedron volume term over the cell slots, all loops SIMD-vectorised);
* "before": the generic path, msslib's node-ordered scalar spring kernel and the hexahedron
  volume loop on the interleaved state.

Accuracy: the same scheme with a 10x smaller step (same saved times) is the reference; the error
is the largest nodal position difference over the saved trajectory relative to the largest
displacement.  The two kernels are also compared with each other (round-off only).
"""

from __future__ import annotations

import os
import time

import numpy as np
from numba import njit

from msslib import mesh as M
from msslib import model as MD
from msslib import solvers as S
from msslib import terms as T
from msslib.fastexplicit import LatticeExplicit


@njit(cache=True, nogil=True)
def _explicit_run(x, v, free, inv_m, mass, fext, alpha, h, n_steps, save_every,
                  rowptr, ib, k, L0, hconn, kappa, V0, out):
    g = np.zeros(x.size)
    j = 0
    for step in range(n_steps):
        g[:] = 0.0
        T._spring3d_gradient_fast(x, rowptr, ib, k, L0, g)
        if hconn.shape[0]:
            T._hex_gradient_loop(x, hconn, kappa, V0, g)
        for i in range(x.size):
            if free[i]:
                v[i] += h * (fext[i] - g[i] - alpha * mass[i] * v[i]) * inv_m[i]
                x[i] += h * v[i]
        if (step + 1) % save_every == 0:
            out[j, :] = x
            j += 1
    return j


def sample(nu: float = 0.3, E: float = 2e4, a: float = 0.01, rho: float = 1000.0):
    """10 x 10 x 10 Golec cubes of edge ``a`` (10 cm sample), bottom clamped, gravity -z."""
    mesh = M.hex_grid(10 * a, 10 * a, 10 * a, 10, 10, 10)
    terms = MD.golec_cube_springs(mesh, [(E, nu)], 1.0)
    masses = M.lumped_masses(mesh, rho)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    grav = T.Gravity(masses, [0.0, 0.0, -9.81])
    return MD.Model(mesh, terms + [grav], fixed=fixed, masses=masses), terms


def simulate_generic(model, terms, h, n_steps, save_every, alpha):
    """The "before" path: generic scalar kernels.  Returns (wall, saved states)."""
    springs, hexv = terms
    _, rowptr, ib, k, L0 = springs.node_layout()
    x = model.x0.copy()
    v = np.zeros_like(x)
    fext = model.external_force(1.0)
    out = np.empty((n_steps // save_every, x.size))
    t = time.perf_counter()
    _explicit_run(x, v, model.free, 1.0 / model.mass, model.mass, fext, alpha, h, n_steps, save_every,
                  rowptr, ib, k, L0, hexv.conn, hexv.kappa, hexv.V0, out)
    return time.perf_counter() - t, out


def simulate_fast(fast, model, h, n_steps, save_every, alpha):
    """The "after" path: structured-lattice kernels.  Returns (wall, saved states)."""
    x0 = model.x0
    v0 = np.zeros_like(x0)
    t = time.perf_counter()
    _, _, out = fast.run(x0, v0, h, n_steps, alpha, save_every)
    return time.perf_counter() - t, out


def run(res, quick: bool):
    t_end = 1.0 if quick else 10.0
    alpha = 5.0  # mass-proportional damping (1/s): the sample settles under gravity
    model, terms = sample()
    fast = LatticeExplicit(model)
    dt_crit = S.explicit_stability_limit(model, model.x0)
    h = 0.9 * dt_crit
    n_steps = int(round(t_end / h))
    n_save = 100
    save_every = max(1, n_steps // n_save)
    paper = 2.88 * t_end / 10.0

    # warm up (compile or load the numba caches)
    simulate_fast(fast, model, h, 10, 1, alpha)
    simulate_generic(model, terms, h, 10, 1, alpha)

    repeats = 5
    runs = [simulate_fast(fast, model, h, n_steps, save_every, alpha) for _ in range(repeats)]
    walls = [r[0] for r in runs]
    wall = float(np.median(walls))
    traj = runs[0][1]
    gen = [simulate_generic(model, terms, h, n_steps, save_every, alpha) for _ in range(3)]
    wall_gen = float(np.median([r[0] for r in gen]))
    traj_gen = gen[0][1]
    load = os.getloadavg()[0]

    # reference: same scheme, 10x smaller step, saved at the same times (every 10 save_every steps)
    wall_ref, traj_ref = simulate_fast(fast, model, h / 10, 10 * n_steps, 10 * save_every, alpha)
    disp = np.abs(traj_ref - model.x0).max()
    err = float(np.abs(traj - traj_ref).max() / disp)
    final_err = float(np.abs(traj[-1] - traj_ref[-1]).max() / disp)
    kernel_diff = float(np.abs(traj - traj_gen).max() / disp)

    # one force evaluation (called from Python: includes ~1 us of dispatch)
    P = fast.to_lattice(model.x0 + 1e-3 * np.random.default_rng(0).standard_normal(model.n_dof))
    G = np.empty_like(P)
    fast.gradient_lattice(P, G)
    t_force = np.median([_t(lambda: [fast.gradient_lattice(P, G) for _ in range(200)]) / 200 for _ in range(7)])

    res.add("golec_sample_explicit_wall", wall, "s", paper / wall, "Golec et al. 2.88 s per 10 s on 8 cores",
            f"{t_end:g} s simulated, nu = 0.3, E = 20 kPa, 1 cm cubes, gravity, alpha = {alpha:g}/s, {n_steps} "
            f"steps of {h:.3g} s (0.9 x dt_crit), symplectic Euler, structured-lattice SIMD kernels "
            f"(msslib.fastexplicit), 1 thread; median of {repeats} (min {min(walls):.3g} s, max "
            f"{max(walls):.3g} s), load average {load:.1f}", target=("<=", 0.029 * t_end, "value"))
    res.add("golec_sample_explicit_wall_generic", wall_gen, "s", paper / wall_gen,
            "Golec et al. 2.88 s per 10 s on 8 cores",
            f"before: same run with the generic scalar kernels (terms._spring3d_gradient_fast + "
            f"_hex_gradient_loop), median of 3; after/before speed-up {wall_gen / wall:.2f}x")
    res.add("golec_sample_step_cost", wall / n_steps * 1e6, "us/step", None, None,
            f"after; before {wall_gen / n_steps * 1e6:.0f} us/step; one force evaluation (springs + hex volume) "
            f"{t_force * 1e6:.1f} us called from Python")
    res.add("golec_sample_error_vs_reference", err, "", None, None,
            "max |x - x_ref| over the 100 saved states / max displacement; reference: same scheme, dt/10, same "
            "saved times (first-order scheme: the error against the exact solution is ~1.1x this)")
    res.add("golec_sample_final_error_vs_reference", final_err, "", None, None,
            f"at t = {n_steps * h:.4g} s, relative to the max displacement")
    res.add("golec_sample_kernel_difference", kernel_diff, "", None, None,
            "max |x_after - x_before| over the trajectory / max displacement (round-off: same scheme and forces)")
    res.add("golec_sample_reference_wall", wall_ref, "s", None, None, "dt/10 reference run (fast kernels)")


def _t(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t

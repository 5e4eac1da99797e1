"""The JAX backend of the explicit steps against the numba CPU path, in one run:
``python -m benchmarks.gpu [--quick] [--out FILE.json]``.

Cases (symplectic Euler at 0.9 of the stability limit given by the cheap Gershgorin bound, mass-
proportional damping, gravity, bottom face clamped, fp64):

* generic: :class:`msslib.stepping.jax_backend.JaxNetwork` on the springs of a Golec lattice of
  n^3 cubes (run as a general network: gather + segment_sum), >= 10 M springs when JAX sees a GPU;
* lattice: :class:`msslib.stepping.jax_backend.JaxLattice` on the same kind of lattice with
  Golec's hexahedron volume term (nu = 0.3), the stencil of shifted slices;
* scene: a Lloyd tetrahedral network of about 10 k springs (gmsh cylinder), steps per second of
  one fused call of 1,000 steps and of one step per call.

Each case prints springs, steps/s, spring-steps/s and the ratio to the numba path on one CPU
thread (numba and BLAS pinned to 1 thread) measured on the same network in the same run, beside
the targets on one H100 (>= 10 G spring-steps/s generic at >= 10 M springs, >= 50 G
lattice, >= 10 k steps/s at 10 k springs).  Without a GPU the sizes are smaller (the script says
so) and the figures are JAX's CPU backend: "no GPU: CPU figures only".  The lattices are built
directly from Golec's cube constants (a uniform grid: each pair's constant is the cube constant
times the number of cubes sharing it); the script first checks that construction against
:func:`msslib.models.golec.golec_cube_springs` on a small grid (forces to 1e-12).
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

E, RHO, A_CELL = 1e6, 1000.0, 0.01
TARGETS = {"generic": 10e9, "lattice": 50e9}  # spring-steps/s on one H100
TARGET_SCENE_STEPS = 10e3  # steps/s at 10 k springs
_STEPS13 = [(di, dj, dk) for dk in (-1, 0, 1) for dj in (-1, 0, 1) for di in (-1, 0, 1)
            if next((c for c in (dk, dj, di) if c), 0) > 0]


def golec_arrays(n, nu):
    """Golec's lattice of n^3 cubes of A_CELL (E, nu; A = 1), vectorised from the cube constants:
    ``(mesh, conn, k, rest_length, constants)``."""
    from msslib import mesh as M
    from msslib.models.golec import golec_cube

    mesh = M.hex_grid(n * A_CELL, n * A_CELL, n * A_CELL, n, n, n)
    c = golec_cube(E, nu=nu, a=A_CELL, A=1.0)
    kc = {1: c.k_edge, 2: c.k_face, 3: c.k_inner}
    ids = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)  # [k, j, i]: node i + (n+1)(j + (n+1) k)
    conn, k, L0 = [], [], []
    for step in _STEPS13:
        t = sum(abs(s) for s in step)
        sl_a, sl_b, shared = [], [], []
        for ax in (2, 1, 0):  # array axes z, y, x <- steps dk, dj, di
            s = step[ax]
            sl_a.append(slice(max(0, -s), n + 1 - max(0, s)))
            sl_b.append(slice(max(0, s), n + 1 - max(0, -s)))
            idx = np.arange(n + 1)[sl_a[-1]]
            # cubes sharing the pair along this axis: 1 across it, 1 or 2 (boundary / interior) along it
            shared.append(np.ones(len(idx)) if s else (idx > 0).astype(float) + (idx < n))
        a, b = ids[tuple(sl_a)].ravel(), ids[tuple(sl_b)].ravel()
        mult = (shared[0][:, None, None] * shared[1][None, :, None] * shared[2][None, None, :]).ravel()
        conn.append(np.column_stack([a, b]))
        k.append(kc[t] * mult)
        L0.append(np.full(len(a), A_CELL * np.sqrt(t)))
    return mesh, np.concatenate(conn), np.concatenate(k), np.concatenate(L0), c


def _support(mesh):
    from msslib import mesh as M

    masses = M.lumped_masses(mesh, RHO)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return masses, fixed


def golec_lattice(n, nu, volume):
    """The :class:`msslib.system.Model` of :func:`golec_arrays`, bottom clamped, gravity, with or
    without the volume term."""
    from msslib.system import Model
    from msslib.terms import Gravity, HexVolume, Springs

    mesh, conn, k, L0, c = golec_arrays(n, nu)
    terms = [Springs(conn, k, L0, 3)]
    if volume:
        terms.append(HexVolume(mesh.cells, np.full(len(mesh.cells), c.kappa), np.full(len(mesh.cells), A_CELL ** 3)))
    masses, fixed = _support(mesh)
    return Model(mesh, terms + [Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed, masses=masses)


def check_construction():
    """The vectorised lattice against golec_cube_springs on 3^3 cubes: forces at a perturbed state."""
    from msslib import mesh as M
    from msslib.system import Model
    from msslib.models.golec import golec_cube_springs

    ours = golec_lattice(3, 0.3, True)
    mesh = M.hex_grid(3 * A_CELL, 3 * A_CELL, 3 * A_CELL, 3, 3, 3)
    ref = Model(mesh, golec_cube_springs(mesh, [(E, 0.3)], 1.0) + [ours.terms[-1]], fixed=ours.fixed.reshape(-1, 3),
                masses=ours.mass.reshape(-1, 3)[:, 0])
    x = ours.x0 + 1e-3 * np.random.default_rng(0).standard_normal(ours.n_dof)
    f0, f1 = ref.force(x), ours.force(x)
    err = np.abs(f1 - f0).max() / np.abs(f0).max()
    if not err <= 1e-12:
        raise SystemExit(f"benchmarks.gpu: the vectorised Golec lattice differs from golec_cube_springs by {err:.3g}")
    print(f"lattice construction checked against golec_cube_springs on 3^3 cubes: forces agree to {err:.1e}")


def stable_step(model):
    from msslib import solvers as S

    omega, _ = S.omega_max_bound(model, model.x0)
    return 0.9 * 2.0 / omega


def timed(advance, block, min_wall):
    """(steps, wall) of a run of at least ``min_wall`` seconds (one step first to size it)."""
    t = time.perf_counter()
    advance(1)
    block()
    one = max(time.perf_counter() - t, 1e-7)
    n = int(min(max(min_wall / one, 5), 10**6))
    t = time.perf_counter()
    advance(n)
    block()
    return n, time.perf_counter() - t


def report(rows, name, springs, steps, wall, cpu_rate, target, note=""):
    rate = springs * steps / wall
    row = dict(case=name, springs=int(springs), steps=int(steps), wall_s=wall, steps_per_s=steps / wall,
               spring_steps_per_s=rate, numba_1core_spring_steps_per_s=cpu_rate,
               ratio_to_numba_1core=rate / cpu_rate if cpu_rate else None, target=target, note=note)
    rows.append(row)
    tgt = f"   target (one H100): {target}" if target else ""
    ratio = f"{row['ratio_to_numba_1core']:.2f} x numba 1-core ({cpu_rate / 1e6:.0f} M)" if cpu_rate else ""
    print(f"{name:<22} {springs:>11,d} springs  {steps / wall:>10.1f} steps/s  {rate / 1e9:>8.3f} G spring-steps/s  "
          f"{ratio}{tgt}{('  ' + note) if note else ''}", flush=True)


def generic_case(rows, n, min_wall):
    """The springs of a Golec lattice (nu = 1/4: the volume term vanishes) as a general network,
    given as arrays (no Model: its sparsity pattern is not needed)."""
    from msslib.stepping.jax_backend import CpuNetwork, JaxNetwork

    mesh, conn, k, L0, _ = golec_arrays(n, 0.25)
    masses, fixed = _support(mesh)
    mass = np.repeat(masses, 3)
    free = ~fixed.reshape(-1)
    fext = np.where(free, mass * np.tile([0.0, 0.0, -9.81], mesh.n_nodes), 0.0)
    arrays = dict(x0=mesh.points.reshape(-1), conn=conn, k=k, rest_length=L0, mass=mass, free=free, fext=fext)
    cpu = CpuNetwork(**arrays, h=1e-12, alpha=1.0)  # a step within the cheap bound: the bound, no Lanczos
    h = 0.9 * 2.0 / cpu.stability["omega_max_bound"]
    cpu = CpuNetwork(**arrays, h=h, alpha=1.0)
    steps, wall = timed(cpu.steps, lambda: None, min_wall)
    cpu_rate = cpu.n_springs * steps / wall
    net = JaxNetwork(**arrays, h=h, alpha=1.0)
    steps, wall = timed(net.steps, net.block, min_wall)
    if not np.all(np.isfinite(net.positions())):
        raise SystemExit("benchmarks.gpu: the generic network diverged")
    report(rows, f"generic {n}^3 cubes", net.n_springs, steps, wall, cpu_rate,
           ">= 10 G spring-steps/s at >= 10 M springs", f"unroll {net.unroll}")


def lattice_case(rows, n, min_wall):
    from msslib.stepping import LatticeExplicit
    from msslib.stepping.jax_backend import JaxLattice
    from msslib import solvers as S

    model = golec_lattice(n, 0.3, True)
    x0, v0 = model.x0, np.zeros(model.n_dof)
    bound = S.omega_max_bound(model, x0)[0]  # safe: never below omega_max
    h = 0.9 * 2.0 / bound
    cpu = LatticeExplicit(model, precision="double")
    # LatticeExplicit checks the step against Lanczos' omega_max, kept per start state: the safe
    # Gershgorin bound is given instead (minutes of Lanczos on millions of dofs are not the benchmark)
    cpu._omega_cache = (np.asarray(x0, dtype=float).reshape(-1).copy(), bound)
    steps, wall = timed(lambda k: cpu.run(x0, v0, h, k, 1.0, max(k, 1)), lambda: None, min_wall)
    cpu_rate = cpu.n_springs * steps / wall
    lat = JaxLattice(model).reset(x0, v0, h, 1.0, omega_max=bound)
    steps, wall = timed(lat.steps, lat.block, min_wall)
    if not np.all(np.isfinite(lat.positions())):
        raise SystemExit("benchmarks.gpu: the lattice diverged")
    report(rows, f"lattice {n}^3 cubes", lat.n_springs, steps, wall, cpu_rate, ">= 50 G spring-steps/s",
           f"with {lat.n_hexes:,d} hexahedron volume terms; unroll {lat.unroll}")


def scene_case(rows, min_wall):
    import msslib
    from msslib import mesh as M
    from msslib.stepping.jax_backend import CpuNetwork, JaxNetwork

    mesh = M.cylinder_mesh(0.05, 0.2, 0.01)
    model = msslib.build_model("lloyd_tetrahedron", mesh, msslib.Material(E, 0.25, density=RHO),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0, 0, -9.81]}).model
    h = stable_step(model)
    cpu = CpuNetwork.from_model(model, h, 1.0)
    steps, wall = timed(cpu.steps, lambda: None, min_wall)
    cpu_rate = cpu.n_springs * steps / wall
    net = JaxNetwork.from_model(model, h, 1.0)
    fused = lambda k: [net.steps(1000) for _ in range(max(k // 1000, 1))]  # noqa: E731
    steps, wall = timed(fused, net.block, min_wall)
    steps = max(steps // 1000, 1) * 1000
    report(rows, "scene 1000 steps/call", net.n_springs, steps, wall, cpu_rate, ">= 10 k steps/s at 10 k springs",
           "Lloyd tetrahedra")
    steps, wall = timed(lambda k: [net.steps(1) for _ in range(k)], net.block, min_wall)
    report(rows, "scene 1 step/call", net.n_springs, steps, wall, cpu_rate, "", "one device call per step")
    # agreement on this device: fp64 against numba, fp32 forces against fp64, after 1,000 steps from rest
    size = float(np.ptp(model.x0.reshape(-1, 3), axis=0).max())
    ref = CpuNetwork.from_model(model, h, 1.0).steps(1000).positions()
    x64 = JaxNetwork.from_model(model, h, 1.0).steps(1000).positions()
    x32 = JaxNetwork.from_model(model, h, 1.0, precision="single").steps(1000).positions()
    moved = np.abs(ref - model.x0).max() / size
    e64, e32 = np.abs(x64 - ref).max() / size, np.abs(x32 - ref).max() / size
    rows.append(dict(case="scene agreement after 1000 steps", fp64_vs_numba=e64, fp32_vs_numba=e32, motion=moved))
    print(f"scene after 1000 steps (motion {moved:.2g} of the body's size): fp64 JAX vs numba {e64:.2g}, "
          f"fp32 forces vs numba {e32:.2g} of the body's size", flush=True)
    if not e64 <= 1e-12:
        raise SystemExit(f"benchmarks.gpu: fp64 JAX differs from numba by {e64:.3g} of the body's size")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m benchmarks.gpu", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="shorter timings (and smaller lattices on CPU)")
    ap.add_argument("--out", default="", help="also write the figures to this JSON file")
    args = ap.parse_args(argv)
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    import numba
    from threadpoolctl import threadpool_limits

    numba.set_num_threads(1)
    _limits = threadpool_limits(1)  # noqa: F841 - the numba/BLAS baseline on one core
    from msslib.stepping.jax_backend import available, has_gpu

    t0 = time.perf_counter()
    ok, reason = available()
    if not ok:
        raise SystemExit(f"benchmarks.gpu: the JAX backend is not available: {reason}")
    gpu = has_gpu()
    print(f"backend: {reason}; numba threads {numba.get_num_threads()} (the CPU baseline)")
    if gpu:
        n_generic, n_lattice = 92, (64 if args.quick else 92)
        print(f"GPU: generic network of {n_generic}^3 cubes (>= 10 M springs), lattice of {n_lattice}^3 cubes")
    else:
        n_generic, n_lattice = (16, 20) if args.quick else (24, 32)
        print(f"no GPU: CPU figures only (JAX's CPU backend); sizes chosen for a CPU: generic {n_generic}^3 cubes, "
              f"lattice {n_lattice}^3 cubes; the targets are for one H100")
    min_wall = 0.5 if args.quick else 2.0
    check_construction()
    rows = []
    generic_case(rows, n_generic, min_wall)
    lattice_case(rows, n_lattice, min_wall)
    scene_case(rows, min_wall)
    print("targets (one H100): generic >= 10 G spring-steps/s at >= 10 M springs; lattice >= 50 G; "
          "10 k-spring scene >= 10 k steps/s" + ("" if gpu else "  [no GPU: CPU figures only]"))
    wall = time.perf_counter() - t0
    print(f"wall {wall:.0f} s")
    if args.out:  # atomic: no partial file
        from msslib.results import write_text

        write_text(args.out, json.dumps({"backend": reason, "gpu": gpu, "quick": args.quick, "wall_s": wall,
                                         "cases": rows}, indent=1))
    return rows


def run(res, quick: bool):
    """The GPU cases as figures of ``python -m benchmarks`` (called there when JAX sees a GPU)."""
    for row in main(["--quick"] if quick else []):
        if "spring_steps_per_s" not in row:  # the agreement row
            res.add("gpu_scene_fp64_vs_numba", row["fp64_vs_numba"], "of the body size", None, None,
                    f"after 1000 steps (motion {row['motion']:.2g}); fp32 forces: {row['fp32_vs_numba']:.2g}")
            continue
        res.add(f"gpu_{row['case']}", row["spring_steps_per_s"] / 1e9, "G spring-steps/s",
                row["ratio_to_numba_1core"], "numba, 1 CPU core, same network",
                f"{row['springs']} springs, {row['steps_per_s']:.4g} steps/s; target on one H100: {row['target']}"
                + (f"; {row['note']}" if row["note"] else ""))


if __name__ == "__main__":
    main()

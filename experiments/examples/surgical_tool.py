"""A tool pressed into a soft body, stepped like a surgical simulator would step it.

The liver-like gmsh mesh of :mod:`experiments.examples.liver_plan` (two physical volumes,
``liver`` and a ten times stiffer ``inclusion``; physical surfaces ``base`` and ``capsule``),
Lloyd's tetrahedral springs, the base clamped, gravity.  A rigid tool (the capsule nodes within
``radius`` of the top) is driven down along a path: ``depth`` in ``t_push``, then held.  Every
step the simulator moves the tool, steps the body (symplectic Euler at 0.9 of the stability
limit) and the tool's force is read from the reactions, as a haptic loop would; the history and
the real-time factor (simulated time over wall time) are written as CSV.

    python -m experiments.examples.surgical_tool [OUT_DIR]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from experiments.examples.liver_plan import write_mesh

MATERIALS = {"liver": {"E": 5.0e3, "nu": 0.25, "density": 1060.0},
             "inclusion": {"E": 5.0e4, "nu": 0.25, "density": 1060.0}}


def build(mesh_path, damping: float = 20.0):
    """The model and a simulator at 0.9 of the stability limit."""
    import msslib
    from msslib.stepping import Simulator
    from msslib.solvers import explicit_stability_limit

    setup = msslib.build_model("lloyd_tetrahedron", str(mesh_path), {k: msslib.Material(**v) for k, v in MATERIALS.items()},
                               fixed={"select": {"group": "base"}, "fix": "all"},
                               loads={"type": "gravity", "g": [0.0, 0.0, -9.81]})
    model = setup.model
    dt = 0.9 * explicit_stability_limit(model, model.x0)
    return model, Simulator(model, dt=dt, damping=damping)


def tool_nodes(model, radius: float = 0.02) -> np.ndarray:
    """The capsule nodes within ``radius`` (m) of the top of the body, measured in the plane."""
    capsule = np.unique(model.mesh.facet_groups["capsule"])
    p = model.mesh.points
    top = capsule[np.argmax(p[capsule, 2])]
    near = np.linalg.norm(p[capsule, :2] - p[top, :2], axis=1) <= radius
    return capsule[near]


def press(sim, nodes, depth: float = 0.01, t_push: float = 0.25, t_end: float = 0.6):
    """Drive the tool down by ``depth`` (m) in ``t_push`` (s), hold until ``t_end``; record time, tool
    displacement and tool force (N) after every step, and the wall time of the stepping."""
    path = [[0.0, 0.0, 0.0, 0.0], [t_push, 0.0, 0.0, -depth]]
    sim.prescribe(nodes, path)
    n = int(np.ceil(t_end / sim.dt))
    rows = np.empty((n, 5))
    wall = 0.0
    for i in range(n):
        t0 = time.perf_counter()
        sim.step()
        force = sim.reaction[nodes].sum(axis=0)  # what the tool pushes with (N)
        wall += time.perf_counter() - t0
        rows[i] = (sim.t, sim.displacement[nodes, 2].mean(), *force)
    return rows, wall


def main(out_dir=".", size: str = "0.02"):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    mesh_path = write_mesh(out / "liver.msh", float(size))
    model, sim = build(mesh_path)
    nodes = tool_nodes(model)
    rows, wall = press(sim, nodes)
    header = "time_s,tool_displacement_z_m,tool_force_x_N,tool_force_y_N,tool_force_z_N"
    np.savetxt(out / "tool_force.csv", rows, delimiter=",", header=header, comments="")
    rtf = rows[-1, 0] / wall
    print(f"{model.n_nodes} nodes, {sum(len(t.conn) for t in model.terms if t.kind == 'springs')} springs, "
          f"{len(rows)} steps of {sim.dt * 1e6:.1f} us on the {sim.engine} engine; tool of "
          f"{len(nodes)} nodes pressed {-rows[-1, 1] * 1000:.1f} mm: force {rows[-1, 4]:.4g} N; "
          f"{len(rows) / wall:.0f} steps/s, real-time factor {rtf:.2f} (simulated time over wall time)")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))

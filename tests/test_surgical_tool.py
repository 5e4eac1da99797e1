"""The worked example of the stepping API: a tool driven into a two-material gmsh body; its
force, read from the reactions at every step, settles on the static solution of the same
prescribed displacement (an independent solve), and the tool follows its path exactly."""

import numpy as np
import pytest

from experiments.examples import surgical_tool as ex
from msslib import solvers as S
from msslib.system import Model


def test_example_writes_the_force_history(tmp_path, capsys):
    assert ex.main(tmp_path, "0.03") == 0
    rows = np.loadtxt(tmp_path / "tool_force.csv", delimiter=",", skiprows=1)
    assert rows.shape[1] == 5 and len(rows) > 100
    assert rows[-1, 1] == pytest.approx(-0.01, rel=1e-12)
    out = capsys.readouterr().out
    assert "real-time factor" in out and "network engine" in out


def test_the_held_tool_force_is_the_static_one(tmp_path):
    mesh_path = ex.write_mesh(tmp_path / "liver.msh", 0.03)
    model, sim = ex.build(mesh_path)
    assert sim.engine == "network"
    assert len(np.unique(model.mesh.material)) == 2  # liver and inclusion
    nodes = ex.tool_nodes(model)
    rows, _ = ex.press(sim, nodes, depth=0.005, t_push=0.1, t_end=1.5)
    # the tool followed the ramp at every step
    expected = -0.005 * np.minimum(rows[:, 0] / 0.1, 1.0)
    assert np.abs(rows[:, 1] - expected).max() < 1e-15
    # independent: the static solve with the tool's nodes fixed at the final depth
    fixed = np.array(model.fixed).reshape(-1, 3).copy()
    fixed[nodes] = True
    prescribed = np.zeros((model.n_nodes, 3))
    prescribed[nodes, 2] = -0.005
    static_model = Model(model.mesh, model.terms, fixed=fixed, prescribed=prescribed, masses=model.node_masses)
    static = S.static_solve(static_model, static_model.x0)
    force = static_model.reaction(static.x)[nodes].sum(axis=0)
    assert rows[-1, 4] == pytest.approx(force[2], rel=1e-4)
    assert np.abs(rows[-1, 2:4] - force[:2]).max() < 1e-4 * abs(force[2])

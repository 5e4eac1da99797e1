"""The MuJoCo model of a large mass-spring system loads and steps: the MJCF sizes MuJoCo's arena
from the model (``<size memory>``); MuJoCo's own sizing grows with the tendons times the degrees
of freedom and fails to allocate from about 50 k springs up."""

from __future__ import annotations

import re

import numpy as np
import pytest

from msslib import export
from msslib.export import simulators

G = 9.81


def _cube(n, nz=None):
    """Golec's springs on an n x n x nz grid of 1 cm cubes (nz = n unless given), clamped at x = 0,
    under gravity: 28 springs per cell less the shared ones, 108 860 for 20 x 20 x 20 and 103 499
    for 20 x 20 x 19 (one layer less: just over 100 k springs; 20 x 19 x 19 has 98 402)."""
    nz = n if nz is None else nz
    return {"name": f"cube{n}", "geometry": {"generator": "hex_grid", "args": {
                "lx": 0.01 * n, "ly": 0.01 * n, "lz": 0.01 * nz, "nx": n, "ny": n, "nz": nz}},
            "materials": [{"E": 1.0e5, "nu": 0.3, "density": 1000.0}],
            "model": {"type": "golec_cube", "terms": ["springs"]},
            "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
            "loads": [{"type": "gravity", "g": [0.0, 0.0, -G]}]}


def test_the_memory_follows_the_model():
    assert simulators.mjcf_memory(0, 0, 1, 0) == simulators.MJCF_ARENA_MIN
    per = simulators.MJCF_ARENA_BYTES_PER_ELEMENT
    assert simulators.mjcf_memory(26460, 108860, 9262, 0) == -(-per * 144582 // 2**20) * 2**20  # 18 MiB
    exp = export.build(_cube(2))
    text = simulators.mjcf_text(exp)
    assert re.search(r'<size memory="8M" />', text)


def test_a_model_of_100k_springs_loads_and_steps_in_mujoco():
    mujoco = pytest.importorskip("mujoco")
    exp = export.build(_cube(20, 19))
    assert len(exp.pairs) == 103499 >= 100_000
    text = simulators.mjcf_text(exp)
    memory = int(re.search(r'<size memory="(\d+)M" />', text).group(1)) << 20
    m = mujoco.MjModel.from_xml_string(text)
    assert m.ntendon == len(exp.pairs) and m.nv == 3 * 20 * 21 * 20 and m.narena == memory
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d)
    # from rest, the springs at their rest lengths pull nothing: one step is free fall, v = -g dt
    # (semi-implicit Euler) on every z axis, nothing on x and y
    z = np.array([m.joint(j).name.endswith("_z") for j in range(m.njnt)])
    np.testing.assert_allclose(d.qvel[m.jnt_dofadr[z]], -G * m.opt.timestep, rtol=1e-12)
    np.testing.assert_array_equal(d.qvel[m.jnt_dofadr[~z]], 0.0)
    mujoco.mj_step(m, d, 20)
    assert np.isfinite(d.qpos).all() and d.maxuse_arena + d.maxuse_stack < memory

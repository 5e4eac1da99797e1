"""The README's worked example of a pressurised hollow body, run as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_hollow_body_section_runs_as_written(tmp_path):
    pytest.importorskip("gmsh")
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Pressure loads: an inflated hollow body", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```(bash|python)\n(.*?)```", section, re.S)
    assert [kind for kind, _ in blocks] == ["bash"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    proc = subprocess.run(["bash", "-ec", f'export PATH="{Path(sys.executable).parent}:$PATH"\n{blocks[0][1]}'],
                          cwd=tmp_path, capture_output=True, text=True, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "| max |" in proc.stdout

    from msslib import mesh as M
    from msslib.export.text import read_csv
    from msslib.results import read_result

    mesh = M.read(tmp_path / "hollow.msh")
    walls = np.unique(mesh.facet_groups["inner"])
    for name in ("hollow_mss.nc", "hollow_fem.nc"):
        u = read_result(tmp_path / name)["displacement"].values
        assert np.all(np.einsum("ij,ij->i", u[walls], mesh.points[walls] - 0.5) > 0), name
    table = read_csv(tmp_path / "hollow_export" / "hollow_pressure_0.csv")
    assert len(table["facet"]) == len(mesh.facet_groups["inner"])
    np.testing.assert_array_equal(table["pressure"], 300.0)
    np.testing.assert_array_equal(table["follow"], 1)

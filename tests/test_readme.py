"""The README's quick start, run as written: a user's gmsh mesh with two materials to a ParaView
series, an export with a MuJoCo model, and the same model through the Python API."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def _quick_start_blocks():
    text = README.read_text(encoding="utf-8")
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```(bash|python)\n(.*?)```", section, re.S)


def test_quick_start_runs_as_written(tmp_path):
    blocks = _quick_start_blocks()
    assert [kind for kind, _ in blocks] == ["bash", "python"]
    env_python = Path(sys.executable).parent
    for kind, body in blocks:
        cmd = ["bash", "-ec", f'export PATH="{env_python}:$PATH"\n{body}'] if kind == "bash" else [sys.executable, "-c", body]
        proc = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr[-2000:]

    from msslib.results import read_result

    ds = read_result(tmp_path / "bar.nc")
    # the two materials reached the cells of their groups, the clamp held the base
    assert list(ds["material_name"].values) == ["soft", "stiff"]
    assert sorted(np.unique(ds["cell_material"].values)) == [0, 1]
    x = ds["rest_position"].values[:, 0]
    centroid_x = x[ds["cells"].values].mean(axis=1)
    assert np.all(ds["cell_material"].values[centroid_x < 0.1] == 0) and np.all(ds["cell_material"].values[centroid_x > 0.1] == 1)
    assert np.abs(ds["displacement"].values[np.isclose(x, 0.0)]).max() == 0.0
    assert ds.attrs["inverted_cells"] == 0
    pvd = (tmp_path / "bar.pvd").read_text()
    assert pvd.count("<DataSet") == ds.sizes["time"] == 26
    assert (tmp_path / "bar_springs.vtu").is_file() and (tmp_path / "bar_static.pvd").is_file()
    mjcf = tmp_path / "bar_export" / "bar_mujoco.xml"
    assert mjcf.is_file()
    try:
        import mujoco
    except ImportError:  # pragma: no cover - mujoco is in the test extra
        return
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert model.ntendon == ds.sizes["spring"]


def _section_blocks(title):
    text = README.read_text(encoding="utf-8")
    section = text.split(f"## {title}", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```(bash|python)\n(.*?)```", section, re.S)


def test_model_against_fem_runs_as_written(tmp_path):
    """The quick start's mesh, then the comparison section as written; the numbers behind the table
    are checked from the two result files: each reaction carries the bar's weight, and the error field
    is the distance between the two displacements."""
    mesh_script = _quick_start_blocks()[0][1].split("python3 -m msslib export", 1)[0]
    (kind, body), = _section_blocks("Your model against FEM, on your mesh")
    env_python = Path(sys.executable).parent
    proc = subprocess.run(["bash", "-ec", f'export PATH="{env_python}:$PATH"\n{mesh_script}\n{body}'],
                          cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    import meshio

    from msslib.results import mesh_from_result, read_result
    from msslib.metrics import cell_volumes

    results = [read_result(tmp_path / name) for name in ("bar_mss.nc", "bar_fem.nc")]
    for ds in results:
        weight = 1000.0 * 9.81 * cell_volumes(mesh_from_result(ds)).sum()  # both materials: 1000 kg/m^3
        reaction = ds["reaction_force"].transpose("node", "axis").values
        assert reaction[:, 2].sum() == pytest.approx(weight, rel=1e-6)
    u, u_ref = (ds["displacement"].transpose("node", "axis").values for ds in results)
    distance = np.linalg.norm(u - u_ref, axis=1)
    field = meshio.read(tmp_path / "bar_error.vtu").point_data["error_magnitude"]
    np.testing.assert_allclose(field, distance, rtol=1e-12, atol=1e-15)
    table = (tmp_path / "bar_error.md").read_text()
    assert f"| max | {distance.max():.6g} m |" in table
    assert "(lloyd_tetrahedron) against bar_fem.nc (fem_neohookean)" in table


def test_stepping_section_runs_as_written(tmp_path):
    """The stepping example: a tool pressed into the two-material gmsh liver, its force read back."""
    text = README.read_text(encoding="utf-8")
    section = text.split("## Stepping a simulation yourself", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```(bash|python)\n(.*?)```", section, re.S)
    assert [kind for kind, _ in blocks] == ["python"]
    root = str(README.parent)
    proc = subprocess.run([sys.executable, "-c", blocks[0][1]], cwd=tmp_path, capture_output=True, text=True,
                          env={**__import__("os").environ, "PYTHONPATH": root}, timeout=600)
    assert proc.returncode == 0, proc.stderr
    force = float(re.search(r"tool force (-?[0-9.]+) N", proc.stdout).group(1))
    assert force < -0.5  # the tool pushes down on the body
    assert (tmp_path / "liver.msh").exists()

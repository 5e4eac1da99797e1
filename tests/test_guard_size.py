"""Size guards: runs that cannot fit in memory are refused before anything large is allocated."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from msslib import mesh
from msslib.scene import resources
from msslib.cli import main
from msslib.errors import ResourceError
from msslib.scene import load_scene

STRUCTURED = [
    ("quad_grid", dict(lx=1.0, ly=0.5, nx=7, ny=3)),
    ("triangle_grid_right", dict(lx=1.0, ly=0.5, nx=7, ny=3)),
    ("hexagon_equilateral", dict(height=1.0, n_rings=4)),
    ("hex_grid", dict(lx=1.0, ly=0.5, lz=0.2, nx=5, ny=3, nz=2)),
    ("tet_grid", dict(lx=1.0, ly=0.5, lz=0.2, nx=5, ny=3, nz=2)),
    ("tet_grid", dict(lx=1.0, ly=0.5, lz=0.2, nx=5, ny=3, nz=2, scheme=5)),
]


@pytest.mark.parametrize("generator, args", STRUCTURED)
def test_structured_mesh_size_is_exact(generator, args):
    n_nodes, n_cells, dim = resources.generated_mesh_size(generator, args)
    m = getattr(mesh, generator)(**args)
    assert (n_nodes, n_cells, dim) == (m.n_nodes, m.n_cells, m.dim)


@pytest.mark.parametrize("generator, args", [
    ("l_block_hex", dict(size=1.0, n=6)),
    ("triangle_grid_equilateral", dict(width=1.0, height=0.8, n=9)),
])
def test_nearly_structured_mesh_size_is_close(generator, args):
    n_nodes, n_cells, _ = resources.generated_mesh_size(generator, args)
    m = getattr(mesh, generator)(**args)
    assert m.n_nodes <= n_nodes <= 1.3 * m.n_nodes
    assert 0.85 * m.n_cells <= n_cells <= 1.15 * m.n_cells


@pytest.mark.parametrize("generator, args", [
    ("cylinder_mesh", dict(radius=0.05, height=0.1, h=0.01)),
    ("l_block_tet", dict(size=0.1, h=0.02)),
    ("cone_mesh", dict(r_bottom=0.05, r_top=0.01, height=0.1, h=0.01)),
    ("polygon_mesh", dict(vertices=[(0, 0), (1, 0), (1, 1), (0, 1)], h=0.1)),
])
def test_gmsh_mesh_size_estimate_within_a_factor_three(generator, args):
    n_nodes, n_cells, _ = resources.generated_mesh_size(generator, args)
    m = getattr(mesh, generator)(**args)
    assert m.n_nodes / 3 <= n_nodes <= 3 * m.n_nodes
    assert m.n_cells / 3 <= n_cells <= 3 * m.n_cells


def _scene(nx=4, solver=None, checks=None, output=None):
    d = {
        "geometry": {"generator": "hex_grid", "args": {"lx": 1.0, "ly": 0.1, "lz": 0.1, "nx": nx, "ny": 10, "nz": 10}},
        "materials": [{"E": 1.0e6, "nu": 0.3, "density": 1000.0}],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["x", 0.0]}}],
    }
    for key, value in (("solver", solver), ("checks", checks), ("output", output)):
        if value is not None:
            d[key] = value
    return d


def test_typo_in_resolution_refused_naming_the_generator():
    with pytest.raises(ResourceError, match=r"scene\.geometry \(hex_grid .*nx=100000.*nodes would need about .* GB"):
        load_scene(_scene(nx=100000))


def test_tiny_time_step_refused_naming_the_solver():
    solver = {"type": "dynamic", "dt": 1.0e-9, "t_end": 0.1}
    with pytest.raises(ResourceError, match=r"scene\.solver: 1e\+08 saved states .*history: false"):
        load_scene(_scene(solver=solver))
    # the same run without a stored history is not refused for its memory
    load_scene(_scene(solver=solver, output={"history": False}))


def test_memory_limit_from_the_scene():
    with pytest.raises(ResourceError, match=r"checks\.max_memory_gb = 0\.01"):
        load_scene(_scene(checks={"max_memory_gb": 0.01}))
    load_scene(_scene(checks={"max_memory_gb": 100.0}))
    with pytest.raises(ValueError, match=r"scene\.checks\.max_memory_gb: must be > 0"):
        load_scene(_scene(checks={"max_memory_gb": 0}))


def test_check_memory_refuses_infinite_estimate():
    with pytest.raises(ResourceError, match="more than can be counted"):
        resources.check_memory(float("inf"), "x", "y", limit_gb=1.0)
    resources.check_memory(1e8, "x", "y", limit_gb=1.0)


def test_cli_refuses_in_one_line_and_writes_nothing(tmp_path, capsys):
    import yaml

    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(_scene(nx=100000)))
    out = tmp_path / "out.nc"
    assert main(["run", str(scene), "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("msslib: error: scene.geometry")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_available_memory_is_a_positive_number():
    avail = resources.available_memory()
    assert avail is None or avail > 0


def test_estimate_is_above_the_measured_peak(tmp_path):
    """The per-node cost is an upper bound of a real run's peak resident memory."""
    import yaml

    scene = tmp_path / "s.yaml"
    d = _scene(nx=20)
    d["geometry"]["args"].update(ny=20, nz=20, ly=1.0, lz=1.0)
    d["loads"] = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
    scene.write_text(yaml.safe_dump(d))
    code = textwrap.dedent(f"""
        import resource
        from msslib.scene import run_scene
        run_scene({str(scene)!r}, progress=False)
        print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
    """)
    peak = float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout)
    estimate = resources.run_memory(21 ** 3, 3)
    assert peak < estimate
    # and not absurdly generous: within a factor 3 of the measured peak
    assert estimate < 3 * peak
    assert np.isfinite(estimate)


def test_file_mesh_checked_after_reading(tmp_path):
    """A mesh file is read before its size is known: the dynamic history is checked then."""
    from msslib.scene import prepare

    path = tmp_path / "m.vtu"
    mesh.write_vtu(path, mesh.hex_grid(1.0, 0.1, 0.1, 4, 1, 1))
    d = _scene(solver={"type": "dynamic", "dt": 1.0e-9, "t_end": 0.1})
    d["geometry"] = {"file": "m.vtu"}
    scene = load_scene(d, base_dir=tmp_path)  # size unknown before reading: accepted
    with pytest.raises(ResourceError, match=r"scene\.solver: 1e\+08 saved states of 20 nodes"):
        prepare(scene)


@pytest.mark.parametrize("solver, message", [
    ({"load_steps": 10**30}, r"scene\.solver\.load_steps: must be at most 100000 \(each load step is a Newton solve\)"),
    ({"max_iter": 10**6}, r"scene\.solver\.max_iter: must be at most 10000"),
    ({"type": "dynamic", "dt": 1e-12, "t_end": 1.0}, r"scene\.solver\.dt: t_end / dt = 1e\+12 time steps, more than"),
])
def test_runs_that_cannot_end_are_refused(solver, message):
    with pytest.raises(ValueError, match=message):
        load_scene(_scene(solver=solver, output={"history": False}))


def _refine_must_not_run(monkeypatch):
    import msslib.mesh.refine

    def refused(*args, **kwargs):
        raise AssertionError("the mesh was refined before its size was checked")

    monkeypatch.setattr(msslib.mesh.refine, "uniform", refused)


def test_refined_mesh_size_counts_the_children():
    """Cells exactly (2^dim children each), nodes exactly for a grid of cubes."""
    from msslib.mesh.refine import uniform

    m = mesh.hex_grid(1.0, 0.5, 0.5, 4, 2, 2)
    fine = uniform(m, 2)
    nodes, cells = resources.refined_mesh_size(m.n_nodes, m.n_cells, 3, 2)
    assert cells == fine.n_cells == 16 * 64
    assert fine.n_nodes == 17 * 9 * 9 and nodes >= fine.n_nodes  # about, never below


def test_refined_mesh_file_over_the_limit_refused_before_refining(tmp_path, monkeypatch):
    """``refine:`` on a mesh file: the refined size is estimated from the file before refining."""
    from msslib.scene import prepare

    mesh.write_vtu(tmp_path / "m.vtu", mesh.hex_grid(1.0, 0.1, 0.1, 4, 1, 1))
    d = _scene(checks={"max_memory_gb": 1.0})
    d["geometry"] = {"file": "m.vtu", "refine": 6}
    scene = load_scene(d, base_dir=tmp_path)
    _refine_must_not_run(monkeypatch)
    # 20 nodes x 8^6 = 5.24e+06 nodes x 32 kB (MSS, 3D) + 0.8 GB = 169 GB
    with pytest.raises(ResourceError, match=r"scene\.geometry\.file \(m\.vtu\) refined 6 times \(refine: 6\): "
                                            r"5\.24e\+06 nodes would need about 169 GB, over the limit of 1 GB"):
        prepare(scene)


def test_plan_refuses_levels_of_a_mesh_file_over_the_limit_in_one_line(tmp_path, capsys, monkeypatch):
    import yaml

    mesh.write_vtu(tmp_path / "m.vtu", mesh.tet_grid(1.0, 0.2, 0.2, 5, 1, 1))
    d = _scene()
    d["geometry"] = {"file": "m.vtu"}
    d["model"] = "fem_linear"
    d["loads"] = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(d))
    _refine_must_not_run(monkeypatch)
    code = main(["plan", str(tmp_path / "s.yaml"), "--max-error", "0.2", "--levels", "1,9", "--repeats", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1, err
    assert len(err) == 1, err
    # 24 nodes, 30 cells refined 8 times: 24 x 8^8 = 4.03e+08 nodes, 30 x 8^8 = 5.03e+08 cells
    assert err[0].startswith("msslib: error: --levels 9: the mesh file m.vtu (24 nodes, 30 cells) refined 8 times, "
                             "about 4.03e+08 nodes and 5.03e+08 cells for the fem_neohookean reference would need "
                             "about 4.03e+04 GB"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.vtu", "s.yaml"]


def test_plan_names_the_level_of_a_generated_mesh_over_the_limit(tmp_path, capsys):
    import yaml

    d = _scene(nx=4)
    d["model"] = "fem_linear"
    d["loads"] = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(d))
    code = main(["plan", str(tmp_path / "s.yaml"), "--max-error", "0.2", "--levels", "1,9", "--repeats", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1, err
    assert err[0].startswith("msslib: error: --levels 9: scene.geometry (hex_grid with ") and "refined 8 times" in err[0], err
    assert " GB" in err[0]

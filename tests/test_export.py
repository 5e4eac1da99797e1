"""``msslib export``: the complete mass-spring system of a scene, without solving.

The tables (CSV, JSON) read back equal to the model's terms; the VTU has one line cell per spring;
the MuJoCo model, loaded by the real ``mujoco`` package, has msslib's static equilibrium as its own
(residual at msslib's solution, and a damped run that comes to rest there); the SOFA scene uses
only documented components and attributes and carries the same springs, masses and constraints;
the generated C headers compile warning-free and agrees with the generated Python code; the
command refuses outputs that are inputs and writes all files or none.
"""

from __future__ import annotations

import ctypes
import errno
import hashlib
import importlib
import inspect
import os
import re
import shutil
import subprocess
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from derivations import codegen, registry
from msslib import cli
from msslib.export import simulators as export_simulators
from msslib.export import text as export_text
from msslib.export import files as export_files
from msslib import export
from msslib.solvers import static_solve
from msslib.terms import BaudetCorrection, HexVolume, Springs, TetVolume

# ---- scenes -----------------------------------------------------------------------------------

# The scenes are data (tests/data/export_scenes.yaml): Golec's full model with gravity, his springs
# alone, Lloyd's prestrained 2D square with partial fixing, a prescribed displacement, a traction and
# gravity, Baudet's springs and correction under tension, Lloyd's tetrahedra with the volume term.
_SCENES = yaml.safe_load((Path(__file__).parent / "data" / "export_scenes.yaml").read_text())
GOLEC, SQUARE, BAUDET, LLOYD_TET = (_SCENES[key] for key in ("golec", "square", "baudet", "lloyd_tet"))
GOLEC_SPRINGS = {**GOLEC, "name": "golec_springs", "model": {"type": "golec_cube", "terms": ["springs"]}}


def _scene_file(tmp_path: Path, scene: dict, name: str | None = None) -> Path:
    path = tmp_path / (name or f"{scene['name']}.yaml")
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    return path


def _cli(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    return code, capsys.readouterr().err


def _snapshot(directory: Path) -> dict:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(directory.iterdir()) if p.is_file()}


def _assert_one_error_line(code, err, *names):
    lines = err.splitlines()
    assert code == 1, err
    assert len(lines) == 1 and lines[0].startswith("msslib: error:"), err
    for name in names:
        assert str(name) in lines[0], (name, err)


def _springs(model):
    (s,) = [t for t in model.terms if isinstance(t, Springs)]
    return s


# ---- tables -----------------------------------------------------------------------------------


def test_csv_and_json_round_trip_equal_the_model(tmp_path, capsys):
    scene = _scene_file(tmp_path, GOLEC)
    code, err = _cli(capsys, "export", scene, "--out", f"{tmp_path / 'out'}/", "--format", "csv,json")
    assert code == 0, err
    exp = export.build(scene)
    model = exp.model
    springs = _springs(model)
    (hexv,) = [t for t in model.terms if isinstance(t, HexVolume)]
    out = tmp_path / "out"
    csv_tables = {name: export_text.read_csv(out / f"golec_beam_{name}.csv", name)
                  for name in ("nodes", "springs", "fixed", "loads", "gravity", "hex_volume")}
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [f"golec_beam_{n}.csv" for n in csv_tables] + ["golec_beam.json", "golec_beam.export-manifest.json"])
    doc, json_tables = export_text.read_json(out / "golec_beam.json")
    assert doc["schema"] == export.SCHEMA and doc["schema_version"] == export.SCHEMA_VERSION
    assert doc["units"]["stiffness"] == "N/m" and doc["index_base"] == 0 and doc["dim"] == 3
    assert doc["gravity"] == [0.0, 0.0, -9.81]
    assert [t["kind"] for t in doc["terms"]] == ["springs", "hex_volume"]
    assert set(json_tables) == set(csv_tables)
    for tables in (csv_tables, json_tables):
        sp = tables["springs"]
        assert (sp.columns[3].unit, sp.columns[4].unit) == ("N/m", "m")
        np.testing.assert_array_equal(np.column_stack([sp["node_i"], sp["node_j"]]), springs.pairs)
        np.testing.assert_array_equal(sp["stiffness"], springs.k)  # bit for bit
        np.testing.assert_array_equal(sp["rest_length"], springs.rest_length)
        nodes = tables["nodes"]
        np.testing.assert_array_equal(np.column_stack([nodes["x"], nodes["y"], nodes["z"]]), exp.setup.mesh.points)
        np.testing.assert_array_equal(nodes["mass"], model.node_masses)
        np.testing.assert_array_equal(nodes["mass"], exp.setup.masses)
        fixed = tables["fixed"]
        np.testing.assert_array_equal(fixed["node"], np.flatnonzero(exp.setup.fixed.any(axis=1)))
        assert fixed["fixed_x"].sum() == 4 and np.all(fixed["u_z"] == 0)
        hv = tables["hex_volume"]
        np.testing.assert_array_equal(np.column_stack([hv[f"node_{a}"] for a in range(8)]), hexv.conn)
        np.testing.assert_array_equal(hv["kappa"], hexv.kappa)
        np.testing.assert_array_equal(hv["V0"], hexv.V0)
        assert tables["loads"].n_rows == 0
        np.testing.assert_array_equal([tables["gravity"][f"g_{a}"][0] for a in "xyz"], [0.0, 0.0, -9.81])
        # the total weight the tables imply is the model's
        np.testing.assert_allclose(nodes["mass"].sum() * 9.81, 1000.0 * 0.2 * 0.05 * 0.05 * 9.81, rtol=1e-12)


@pytest.mark.parametrize("scene", [SQUARE, BAUDET, LLOYD_TET], ids=lambda s: s["name"])
def test_tables_carry_every_term(scene, tmp_path):
    exp = export.build(_scene_file(tmp_path, scene))
    tables = {name: export_text.read_csv(_write(tmp_path / f"{name}.csv", export_text.csv_text(t)), name)
              for name, t in exp.tables().items()}
    springs = _springs(exp.model)
    np.testing.assert_array_equal(tables["springs"]["stiffness"], springs.k)
    np.testing.assert_array_equal(tables["springs"]["rest_length"], springs.rest_length)
    loads = tables["loads"]
    full = np.zeros_like(exp.setup.surface_forces)
    full[loads["node"]] = np.column_stack([loads[f"f_{a}"] for a in "xyz"[:exp.dim]])
    np.testing.assert_array_equal(full, exp.setup.surface_forces)
    assert loads.n_rows > 0
    fixed = tables["fixed"]
    mask = np.zeros_like(exp.setup.fixed)
    disp = np.zeros_like(exp.setup.prescribed)
    mask[fixed["node"]] = np.column_stack([fixed[f"fixed_{a}"] for a in "xyz"[:exp.dim]]).astype(bool)
    disp[fixed["node"]] = np.column_stack([fixed[f"u_{a}"] for a in "xyz"[:exp.dim]])
    np.testing.assert_array_equal(mask, exp.setup.fixed)
    np.testing.assert_array_equal(disp, exp.setup.prescribed)
    if scene is SQUARE:  # Lloyd's prestrain: rest lengths 6/5 and 6/7 of the distances
        d = np.linalg.norm(np.diff(exp.points[springs.pairs], axis=1)[:, 0], axis=1)
        np.testing.assert_allclose(np.unique(np.round(springs.rest_length / d, 12)), [6 / 7, 6 / 5])
        assert fixed["u_y"].max() == 0.002
    if scene is BAUDET:
        (corr,) = [t for t in exp.model.terms if isinstance(t, BaudetCorrection)]
        np.testing.assert_array_equal(tables["baudet_correction"]["factor"], corr.factor)
        np.testing.assert_array_equal(tables["baudet_correction"]["face_force_3"], corr.face_force[:, 3])
        f = tables["baudet_correction_forces"]
        full = np.zeros((exp.n_nodes, 3))
        full[f["node"]] = np.column_stack([f["f_x"], f["f_y"], f["f_z"]])
        np.testing.assert_array_equal(full, corr.nodal)
        assert np.abs(corr.nodal).max() > 0
    if scene is LLOYD_TET:
        (tet,) = [t for t in exp.model.terms if isinstance(t, TetVolume)]
        np.testing.assert_array_equal(tables["tet_volume"]["k_v"], tet.k_v)
        np.testing.assert_array_equal(tables["tet_volume"]["V0"], tet.V0)
        assert tables["tet_volume"].columns[5].unit == "J"


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_vtu_has_one_line_cell_per_spring(tmp_path, capsys):
    import meshio

    scene = _scene_file(tmp_path, SQUARE)
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "sq", "--format", "vtu")
    assert code == 0, err
    exp = export.build(scene)
    springs = _springs(exp.model)
    m = meshio.read(tmp_path / "sq.vtu")
    assert [c.type for c in m.cells] == ["line"]
    np.testing.assert_array_equal(m.cells[0].data, springs.pairs)
    np.testing.assert_array_equal(m.cell_data["stiffness"][0], springs.k)
    np.testing.assert_array_equal(m.cell_data["rest_length"][0], springs.rest_length)
    np.testing.assert_array_equal(m.point_data["mass"], exp.model.node_masses)
    np.testing.assert_array_equal(m.point_data["fixed"][:, :2], exp.setup.fixed.astype(int))
    np.testing.assert_array_equal(m.point_data["prescribed_displacement"][:, 1], exp.setup.prescribed[:, 1])


# ---- MuJoCo -----------------------------------------------------------------------------------


def _mujoco():
    try:
        import mujoco
    except ImportError as exc:  # the test extra installs it
        pytest.skip(f"mujoco is not importable ({exc}); `pip install -e '.[test]'` installs it")
    return mujoco


@pytest.mark.parametrize("scene", [GOLEC_SPRINGS, SQUARE, BAUDET], ids=lambda s: s["name"])
def test_mujoco_model_rests_at_msslib_equilibrium(scene, tmp_path, capsys):
    """MuJoCo loads the exported model; its forces vanish at msslib's static equilibrium (to 1e-9
    of the applied forces), and a damped MuJoCo run from the rest configuration comes to rest at it
    (within 1e-7 of the largest displacement)."""
    mujoco = _mujoco()
    path = _scene_file(tmp_path, scene)
    code, err = _cli(capsys, "export", path, "--out", tmp_path / "m", "--format", "mjcf")
    assert code == 0, err
    assert "warning" not in err  # springs-only models: the MJCF carries the whole model
    exp = export.build(path)
    model = exp.model
    text = (tmp_path / "m_mujoco.xml").read_text()
    assert "carries the whole mass-spring system" in text
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "m_mujoco.xml"))
    d = mujoco.MjData(m)
    springs = _springs(model)
    assert m.ntendon == len(springs.pairs) and m.nbody == exp.n_nodes + 1
    np.testing.assert_array_equal(m.tendon_stiffness, springs.k)
    np.testing.assert_array_equal(m.tendon_lengthspring[:, 0], springs.rest_length)
    np.testing.assert_array_equal(m.tendon_lengthspring[:, 1], springs.rest_length)
    np.testing.assert_array_equal(m.body_mass[1:], exp.masses)
    assert m.nv == int((~exp.setup.fixed).sum())  # one slide joint per free axis
    dofs = []
    for j in range(m.njnt):
        node, axis = re.fullmatch(r"node(\d+)_([xyz])", m.joint(j).name).groups()
        dofs.append((int(node), "xyz".index(axis), m.jnt_qposadr[j], m.jnt_dofadr[j]))
    start = exp.points + exp.prescribed

    def positions():
        x = start.copy()
        for node, a, q, _ in dofs:
            x[node, a] += d.qpos[q]
        return x

    res = static_solve(model, model.x0, load_steps=4, tol=1e-12)
    x_star = res.x.reshape(-1, exp.dim)
    u_max = np.abs(x_star - exp.points).max()
    assert u_max > 1e-4  # a real deformation
    for node, a, q, _ in dofs:
        d.qpos[q] = x_star[node, a] - start[node, a]
    mujoco.mj_forward(m, d)
    residual = d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias
    scale = np.abs(model.external_force(1.0)).sum()
    assert scale > 0
    assert np.abs(residual).max() <= 1e-9 * scale, (np.abs(residual).max(), scale)
    # brought to rest: mass-proportional damping critical for the slowest mode, MuJoCo's own step
    free = model.free
    K = model.stiffness(res.x).toarray()[np.ix_(free, free)]
    mass = model.mass[free]
    omega_min = np.sqrt(np.linalg.eigvalsh(K / np.sqrt(np.outer(mass, mass))).min())
    mujoco.mj_resetData(m, d)
    for node, _, _, dof in dofs:
        m.dof_damping[dof] = 2.0 * omega_min * exp.masses[node]
    mujoco.mj_step(m, d, int(30.0 / omega_min / m.opt.timestep) + 1)
    err_x = np.abs(positions() - x_star).max()
    assert err_x <= 1e-7 * u_max, (err_x, u_max)


def test_volume_terms_are_not_offered_silently(tmp_path, capsys):
    mujoco = _mujoco()
    scene = _scene_file(tmp_path, GOLEC)
    code, err = _cli(capsys, "export", scene, "--out", f"{tmp_path / 'd'}/")
    assert code == 0, err
    names = sorted(p.name for p in (tmp_path / "d").iterdir())
    assert "golec_beam_mujoco.xml" not in names and "golec_beam.scn" not in names
    assert "golec_beam.json" in names and "msslib_mss.h" in names
    (warn,) = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert "mjcf and sofa not written" in warn and "hex_volume" in warn
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "e", "--format", "mjcf,sofa")
    assert code == 0, err
    warns = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert len(warns) == 2 and all("volume energy" in w for w in warns)
    for name in ("e_mujoco.xml", "e.scn"):
        parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
        root = ET.parse(tmp_path / name, parser=parser).getroot()
        comments = " ".join(c.text for c in root.iter(ET.Comment))
        assert "NOT CARRIED" in comments and "kappa/(2 V0)" in comments and "hex_volume" in comments
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "e_mujoco.xml"))  # the springs-only part loads
    assert m.ntendon == len(_springs(export.build(scene).model).pairs)


# ---- SOFA -------------------------------------------------------------------------------------


@pytest.mark.parametrize("scene", [SQUARE, BAUDET, GOLEC_SPRINGS], ids=lambda s: s["name"])
def test_sofa_scene_uses_documented_names_and_carries_the_model(scene, tmp_path, capsys):
    path = _scene_file(tmp_path, scene)
    code, err = _cli(capsys, "export", path, "--out", tmp_path / "s", "--format", "sofa")
    assert code == 0, err
    exp = export.build(path)
    root = ET.parse(tmp_path / "s.scn").getroot()
    elements = [e for e in root.iter() if isinstance(e.tag, str)]
    for e in elements:
        assert e.tag in export_simulators.SOFA_COMPONENTS, e.tag
        for attr in e.attrib:
            assert attr in export_simulators.SOFA_COMPONENTS[e.tag]["attributes"], (e.tag, attr)
    by_tag = {}
    for e in elements:
        by_tag.setdefault(e.tag, []).append(e)
    used = {e.tag for e in elements}
    plugins = {e.get("name") for e in by_tag["RequiredPlugin"]}
    assert plugins == {export_simulators.SOFA_COMPONENTS[t]["plugin"] for t in used} - {None, "Sofa.Simulation.Core"}
    springs = _springs(exp.model)
    (ff,) = by_tag["SpringForceField"]
    q = np.array(ff.get("spring").split(), dtype=float).reshape(-1, 5)  # i j ks kd L
    np.testing.assert_array_equal(q[:, :2].astype(int), springs.pairs)
    np.testing.assert_array_equal(q[:, 2], springs.k)
    np.testing.assert_array_equal(q[:, 4], springs.rest_length)
    (mass,) = by_tag["DiagonalMass"]
    np.testing.assert_array_equal(np.array(mass.get("vertexMass").split(), dtype=float), exp.masses)
    (mo,) = by_tag["MechanicalObject"]
    assert mo.get("template") == f"Vec{exp.dim}d"
    np.testing.assert_array_equal(np.array(mo.get("position").split(), dtype=float).reshape(-1, exp.dim),
                                  exp.points + exp.prescribed)
    fixed = np.zeros_like(exp.fixed)
    for e in by_tag.get("FixedProjectiveConstraint", []):
        fixed[np.array(e.get("indices").split(), dtype=int)] = True
    for e in by_tag.get("PartialFixedProjectiveConstraint", []):
        fixed[np.array(e.get("indices").split(), dtype=int)] |= np.array(e.get("fixedDirections").split(), dtype=int) == 1
    np.testing.assert_array_equal(fixed, exp.fixed)
    forces = np.zeros_like(exp.loads)
    for e in by_tag.get("ConstantForceField", []):
        forces[np.array(e.get("indices").split(), dtype=int)] += np.array(e.get("forces").split(), dtype=float).reshape(-1, exp.dim)
    expected = exp.loads + (0 if exp.correction is None else exp.correction.nodal)
    np.testing.assert_allclose(forces, expected, rtol=0, atol=1e-15 * np.abs(expected).max(initial=1.0))
    assert ("StaticSolver" in used) != ("EulerImplicitSolver" in used)
    g = np.array(root.get("gravity").split(), dtype=float)
    np.testing.assert_array_equal(g[:exp.dim], np.zeros(exp.dim) if exp.gravity is None else exp.gravity)


# ---- C header ---------------------------------------------------------------------------------


def _compiler():
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler (cc or gcc) on this machine")
    return cc


def _python_functions():
    out = {}
    for m in registry.generated():
        gen = importlib.import_module(f"msslib.generated.{m}")
        for name, outputs in gen.OUTPUTS.items():
            out[name] = (getattr(gen, name), outputs)
    return out


def test_c_header_compiles_and_matches_the_python_code(tmp_path):
    cc = _compiler()
    header = export.C_HEADER_PATH
    functions = _python_functions()
    included = re.findall(r'^#include "(msslib_\w+\.h)"$', header.read_text(), flags=re.M)
    assert included == [codegen.c_header(m) for m in registry.generated()]  # one header per module
    declared = [name for h in included for name in re.findall(r"^MSSLIB_API (?:double|void) msslib_(\w+)\(",
                                                              (header.parent / h).read_text(), flags=re.M)]
    assert sorted(declared) == sorted(functions)  # every generated formula and kernel, nothing else, once
    src = tmp_path / "use.c"
    src.write_text('#include "msslib_mss.h"\n')
    flags = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", f"-I{header.parent}"]
    for h in included:  # each module's header stands alone
        alone = tmp_path / f"alone_{h}.c"
        alone.write_text(f'#include "{h}"\n')
        subprocess.run([cc, *flags, "-c", str(alone), "-o", str(tmp_path / "alone.o")], check=True, capture_output=True)
    # as shipped (static inline; strict C99 and the compiler's default dialect) and compiled into a
    # shared library (external linkage)
    subprocess.run([cc, *flags, "-c", str(src), "-o", str(tmp_path / "use.o")], check=True, capture_output=True)
    subprocess.run([cc, *flags[1:], "-Wshadow", "-c", str(src), "-o", str(tmp_path / "use.o")], check=True,
                   capture_output=True)
    lib_path = tmp_path / "libmss.so"
    subprocess.run([cc, *flags, "-O1", "-fPIC", "-shared", "-DMSSLIB_API=", str(src), "-o", str(lib_path), "-lm"],
                   check=True, capture_output=True)
    lib = ctypes.CDLL(str(lib_path))
    rng = np.random.default_rng(20240611)
    worst = 0.0
    for name, (pyf, outputs) in functions.items():
        args = list(inspect.signature(pyf).parameters)
        cf = getattr(lib, f"msslib_{name}")
        n_out = len(outputs)
        cf.argtypes = [ctypes.c_double] * len(args) + ([ctypes.POINTER(ctypes.c_double)] if n_out > 1 else [])
        cf.restype = ctypes.c_double if n_out == 1 else None
        for _ in range(8):
            vals = [float(rng.uniform(0.05, 0.45)) if a == "nu" else float(rng.uniform(-1.0, 1.0))
                    if re.fullmatch(r"[xyz]\d+", a) else float(rng.uniform(0.5, 2.0)) for a in args]
            py = np.atleast_1d(np.asarray(pyf(*vals), dtype=float))
            if n_out == 1:
                c = np.array([cf(*vals)])
            else:
                buf = (ctypes.c_double * n_out)()
                cf(*vals, buf)
                c = np.array(buf[:])
            assert py.shape == (n_out,) and np.all(np.isfinite(py)), name
            err = np.abs(c - py).max() / np.abs(py).max()
            worst = max(worst, err)
            assert err <= 1e-12, (name, vals, err)
    assert worst <= 1e-12


def test_codegen_check_covers_the_c_header(tmp_path, monkeypatch):
    out = tmp_path / "generated"
    shutil.copytree(codegen.OUT, out, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(codegen, "OUT", out)
    monkeypatch.setattr(codegen, "ROOT", tmp_path)
    assert codegen.check() == []
    name = f"generated/c/{codegen.c_header('triangle')}"
    path = tmp_path / name
    original = path.read_text()
    path.write_text(original.replace("(1.0/4.0)*sqrt(3)*E*t", "(1.0/3.0)*sqrt(3)*E*t"))
    assert codegen.check() == [f"{name} was edited by hand"]
    path.unlink()
    assert codegen.check() == [f"{name} is missing"]
    path.write_text(original)
    umbrella = out / "c" / codegen.C_UMBRELLA
    umbrella.write_text(umbrella.read_text().replace('#include "msslib_square.h"\n', ""))
    assert codegen.check() == [f"generated/c/{codegen.C_UMBRELLA} does not include exactly the generated modules"]
    umbrella.unlink()
    assert codegen.check() == [f"generated/c/{codegen.C_UMBRELLA} is missing"]
    umbrella.write_text(codegen.render_c_umbrella())
    api = out / "c" / codegen.C_API
    api.write_text(api.read_text().replace("static inline", "static"))
    assert codegen.check() == [f"generated/c/{codegen.C_API} differs from what the code generator writes"]
    api.unlink()
    assert codegen.check() == [f"generated/c/{codegen.C_API} is missing"]


def test_codegen_check_finds_a_stale_c_header(monkeypatch):
    real = codegen.source_hash
    monkeypatch.setattr(codegen, "source_hash", lambda m: "0" * 64 if m == "cube_golec" else real(m))
    assert codegen.check() == [
        f"msslib/generated/{f} is stale: derivations/elements/cube_golec.py or the engine changed"
        for f in ("cube_golec.py", f"c/{codegen.c_header('cube_golec')}")]


def test_export_copies_the_c_headers(tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "b", "--format", "c")
    assert code == 0, err
    headers = sorted(export.C_HEADER_PATH.parent.glob("*.h"))
    assert len(headers) == len(registry.generated()) + 2  # the modules', the include list, msslib_api.h
    assert sorted(p.name for p in tmp_path.glob("*.h")) == [h.name for h in headers]
    for h in headers:
        assert (tmp_path / h.name).read_bytes() == h.read_bytes()


# ---- the command: inputs, outputs, errors ------------------------------------------------------


def test_outputs_that_are_inputs_are_refused(tmp_path, capsys, monkeypatch):
    # a scene written as JSON (JSON is YAML): its own JSON export would overwrite it
    scene = tmp_path / "model.json"
    scene.write_text(__import__("json").dumps(BAUDET))
    before = _snapshot(tmp_path)
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "model", "--format", "csv,json")
    _assert_one_error_line(code, err, "model.json", "scene file")
    assert _snapshot(tmp_path) == before
    # the scene's mesh file
    import meshio

    mesh_dir = tmp_path / "m"
    mesh_dir.mkdir()
    mesh = export.build(scene).setup.mesh
    meshio.write(mesh_dir / "bar.vtu", meshio.Mesh(mesh.points, [("hexahedron", mesh.cells)]))
    with_file = {**BAUDET, "geometry": {"file": "bar.vtu"}}
    path = _scene_file(mesh_dir, with_file, "s.yaml")
    before = _snapshot(mesh_dir)
    code, err = _cli(capsys, "export", path, "--out", mesh_dir / "bar", "--format", "json,vtu")
    _assert_one_error_line(code, err, "bar.vtu", "mesh file")
    assert _snapshot(mesh_dir) == before
    # the header the c format copies
    fake = tmp_path / "gen" / "msslib_mss.h"
    fake.parent.mkdir()
    fake.write_text("/* header */\n")
    monkeypatch.setattr(export, "C_HEADER_PATH", fake)
    code, err = _cli(capsys, "export", path, "--out", fake.parent / "x", "--format", "json,c")
    _assert_one_error_line(code, err, "generated C header")
    assert sorted(p.name for p in fake.parent.iterdir()) == ["msslib_mss.h"]


def test_all_outputs_or_none(tmp_path, capsys, monkeypatch):
    scene = _scene_file(tmp_path, BAUDET)
    out = tmp_path / "out"
    out.mkdir()
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json,sofa")
    assert code == 0, err
    before = _snapshot(out)
    assert len(before) == 10  # 7 tables, JSON, SOFA, the export manifest

    def fail(_exp):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(export_simulators, "sofa_text", fail)
    monkeypatch.setattr(export_text, "json_text", lambda e: '{"changed": true}\n')
    code, err = _cli(capsys, "export", scene, "--out", f"{out}/", "--format", "csv,json,sofa")
    _assert_one_error_line(code, err, "baudet_bar.scn")
    assert _snapshot(out) == before  # the JSON written before the failure was not put in place
    assert not [p for p in out.iterdir() if "msslib-tmp" in p.name]


@pytest.mark.parametrize("argv, expected", [
    (["--format", "csv,foo"], "'foo' is not a format"),
    (["--format", "csv,csv"], "given twice"),
    (["--format", ""], "separated by commas"),
])
def test_bad_formats(argv, expected, tmp_path, capsys):
    scene = _scene_file(tmp_path, BAUDET)
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "x", *argv)
    _assert_one_error_line(code, err, expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["baudet_bar.yaml"]


def test_fem_scene_is_refused(tmp_path, capsys):
    scene = _scene_file(tmp_path, {**BAUDET, "model": "fem_linear"})
    code, err = _cli(capsys, "export", scene, "--out", tmp_path / "x")
    _assert_one_error_line(code, err, "fem_linear", "FEM reference")


def test_python_api_without_files():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        exp = export.build(LLOYD_TET)
    assert export_files.default_formats(exp) == ("csv", "json", "vtu", "c")
    assert export.not_carried(exp, "mjcf") and not export.not_carried(exp, "json")
    assert export_files.parse_formats("c,csv") == ("csv", "c")
    assert os.path.basename(export_files.output_paths(exp, Path("a/b"), ("mjcf",))[0][2]) == "b_mujoco.xml"


def test_dynamic_scene_damping_and_time_step(tmp_path, capsys):
    mujoco = _mujoco()
    scene = {**GOLEC_SPRINGS, "name": "swing",
             "solver": {"type": "dynamic", "method": "velocity_verlet", "dt": 1.0e-4, "t_end": 0.01,
                        "damping": [5.0, 1.0e-4]}}
    path = _scene_file(tmp_path, scene)
    code, err = _cli(capsys, "export", path, "--out", tmp_path / "w", "--format", "mjcf,sofa")
    assert code == 0, err
    (warn,) = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert "mjcf" in warn and "beta" in warn  # MuJoCo gets alpha only, and says so
    exp = export.build(path)
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "w_mujoco.xml"))
    assert m.opt.timestep == 1.0e-4
    node_of_dof = [int(re.fullmatch(r"node(\d+)_[xyz]", m.joint(j).name).group(1)) for j in range(m.njnt)]
    np.testing.assert_allclose(m.dof_damping, 5.0 * exp.masses[node_of_dof], rtol=1e-15)
    root = ET.parse(tmp_path / "w.scn").getroot()
    (ode,) = root.iter("EulerImplicitSolver")
    assert (float(ode.get("rayleighMass")), float(ode.get("rayleighStiffness"))) == (5.0, 1.0e-4)
    assert float(root.get("dt")) == 1.0e-4 and not list(root.iter("StaticSolver"))

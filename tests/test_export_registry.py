"""Every model of the registry (msslib.models) exports: each builds a small scene and is written in
every format; its JSON reads back with the model's own spring constants, rest lengths and the
constants of its other terms (read from the term objects' own attributes); a format that cannot
carry a term says so, naming the model and the term, in the file and on the command line."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml

from cell_helpers import example_geometry
from cli_helpers import run_cli
from msslib import export, models
from msslib.mesh import cells
from msslib.export import files as export_files
from msslib.export.text import read_csv, read_json

SPECS = models.registry()
#: (model, options): every MSS model with its default options, and Baudet's element reading
CASES = [(name, {}) for name, spec in SPECS.items() if spec.kind == "mss"] + [("baudet_cube", {"correction": "element"})]

_GEOMETRY = {cell: example_geometry(cell) for cell in cells.names()}  # the cell registry's examples, 1 cm


def _scene(name, opts):
    spec = SPECS[name]
    dim = spec.dim
    axis = "y" if dim == 2 else "z"
    raw = {"name": "scene", "geometry": _GEOMETRY[spec.cell_type],
           "materials": [{"E": 1.0e6, "nu": 0.3, "density": 1000.0}],
           "model": {"type": name, **{o.name: o.default for o in spec.options}, **opts},
           "boundary": [{"select": {"plane": [axis, 0.0]}, "fix": "all"}],
           "loads": [{"type": "nodal_force", "select": {"box": [[None] * dim, [None] * dim]}, "total": [1e-2] * dim}],
           "solver": {"type": "static", "load_steps": 1, "tol": 1e-10}}
    if dim == 2:
        raw["thickness"] = 0.001
    return raw


def _expected_columns(term):
    """The columns a term's table must hold, read from the term's own attributes (not its tables)."""
    name = type(term).__name__
    if name == "TetVolume":
        return "tet_volume", {"k_v": term.k_v, "V0": term.V0}, term.conn
    if name == "HexVolume":
        return "hex_volume", {"kappa": term.kappa, "V0": term.V0}, term.conn
    if name == "BaudetCorrection":
        return "baudet_correction", {"factor": term.factor, **{f"face_force_{f}": term.face_force[:, f]
                                                               for f in range(6)}}, None
    if name == "ElementBaudetCorrection":
        return "baudet_element_correction", {"k_edge": term.k[:, 0], "k_diagonal": term.k[:, 15],
                                             "factor": term.factor}, term.cells
    if name == "TriangleAngular":
        Q = term.Q
        return "delingette_triangle", {"k_01": Q[:, 0, 0], "k_12": Q[:, 1, 1], "k_02": Q[:, 2, 2],
                                       "c_01_12": Q[:, 1, 0], "c_12_02": Q[:, 2, 1], "c_01_02": Q[:, 2, 0],
                                       "L2_01": term.L2[:, 0], "L2_12": term.L2[:, 1], "L2_02": term.L2[:, 2]}, \
            term.conn
    # any other term: the per-cell constants it declares (variable, attribute, unit, long name) are
    # columns of its table named by the variable, holding the attribute's values
    declared = getattr(term, "cell_constants", ())
    assert declared, f"term {name} declares no cell_constants: declare them (or give this test its columns)"
    columns = {var: getattr(term, attr) for var, attr, *_ in declared}
    if name == "TetrahedronEdges":  # optional: columns beyond the declared constants (Kikuuwe's rest lengths)
        columns.update({f"L2_{n}": term.L2[:, i] for i, n in enumerate(("01", "02", "03", "12", "13", "23"))})
    return term.export_name, columns, getattr(term, "conn", None)


def _build(name, opts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return export.build(_scene(name, opts))


@pytest.mark.parametrize("name,opts", CASES, ids=[n + "".join(f"-{v}" for v in o.values()) for n, o in CASES])
def test_model_exports_to_every_format_and_json_round_trips(tmp_path, name, opts):
    exp = _build(name, opts)
    stem = tmp_path / "m"
    planned = export_files.output_paths(exp, stem, export.formats.names())
    assert {fmt for fmt, *_ in planned} == set(export.formats.names())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        written = export_files.write_outputs(exp, stem, planned)
    assert all(p.is_file() and p.stat().st_size > 0 for p in written)

    doc, tables = read_json(tmp_path / "m.json")
    model = exp.model
    springs = [t for t in model.terms if type(t).__name__ == "Springs"]
    pairs = np.concatenate([t.pairs for t in springs]) if springs else np.zeros((0, 2), dtype=int)
    k = np.concatenate([t.k for t in springs]) if springs else np.zeros(0)
    rest = np.concatenate([t.rest_length for t in springs]) if springs else np.zeros(0)
    s = tables["springs"]
    np.testing.assert_array_equal(np.column_stack([s["node_i"], s["node_j"]]).reshape(-1, 2), pairs)
    np.testing.assert_array_equal(s["stiffness"], k)  # floats written by repr: bit for bit
    np.testing.assert_array_equal(s["rest_length"], rest)
    np.testing.assert_array_equal(tables["nodes"]["x"], model.mesh.points[:, 0])

    others = [t for t in model.terms if type(t).__name__ not in ("Springs", "NodalForces", "Gravity")]
    assert [e["table"] for e in doc["terms"][1:]] == [_expected_columns(t)[0] for t in others]
    for t in others:
        table, columns, conn = _expected_columns(t)
        assert table in tables, (name, table, sorted(tables))
        for col, values in columns.items():
            np.testing.assert_array_equal(tables[table][col], values, err_msg=f"{name} {table}.{col}")
        if conn is not None:
            for a in range(conn.shape[1]):
                np.testing.assert_array_equal(tables[table][f"node_{a}"], conn[:, a])
        unit = {c.name: c.unit for c in tables[table].columns}
        assert all(unit[c] is not None for c in columns), unit  # every constant has its unit
        # the CSV table is the same table
        csv = read_csv(tmp_path / f"m_{table}.csv")
        for col, values in columns.items():
            np.testing.assert_array_equal(csv[col], values)
    # the JSON's own energy count equals the term's element count
    for entry, t in zip(doc["terms"][1:], others):
        assert entry["count"] == len(tables[entry["table"]]["cell"])


def test_delingette_constants_are_the_derived_triangle_constants():
    """The exported constants of one triangle equal msslib.models.delingette.delingette_triangle of
    that triangle's own shape (an independent evaluation of the derived formulas)."""
    from msslib.models.delingette import delingette_triangle

    exp = _build("delingette_triangle", {})
    t = exp.tables()["delingette_triangle"]
    p = exp.setup.mesh.points[[t["node_0"][3], t["node_1"][3], t["node_2"][3]]]
    e1, e2 = p[1] - p[0], p[2] - p[0]
    a = np.linalg.norm(e1)
    c = delingette_triangle(1.0e6, nu=0.3, t=0.001, a=a, x2=e1 @ e2 / a, y2=abs(e1[0] * e2[1] - e1[1] * e2[0]) / a)
    for col in ("k_01", "k_12", "k_02", "c_01_12", "c_12_02", "c_01_02"):
        assert t[col][3] == pytest.approx(getattr(c, col), rel=1e-12)
    assert t["L2_01"][3] == pytest.approx(a * a, rel=1e-12)


@pytest.mark.parametrize("name,opts,table", [("delingette_triangle", {}, "delingette_triangle"),
                                             ("baudet_cube", {"correction": "element"}, "baudet_element_correction"),
                                             ("golec_cube", {}, "hex_volume")])
def test_springs_only_formats_name_model_and_term(tmp_path, capsys, name, opts, table):
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(_scene(name, opts)), encoding="utf-8")
    code, err = run_cli(capsys, "export", scene, "--out", f"{tmp_path / 'd'}/")
    assert code == 0, err
    (warn,) = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert "mjcf and sofa not written" in warn and f"model {name}" in warn and table in warn
    written = sorted(p.name for p in (tmp_path / "d").iterdir())
    assert f"scene_{table}.csv" in written and "scene.json" in written
    assert not any(n.endswith((".scn", "_mujoco.xml")) for n in written)

    code, err = run_cli(capsys, "export", scene, "--out", tmp_path / "e", "--format", "mjcf,sofa")
    assert code == 0, err
    warns = [line for line in err.splitlines() if line.startswith("msslib: warning:")]
    assert len(warns) == 2 and all(f"model {name}" in w and table in w and "does not carry" in w for w in warns)
    for file in ("e_mujoco.xml", "e.scn"):
        parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
        root = ET.parse(tmp_path / file, parser=parser).getroot()
        comments = " ".join(c.text for c in root.iter(ET.Comment))
        assert "NOT CARRIED" in comments and table in comments and f"model {name}" in comments


def test_a_term_that_does_not_describe_itself_is_refused():
    """A term without an export kind is never left out silently: the exporter names it and the model."""
    from msslib.scene import load_scene, prepare
    from msslib.terms import Term

    class Strange(Term):
        def energy(self, x):
            return 0.0

    setup = prepare(load_scene(_scene("lloyd_triangle", {})))
    setup.model.terms.append(Strange())
    with pytest.raises(ValueError, match=r"cannot export a term of type Strange \(model lloyd_triangle\)"):
        export.from_setup(setup)


def test_format_help_lists_every_format():
    from msslib.cli import build_parser

    help_text = " ".join(build_parser()._subparsers._group_actions[0].choices["export"].format_help().split())
    for f in export.formats.table():
        assert f"{f.name}: {' '.join(f.help.split())}" in help_text
    assert export.formats.names() == ("csv", "json", "vtu", "mjcf", "sofa", "c")
    assert export.formats.whole_only() == ("mjcf", "sofa")

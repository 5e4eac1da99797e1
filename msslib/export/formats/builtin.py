"""The six built-in export formats: CSV, JSON, VTU, MuJoCo, SOFA and the generated C headers
(what each writes: :mod:`msslib.export`)."""

from __future__ import annotations

from msslib.export import simulators, text
from msslib.export.formats import Format, one_file, text_writer
from msslib.export.model import C_HEADER_PATH, c_header_paths


def _csv_files(exp, stem):
    return [(f"CSV table {name}", stem.with_name(f"{stem.name}_{name}.csv"), name) for name in exp.tables()]


def _c_files(exp, stem):
    return [(f"C header {p.name}", stem.with_name(p.name), p.name) for p in c_header_paths()]


def _c_header(exp, table):
    return text_writer(lambda: (C_HEADER_PATH.parent / (table or C_HEADER_PATH.name)).read_text(encoding="utf-8"))


FORMATS = (
    Format("csv", 10, _csv_files, lambda exp, table: text_writer(lambda: text.csv_text(exp.tables()[table])),
           "every table: nodes, springs, fixed, loads, gravity and each term's own tables",
           "one table per file STEM_TABLE.csv, header row with units"),
    Format("json", 20, one_file("JSON document", ".json"), lambda exp, table: text_writer(lambda: text.json_text(exp)),
           "every table and term, with a schema version", "one document STEM.json with a schema version"),
    Format("vtu", 30, one_file("VTU file", ".vtu"), lambda exp, table: lambda path: text.write_vtu(path, exp),
           "the springs as line cells, masses, fixed axes, loads and the terms' constant forces",
           "springs as line cells STEM.vtu (ParaView)"),
    Format("mjcf", 40, one_file("MuJoCo model", "_mujoco.xml"),
           lambda exp, table: text_writer(lambda: simulators.mjcf_text(exp)),
           "the springs as tendons, masses, fixed axes, loads, gravity and constant forces",
           "a MuJoCo model STEM_mujoco.xml (springs only: other terms are named in a note)", whole_only=True),
    Format("sofa", 50, one_file("SOFA scene", ".scn"), lambda exp, table: text_writer(lambda: simulators.sofa_text(exp)),
           "the springs, masses, fixed axes, loads and constant forces",
           "a SOFA scene STEM.scn (springs only: other terms are named in a note)", whole_only=True),
    Format("c", 60, _c_files, _c_header,
           "the generated C headers (the formulas and kernels of every term)", "the generated C headers msslib_mss.h"),
)

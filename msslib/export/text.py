"""The table formats of ``msslib export``: CSV (one file per table), JSON (one document) and VTU
(the springs for ParaView), with readers of the CSV and JSON; see :mod:`msslib.export.model`."""

from __future__ import annotations

import csv
import io
import json
import math
import re
from pathlib import Path

import numpy as np

from msslib.export.model import SCHEMA, SCHEMA_VERSION, UNITS, Column, MssExport, Table, _pad3, _version

# --------------------------------------------------------------------------------------------
# CSV and JSON
# --------------------------------------------------------------------------------------------


def _cell(v) -> str:
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"cannot export the non-finite value {v!r}")
    return repr(v)


def csv_text(table: Table) -> str:
    """A table as CSV: a header row ``name [unit]``, one row per entry, floats by ``repr``."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([c.header for c in table.columns])
    cols = [c.values.tolist() for c in table.columns]
    for row in zip(*cols):
        w.writerow([_cell(v) for v in row])
    return buf.getvalue()


_HEADER = re.compile(r"^(?P<name>[^\[\]]+?)(?: \[(?P<unit>[^\[\]]+)\])?$")


def read_csv(path, name: str | None = None) -> Table:
    """Read a table written by :func:`csv_text` (integer columns as ints, the rest as floats)."""
    path = Path(path)
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise ValueError(f"{path}: empty CSV file, expected a header row")
    columns = []
    for j, head in enumerate(rows[0]):
        m = _HEADER.match(head)
        if m is None:
            raise ValueError(f"{path}: column header {head!r} is not 'name [unit]'")
        raw = [r[j] for r in rows[1:]]
        is_int = all(re.fullmatch(r"-?\d+", s) for s in raw) and (m["unit"] is None)
        values = np.array([int(s) for s in raw], dtype=np.int64) if is_int else np.array([float(s) for s in raw])
        columns.append(Column(m["name"], m["unit"], values))
    return Table(name or path.stem, "", columns)


def json_document(exp: MssExport) -> dict:
    """The export as one JSON-able document (see the module docstring)."""
    scene = exp.scene
    terms = [{"kind": "springs", "count": int(len(exp.pairs)), "table": "springs",
              "energy": "k/2 (|x_j - x_i| - L)^2", "conservative": True, "scales_with_load": False}]
    terms += [t.export_entry() for t in exp.terms]
    tables = {}
    for name, t in exp.tables().items():
        tables[name] = {"description": t.description,
                        "columns": [{"name": c.name, "unit": c.unit, "description": c.description,
                                     "values": c.values.tolist()} for c in t.columns]}
    opts = {k: (list(v) if isinstance(v, tuple) else v) for k, v in scene.model_options.items()}
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION,
        "generator": f"msslib {_version()}",
        "scene": {"name": scene.name, "description": scene.description, "model": scene.model,
                  "model_options": opts, "solver": _plain(scene.solver), "text": scene.text},
        "dim": exp.dim, "index_base": 0, "units": UNITS,
        "n_nodes": exp.n_nodes, "mass_source": exp.mass_source,
        "gravity": None if exp.gravity is None else exp.gravity.tolist(),
        "load_factor": 1.0,
        "damping": {"alpha": exp.damping[0], "beta": exp.damping[1],
                    "meaning": "Rayleigh damping C = alpha M + beta K of a dynamic scene (0 for static scenes)"},
        "terms": terms, "tables": tables,
    }


def _plain(value):
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value




def json_text(exp: MssExport) -> str:
    return json.dumps(json_document(exp), indent=1, allow_nan=False) + "\n"


def read_json(path) -> tuple[dict, dict[str, Table]]:
    """``(document, tables)`` of a JSON export; ValueError if it is not one of this schema."""
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise ValueError(f"{path}: not an {SCHEMA} document")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise ValueError(f"{path}: schema version {doc.get('schema_version')!r}, this msslib reads {SCHEMA_VERSION}")
    tables = {}
    for name, t in doc["tables"].items():
        cols = []
        for c in t["columns"]:
            v = c["values"]
            arr = np.array(v, dtype=np.int64) if all(isinstance(x, int) for x in v) and c["unit"] is None \
                else np.array(v, dtype=float)
            cols.append(Column(c["name"], c["unit"], arr, c.get("description", "")))
        tables[name] = Table(name, t.get("description", ""), cols)
    return doc, tables


# --------------------------------------------------------------------------------------------
# VTU
# --------------------------------------------------------------------------------------------




def write_vtu(path, exp: MssExport) -> Path:
    """The springs as VTK line cells with cell data ``stiffness`` (N/m) and ``rest_length`` (m), on
    the rest positions, with point data ``mass`` (kg), ``fixed`` (0/1 per axis),
    ``prescribed_displacement`` (m), ``load`` (N) and the constant forces of the terms
    (``baudet_correction``, N, when present: :meth:`MssExport.forces`).  A model without springs
    has one vertex cell per mass instead, and no cell data: a VTU file without cells is valid VTK,
    but meshio cannot read it back."""
    import meshio

    point_data = {"mass": exp.masses, "fixed": _pad3(exp.fixed.astype(np.int8)),
                  "prescribed_displacement": _pad3(exp.prescribed), "load": _pad3(exp.loads)}
    for label, forces, _ in exp.forces():
        point_data[label] = _pad3(forces)
    if len(exp.pairs):
        cells = [("line", exp.pairs.astype(np.int64))]
        cell_data = {"stiffness": [exp.stiffness], "rest_length": [exp.rest_length]}
    else:
        cells, cell_data = [("vertex", np.arange(len(exp.points), dtype=np.int64)[:, None])], {}
    mesh = meshio.Mesh(_pad3(exp.points), cells, point_data=point_data, cell_data=cell_data)
    meshio.write(path, mesh, file_format="vtu")
    from msslib.export import formats
    from msslib.export.model import not_carried

    missing = not_carried(exp, "vtu")
    if any(t.kind == "external" for t in exp.terms if not formats.get("vtu").carries_term(t)):
        # a load the file cannot hold (a follower pressure): said in an XML comment after the declaration
        note = ("NOT CARRIED (a ParaView file of the model at rest): " + "; ".join(missing).replace("--", "- -")
                + ". The CSV/JSON export carries them.")
        raw = Path(path).read_bytes()
        head, sep, rest = raw.partition(b"?>")
        Path(path).write_bytes(head + sep + f"\n<!-- {note} -->".encode() + rest if sep else
                               f"<!-- {note} -->\n".encode() + raw)
    return Path(path)

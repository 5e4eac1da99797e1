"""The formats and file names of ``msslib export``: which formats a model can be written in, the
paths of the outputs, and the writer of each (:class:`msslib.io.StagedOutputs` writes them
together). ``not_carried`` is re-exported for the command line."""

from __future__ import annotations

from pathlib import Path

from . import export_simulators, export_text
from .export import C_HEADER_PATH, FORMATS, SPRINGS_ONLY_FORMATS, MssExport, _safe_name, c_header_paths, not_carried  # noqa: F401

# --------------------------------------------------------------------------------------------
# formats and file names
# --------------------------------------------------------------------------------------------


def parse_formats(text: str | None) -> tuple[str, ...] | None:
    """``"csv,mjcf"`` -> ``("csv", "mjcf")`` in :data:`FORMATS` order; None for None (the default).
    ValueError naming an unknown or repeated format."""
    if text is None:
        return None
    items = [s.strip() for s in text.split(",")]
    if not text.strip() or any(not s for s in items):
        raise ValueError(f"--format {text!r}: give formats separated by commas, from {','.join(FORMATS)}")
    for s in items:
        if s not in FORMATS:
            raise ValueError(f"--format {text!r}: {s!r} is not a format; expected some of {','.join(FORMATS)}")
        if items.count(s) > 1:
            raise ValueError(f"--format {text!r}: {s!r} is given twice")
    return tuple(f for f in FORMATS if f in items)


def default_formats(exp: MssExport) -> tuple[str, ...]:
    """Every format that carries the whole model: MuJoCo and SOFA only without volume terms."""
    return tuple(f for f in FORMATS if not (f in SPRINGS_ONLY_FORMATS and exp.volume_terms))






def output_paths(exp: MssExport, stem: Path, formats) -> list[tuple[str, str, Path, str | None]]:
    """``(format, what, path, table)`` of every file the formats write (``table``: the table of a
    CSV file, else None), ``stem`` the path prefix: CSV ``STEM_TABLE.csv``, JSON ``STEM.json``, VTU
    ``STEM.vtu``, MuJoCo ``STEM_mujoco.xml``, SOFA ``STEM.scn``, C ``msslib_mss.h`` and the headers it
    includes in the stem's directory (``table``: the header's file name)."""
    stem = Path(stem)
    out = []
    for fmt in formats:
        if fmt == "csv":
            out += [("csv", f"CSV table {name}", stem.with_name(f"{stem.name}_{name}.csv"), name)
                    for name in exp.tables()]
        elif fmt == "json":
            out.append(("json", "JSON document", stem.with_name(f"{stem.name}.json"), None))
        elif fmt == "vtu":
            out.append(("vtu", "VTU file", stem.with_name(f"{stem.name}.vtu"), None))
        elif fmt == "mjcf":
            out.append(("mjcf", "MuJoCo model", stem.with_name(f"{stem.name}_mujoco.xml"), None))
        elif fmt == "sofa":
            out.append(("sofa", "SOFA scene", stem.with_name(f"{stem.name}.scn"), None))
        elif fmt == "c":
            out += [("c", f"C header {p.name}", stem.with_name(p.name), p.name) for p in c_header_paths()]
        else:
            raise ValueError(f"unknown format {fmt!r}")
    return out


def file_writer(exp: MssExport, fmt: str, table: str | None = None):
    """``writer(path)`` that writes one output of ``fmt`` (for :class:`msslib.io.StagedOutputs`,
    which then names the destination in any error)."""
    def text(make):
        def write(path):
            Path(path).write_text(make(), encoding="utf-8")
        return write

    if fmt == "csv":
        return text(lambda: export_text.csv_text(exp.tables()[table]))
    if fmt == "json":
        return text(lambda: export_text.json_text(exp))
    if fmt == "vtu":
        return lambda path: export_text.write_vtu(path, exp)
    if fmt in ("mjcf", "sofa"):
        make = export_simulators.mjcf_text if fmt == "mjcf" else export_simulators.sofa_text
        return text(lambda: make(exp))
    if fmt == "c":
        return text(lambda: (C_HEADER_PATH.parent / (table or C_HEADER_PATH.name)).read_text(encoding="utf-8"))
    raise ValueError(f"unknown format {fmt!r}")


def stem_for(out: Path, scene_name: str, directory: bool) -> Path:
    """The path prefix of the outputs: ``out / NAME`` in a directory, else ``out`` itself."""
    return Path(out) / _safe_name(scene_name) if directory else Path(out)

"""The formats and file names of ``msslib export``: which formats a model can be written in, the
paths of the outputs, the writer of each, and :func:`write_outputs`, which writes them all or none
with a manifest of what the export owns.

The manifest (``STEM.export-manifest.json``, :data:`MANIFEST_SCHEMA`) lists every file the export
wrote with its SHA-256. A later export to the same stem replaces those files and removes the ones it
no longer writes (a previous ``--format csv,json`` export's tables when the next is ``--format
json``), but only those: a file that no manifest in the folder lists, or that changed since msslib
wrote it, is never overwritten (the export is refused, naming it) and never removed.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import secrets
import shutil
import warnings
from pathlib import Path

from msslib.errors import MsslibWarning
from msslib.export import formats as format_table
from msslib.export.model import MssExport, _safe_name
from msslib.export.model import _version
from msslib.results.staging import TEMP_TAG, StagedOutputs, terminate_raises

MANIFEST_SCHEMA = "msslib-export-manifest"
MANIFEST_SUFFIX = ".export-manifest.json"

# --------------------------------------------------------------------------------------------
# formats and file names
# --------------------------------------------------------------------------------------------


def format_help() -> str:
    """The help of ``msslib export --format``, from the format table (:mod:`msslib.export.formats`)."""
    return ("formats separated by commas (default: every format that carries the whole model): "
            + "; ".join(f"{f.name}: {f.help}" for f in format_table.table()))


def parse_formats(text: str | None) -> tuple[str, ...] | None:
    """``"csv,mjcf"`` -> ``("csv", "mjcf")`` in the table's order; None for None (the default).
    ValueError naming an unknown or repeated format."""
    if text is None:
        return None
    known = format_table.names()
    items = [s.strip() for s in text.split(",")]
    if not text.strip() or any(not s for s in items):
        raise ValueError(f"--format {text!r}: give formats separated by commas, from {','.join(known)}")
    for s in items:
        if s not in known:
            raise ValueError(f"--format {text!r}: {s!r} is not a format; expected some of {','.join(known)}")
        if items.count(s) > 1:
            raise ValueError(f"--format {text!r}: {s!r} is given twice")
    return tuple(f for f in known if f in items)


def default_formats(exp: MssExport) -> tuple[str, ...]:
    """Every format that carries the whole model: the springs-only formats (MuJoCo, SOFA) only when
    they carry every term of the model."""
    return tuple(f.name for f in format_table.table()
                 if not f.whole_only or all(f.carries_term(t) for t in exp.terms))


def output_paths(exp: MssExport, stem: Path, formats) -> list[tuple[str, str, Path, str | None]]:
    """``(format, what, path, table)`` of every file the formats write (``table``: the table of a
    CSV file, else None), ``stem`` the path prefix: CSV ``STEM_TABLE.csv``, JSON ``STEM.json``, VTU
    ``STEM.vtu``, MuJoCo ``STEM_mujoco.xml``, SOFA ``STEM.scn``, C ``msslib_mss.h`` and the headers it
    includes in the stem's directory (``table``: the header's file name)."""
    stem = Path(stem)
    return [(fmt, what, path, table) for fmt in formats for what, path, table in format_table.get(fmt).files(exp, stem)]


def file_writer(exp: MssExport, fmt: str, table: str | None = None):
    """``writer(path)`` that writes one output of ``fmt`` (for :class:`msslib.results.staging.StagedOutputs`,
    which then names the destination in any error)."""
    return format_table.get(fmt).writer(exp, table)


def stem_for(out: Path, scene_name: str, directory: bool) -> Path:
    """The path prefix of the outputs: ``out / NAME`` in a directory, else ``out`` itself."""
    return Path(out) / _safe_name(scene_name) if directory else Path(out)


# --------------------------------------------------------------------------------------------
# writing: all files or none, with a manifest of what the export owns
# --------------------------------------------------------------------------------------------


def manifest_path(stem: Path) -> Path:
    """The manifest of the export with path prefix ``stem``: ``STEM.export-manifest.json``."""
    stem = Path(stem)
    return stem.with_name(stem.name + MANIFEST_SUFFIX)


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(path: Path) -> dict[str, str] | None:
    """``{file name: sha256}`` of an export manifest, None if ``path`` is not one (missing,
    unreadable, another schema). Only plain file names in the manifest's own folder are kept."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or doc.get("schema") != MANIFEST_SCHEMA or not isinstance(doc.get("files"), dict):
        return None
    return {name: digest for name, digest in doc["files"].items()
            if isinstance(name, str) and isinstance(digest, str) and name not in ("", ".", "..")
            and Path(name).name == name and "/" not in name and "\\" not in name}


def _manifests(directory: Path) -> dict[Path, dict[str, str]]:
    """Every export manifest in ``directory``, by path."""
    out = {}
    if directory.is_dir():
        for path in sorted(directory.glob("*" + MANIFEST_SUFFIX)):
            files = read_manifest(path)
            if files is not None and path.is_file() and not path.is_symlink():
                out[path] = files
    return out


def _plain_file(path: Path) -> bool:
    return path.is_file() and not path.is_symlink()


def _ownership(stem: Path, planned) -> list[Path]:
    """Refuse (FileExistsError naming it) an output that would replace a file no export manifest of
    the folder lists with its present content; returns the files the previous export of ``stem``
    owned that this one does not write and no other manifest lists (to remove once written)."""
    stem = Path(stem)
    manifests = _manifests(stem.parent)
    own = manifest_path(stem)
    targets = [(path, what) for _, what, path, _ in planned]
    for path, what in targets:
        if not os.path.lexists(path):
            continue
        listed = [files[path.name] for files in manifests.values() if path.name in files]
        if _plain_file(path) and listed and _digest(path) in listed:
            continue
        why = ("has changed since msslib export wrote it" if listed else
               f"was not written by msslib export (no {MANIFEST_SUFFIX} in the folder lists it)")
        raise FileExistsError(f"{what} {str(path)!r} exists and {why}: refusing to overwrite it; move it away or "
                              f"export to another folder or --out prefix")
    if os.path.lexists(own) and own not in manifests:
        raise FileExistsError(f"export manifest {str(own)!r} exists and is not one (schema {MANIFEST_SCHEMA}): "
                              f"refusing to overwrite it; move it away or export elsewhere")
    previous = manifests.pop(own, {})
    written = {path.name for path, _ in targets}
    others = {name for files in manifests.values() for name in files}
    stale = []
    for name, digest in previous.items():
        path = stem.parent / name
        if name in written or name in others or not os.path.lexists(path):
            continue
        if _plain_file(path) and _digest(path) == digest:
            stale.append(path)
        else:
            warnings.warn(f"{str(path)!r}, written by the previous export to {str(stem)!r}, has changed since: left in "
                          f"place (this export does not write it)", MsslibWarning, stacklevel=3)
    return stale


def _manifest_text(exp: MssExport, stem: Path, formats, digests: dict[str, str]) -> str:
    return json.dumps({"schema": MANIFEST_SCHEMA, "schema_version": 1, "generator": f"msslib {_version()}",
                       "scene": exp.scene.name, "stem": Path(stem).name, "formats": list(formats),
                       "meaning": "the files this export wrote (sha256 of each); a later export to the same "
                                  "stem replaces or removes exactly these", "files": digests},
                      indent=1, sort_keys=False) + "\n"


def _hashing(writer, name: str, digests: dict[str, str]):
    def write(path):
        writer(path)
        digests[name] = _digest(Path(path))
    return write


def write_outputs(exp: MssExport, stem: Path, planned) -> list[Path]:
    """Write the outputs ``planned`` (:func:`output_paths` of ``stem``) and their manifest, all or
    none; returns the paths written, the manifest last.

    Into an existing folder the files are staged beside their targets and renamed into place
    together (:class:`msslib.results.staging.StagedOutputs`); then the files that the previous export to
    ``stem`` owned and this one does not write are removed (see the module docstring: nothing else
    is ever removed, and a file that is not the export's is never overwritten: FileExistsError).
    A folder that does not exist yet is built as a hidden temporary folder beside it and renamed
    into place at the end, so a failed export leaves nothing behind (no empty folder either)."""
    stem = Path(stem)
    formats = list(dict.fromkeys(fmt for fmt, *_ in planned))
    directory = stem.parent
    top = None
    while not os.path.lexists(directory):
        top, directory = directory, directory.parent
    if top is not None:
        return _write_new_folder(exp, stem, planned, formats, top)
    stale = _ownership(stem, planned)
    digests: dict[str, str] = {}
    with StagedOutputs() as staged:  # every file, or none
        for fmt, what, path, table in planned:
            staged.write(path, _hashing(file_writer(exp, fmt, table), path.name, digests), what=what)
        staged.write_text(manifest_path(stem), _manifest_text(exp, stem, formats, digests), what="export manifest")
    for path in stale:
        try:
            path.unlink()
        except OSError as exc:
            warnings.warn(f"{str(path)!r}, written by the previous export to {str(stem)!r} and not by this one, could "
                          f"not be removed: {exc.strerror or exc}", MsslibWarning, stacklevel=2)
    return [path for _, _, path, _ in planned] + [manifest_path(stem)]


_TEMP_FOLDER = re.compile(r"^\.(?P<name>.+)\." + TEMP_TAG + r"-(?P<pid>\d+)-[0-9a-f]+$")


def _remove_stale_folders(top: Path) -> None:
    """Remove the temporary folders that exports of ``top`` killed outright left beside it."""
    try:
        names = os.listdir(top.parent)
    except OSError:
        return
    for name in names:
        m = _TEMP_FOLDER.match(name)
        if m is None or m["name"] != top.name or int(m["pid"]) == os.getpid():
            continue
        try:
            os.kill(int(m["pid"]), 0)
            continue  # its process still runs
        except ProcessLookupError:
            shutil.rmtree(top.parent / name, ignore_errors=True)
        except OSError:
            continue


def _named(exc: Exception, dest: Path, what: str) -> Exception:
    """``exc`` raised while writing into the temporary folder, re-made to name ``dest``."""
    if isinstance(exc, OSError) and exc.errno is not None:
        new = type(exc)(exc.errno, f"cannot write {what}: {exc.strerror or exc}", str(dest))
    else:
        try:
            new = type(exc)(f"cannot write {what} {str(dest)!r}: {' '.join(str(exc).split())}")
        except Exception:
            new = OSError(f"cannot write {what} {str(dest)!r}: {' '.join(str(exc).split())}")
    new.msslib_output = str(dest)  # the command line reports it as one line
    return new


def _write_new_folder(exp: MssExport, stem: Path, planned, formats, top: Path) -> list[Path]:
    _remove_stale_folders(top)
    temp = top.parent / f".{top.name}.{TEMP_TAG}-{os.getpid()}-{secrets.token_hex(4)}"
    inner = temp / stem.parent.relative_to(top)
    digests: dict[str, str] = {}
    with terminate_raises():
        try:
            inner.mkdir(parents=True)
            for fmt, what, path, table in planned:
                target = inner / path.name
                try:
                    file_writer(exp, fmt, table)(target)
                except Exception as exc:
                    raise _named(exc, path, what) from exc
                digests[path.name] = _digest(target)
            (inner / manifest_path(stem).name).write_text(_manifest_text(exp, stem, formats, digests),
                                                          encoding="utf-8")
            try:
                os.rename(temp, top)  # the whole folder appears at once
            except OSError as exc:
                raise _named(exc, top, "output directory") from exc
        except BaseException:
            shutil.rmtree(temp, ignore_errors=True)
            raise
    return [path for _, _, path, _ in planned] + [manifest_path(stem)]

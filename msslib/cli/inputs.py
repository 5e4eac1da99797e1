"""Inputs and outputs of the command line, checked before anything runs.

Every check ends in a :class:`CommandError`, which :func:`msslib.cli.main` prints as one line with
exit code 1: inputs that are missing, unreadable or not UTF-8, outputs that equal an input or each
other, outputs in a directory that cannot be written, result files without what a command needs.
ParaView outputs (one ``.vtu`` or a ``.pvd`` series) are staged here with the other outputs.
"""

from __future__ import annotations

import os
from pathlib import Path

class CommandError(Exception):
    """A user-facing error reported as one line with exit code 1."""


def one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


# --------------------------------------------------------------------------------------------
# inputs and outputs: checked before anything runs
# --------------------------------------------------------------------------------------------


def same_file(a: Path, b: Path) -> bool:
    """``a`` and ``b`` name one file: the same resolved path, or (existing files) the same inode
    (hard links, symbolic links, other spellings)."""
    try:
        if a.resolve() == b.resolve():
            return True
    except (OSError, RuntimeError):  # a symlink loop
        pass
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _file_keys(path: Path) -> list:
    """What identifies the file ``path`` names: its resolved path and, for an existing file, its
    device and inode (hard links, symbolic links, other spellings); two paths name one file when
    they share a key (as :func:`same_file` decides)."""
    keys = []
    try:
        keys.append(("path", str(path.resolve())))
    except (OSError, RuntimeError):  # a symlink loop
        pass
    try:
        st = os.stat(path)
        keys.append(("inode", st.st_dev, st.st_ino))
    except (OSError, ValueError):
        pass
    return keys


def check_distinct(outputs, inputs=()) -> None:
    """Refuse an output that is one of the inputs or another output (pairs ``(what, path)``).

    Linear in the number of paths (a series of 10 000 files is checked in a fraction of a second):
    each path is looked up by its keys (:func:`_file_keys`) in a dict."""
    known_inputs: dict = {}
    for what_in, src in inputs:
        if src is not None:
            for key in _file_keys(Path(src)):
                known_inputs.setdefault(key, (what_in, Path(src)))
    known_outputs: dict = {}
    for what, out in outputs:
        if out is None:
            continue
        out = Path(out)
        keys = _file_keys(out)
        for key in keys:
            if key in known_inputs:
                what_in, src = known_inputs[key]
                raise CommandError(f"{what} {str(out)!r} is the {what_in} {str(src)!r}: refusing to overwrite "
                                   f"an input; give another {what}")
        for key in keys:
            if key in known_outputs:
                what_other, other = known_outputs[key]
                raise CommandError(f"{what} {str(out)!r} and {what_other} {str(other)!r} are the same file; "
                                   f"give two different files")
        for key in keys:
            known_outputs.setdefault(key, (what, out))


def check_writable(path: Path, what: str) -> None:
    """Fail early (before a long run) when ``path`` cannot be written."""
    if path.is_dir():
        raise CommandError(f"{what} {str(path)!r} is a directory")
    if path.exists() and not path.is_file():
        raise CommandError(f"{what} {str(path)!r} exists and is not a regular file; give a file name")
    directory = path.parent
    if not directory.exists():
        raise CommandError(f"cannot write {what} {str(path)!r}: directory {str(directory)!r} does not exist")
    if not directory.is_dir():
        raise CommandError(f"cannot write {what} {str(path)!r}: {str(directory)!r} is not a directory")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise CommandError(f"cannot write {what} {str(path)!r}: directory {str(directory)!r} is not writable")


def input_file(path: Path, what: str) -> Path:
    path = Path(path)
    if not path.exists():
        raise CommandError(f"{what} not found: {str(path)!r}")
    if not path.is_file():
        raise CommandError(f"{what} {str(path)!r} is not a file")
    if not os.access(path, os.R_OK):
        raise CommandError(f"{what} {str(path)!r} is not readable")
    return path


def not_utf8(path, what, exc: UnicodeDecodeError) -> CommandError:
    return CommandError(f"{what} {str(path)!r} is not UTF-8 text (byte {exc.start}: {exc.reason})")


def load_scene(path):
    from msslib.scene import load_scene

    input_file(Path(path), "scene file")
    try:
        return load_scene(path)
    except UnicodeDecodeError as exc:
        raise not_utf8(path, "scene file", exc) from None


def mesh_input(scene):
    """``[("mesh file", path)]`` when the scene reads its mesh from a file."""
    return [("mesh file", scene.geometry["file"])] if "file" in scene.geometry else []


def load_experiment(path):
    import yaml

    from msslib import experiment

    input_file(Path(path), "experiment file")
    try:
        return experiment.load_experiment(path)
    except UnicodeDecodeError as exc:
        raise not_utf8(path, "experiment file", exc) from None
    except yaml.YAMLError as exc:
        raise CommandError(f"experiment file {str(path)!r}: invalid YAML: {one_line(exc)}") from None
    except FileNotFoundError:
        raise
    except ValueError as exc:
        raise CommandError(f"experiment file {str(path)!r}: {one_line(exc)}") from None
    except (TypeError, AttributeError, KeyError) as exc:  # a value of the wrong kind somewhere in the file
        raise CommandError(f"experiment file {str(path)!r} is not a valid experiment ({type(exc).__name__}: "
                           f"{one_line(exc)})") from None


def choice(option: str, value: str, allowed, what: str) -> str:
    if value not in allowed:
        raise CommandError(f"{option} {value!r} is not a {what}; expected one of {', '.join(map(str, allowed))}")
    return value


#: the variables a result needs for ``vtu`` and ``experiment compare``
RESULT_VARIABLES = ("rest_position", "displacement", "cells")


def read_result_file(path: Path, what: str = "result file", required=RESULT_VARIABLES):
    """Read an msslib result; CommandError naming ``path`` when it is not one."""
    from msslib.results import SCHEMA_VERSION, read_result

    input_file(path, what)
    try:
        ds = read_result(path)
    except (OSError, ValueError, RuntimeError) as exc:
        detail = one_line(exc).replace(str(Path(path).resolve()), "").replace(str(path), "").strip(" :'")
        raise CommandError(f"{what} {str(path)!r} is not a NetCDF file msslib can read ({detail})") from None
    missing = [v for v in required if v not in ds.variables]
    if missing:
        ours = ds.attrs.get("msslib_schema") == SCHEMA_VERSION
        kind = "an msslib result" if ours else f"a {SCHEMA_VERSION} result"
        raise CommandError(f"{what} {str(path)!r} is not {kind} with a mesh: no variable "
                           f"{', '.join(map(repr, missing))}")
    for name in ("rest_position", "displacement"):
        if name in required and set(ds[name].dims) != {"node", "axis"}:
            raise CommandError(f"{what} {str(path)!r}: variable {name!r} has dimensions {ds[name].dims}, "
                               f"expected (node, axis)")
    if "cells" in required:
        from msslib.results import mesh_from_result

        try:
            mesh_from_result(ds)
        except (ValueError, TypeError, KeyError) as exc:
            raise CommandError(f"{what} {str(path)!r}: not a valid mesh ({one_line(exc)})") from None
    return ds


def vtu_path(scene, out: Path, cli_vtu: str | None) -> Path | None:
    if cli_vtu:
        return Path(cli_vtu)
    vtu = scene.output.get("vtu", False)
    if vtu is True:
        return out.with_suffix(".vtu")
    if isinstance(vtu, str):
        return out.parent / vtu
    return None


def check_paraview(view, others) -> None:
    """Refuse, before anything runs, a ParaView output (a :class:`msslib.results.paraview.ParaViewOutput`)
    whose suffix is neither .vtu nor .pvd, or a series that would write over one of ``others``
    (pairs ``(what, path)``: the inputs and the other outputs) (:meth:`~msslib.results.paraview.ParaViewOutput.check`)."""
    try:
        view.check(others)
    except ValueError as exc:
        raise CommandError(one_line(exc)) from None

"""ParaView export of msslib results: the final state as one VTU file, or every saved state as a
time series (a ``.pvd`` collection of VTU files).

:class:`ParaViewOutput` is one such output at a path: what it is, the files it writes, the checks
before a run (its suffix; a series's files beside the ``.pvd`` that must not be an input or a
directory) and the staged writing (all files, or none). The suffix of the path decides:

``OUT.vtu``
    The final state (:func:`write_state`): the mesh at rest with the point data ``displacement``
    (m), ``reaction_force`` (N) and ``fixed`` (0/1), and the cell data ``material``,
    ``cell_state`` and ``relative_jacobian`` (the final state's cell check, :mod:`msslib.mesh.quality`).
``OUT.pvd``
    Every saved state, written together (all files, or none):

    * ``OUT.pvd``: the collection, one ``DataSet`` per state with its ``timestep``: the time (s)
      of a dynamic run's saved states, the step number of a result stored along ``step``; a result
      without history (a static solve, a dynamic run with ``output: {history: false}``) is one
      state, at ``t = 0`` for a static result and at the end time ``n_steps * dt`` for a dynamic one.
    * ``OUT_0000.vtu``, ``OUT_0001.vtu``, ... beside it (four digits, more when there are more
      states), the mesh at rest with the point data ``displacement`` (m) of the state,
      ``velocity`` (m/s) when the result stores velocities, ``reaction_force`` (N) of that state
      when the result stores the reactions of every state (``reaction_force_history``, written by
      dynamic scene runs), else ``reaction_force_final`` (the final state's, and the name says so),
      and ``fixed``; the cell data ``material``, and ``cell_state`` and ``relative_jacobian`` of
      that state (:func:`msslib.mesh.quality.check_state`, at the result's ``collapse_threshold``).
    * ``OUT_springs.vtu`` (results with springs): one line cell (VTK_LINE) per spring between
      the rest positions, with the cell data ``spring_constant`` (N/m) and ``rest_length`` (m).
      It is a file of its own, not part of the collection (cells of two types in one grid would
      need cell data for both), and has no time: open it beside the ``.pvd``.

    In ParaView, open the ``.pvd`` and apply *Warp By Vector* (``displacement``) to see the
    deformed states.  Files of an earlier, longer series with the same name are not removed; the
    ``.pvd`` lists only the new ones.  ``run --vtu OUT.pvd`` refuses, before it solves, a
    directory (or anything but a regular file, or a link to an input) where the series would
    write one of its files (``OUT_NNNN.vtu`` whatever the number of states, ``OUT_springs.vtu``).
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

__all__ = ["SUFFIXES", "ParaViewOutput", "states", "series_files", "in_series", "write_state", "write"]

#: suffix -> what is written
SUFFIXES = {".vtu": "the final state (one VTU file)", ".pvd": "every saved state (ParaView series)"}


def _check_suffix(path, what: str = "ParaView file") -> Path:
    """``path`` if it ends in ``.vtu`` or ``.pvd`` (any case), else a one-line ValueError."""
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        allowed = "; ".join(f"{s} for {w}" for s, w in SUFFIXES.items())
        raise ValueError(f"{what} {str(path)!r}: unknown suffix {path.suffix or '(none)'!r}; allowed: {allowed}")
    return path


def _is_series(path) -> bool:
    """True for a ``.pvd`` path (a time series), False for anything else."""
    return Path(path).suffix.lower() == ".pvd"


# --------------------------------------------------------------------------------------------
# what a result holds
# --------------------------------------------------------------------------------------------


def _nodes_axes(ds, name):
    return np.asarray(ds[name].transpose(..., "node", "axis").values, dtype=float)


def states(ds):
    """``(times, displacements, velocities)`` of every state of the result ``ds``.

    ``times`` ``(n_states,)``, ``displacements`` ``(n_states, n_nodes, dim)`` (m), ``velocities``
    the same shape (m/s) or None; see the module docstring for the times of each kind of result.
    """
    if "displacement_history" in ds:
        var = ds["displacement_history"]
        state_dim = var.dims[0]
        u = _nodes_axes(ds, "displacement_history")
        times = np.asarray(ds[state_dim].values if state_dim in ds.variables else np.arange(len(u)), dtype=float)
        v = None
        if "velocity_history" in ds and ds["velocity_history"].dims[0] == state_dim:
            v = _nodes_axes(ds, "velocity_history")
        return times, u, v
    t = 0.0
    if ds.attrs.get("solver_type") == "dynamic":
        try:
            t = float(ds.attrs["solver_n_steps"]) * float(ds.attrs["solver_dt"])
        except (KeyError, TypeError, ValueError):
            t = 0.0
    return np.array([t]), _nodes_axes(ds, "displacement")[None], None


def _digits(n_states: int) -> int:
    return max(4, len(str(max(n_states - 1, 0))))


def series_files(path, n_states: int, springs: bool) -> list[tuple[str, Path]]:
    """The files of a series written at ``path`` (a ``.pvd``): ``[(what, path), ...]``, the
    collection first, then the states, then the springs (when ``springs``)."""
    pvd = Path(path)
    width = _digits(n_states)
    files = [("ParaView series", pvd)]
    files += [("VTU file of the series", pvd.with_name(f"{pvd.stem}_{i:0{width}d}.vtu")) for i in range(n_states)]
    if springs:
        files.append(("springs VTU file", pvd.with_name(f"{pvd.stem}_springs.vtu")))
    return files


def _same_file(a: Path, b: Path) -> bool:
    """``a`` and ``b`` name one existing file (hard links, symbolic links, other spellings)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _member_pattern(pvd: Path) -> re.Pattern:
    """The names of the VTU files of a series at ``pvd`` beside it, whatever its number of states:
    ``STEM_NNNN.vtu`` (four digits or more) and ``STEM_springs.vtu``."""
    return re.compile(re.escape(pvd.stem) + r"_(\d{4,}|springs)\.vtu")


def in_series(pvd, path) -> bool:
    """Whether ``path`` is, or would be, one of the files of a series written at ``pvd`` whatever
    its number of states: the ``.pvd`` itself, ``STEM_NNNN.vtu`` or ``STEM_springs.vtu`` in its
    directory (also through a symbolic link).  Used to refuse an export that would overwrite an
    input before anything runs."""
    pvd = Path(pvd)
    pattern = _member_pattern(pvd)
    try:
        directory = pvd.parent.resolve()
    except (OSError, RuntimeError):
        return False
    candidates = [Path(path)]
    try:
        candidates.append(Path(path).resolve())
    except (OSError, RuntimeError):
        pass
    for p in candidates:
        try:
            same_dir = p.parent.resolve() == directory
        except (OSError, RuntimeError):
            continue
        if same_dir and (p.name == pvd.name or pattern.fullmatch(p.name)):
            return True
    return False


# --------------------------------------------------------------------------------------------
# writers (each writes one file at the path it is given: a temporary file when staged)
# --------------------------------------------------------------------------------------------


def _mesh(ds):
    from msslib.results.netcdf import mesh_from_result

    return mesh_from_result(ds)


def _fixed(ds):
    return np.asarray(ds["fixed"].transpose("node", "axis").values, dtype=np.int8)


def write_state(path, ds) -> Path:
    """Write the final state of the result ``ds`` as one VTU file (see the module docstring)."""
    from msslib.mesh import write_vtu

    mesh = _mesh(ds)
    point_data = {"displacement": _nodes_axes(ds, "displacement")}
    if "reaction_force" in ds:
        point_data["reaction_force"] = _nodes_axes(ds, "reaction_force")
    if "fixed" in ds:
        point_data["fixed"] = _fixed(ds)
    # the final state's cell check (msslib.mesh.quality): ParaView can threshold on the inverted cells
    cell_data = {name: np.asarray(ds[name].values) for name in ("cell_state", "relative_jacobian") if name in ds}
    return write_vtu(path, mesh, point_data=point_data, cell_data=cell_data or None)


def _state_writer(mesh, u, v, reaction, fixed, threshold):
    def write(path):
        from msslib.mesh import write_vtu
        from msslib.mesh.quality import check_state

        point_data = {"displacement": u}
        if v is not None:
            point_data["velocity"] = v
        if reaction is not None:
            point_data[reaction[0]] = reaction[1]
        if fixed is not None:
            point_data["fixed"] = fixed
        check = check_state(mesh, mesh.points + u, threshold=threshold)
        cell_data = {"cell_state": check.state, "relative_jacobian": check.ratio}
        write_vtu(path, mesh, point_data=point_data, cell_data=cell_data)
    return write


def _springs_writer(ds):
    def write(path):
        import meshio

        points = np.asarray(ds["rest_position"].transpose("node", "axis").values, dtype=float)
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        lines = np.asarray(ds["springs"].transpose("spring", "spring_end").values, dtype=np.int64)
        cell_data = {name: [np.asarray(ds[name].values, dtype=float)] for name in ("spring_constant", "rest_length")
                     if name in ds}
        meshio.write(Path(path), meshio.Mesh(points, [("line", lines)], cell_data=cell_data), file_format="vtu")
    return write


def _collection(times, names) -> str:
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    for t, name in zip(times, names):
        ET.SubElement(collection, "DataSet", timestep=repr(float(t)), group="", part="0", file=name)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _stage_series(staged, path, ds) -> list[Path]:
    times, u, v = states(ds)
    if not np.all(np.isfinite(times)):
        raise ValueError(f"ParaView series {str(path)!r}: the result's state times are not all finite")
    mesh = _mesh(ds)
    # the reaction of every state when the result stores it, else the final one (and it says so)
    if "reaction_force_history" in ds and len(times) == ds.sizes.get(ds["reaction_force_history"].dims[0]):
        history = np.asarray(ds["reaction_force_history"].transpose(..., "node", "axis").values, dtype=float)
        reactions = [("reaction_force", r) for r in history]
    elif "reaction_force" in ds:
        reactions = [("reaction_force_final", _nodes_axes(ds, "reaction_force"))] * len(times)
    else:
        reactions = [None] * len(times)
    fixed = _fixed(ds) if "fixed" in ds else None
    from msslib.mesh.quality import COLLAPSE_THRESHOLD

    threshold = float(ds.attrs.get("collapse_threshold", COLLAPSE_THRESHOLD))
    files = series_files(path, len(times), "springs" in ds)
    pvd, state_files = files[0][1], files[1:1 + len(times)]
    for i, (what, dest) in enumerate(state_files):
        staged.write(dest, _state_writer(mesh, u[i], None if v is None else v[i], reactions[i], fixed, threshold),
                     what=what)
    if "springs" in ds:
        what, dest = files[-1]
        staged.write(dest, _springs_writer(ds), what=what)
    staged.write_text(pvd, _collection(times, [dest.name for _, dest in state_files]), what=files[0][0])
    return [dest for _, dest in files]


class ParaViewOutput:
    """The ParaView output of a result at ``path``: ``.vtu`` the final state, ``.pvd`` every saved
    state (see the module docstring). ``what`` names it in messages, ``series`` says which."""

    def __init__(self, path):
        self.path = Path(path)
        self.series = _is_series(self.path)
        self.what = "ParaView series" if self.series else "VTU file"

    def __repr__(self) -> str:
        return f"ParaViewOutput({str(self.path)!r})"

    def check(self, others=()) -> None:
        """Before anything runs: a one-line ValueError for a suffix other than ``.vtu`` or ``.pvd``,
        and for a series whose files beside the ``.pvd`` (``STEM_NNNN.vtu``, ``STEM_springs.vtu``,
        whatever the number of states) would overwrite one of ``others`` (pairs ``(what, path)``:
        the inputs and the other outputs, also through a link) or are there as a directory or
        anything but a regular file (one listing of the directory)."""
        _check_suffix(self.path, self.what)
        if not self.series:
            return
        pvd = self.path
        beside = f"it writes {pvd.stem}_NNNN.vtu and {pvd.stem}_springs.vtu beside it"
        for what, other in others:
            if other is not None and in_series(pvd, other):
                raise ValueError(f"{what} {str(other)!r} would be overwritten by the ParaView series {str(pvd)!r} "
                                 f"({beside}); give another .pvd name")
        pattern = _member_pattern(pvd)
        try:
            names = sorted(n for n in os.listdir(pvd.parent if str(pvd.parent) else ".") if pattern.fullmatch(n))
        except OSError:
            return  # a missing or unreadable directory: the caller's check of the output refuses it
        others = [(what, Path(other)) for what, other in others if other is not None]
        for name in names:
            member = pvd.parent / name
            if member.is_dir() or (member.exists() and not member.is_file()):
                kind = "a directory" if member.is_dir() else "not a regular file"
                raise ValueError(f"ParaView series {str(pvd)!r}: {str(member)!r}, where it writes one of its files "
                                 f"({pvd.stem}_NNNN.vtu, {pvd.stem}_springs.vtu), is {kind}; move it away or give "
                                 f"another .pvd name")
            for what, other in others:
                if _same_file(member, other):
                    raise ValueError(f"{what} {str(other)!r} would be overwritten by the ParaView series "
                                     f"{str(pvd)!r} (its file {str(member)!r} is a link to it); give another .pvd name")

    def files(self, ds) -> list[tuple[str, Path]]:
        """Every file it writes for the result ``ds``: pairs ``(what, path)``, the ``.pvd`` first."""
        if not self.series:
            return [(self.what, self.path)]
        return series_files(self.path, len(states(ds)[0]), "springs" in ds)

    def stage(self, staged, ds) -> list[Path]:
        """Add its files for ``ds`` to ``staged`` (a :class:`msslib.results.staging.StagedOutputs`:
        they replace the old ones together with the other staged outputs, or none does); returns
        the files."""
        _check_suffix(self.path, self.what)
        if self.series:
            return _stage_series(staged, self.path, ds)
        staged.write(self.path, lambda tmp: write_state(tmp, ds), what=self.what)
        return [self.path]

    def write(self, ds) -> list[Path]:
        """Write its files for ``ds``, all together or none; returns them."""
        from msslib.results.staging import StagedOutputs

        with StagedOutputs() as staged:
            files = self.stage(staged, ds)
        return files


def write(path, ds) -> list[Path]:
    """Write the ParaView export of the result ``ds`` at ``path`` (the suffix decides, see the
    module docstring), all files together or none; returns the files written."""
    return ParaViewOutput(path).write(ds)

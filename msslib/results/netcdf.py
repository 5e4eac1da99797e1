"""NetCDF results: one schema for every simulation (mass-spring system or FEM reference).

Results are :class:`xarray.Dataset` objects built by :func:`make_dataset`, written atomically by
:func:`write_result` (engine ``netcdf4``) and read back fully into memory by :func:`read_result`.
:func:`mesh_from_result` rebuilds the :class:`~msslib.mesh.Mesh`. Every write goes through
:class:`msslib.results.staging.StagedOutputs` (several files as one; temporaries removed on any error, on
SIGINT and on SIGTERM). The schema (CF-1.11 and UGRID-1.0, ``msslib-result-2.0``: dimensions,
variables, attributes) is described in :mod:`msslib.results.conventions`.
"""

from __future__ import annotations

import json
import math
import os
import platform
import subprocess
from collections.abc import Mapping
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import xarray as xr

from msslib import __version__
from msslib.mesh import CELL_TYPES, Mesh
from msslib.results.conventions import (
    CONVENTIONS,
    SCHEMA_VERSION,
    AXIS_NAMES,
    ENGINE,
    FINITE_VARIABLES,
    MESH,
    SPRING_NETWORK,
    VOLUME_SHAPES,
    _VOLUME_SHAPE_OF,
    DOUBLE_FILL,
    FILLED_VARIABLES,
)
from msslib.results.staging import StagedOutputs

__all__ = ["git_commit", "make_dataset", "write_result", "write_text", "read_result", "mesh_from_result"]

# --------------------------------------------------------------------------------------------------
# provenance and attribute sanitising


def git_commit(directory: str | os.PathLike | None = None, *, timeout: float = 10.0) -> str:
    """Commit of the git work tree holding ``directory`` (default: this package's directory).

    Returns the full hash, with ``"+dirty"`` appended when tracked files differ from the commit, or
    ``"unknown"`` when git is missing, the directory is not in a work tree, or git fails. Only
    read-only git commands are run, and ``--no-optional-locks`` keeps ``git status`` from taking the
    index lock (so concurrent git operations in the same tree are not disturbed).
    """
    cwd = Path(__file__).resolve().parent if directory is None else Path(directory)

    def run(*args: str) -> str:
        return subprocess.run(
            ["git", "--no-optional-locks", *args], cwd=cwd, capture_output=True, text=True,
            timeout=timeout, check=True,
        ).stdout.strip()

    try:
        commit = run("rev-parse", "--verify", "HEAD")
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    if not commit:
        return "unknown"
    try:
        dirty = bool(run("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        return commit
    return commit + "+dirty" if dirty else commit


#: returned by :func:`_attr_value` for values that drop the attribute (``None``, ``"None"``)
_DROP = object()


def _attr_value(value):
    """Convert ``value`` to something netCDF can store as an attribute (see the module docstring);
    :data:`_DROP` for ``None`` and ``"None"``, which drop the attribute."""
    if value is None or (isinstance(value, str) and value == "None"):
        return _DROP
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (str, int, float, np.integer, np.floating)):
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        try:
            arr = np.asarray(value) if not isinstance(value, np.ndarray) else value
        except ValueError:  # ragged nesting, e.g. residual histories per load step: stored as JSON
            arr = np.asarray(None)
            return json.dumps(value, default=_json_default, sort_keys=True)
        if arr.ndim == 0:
            return _attr_value(arr.item())
        if arr.ndim == 1 and arr.size and arr.dtype.kind in "biuf":
            return arr.astype(np.int8) if arr.dtype.kind == "b" else arr
    try:
        return json.dumps(value, default=_json_default, sort_keys=True)
    except (TypeError, ValueError):
        return str(value)


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return str(obj)


def _attrs(mapping: Mapping) -> dict:
    """``mapping`` with every value converted by :func:`_attr_value`; dropped values left out."""
    out = {}
    for key, value in mapping.items():
        value = _attr_value(value)
        if value is not _DROP:
            out[key] = value
    return out


def _flatten(stats: Mapping, prefix: str) -> dict:
    """Flatten a nested mapping into ``{prefix_key_subkey: value}`` (values not yet sanitised)."""
    out = {}
    for key, value in stats.items():
        name = f"{prefix}_{key}"
        if isinstance(value, Mapping):
            out.update(_flatten(value, name))
        else:
            out[name] = value
    return out


def _per_material(value, name: str, n_mat: int | None = None) -> np.ndarray:
    """A number or a 1-D array of one value per material, as a float array."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim > 1 or arr.size == 0:
        raise ValueError(f"{name} must be a number or a non-empty 1-D array, got shape {arr.shape}")
    if arr.ndim == 1 and n_mat is not None and len(arr) < n_mat:
        raise ValueError(f"{name} has {len(arr)} entries but mesh.material refers to {n_mat} materials")
    return arr


# --------------------------------------------------------------------------------------------------
# building a dataset


def _array(value, shape, name, dtype=float):
    arr = np.asarray(value, dtype=dtype)
    if arr.shape != tuple(shape):
        raise ValueError(f"{name} must have shape {tuple(shape)}, got {arr.shape}")
    return arr


def _var(dims, data, units, long_name, **attrs):
    """A variable with ``long_name`` and, unless ``units`` is None, ``units``."""
    head = {"long_name": long_name} if units is None else {"units": units, "long_name": long_name}
    return xr.Variable(dims, data, attrs={**head, **attrs})


def _is_flag_or_text(var: xr.Variable) -> bool:
    return ("flag_values" in var.attrs and "flag_meanings" in var.attrs) or var.dtype.kind in "OSU"


def _topology(mesh: Mesh, axes: list[str]) -> tuple[dict, dict]:
    """The UGRID variables of ``mesh``: ``(coordinates, variables)``."""
    dim = mesh.dim
    node_coords = [f"node_{a}" for a in axes]
    coords = {
        name: _var(("node",), mesh.points[:, i].copy(), "m", f"{a} coordinate of the node in the undeformed mesh")
        for i, (name, a) in enumerate(zip(node_coords, axes))
    }
    topo = {"cf_role": "mesh_topology", "long_name": f"topology of the {dim}D mesh",
            "topology_dimension": np.int32(dim), "node_coordinates": " ".join(node_coords)}
    role = "face_node_connectivity" if dim == 2 else "volume_node_connectivity"
    variables = {}
    if dim == 2:
        topo.update(face_node_connectivity="cells", face_dimension="cell")
    else:
        topo.update(volume_node_connectivity="cells", volume_dimension="cell", volume_shape_type="cell_shape")
        code = VOLUME_SHAPES.index(_VOLUME_SHAPE_OF[mesh.cell_type])
        variables["cell_shape"] = _var(
            ("cell",), np.full(mesh.n_cells, code, dtype=np.int8), None, "shape of the volume",
            cf_role="volume_shape_type", flag_values=np.arange(len(VOLUME_SHAPES), dtype=np.int8),
            flag_meanings=" ".join(VOLUME_SHAPES))
    variables[MESH] = xr.Variable((), np.int32(0), attrs=topo)
    variables["cells"] = _var(
        ("cell", "cell_node"), mesh.cells.copy(), None,
        f"nodes of the cell (0-based, node order of msslib.mesh: VTK's {mesh.cell_type})",
        cf_role=role, start_index=np.int64(0), cell_type=mesh.cell_type)
    return coords, variables


def _locate(variables: Mapping, dim: int, has_springs: bool) -> None:
    """Add UGRID ``mesh``/``location`` to the variables defined on nodes, cells or springs."""
    cell_location = "face" if dim == 2 else "volume"
    for var in variables.values():
        if "cf_role" in var.attrs or "mesh" in var.attrs or "location" in var.attrs:
            continue
        on = [d for d in var.dims if d in ("node", "cell", "spring")]
        if len(on) != 1:
            continue
        if on[0] == "node":
            var.attrs.update(mesh=MESH, location="node")
        elif on[0] == "cell":
            var.attrs.update(mesh=MESH, location=cell_location)
        elif has_springs:
            var.attrs.update(mesh=SPRING_NETWORK, location="edge")


def make_dataset(
    mesh: Mesh,
    displacement,
    *,
    model: str,
    E,
    nu,
    density=None,
    material_names=None,
    thickness: float | None = None,
    scene=None,
    springs=None,
    spring_constant=None,
    rest_length=None,
    reaction=None,
    fixed=None,
    history: Mapping | None = None,
    solver_stats: Mapping | None = None,
    wall_time: float | None = None,
    extra_vars: Mapping | None = None,
    extra_attrs: Mapping | None = None,
) -> xr.Dataset:
    """Build a result dataset following the schema of this module's docstring.

    Parameters
    ----------
    mesh : the undeformed mesh (node coordinates, ``cells``, ``cell_material``).
    displacement : ``(n_nodes, dim)`` displacement of the final state [m].
    model : model name (global attribute ``model``).
    E, nu : Young's modulus [Pa] and Poisson's ratio, numbers (every material) or 1-D arrays indexed
        by ``mesh.material`` (variables ``material_E``, ``material_nu``).
    density : density [kg/m^3], a number or one value per material, NaN (or None) where a material
        has none (variable ``material_density``, left out when no material has one).
    material_names : one name per material (variable ``material_name``).
    thickness : membrane thickness [m] of a 2D mesh (scalar variable ``thickness``); refused for 3D.
    scene : scene text or name (a mapping is stored as JSON); ``None`` stores ``""``.
    springs : ``(n_springs, 2)`` node indices; ``spring_constant`` [N/m] and ``rest_length`` [m]
        are ``(n_springs,)`` and need ``springs``.
    reaction : ``(n_nodes, dim)`` reaction forces [N].
    fixed : ``(n_nodes, dim)`` bool mask of constrained components, or ``(n_nodes,)`` for nodes
        constrained along every axis.
    history : mapping with ``"time"`` [s] (``(n_t,)``) and/or ``"step"`` (``(n_t,)`` ints), and
        ``"displacement"`` [m] and/or ``"velocity"`` [m/s] of shape ``(n_t, n_nodes, dim)``. The
        states run along ``time`` if given, else along ``step``; with both, ``step`` is a variable
        along ``time``.
    solver_stats : mapping (possibly nested) stored as ``solver_*`` global attributes.
    wall_time : wall time of the run [s] (``wall_time_s``; NaN if ``None``).
    extra_vars : mapping name -> :class:`xarray.DataArray`/:class:`xarray.Variable` or
        ``(dims, data, attrs)`` tuple; each needs a ``long_name`` attribute, and ``units`` unless it
        is a flag variable (``flag_values`` and ``flag_meanings``) or text. Those on nodes, cells or
        springs get the UGRID ``mesh`` and ``location`` attributes.
    extra_attrs : further global attributes (sanitised like ``solver_*``).
    """
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh must be a msslib.mesh.Mesh, got {type(mesh).__name__}")
    if not isinstance(model, str) or not model:
        raise ValueError("model must be a non-empty string")
    n, dim = mesh.n_nodes, mesh.dim
    axes = list(AXIS_NAMES[:dim])

    # materials: one entry per material index a cell uses, or more if the tables are longer
    n_used = int(mesh.material.max()) + 1 if mesh.n_cells else 0
    E_arr, nu_arr = _per_material(E, "E", n_used), _per_material(nu, "nu", n_used)
    dens_arr = None
    if density is not None:
        dens = np.asarray(density, dtype=object)
        dens_arr = _per_material(np.array([np.nan if d is None else d for d in dens.ravel()], dtype=float)
                                 .reshape(dens.shape), "density", n_used)
    names = None
    if material_names is not None:
        names = [str(x) for x in np.atleast_1d(np.asarray(material_names, dtype=object))]
    n_mat = max([n_used, 1] + [len(a) for a in (E_arr, nu_arr, dens_arr) if a is not None and a.ndim == 1]
                + ([len(names)] if names is not None else []))
    for name, arr in (("E", E_arr), ("nu", nu_arr), ("density", dens_arr)):
        if arr is not None and arr.ndim == 1 and len(arr) != n_mat:
            raise ValueError(f"{name} has {len(arr)} entries but there are {n_mat} materials")
    if names is not None and len(names) != n_mat:
        raise ValueError(f"material_names has {len(names)} entries but there are {n_mat} materials")

    coords, variables = _topology(mesh, axes)
    coords["axis_name"] = _var(("axis",), np.array(axes, dtype=object), None, "name of the spatial axis")
    coords["material"] = _var(("material",), np.arange(n_mat, dtype=np.int64), None, "material index")
    variables.update({
        "rest_position": _var(("node", "axis"), mesh.points.copy(), "m", "node position of the undeformed mesh"),
        "displacement": _var(("node", "axis"), _array(displacement, (n, dim), "displacement"), "m",
                             "node displacement of the final state"),
        "cell_material": _var(("cell",), mesh.material.copy(), None, "material index of the cell"),
        "material_E": _var(("material",), np.broadcast_to(E_arr, (n_mat,)).copy(), "Pa", "Young's modulus"),
        "material_nu": _var(("material",), np.broadcast_to(nu_arr, (n_mat,)).copy(), "1", "Poisson's ratio"),
    })
    if dens_arr is not None and np.isfinite(dens_arr).any():
        variables["material_density"] = _var(("material",), np.broadcast_to(dens_arr, (n_mat,)).copy(), "kg m-3",
                                             "density (missing where the material has none)")
    if names is not None:
        variables["material_name"] = _var(("material",), np.array(names, dtype=object), None, "material name")
    if thickness is not None:
        if dim != 2:
            raise ValueError("thickness applies to 2D meshes only")
        t = float(thickness)
        if not (math.isfinite(t) and t > 0):
            raise ValueError(f"thickness must be a positive number, got {thickness!r}")
        variables["thickness"] = _var((), t, "m", "membrane thickness (plane stress)")

    if springs is None:
        if spring_constant is not None or rest_length is not None:
            raise ValueError("spring_constant and rest_length need springs")
    else:
        springs = np.asarray(springs)
        if springs.ndim != 2 or springs.shape[1] != 2:
            raise ValueError(f"springs must have shape (n_springs, 2), got {springs.shape}")
        if springs.dtype.kind not in "iu" and not (springs.size == 0 or np.array_equal(springs, np.round(springs))):
            raise ValueError("springs must hold integer node indices")
        springs = springs.astype(np.int64)
        if springs.size and (springs.min() < 0 or springs.max() >= n):
            raise ValueError("springs refer to nodes that do not exist")
        m = len(springs)
        variables[SPRING_NETWORK] = xr.Variable((), np.int32(0), attrs={
            "cf_role": "mesh_topology", "long_name": "springs of the mass-spring system (a network on the mesh nodes)",
            "topology_dimension": np.int32(1), "node_coordinates": variables[MESH].attrs["node_coordinates"],
            "edge_node_connectivity": "springs", "edge_dimension": "spring"})
        variables["springs"] = _var(("spring", "spring_end"), springs, None, "end nodes of the spring (0-based)",
                                    cf_role="edge_node_connectivity", start_index=np.int64(0))
        if spring_constant is not None:
            variables["spring_constant"] = _var(("spring",), _array(spring_constant, (m,), "spring_constant"),
                                                "N m-1", "spring constant")
        if rest_length is not None:
            variables["rest_length"] = _var(("spring",), _array(rest_length, (m,), "rest_length"), "m",
                                            "spring rest length")

    if reaction is not None:
        variables["reaction_force"] = _var(("node", "axis"), _array(reaction, (n, dim), "reaction"), "N",
                                           "reaction force at the node")
    if fixed is not None:
        fixed = np.asarray(fixed, dtype=bool)
        if fixed.shape == (n,):
            fixed = np.repeat(fixed[:, None], dim, axis=1)
        fixed = _array(fixed, (n, dim), "fixed", dtype=bool)
        variables["fixed"] = _var(("node", "axis"), fixed, None, "displacement component prescribed (Dirichlet)",
                                  flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="free prescribed")

    if history is not None:
        coords_h, vars_h = _history(history, n, dim)
        coords.update(coords_h)
        variables.update(vars_h)

    for name, value in (extra_vars or {}).items():
        if name in variables or name in coords:
            raise ValueError(f"extra variable {name!r} collides with a schema variable")
        if isinstance(value, tuple):
            value = xr.Variable(*value)
        elif isinstance(value, xr.DataArray):
            value = value.variable
        elif not isinstance(value, xr.Variable):
            raise TypeError(f"extra variable {name!r} must be a DataArray, Variable or (dims, data, attrs) tuple")
        value = value.copy(deep=False)
        value.attrs = dict(value.attrs)
        missing = [a for a in ("units", "long_name") if a not in value.attrs
                   and not (a == "units" and _is_flag_or_text(value))]
        if missing:
            raise ValueError(f"extra variable {name!r} lacks the attribute(s) {missing}")
        variables[name] = value

    if isinstance(scene, Mapping):
        scene = json.dumps(scene, default=_json_default, sort_keys=True)
    created = datetime.now(timezone.utc).isoformat(timespec="seconds")
    attrs = {
        "Conventions": CONVENTIONS,
        "msslib_schema": SCHEMA_VERSION,
        "title": f"msslib result: {model}",
        "source": f"msslib {__version__}",
        "history": f"{created} created by msslib {__version__}",
        "model": model,
        "scene": "" if scene is None else str(scene),
        "msslib_version": __version__,
        "git_commit": git_commit(),
        "created": created,
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "wall_time_s": math.nan if wall_time is None else float(wall_time),
    }
    extra = dict(_flatten(solver_stats, "solver")) if solver_stats is not None else {}
    for key, value in (extra_attrs or {}).items():
        if key in attrs or key in extra:
            raise ValueError(f"extra attribute {key!r} collides with a schema attribute")
        extra[key] = value
    attrs.update(_attrs(extra))

    _locate(variables, dim, springs is not None)
    for var in (*variables.values(), *coords.values()):
        var.attrs = _attrs(var.attrs)
    return xr.Dataset(variables, coords=coords, attrs=attrs)


def _history(history: Mapping, n: int, dim: int):
    unknown = set(history) - {"time", "step", "displacement", "velocity", "reaction"}
    if unknown:
        raise ValueError(f"unknown history keys {sorted(unknown)}; expected time, step, displacement, velocity, "
                         f"reaction")
    if "time" not in history and "step" not in history:
        raise ValueError("history needs a 'time' or a 'step' array")
    if "displacement" not in history and "velocity" not in history:
        raise ValueError("history needs a 'displacement' or a 'velocity' array")
    tdim = "time" if "time" in history else "step"
    n_t = len(np.atleast_1d(history[tdim]))
    coords, variables = {}, {}
    if "time" in history:
        coords["time"] = _var(("time",), _array(history["time"], (n_t,), "history['time']"), "s",
                              "simulated time from the start of the run")
    if "step" in history:
        step = np.asarray(history["step"])
        if step.shape != (n_t,) or (step.size and not np.array_equal(step, np.round(step))):
            raise ValueError(f"history['step'] must be {n_t} integers")
        coords["step"] = _var((tdim,), step.astype(np.int64), "1", "step number")
    if "displacement" in history:
        variables["displacement_history"] = _var(
            (tdim, "node", "axis"), _array(history["displacement"], (n_t, n, dim), "history['displacement']"),
            "m", "node displacement of every stored state")
    if "velocity" in history:
        variables["velocity_history"] = _var(
            (tdim, "node", "axis"), _array(history["velocity"], (n_t, n, dim), "history['velocity']"),
            "m s-1", "node velocity of every stored state")
    if "reaction" in history:
        variables["reaction_force_history"] = _var(
            (tdim, "node", "axis"), _array(history["reaction"], (n_t, n, dim), "history['reaction']"),
            "N", "support reaction at the nodes of every stored state (zero on free dofs)")
    return coords, variables


# --------------------------------------------------------------------------------------------------
# writing and reading


def _encoding(ds: xr.Dataset) -> dict:
    """No fill values (results are complete) but for :data:`FILLED_VARIABLES`; zlib for numeric
    arrays."""
    enc = {}
    for name, var in ds.variables.items():
        e = {"_FillValue": DOUBLE_FILL if name in FILLED_VARIABLES and var.dtype.kind == "f" else None}
        if var.dtype.kind in "biuf" and var.ndim >= 1 and var.size:
            e.update(zlib=True, complevel=4)
        enc[name] = e
    return enc


def _check_finite(path: Path, ds: xr.Dataset) -> None:
    for name in FINITE_VARIABLES:
        if name in ds.variables:
            values = np.asarray(ds[name].values)
            if values.dtype.kind in "fc" and not np.isfinite(values).all():
                bad = int(np.count_nonzero(~np.isfinite(values)))
                raise ValueError(f"refusing to write {path}: variable {name!r} has {bad} non-finite value(s)")


def _to_netcdf(ds: xr.Dataset):
    return lambda tmp: ds.to_netcdf(tmp, mode="w", format="NETCDF4", engine=ENGINE, encoding=_encoding(ds))


def stage_result(staged: StagedOutputs, dest: str | os.PathLike, ds: xr.Dataset, what: str = "result") -> Path:
    """Stage a NetCDF result in ``staged`` (refused, ValueError, if :data:`FINITE_VARIABLES` are
    not finite); :meth:`msslib.results.staging.StagedOutputs.write_result` calls it."""
    _check_finite(Path(dest), ds)
    return staged.write(dest, _to_netcdf(ds), what)


def write_result(path: str | os.PathLike, ds: xr.Dataset) -> Path:
    """Write ``ds`` to ``path`` (NetCDF-4, engine netcdf4) atomically and return the path.

    The dataset is written to a hidden temporary file in the target directory (see
    :class:`StagedOutputs`), flushed to disk (``fsync``) and renamed over ``path`` with
    :func:`os.replace`, so readers never see a partial file. On any error (SIGTERM included, see
    :class:`StagedOutputs`) the temporary file is removed and the error re-raised, naming ``path``
    (not the temporary file); ``path`` is left untouched (an older file there survives).

    Raises
    ------
    ValueError
        if a variable of :data:`FINITE_VARIABLES` holds NaN or infinity (nothing is written).
    OSError
        (``FileNotFoundError``, ``NotADirectoryError``, ``PermissionError``, ...) naming ``path``
        when the target directory does not exist or is not writable; ``ENOSPC``, ``no space left
        on device``, when the disk is full (NetCDF reports it as ``NetCDF: HDF error``).
    """
    path = Path(path)
    with StagedOutputs() as out:
        stage_result(out, path, ds)
    return path


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically, like :func:`write_result`: a hidden
    temporary file in the target directory renamed over ``path``; on error it is removed and
    ``path`` is left untouched."""
    path = Path(path)
    with StagedOutputs() as out:
        out.write_text(path, text)
    return path


def read_result(path: str | os.PathLike) -> xr.Dataset:
    """Read a result file fully into memory and close it.

    ``fixed`` comes back as ``bool``; ``time`` stays plain seconds (no timedelta decoding); the
    node coordinates ``node_x``, ... are coordinates of the dataset (from the CF ``coordinates``
    attributes); ``material_density`` is NaN where a material has none.
    """
    return xr.load_dataset(path, engine=ENGINE, decode_timedelta=False)


def _cell_material(ds: xr.Dataset):
    """The per-cell material index: ``cell_material``, or ``material(cell)`` of a
    ``msslib-result-1.0`` file; None if there is neither."""
    if "cell_material" in ds.variables:
        return ds["cell_material"]
    if "material" in ds.variables and ds["material"].dims == ("cell",):
        return ds["material"]
    return None


def mesh_from_result(ds: xr.Dataset, *, deformed: bool = False) -> Mesh:
    """The :class:`~msslib.mesh.Mesh` of a result (its rest configuration; ``deformed=True`` adds
    ``displacement`` to the node positions). Reads ``msslib-result-1.0`` files too."""
    material = _cell_material(ds)
    for name in ("rest_position", "cells"):
        if name not in ds.variables:
            raise ValueError(f"dataset has no variable {name!r}; not a {SCHEMA_VERSION} result")
    if material is None:
        raise ValueError(f"dataset has no variable 'cell_material'; not a {SCHEMA_VERSION} result")
    cell_type = ds["cells"].attrs.get("cell_type")
    if cell_type not in CELL_TYPES:
        raise ValueError(f"variable 'cells' has no valid cell_type attribute (got {cell_type!r})")
    points = ds["rest_position"].transpose("node", "axis").values
    if deformed:
        points = points + ds["displacement"].transpose("node", "axis").values
    return Mesh(
        points=np.array(points, dtype=float),
        cells=np.array(ds["cells"].transpose("cell", "cell_node").values, dtype=np.int64),
        cell_type=str(cell_type),
        material=np.array(material.values, dtype=np.int64),
    )

"""NetCDF results: one schema for every simulation (mass-spring system or FEM reference).

Results are :class:`xarray.Dataset` objects built by :func:`make_dataset`, written atomically by
:func:`write_result` (engine ``netcdf4``) and read back fully into memory by :func:`read_result`.
:func:`mesh_from_result` rebuilds the :class:`~msslib.mesh.Mesh`. :class:`StagedOutputs` writes
several files as one (all are replaced, or none is); every write goes through it, so temporary
files are removed on any error, on SIGINT and on SIGTERM.

Schema ``msslib-result-2.0``: CF-1.11 and UGRID-1.0
===================================================

A result follows the CF metadata conventions 1.11 and the UGRID conventions 1.0 for unstructured
meshes (global attribute ``Conventions = "CF-1.11 UGRID-1.0"``, :data:`CONVENTIONS`); the global
attribute ``msslib_schema`` (:data:`SCHEMA_VERSION`) tells this schema from the older
``msslib-result-1.0`` (which had ``Conventions = "msslib-result-1.0"``, the material constants as
global attributes and the per-cell material index in a variable ``material``; such files are still
read by :func:`mesh_from_result`). ``tests/test_cf.py`` runs the IOOS compliance checker (CF-1.11)
and checks the UGRID rules listed here.

Units are UDUNITS strings (``m``, ``N``, ``N m-1``, ``Pa``, ``kg m-3``, ``J``, ``s``, ``m s-1``;
``1`` for dimensionless quantities). Every variable has a ``long_name``; every physical or
dimensionless quantity has ``units``; connectivity, index, flag and label variables have none (they
are not quantities). CF standard names are used where one exists and fits: none fits Cartesian
coordinates of a body (``projection_x_coordinate`` means map projections), displacements, forces,
spring or material constants, so these have ``long_name`` and ``units`` only. ``time`` has no
``standard_name`` either: CF's ``time`` needs units ``"<unit> since <date>"``, and a simulation's
time is elapsed time with no date.

Mesh topology (UGRID)
---------------------

``mesh`` (a dummy integer, ``cf_role = "mesh_topology"``) describes the mesh of the run:
``topology_dimension`` 2 (triangles, quads: faces) or 3 (tetrahedra, hexahedra: volumes),
``node_coordinates = "node_x node_y"`` (2D) or ``"node_x node_y node_z"`` (3D), and

* 2D: ``face_node_connectivity = "cells"``, ``face_dimension = "cell"``;
* 3D: ``volume_node_connectivity = "cells"``, ``volume_dimension = "cell"``,
  ``volume_shape_type = "cell_shape"`` (UGRID's 3D section: a flag variable with the shape of every
  volume; node order per shape is VTK's, which is :mod:`msslib.mesh`'s).

The springs of a mass-spring system are a second topology, ``spring_network``
(``topology_dimension = 1``, the same ``node_coordinates``, ``edge_node_connectivity = "springs"``,
``edge_dimension = "spring"``): a 1D network on the same nodes. They are not the edges of ``mesh``
because many models have springs along face and cell diagonals. Connectivities are 0-based
(``start_index = 0``); all cells of a mesh have the same number of nodes, so no ``_FillValue`` is
needed. Variables defined on the mesh carry ``mesh`` and ``location``: ``"node"`` (dimension
``node``; with ``coordinates = "node_x node_y (node_z)"``, written by xarray), ``"face"`` (2D) or
``"volume"`` (3D) for dimension ``cell``, and ``mesh = "spring_network"``, ``location = "edge"``
for dimension ``spring``. :func:`make_dataset` adds these to every variable with one of these
dimensions (``extra_vars`` included) that does not set them itself.

Dimensions
----------

============== ===============================================================================
dimension      meaning
============== ===============================================================================
``node``       mesh nodes, in the order of ``Mesh.points``
``axis``       spatial axes x, y (2D) and z (3D); the label variable ``axis_name`` names them
               (CF coordinate variables are numeric, so there is no coordinate variable ``axis``)
``cell``       mesh cells, in the order of ``Mesh.cells``
``cell_node``  nodes of one cell (3 triangle, 4 quad, 4 tetra, 8 hexahedron)
``material``   materials; coordinate variable ``material`` holds ``0, 1, ...``
``spring``     springs of a mass-spring system (optional)
``spring_end`` the two end nodes of a spring (length 2; optional, with ``spring``)
``time``       stored states of a dynamic run; coordinate variable ``time`` [s] (optional)
``step``       stored states of a quasi-static / iterative run when there is no physical time;
               coordinate variable ``step`` [1] (optional; used only if ``time`` is not)
============== ===============================================================================

Variables
---------

====================================================== ======== ========================================
variable                                               units    content
====================================================== ======== ========================================
``mesh``                                               -        UGRID mesh topology (see above)
``node_x(node)``, ``node_y(node)``, ``node_z(node)``   m        node coordinates of the undeformed mesh
                                                                (auxiliary coordinates; ``node_z`` in
                                                                3D only)
``axis_name(axis)``                                    -        ``"x"``, ``"y"`` (, ``"z"``): string
                                                                label (auxiliary coordinate, CF 6.1)
``rest_position(node, axis)``                          m        the same node positions as one array,
                                                                for arithmetic with ``displacement``
``displacement(node, axis)``                           m        displacement of the final state
``cells(cell, cell_node)``                             -        int64 connectivity, 0-based node
                                                                indices, node order of
                                                                :mod:`msslib.mesh`; ``cf_role``
                                                                ``face_node_connectivity`` (2D) or
                                                                ``volume_node_connectivity`` (3D),
                                                                ``start_index = 0``; attribute
                                                                ``cell_type`` (``triangle``,
                                                                ``quad``, ``tetra``, ``hexahedron``)
``cell_shape(cell)``                                   -        3D only: int8 UGRID volume shape flag
                                                                (``flag_values 0 1 2 3``,
                                                                ``flag_meanings "tetrahedron pyramid
                                                                wedge hexahedron"``)
``material(material)``                                 -        int64 material index (coordinate)
``cell_material(cell)``                                -        int64 material index of the cell
``material_E(material)``                               Pa       Young's modulus
``material_nu(material)``                              1        Poisson's ratio
``material_density(material)``                         kg m-3   density (optional: only when some
                                                                material has one; ``_FillValue``
                                                                9.969209968386869e36, read back as NaN,
                                                                where a material has none)
``material_name(material)``                            -        material names (optional)
``thickness``                                          m        membrane thickness of a 2D (plane
                                                                stress) mesh (optional, scalar)
``spring_network``                                     -        UGRID 1D topology of the springs
                                                                (optional, with ``springs``)
``springs(spring, spring_end)``                        -        int64 end nodes of every spring,
                                                                ``cf_role = "edge_node_connectivity"``,
                                                                ``start_index = 0`` (optional)
``spring_constant(spring)``                            N m-1    spring stiffness (optional)
``rest_length(spring)``                                m        spring rest length (optional)
``reaction_force(node, axis)``                         N        reaction force at the nodes (optional)
``fixed(node, axis)``                                  -        Dirichlet mask: ``bool`` in memory,
                                                                stored as ``int8`` 0/1 with attribute
                                                                ``dtype = "bool"`` (xarray decodes it
                                                                back to ``bool``), ``flag_values 0 1``,
                                                                ``flag_meanings "free prescribed"``
                                                                (optional)
``time(time)``                                         s        simulated time of the stored states,
                                                                from the start of the run (optional)
``step(step)`` or ``step(time)``                       1        iteration / load-step number (optional)
``displacement_history(time|step, node, axis)``        m        displacement of every stored state
                                                                (optional)
``velocity_history(time|step, node, axis)``            m s-1    velocity of every stored state
                                                                (optional)
====================================================== ======== ========================================

Further variables may be added with ``extra_vars``; they need a ``long_name``, and ``units`` unless
they are flags (``flag_values`` and ``flag_meanings``) or text. :func:`msslib.scene.run_scene`
adds ``cell_state(cell)`` (flags, :mod:`msslib.quality`), ``relative_jacobian(cell)`` [1], the
energies of dynamic runs (``kinetic_energy(time)``, ``potential_energy(time)`` [J]) and the
potential energy of the final state of static mass-spring runs (scalar ``potential_energy`` [J]).

Global attributes
-----------------

==================== ==========================================================================
attribute            content
==================== ==========================================================================
``Conventions``      ``"CF-1.11 UGRID-1.0"`` (:data:`CONVENTIONS`)
``msslib_schema``    ``"msslib-result-2.0"`` (:data:`SCHEMA_VERSION`)
``title``            ``"msslib result: <model>"``
``source``           ``"msslib <version>"``
``history``          ``"<created> created by msslib <version>"``
``model``            model name, e.g. ``"fem_linear"``, ``"lloyd_tetrahedron"``
``scene``            the scene text or name (``""`` if none; a mapping is stored as JSON)
``msslib_version``   :data:`msslib.__version__`
``git_commit``       ``git rev-parse HEAD`` run in the package's directory, with suffix
                     ``"+dirty"`` when tracked files have uncommitted changes (untracked files are
                     ignored, as by ``git describe --dirty``); ``"unknown"`` when unavailable
``created``          creation time, UTC, ISO 8601 (``YYYY-MM-DDTHH:MM:SS+00:00``)
``python_version``   :func:`platform.python_version`
``numpy_version``    :data:`numpy.__version__`
``wall_time_s``      wall time of the run [s]; NaN when not given
``solver_*``         solver statistics, flattened: ``{"newton": {"iterations": 3}}`` becomes
                     ``solver_newton_iterations = 3``
==================== ==========================================================================

Attribute values are restricted to what netCDF stores: strings, numbers and 1-D numeric arrays.
Booleans become the integers 0/1; ``None`` (and the string ``"None"``, which older callers passed for
"no value") drops the attribute; anything else (lists of strings, nested or ragged lists, mappings)
is stored as its JSON text. A length-1 array attribute reads back as a scalar (a netCDF property).
Further global attributes may be added with ``extra_attrs`` (they must not collide with the
attributes above); physical quantities belong in variables, where they carry units.
"""

from __future__ import annotations

import errno
import json
import math
import os
import platform
import re
import secrets
import signal
import subprocess
import threading
from collections.abc import Mapping
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__
from .mesh import CELL_TYPES, Mesh

__all__ = [
    "CONVENTIONS",
    "SCHEMA_VERSION",
    "git_commit",
    "make_dataset",
    "write_result",
    "write_text",
    "StagedOutputs",
    "Terminated",
    "terminate_raises",
    "remove_stale_temporaries",
    "read_result",
    "mesh_from_result",
]

#: value of the global attribute ``Conventions``
CONVENTIONS = "CF-1.11 UGRID-1.0"
#: value of the global attribute ``msslib_schema``
SCHEMA_VERSION = "msslib-result-2.0"
#: the schema before CF/UGRID (its ``Conventions`` attribute); :func:`mesh_from_result` reads it
LEGACY_SCHEMA_VERSION = "msslib-result-1.0"
AXIS_NAMES = ("x", "y", "z")
ENGINE = "netcdf4"
#: Variables that must be finite for :func:`write_result` to accept a dataset.
FINITE_VARIABLES = ("rest_position", "displacement", "displacement_history", "velocity_history")
#: Global attributes set by :func:`make_dataset` (``solver_*`` apart).
SCHEMA_ATTRS = (
    "Conventions", "msslib_schema", "title", "source", "history", "model", "scene", "msslib_version",
    "git_commit", "created", "python_version", "numpy_version", "wall_time_s",
)
#: the UGRID mesh topology variables
MESH, SPRING_NETWORK = "mesh", "spring_network"
#: UGRID volume shapes (flag values of ``cell_shape``) and the msslib cell types they stand for
VOLUME_SHAPES = ("tetrahedron", "pyramid", "wedge", "hexahedron")
_VOLUME_SHAPE_OF = {"tetra": "tetrahedron", "hexahedron": "hexahedron"}
#: the netCDF default fill value of doubles, used where a material has no density
DOUBLE_FILL = 9.969209968386869e36
#: variables stored with a ``_FillValue`` (:data:`DOUBLE_FILL`; NaN in memory)
FILLED_VARIABLES = ("material_density",)


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


def _to_text(text: str):
    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
    return write


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
        when the target directory does not exist or is not writable.
    """
    path = Path(path)
    with StagedOutputs() as out:
        out.write_result(path, ds)
    return path


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically, like :func:`write_result`: a hidden
    temporary file in the target directory renamed over ``path``; on error it is removed and
    ``path`` is left untouched."""
    path = Path(path)
    with StagedOutputs() as out:
        out.write_text(path, text)
    return path


# --------------------------------------------------------------------------------------------------
# staged outputs: temporary files committed together


#: marks the temporary files of msslib: ``.NAME.msslib-tmp-PID-RANDOM`` beside the target ``NAME``
#: (``msslib-bak`` for the copy of a replaced file kept while several files are committed)
TEMP_TAG = "msslib-tmp"
_BACKUP_TAG = "msslib-bak"


class Terminated(KeyboardInterrupt):
    """Raised by the SIGTERM handler of :func:`terminate_raises` (and of :class:`StagedOutputs`).

    A :class:`KeyboardInterrupt`, so that code which lets an interrupt pass (solvers catching
    ``Exception``) lets a termination pass too, and ``finally`` blocks remove temporary files."""


def _raise_terminated(signum, frame):
    raise Terminated(f"terminated by signal {signum}")


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextmanager
def terminate_raises():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (as SIGINT raises
    :class:`KeyboardInterrupt`), so that ``finally`` blocks run and temporary files are removed;
    the previous handler is restored afterwards. Outside the main thread it does nothing."""
    if not _in_main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _temp_path(dest: Path, tag: str = TEMP_TAG) -> Path:
    return dest.parent / f".{dest.name}.{tag}-{os.getpid()}-{secrets.token_hex(4)}"


def _temp_pattern(name: str) -> re.Pattern:
    # ``..NAME.msslib-tmp-PID-RANDOM.<hex>.tmp`` too: the temporary of a writer (write_vtu) that
    # itself writes beside the path it is given
    return re.compile(r"^\.{1,2}" + re.escape(name) + rf"\.(?:{TEMP_TAG}|{_BACKUP_TAG})-(\d+)-[0-9a-f]+(?:\..+)?$")


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return True  # not one of ours: never remove
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):  # PermissionError: a process of another user is alive
        return True
    return True


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files that runs killed while writing ``path`` left beside it (those
    whose process id is no longer alive); returns the paths removed. Errors are ignored."""
    path = Path(path)
    pattern = _temp_pattern(path.name)
    removed = []
    try:
        names = os.listdir(path.parent if str(path.parent) else ".")
    except OSError:
        return removed
    for name in names:
        match = pattern.match(name)
        if match is None or _pid_alive(int(match.group(1))):
            continue
        stale = path.parent / name
        try:
            if stale.is_file() and not stale.is_symlink():
                stale.unlink()
                removed.append(stale)
        except OSError:
            pass
    return removed


def _unlink(path: Path) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def _fsync(path: Path, flags: int = os.O_RDONLY) -> None:
    try:
        fd = os.open(path, flags)
    except OSError:
        return  # directories cannot be opened on every platform
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _rename_error(exc: BaseException, tmp: Path, dest: Path, what: str) -> BaseException:
    """``exc`` raised while writing ``tmp``, re-made to name ``dest`` (not the temporary file)."""
    pattern = re.compile(r"\.?" + re.escape(tmp.name) + r"(?:\.[0-9a-f]+\.tmp)?")
    if isinstance(exc, OSError) and exc.errno is not None:  # shown as "[Errno N] message: 'dest'"
        message = f"cannot write {what}: {pattern.sub(dest.name, str(exc.strerror or exc))}"
        try:
            new = type(exc)(exc.errno, message, str(dest))
        except Exception:  # an OSError subclass with another signature
            new = OSError(exc.errno, message, str(dest))
    elif isinstance(exc, OSError):
        new = type(exc)(f"cannot write {what} {str(dest)!r}: {pattern.sub(dest.name, str(exc))}")
    else:
        message = f"cannot write {what} {str(dest)!r}: {pattern.sub(dest.name, ' '.join(str(exc).split()))}"
        try:
            new = type(exc)(message)
        except Exception:
            new = OSError(errno.EIO, message, str(dest))
    new.msslib_output = str(dest)  # the command line reports such errors as one line
    return new


class StagedOutputs:
    """Several output files written as one: every file is replaced, or none is.

    .. code-block:: python

        with StagedOutputs() as out:
            out.write_result("run.nc", ds)
            out.write("run.vtu", lambda tmp: write_vtu(tmp, mesh), what="VTU file")
        # here both files are in place; had anything in the block failed, neither would be touched

    Each output is first written to a temporary file in its destination directory, named
    ``.NAME.msslib-tmp-PID-RANDOM``; when the block ends without an error, every temporary file is
    flushed to disk and renamed over its destination (:func:`os.replace`). Should a rename fail
    half-way, the files already replaced get their old content back (a hard link to each replaced
    file is kept until the end). On any error, ``KeyboardInterrupt`` included, every temporary file
    is removed and the error re-raised, naming the destination rather than the temporary file.

    SIGTERM: when the process has the default SIGTERM disposition, the block installs a handler
    that raises :class:`Terminated`; after the clean-up the default is restored and the signal
    re-sent, so that the process still ends as killed by SIGTERM (another handler, such as the
    command line's :func:`terminate_raises`, is left alone). Temporary files of runs killed
    outright (SIGKILL, power loss) are removed the next time the same destination is written, once
    their process id is no longer alive (:func:`remove_stale_temporaries`).

    Without ``with``, call :meth:`commit` or :meth:`discard` yourself.
    """

    def __init__(self):
        self._staged: list[tuple[Path, Path]] = []  # (destination, temporary file)
        self._installed = False
        self._previous = None

    # -- staging

    def stage(self, dest: str | os.PathLike, what: str = "output file") -> Path:
        """Reserve (create, empty) a temporary file for ``dest`` and return its path; it becomes
        ``dest`` at :meth:`commit`."""
        dest = Path(dest)
        for other, _ in self._staged:
            if os.path.abspath(other) == os.path.abspath(dest):
                raise ValueError(f"{what} {str(dest)!r} is staged twice")
        directory = dest.parent
        if not directory.is_dir():
            code = errno.ENOTDIR if directory.exists() else errno.ENOENT
            raise (NotADirectoryError if code == errno.ENOTDIR else FileNotFoundError)(
                code, f"cannot write {what}, directory {str(directory)!r} does not exist", str(dest))
        if dest.is_dir():
            raise IsADirectoryError(errno.EISDIR, f"cannot write {what}, it is a directory", str(dest))
        if dest.exists() and not dest.is_file():  # a device or a pipe: os.replace would replace it
            raise OSError(errno.EINVAL, f"cannot write {what}, it exists and is not a regular file", str(dest))
        remove_stale_temporaries(dest)
        tmp = _temp_path(dest)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # mode honours the umask
        except OSError as exc:
            raise type(exc)(exc.errno, f"cannot write {what}, no temporary file in {str(directory)!r}: "
                                       f"{exc.strerror}", str(dest)) from exc
        os.close(fd)
        self._staged.append((dest, tmp))
        return tmp

    def write(self, dest: str | os.PathLike, writer, what: str = "output file") -> Path:
        """Stage ``dest`` and call ``writer(temporary_path)`` to fill it; an error of the writer
        is re-raised naming ``dest``."""
        dest = Path(dest)
        tmp = self.stage(dest, what)
        try:
            writer(tmp)
        except BaseException as exc:
            self._staged.remove((dest, tmp))
            _unlink(tmp)
            if isinstance(exc, Exception):
                raise _rename_error(exc, tmp, dest, what) from exc
            raise
        return dest

    def write_result(self, dest: str | os.PathLike, ds: xr.Dataset, what: str = "result") -> Path:
        """Stage a NetCDF result (refused, ValueError, if :data:`FINITE_VARIABLES` are not finite)."""
        _check_finite(Path(dest), ds)
        return self.write(dest, _to_netcdf(ds), what)

    def write_text(self, dest: str | os.PathLike, text: str, what: str = "text file") -> Path:
        """Stage a UTF-8 text file."""
        return self.write(dest, _to_text(text), what)

    @property
    def destinations(self) -> list[Path]:
        return [dest for dest, _ in self._staged]

    # -- ending

    def discard(self) -> None:
        """Remove every temporary file; no destination is touched."""
        staged, self._staged = self._staged, []
        for _, tmp in staged:
            _unlink(tmp)

    def commit(self) -> list[Path]:
        """Rename every temporary file over its destination (all, or none); returns the
        destinations."""
        staged = self._staged
        backups: dict[Path, Path | None] = {}
        replaced: list[Path] = []
        existed = {dest: os.path.lexists(dest) for dest, _ in staged}
        try:
            for _, tmp in staged:
                _fsync(tmp)
            for dest, _ in staged:  # keep the files about to be replaced, to put them back on failure
                backups[dest] = None
                if existed[dest]:
                    backup = _temp_path(dest, _BACKUP_TAG)
                    try:
                        os.link(dest, backup, follow_symlinks=False)
                        backups[dest] = backup
                    except OSError:  # no hard links here: that file cannot be put back
                        pass
            for dest, tmp in staged:
                try:
                    os.replace(tmp, dest)
                except Exception as exc:
                    raise _rename_error(exc, tmp, dest, "output file") from exc
                replaced.append(dest)
        except BaseException:
            for dest in reversed(replaced):  # put the old files back
                try:
                    if backups.get(dest) is not None:
                        os.replace(backups.pop(dest), dest)
                    elif not existed[dest]:
                        os.unlink(dest)
                except OSError:
                    pass
            raise
        finally:
            for backup in backups.values():
                if backup is not None:
                    _unlink(backup)
            self.discard()
        for directory in {dest.parent for dest in replaced}:  # make the renames durable
            _fsync(directory)
        return replaced

    def __enter__(self):
        if _in_main_thread() and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
            self._previous = signal.signal(signal.SIGTERM, _raise_terminated)
            self._installed = True
        return self

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                self.commit()
            else:
                self.discard()
        finally:
            if self._installed:
                self._installed = False
                signal.signal(signal.SIGTERM, self._previous)
                if exc_type is not None and issubclass(exc_type, Terminated):
                    os.kill(os.getpid(), signal.SIGTERM)  # end as the default disposition would
        return False


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

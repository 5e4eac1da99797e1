"""Declarative scenes: a YAML file that describes one simulation, from the mesh to the output.

:func:`load_scene` reads and validates a scene (a YAML file or an equivalent ``dict``) into a
:class:`Scene`; :func:`prepare` builds its mesh, boundary conditions, loads and model;
:func:`run_scene` solves it and returns an :class:`xarray.Dataset` in the schema of
:mod:`msslib.io`.  The command line (``python -m msslib run SCENE.yaml --out OUT.nc``) wraps them.

Syntax reference
================

Units are SI throughout: metres, pascals, newtons, kilograms, seconds.  Numbers may be written
``1.0e6`` or ``1e6`` (plain YAML reads the latter as a string; scenes accept both).  Every mapping
is checked for unknown keys: a typo is an error naming its full path, e.g.
``scene.loads[1].tractoin: unknown key; expected one of select, traction, type``.

.. code-block:: yaml

    name: golec_compression            # optional; default: the file name without suffix
    description: Golec cube, 10 % compression          # optional, free text
    geometry:                          # exactly one of `generator` or `file`
      generator: hex_grid              # a generator of msslib.mesh
      args: {lx: 0.1, ly: 0.1, lz: 0.1, nx: 4, ny: 4, nz: 4}
      # file: meshes/part.vtu          # or any file meshio reads, relative to the scene file
    materials:                         # material i applies to the cells with material index i
      - {E: 1.0e6, nu: 0.3, density: 1000.0}
      # or keyed by the cell groups of a mesh file: {soft: {E: ..., nu: ...}, stiff: {...}}
    regions:                           # optional; later entries win
      - {box: [[0.05, null, null], [null, null, null]], material: 1}
    thickness: 0.01                    # 2D meshes only (default 1.0)
    model: golec_cube                  # or a mapping, see "model" below
    boundary:
      - {select: {plane: [z, 0.0]}, fix: [z]}
      - {select: {plane: [z, 0.1]}, fix: [z], displacement: [null, null, -0.01]}
    loads:
      - {type: gravity, g: [0.0, 0.0, -9.81]}
    solver: {type: static, load_steps: 5, tol: 1.0e-8}
    output: {vtu: true}

``geometry``
    ``generator`` names one of :data:`GENERATORS` (``quad_grid``, ``triangle_grid_equilateral``,
    ``hexagon_equilateral``, ``triangle_grid_right``, ``hex_grid``, ``tet_grid``,
    ``l_block_hex``, ``polygon_mesh``, ``cylinder_mesh``, ``cylinder_with_hole_mesh``,
    ``cone_mesh``, ``l_block_tet``) and ``args`` its keyword arguments (see :mod:`msslib.mesh`;
    unknown or missing arguments are errors).  ``file`` is a mesh file read by
    :func:`msslib.mesh.read`, relative to the directory of the scene file (or of ``base_dir`` for a
    scene given as a dict); an integer cell data array ``material`` becomes the material index.
    The file's groups are kept (gmsh physical groups, cell sets, node sets; see
    :func:`msslib.mesh.read`): groups of its cells for ``materials``, groups of boundary facets
    (gmsh physical surfaces of a 3D mesh, curves of a 2D mesh) and nodes for ``select``.  A group
    is known by its name, a gmsh physical group without a name by its number (``3`` or ``"3"``).
    ``refine: k`` (optional) refines the mesh uniformly ``k`` times (:func:`msslib.refine.uniform`:
    nested meshes of one domain, the coarse nodes keeping their numbers).
``materials``
    A non-empty list (every material used by some cell) of ``{E, nu, density}``: Young's modulus ``E > 0`` (Pa), Poisson's ratio
    ``-1 < nu < 0.5`` and the density (kg/m^3, > 0).  ``density`` may be omitted unless the scene
    has gravity or is dynamic.  Note that the triangle and square MSS models are exact only for
    ``nu = 1/3``, Lloyd's tetrahedron without volume term for ``nu = 1/4``.

    Or a mapping from the cell groups of a mesh file to their materials, which assigns each
    group's cells its material (the file's ``material`` cell data is then not used); every cell
    must be in exactly one of the groups named (cells in none or in two are an error counting
    them, with an example cell), and a group the mesh lacks is an error naming the groups it has.
    Material ``i`` is the ``i``-th entry as written; the result names them (``material_name``)::

        geometry: {file: meshes/two_materials.msh}   # physical volumes soft, stiff; surfaces base, top
        materials:
          soft: {E: 1.0e6, nu: 0.45, density: 1100.0}
          stiff: {E: 2.0e8, nu: 0.3, density: 7800.0}
        boundary:
          - {select: {group: base}}
        loads:
          - {type: traction, select: {group: top}, traction: [0.0, 0.0, -1.0e4]}

    With the list form, material ``i`` applies to the cells of material index ``i`` (cell data
    ``material``, ``regions``); a mesh file with cell groups but no material index (every cell 0)
    and a list of several materials is an error asking for the mapping form (or ``regions``), and
    one material for the whole mesh is fine.
``regions``
    Optional list of ``{box: [[xmin, ymin(, zmin)], [xmax, ymax(, zmax)]], material: i}``: cells
    whose centroid lies in the box (``null`` bounds are unbounded) get material ``i`` (with
    materials keyed by group, ``material`` names one of the keys), after the groups.
``thickness``
    Membrane thickness (m) of a 2D mesh (plane stress); an error for 3D meshes.
``model``
    A name, or a mapping ``{type: NAME, ...options}``.  FEM references (scikit-fem):
    ``fem_linear`` (small strain), ``fem_svk`` (St Venant-Kirchhoff), ``fem_neohookean``; option
    ``plane: stress | strain`` for 2D (default ``stress``).  Mass-spring models with their mesh:

    ============================ ============ =========================================
    model                        cells        terms (default: all of them)
    ============================ ============ =========================================
    ``lloyd_triangle``           triangle     ``springs``
    ``van_gelder``               triangle     ``springs``
    ``lloyd_square``             quad         ``springs``
    ``lloyd_tetrahedron``        tetra        ``springs``
    ``lloyd_tetrahedron_volume`` tetra        ``springs``, ``volume``
    ``baudet_cube``              hexahedron   ``springs``, ``correction``
    ``golec_cube``               hexahedron   ``springs``, ``volume``
    ============================ ============ =========================================

    Options: ``published: true`` uses the formulas as printed in the papers (see
    :mod:`msslib.parameters`; models without a separate printed variant ignore it), ``A``
    (``golec_cube`` only, default 1.0) the ratio ``k_inner / k_face``, and ``terms`` the list of
    internal force terms to build — only those listed are built, e.g.
    ``{type: golec_cube, terms: [springs]}`` is a classical MSS without Golec's volume term.
    Baudet's ``correction`` is computed from the traction and nodal-force loads (not gravity); it
    is non-conservative, so the static solver's line search works on the residual norm.  Option
    ``correction: boundary | element`` (``baudet_cube`` only) picks its reading: ``boundary`` (the
    default, as just said) or ``element``, each cube's correction from the forces acting on it from
    outside (neighbours, loads, gravity, supports), see :mod:`msslib.baudet_correction`.
``boundary``
    List of ``{select: SELECTION, fix: [x, y(, z)] | all, displacement: [...]}``, e.g.
    ``{select: {group: base}, fix: all}`` for a gmsh physical surface ``base``.  ``fix``
    (default ``all``) lists the constrained axes of the selected nodes; ``displacement`` (optional)
    gives one value per axis (m), ``null`` or 0 for the axes not fixed.  A dof fixed twice with two
    different displacements is an error.  Static solves ramp prescribed displacements with the
    load factor; dynamic runs apply them at ``t = 0`` and hold them.  A static scene must hold
    every part of its mesh: a floating part or a free rigid-body mode (a translation or rotation
    the fixed dofs do not stop) is an error naming the part and the mode.
``SELECTION``
    ``all``, or a mapping with ``plane: [axis, value]`` (axis ``x``, ``y`` or ``z``),
    ``box: [[xmin, ...], [xmax, ...]]`` (``null`` = unbounded, either corner may be ``null``)
    and/or ``group: NAME`` (a group of the mesh file: the nodes of its facets, or its nodes, or
    for a group of cells the nodes of those cells; a name that is a group of cells and also of
    facets or nodes selects the latter, with a warning); with several, the intersection, e.g.
    ``{group: top, box: [[0.0, null, null], [0.05, null, null]]}``.  ``tol`` (m) widens the
    bounds; default ``1e-8`` times the diagonal of the mesh's bounding box.  Selecting no node is
    an error, and so is a group the mesh lacks (naming the groups it has).
``loads``
    List of load entries, all proportional to the load factor of the static solver:

    * ``{type: gravity, g: [0, 0, -9.81]}`` — weight of the lumped node masses (m/s^2);
    * ``{type: traction, select: SELECTION, traction: [tx, ty(, tz)]}`` — a dead traction (Pa) on
      the boundary facets whose nodes are all selected (consistent nodal forces; in 2D per unit
      area of the edge times ``thickness``); with ``group``, on the facets of that facet group
      (each must be a boundary facet) or the boundary facets of the cells of that cell group,
      those all of whose nodes lie in ``plane``/``box`` when given;
    * ``{type: nodal_force, select: SELECTION, total: [Fx, Fy(, Fz)]}`` — a total force (N) split
      equally over the selected nodes.
``solver``
    ``{type: static, load_steps: 1, tol: 1.0e-8, max_iter: 50}`` (default; load-stepped Newton
    of :func:`msslib.solvers.static_solve` for MSS, :func:`msslib.fem.solve_nonlinear` for the
    non-linear FEM; ``fem_linear`` ignores them; ``linear: true`` makes one solve with the
    stiffness at rest instead: the MSS model's Hessian, or linear FEM), or ``{type: dynamic, method:
    symplectic_euler | velocity_verlet | implicit_euler, dt: 1.0e-4, t_end: 0.1, damping: 0.0,
    save_every: 1, allow_unstable: false}`` (MSS only, :func:`msslib.solvers.integrate` from rest;
    ``damping`` is a mass-proportional ``alpha`` (1/s) or a Rayleigh pair ``[alpha, beta]``).  An
    explicit step above the stability limit of the model at rest is refused with both numbers
    unless ``allow_unstable: true``.
``output``
    ``{vtu: false, history: true}``: ``vtu: true`` also writes a VTU file next to the NetCDF result
    (same name, suffix ``.vtu``), a string names that file (relative to the result's directory);
    ``history: false`` drops the stored states of a dynamic run.
``checks``
    ``{inverted: warn, coincident_nodes: merge, max_memory_gb: null}``: ``inverted: error`` turns
    inverted or collapsed cells in the final (or a saved) state from a warning recorded in the
    result into an error; ``coincident_nodes: error`` refuses a mesh with coincident nodes instead
    of merging them (with a message naming them); ``max_memory_gb`` caps the memory a run may plan
    to use (default: the memory available on the machine).

Result
------
:func:`run_scene` returns :func:`msslib.io.make_dataset`'s dataset (CF-1.11 and UGRID-1.0, see
:mod:`msslib.io`): rest positions, final displacement, reactions, fixed mask, the materials as
variables (``material_E``, ``material_nu``, ``material_density``, ``material_name`` when they are
keyed by group), ``thickness`` (2D), springs with constants and rest lengths (MSS), the history
(time, displacement, velocity, kinetic energy) of dynamic runs, the cell check of
:mod:`msslib.quality`, solver statistics (``solver_*``), wall time, the scene text, the model name,
plus the attributes ``scene_name`` and ``scene_description``.
"""

from __future__ import annotations

import difflib
import inspect
import math
import sys
import time
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np
import yaml

from msslib import mesh as _mesh

__all__ = [
    "GENERATORS",
    "MSS_MODELS",
    "FEM_MODELS",
    "MODELS",
    "Material",
    "Scene",
    "Setup",
    "TextProgress",
    "load_scene",
    "prepare",
    "run_scene",
]

GENERATORS = {
    "quad_grid": 2, "triangle_grid_equilateral": 2, "hexagon_equilateral": 2, "triangle_grid_right": 2,
    "polygon_mesh": 2, "hex_grid": 3, "tet_grid": 3, "l_block_hex": 3, "cylinder_mesh": 3,
    "cylinder_with_hole_mesh": 3, "cone_mesh": 3, "l_block_tet": 3,
}
"""Mesh generators of :mod:`msslib.mesh` a scene may name, with their dimension."""

#: MSS model name -> (cell type, internal terms it can build)
MSS_MODELS = {
    "lloyd_triangle": ("triangle", ("springs",)),
    "van_gelder": ("triangle", ("springs",)),
    "lloyd_square": ("quad", ("springs",)),
    "lloyd_tetrahedron": ("tetra", ("springs",)),
    "lloyd_tetrahedron_volume": ("tetra", ("springs", "volume")),
    "baudet_cube": ("hexahedron", ("springs", "correction")),
    "golec_cube": ("hexahedron", ("springs", "volume")),
}
#: FEM model name -> material law of :func:`msslib.fem.solve_nonlinear` (None: linear)
FEM_MODELS = {"fem_linear": None, "fem_svk": "svk", "fem_neohookean": "neohookean"}
MODELS = tuple(FEM_MODELS) + tuple(MSS_MODELS)

LOAD_TYPES = ("gravity", "nodal_force", "traction")
SOLVER_TYPES = ("static", "dynamic")
METHODS = ("symplectic_euler", "velocity_verlet", "implicit_euler")
AXES = ("x", "y", "z")

_TOP_KEYS = ("name", "description", "geometry", "materials", "regions", "thickness", "model", "boundary",
             "loads", "solver", "output", "checks")

#: what ``checks.inverted`` and ``checks.coincident_nodes`` may say
CHECK_CHOICES = {"inverted": ("warn", "error"), "coincident_nodes": ("merge", "error")}


# --------------------------------------------------------------------------------------------
# data classes
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Material:
    """An isotropic material: ``E`` (Pa), ``nu`` and ``density`` (kg/m^3, None if not given)."""

    E: float
    nu: float
    density: float | None = None


@dataclass
class Scene:
    """A validated scene (see the module docstring for the syntax).

    ``geometry`` is ``{"generator": name, "args": {...}}`` or ``{"file": Path}`` (absolute);
    ``model_options`` holds ``published`` (bool), ``A`` (float), ``terms`` (tuple of names) and
    ``plane``; ``boundary``, ``loads``, ``solver`` and ``output`` are normalised mappings.
    ``text`` is the scene source (YAML), ``path`` its file (None for a dict).
    ``material_groups``: the mesh groups of the materials (mapping form of ``materials``), one per
    material in index order; None for the list form.
    """

    name: str
    description: str
    geometry: dict
    materials: list[Material]
    model: str
    model_options: dict = field(default_factory=dict)
    regions: list[dict] = field(default_factory=list)
    thickness: float | None = None
    boundary: list[dict] = field(default_factory=list)
    loads: list[dict] = field(default_factory=list)
    solver: dict = field(default_factory=dict)
    output: dict = field(default_factory=dict)
    checks: dict = field(default_factory=lambda: dict(_DEFAULT_CHECKS))  # see "checks" above
    text: str = ""
    path: Path | None = None
    material_groups: tuple[str, ...] | None = None

    @property
    def is_fem(self) -> bool:
        return self.model in FEM_MODELS

    @property
    def is_dynamic(self) -> bool:
        return self.solver.get("type") == "dynamic"


@dataclass
class Setup:
    """What :func:`prepare` builds from a scene: mesh, boundary conditions, loads and model.

    ``fixed`` (n, dim) bool and ``prescribed`` (n, dim) m; ``surface_forces`` (n, dim) N, the
    traction and nodal-force loads; ``gravity`` (dim,) m/s^2 or None; ``cell_density`` (n_cells,)
    (NaN where not given); ``masses`` (n,) kg lumped node masses (None without densities);
    ``model`` the :class:`msslib.model.Model` of an MSS scene (None for FEM).
    """

    scene: Scene
    mesh: _mesh.Mesh
    fixed: np.ndarray
    prescribed: np.ndarray
    surface_forces: np.ndarray
    gravity: np.ndarray | None
    cell_density: np.ndarray
    masses: np.ndarray | None
    model: Any = None

    @property
    def thickness(self) -> float:
        return 1.0 if self.mesh.dim == 3 else float(self.scene.thickness or 1.0)


# --------------------------------------------------------------------------------------------
# YAML loading (duplicate keys are errors)
# --------------------------------------------------------------------------------------------


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader that rejects duplicate keys in a mapping."""


def _construct_mapping(loader, node, deep=False):
    seen = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                "while constructing a mapping", node.start_mark, f"found duplicate key {key!r}", key_node.start_mark)
        seen[key] = True
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


_StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _parse_yaml(text: str, source: str):
    try:
        return yaml.load(text, Loader=_StrictLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        what = " ".join(str(x) for x in (exc.context, exc.problem) if x)
        raise ValueError(f"{source}{where}: invalid YAML: {what}") from None
    except yaml.YAMLError as exc:
        detail = " ".join(str(exc).split())
        raise ValueError(f"{source}: invalid YAML: {detail}") from None


# --------------------------------------------------------------------------------------------
# validation helpers: every error names the key path
# --------------------------------------------------------------------------------------------


def _fail(path: str, message: str):
    raise ValueError(f"{path}: {message}")


def _mapping(path, value, allowed, required=()):
    if not isinstance(value, Mapping):
        _fail(path, f"expected a mapping with keys {', '.join(sorted(allowed))}, got {value!r}")
    for key in value:
        if key not in allowed:
            hint = difflib.get_close_matches(str(key), list(allowed), n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            _fail(f"{path}.{key}", f"unknown key; expected one of {', '.join(sorted(allowed))}{did}")
    for key in required:
        if key not in value:
            _fail(f"{path}.{key}", "required key missing")
    return value


def _show(value) -> str:
    """A value as the user wrote it (numbers written as strings such as 1e6 without quotes)."""
    if isinstance(value, str):
        try:
            float(value)
            return value
        except ValueError:
            return repr(value)
    return repr(value)


def _number(path, value, *, low=None, high=None, low_open=True, high_open=True, what="a number"):
    if isinstance(value, bool) or value is None:
        _fail(path, f"expected {what}, got {value!r}")
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            _fail(path, f"expected {what}, got {value!r}")
    elif isinstance(value, (int, float, np.integer, np.floating)):
        try:
            number = float(value)
        except OverflowError:  # an integer beyond double precision
            number = math.inf
    else:
        _fail(path, f"expected {what}, got {value!r}")
    if not math.isfinite(number):
        _fail(path, f"expected a finite number, got {_show(value)}")
    if low is not None and (number <= low if low_open else number < low):
        _fail(path, f"must be {'>' if low_open else '>='} {low:g}, got {_show(value)}")
    if high is not None and (number >= high if high_open else number > high):
        _fail(path, f"must be {'<' if high_open else '<='} {high:g}, got {_show(value)}")
    return number


def _integer(path, value, minimum=1, maximum=None, why=""):
    number = _number(path, value, what="an integer")
    if number != int(number) or number < minimum:
        _fail(path, f"must be an integer >= {minimum}, got {_show(value)}")
    if maximum is not None and number > maximum:
        _fail(path, f"must be at most {maximum:g}{why}, got {_show(value)}")
    return int(number)


#: the most load steps, Newton iterations and time steps a scene may ask for: beyond them a run
#: cannot end in any useful time (a typo such as load_steps: 1e30 fails at once instead)
MAX_LOAD_STEPS = 10**5
MAX_NEWTON_ITERATIONS = 10**4
MAX_TIME_STEPS = 10**9


def _boolean(path, value):
    if not isinstance(value, bool):
        _fail(path, f"expected true or false, got {value!r}")
    return value


def _string(path, value):
    if not isinstance(value, str):
        _fail(path, f"expected a string, got {value!r}")
    return value


def _choice(path, value, choices, what):
    if not isinstance(value, str) or value not in choices:
        hint = difflib.get_close_matches(str(value), list(choices), n=1)
        did = f" (did you mean {hint[0]!r}?)" if hint else ""
        _fail(path, f"unknown {what} {value!r}; expected one of {', '.join(choices)}{did}")
    return value


def _vector(path, value, *, allow_null=False, length=None):
    if not isinstance(value, (list, tuple)) or not value:
        _fail(path, f"expected a list of numbers, got {value!r}")
    if length is not None and len(value) != length:
        _fail(path, f"expected {length} values, got {len(value)}: {value!r}")
    if len(value) not in (2, 3):
        _fail(path, f"expected 2 or 3 values (one per axis), got {len(value)}: {value!r}")
    out = []
    for i, v in enumerate(value):
        if v is None and allow_null:
            out.append(None)
        else:
            out.append(_number(f"{path}[{i}]", v))
    return out


def _list(path, value):
    if value is None:
        return []
    if not isinstance(value, list):
        _fail(path, f"expected a list, got {value!r}")
    return value


def _box(path, value):
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        _fail(path, f"expected [[min...], [max...]] (null for unbounded), got {value!r}")
    corners = []
    for i, corner in enumerate(value):
        corners.append(None if corner is None else _vector(f"{path}[{i}]", corner, allow_null=True))
    if corners[0] is not None and corners[1] is not None and len(corners[0]) != len(corners[1]):
        _fail(path, f"both corners need the same number of coordinates, got {value!r}")
    return corners


def _group_key(path, value):
    """A mesh group named in a scene: a name, or the number of a group without name."""
    if isinstance(value, bool) or not isinstance(value, (str, int)) or value == "":
        _fail(path, f"expected the name of a mesh group (or the number of an unnamed one), got {value!r}")
    return str(value)


def _selection(path, value):
    if value == "all":
        return {"all": True}
    if not isinstance(value, Mapping):
        _fail(path, f"expected 'all' or a mapping with plane, box and/or group, got {value!r}")
    _mapping(path, value, ("plane", "box", "group", "tol"))
    if "plane" not in value and "box" not in value and "group" not in value:
        _fail(path, "give plane, box and/or group (or write select: all)")
    out = {}
    if "group" in value:
        out["group"] = _group_key(f"{path}.group", value["group"])
    if "plane" in value:
        plane = value["plane"]
        if not isinstance(plane, (list, tuple)) or len(plane) != 2:
            _fail(f"{path}.plane", f"expected [axis, value] such as [z, 0.0], got {plane!r}")
        axis = plane[0]
        if axis in (0, 1, 2) and not isinstance(axis, bool):
            axis = AXES[axis]
        _choice(f"{path}.plane[0]", axis, AXES, "axis")
        out["plane"] = (axis, _number(f"{path}.plane[1]", plane[1]))
    if "box" in value:
        out["box"] = _box(f"{path}.box", value["box"])
    if "tol" in value:
        out["tol"] = _number(f"{path}.tol", value["tol"], low=0.0)
    return out


# --------------------------------------------------------------------------------------------
# load_scene
# --------------------------------------------------------------------------------------------


def _generator_function(name):
    return getattr(_mesh, name)


def _geometry(path, value, base_dir: Path):
    _mapping(path, value, ("generator", "args", "file", "refine"))
    has_gen, has_file = "generator" in value, "file" in value
    if has_gen == has_file:
        _fail(path, "give exactly one of 'generator' (with 'args') or 'file'")
    # uniform midpoint refinements of the mesh (msslib.refine.uniform); only stored when asked for
    refine = {"refine": _integer(f"{path}.refine", value["refine"], minimum=0, maximum=8,
                                 why=" (each multiplies the cells by 4 or 8)")} if "refine" in value else {}
    if has_file:
        if "args" in value:
            _fail(f"{path}.args", "only used with 'generator'")
        file_value = _string(f"{path}.file", value["file"])
        file_path = Path(file_value)
        if not file_path.is_absolute():
            file_path = base_dir / file_path
        if file_path.is_dir():
            _fail(f"{path}.file", f"{file_value!r} is a directory ({file_path}); allowed: a mesh file")
        if not file_path.is_file():
            raise FileNotFoundError(f"{path}.file: mesh file not found: {file_value!r} (looked for {file_path})")
        try:
            _mesh.check_mesh_suffix(file_path)
        except ValueError as exc:
            _fail(f"{path}.file", str(exc))
        return {"file": file_path, **refine}
    name = _choice(f"{path}.generator", value["generator"], tuple(GENERATORS), "generator")
    args = value.get("args") or {}
    if not isinstance(args, Mapping):
        _fail(f"{path}.args", f"expected a mapping of keyword arguments of {name}, got {args!r}")
    sig = inspect.signature(_generator_function(name))
    params = [p for p in sig.parameters]
    converted = {}
    for key, v in args.items():
        if key not in params:
            hint = difflib.get_close_matches(str(key), params, n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            _fail(f"{path}.args.{key}", f"unknown argument of {name}; expected one of {', '.join(params)}{did}")
        converted[key] = _generator_arg(f"{path}.args.{key}", v)
    missing = [p.name for p in sig.parameters.values() if p.default is inspect.Parameter.empty and p.name not in args]
    if missing:
        _fail(f"{path}.args", f"{name} needs the argument(s) {', '.join(missing)}")
    return {"generator": name, "args": converted, **refine}


def _generator_arg(path, value):
    """Numbers (also written as strings like '1e-2') and nested lists of them."""
    if isinstance(value, (list, tuple)):
        return tuple(_generator_arg(f"{path}[{i}]", v) for i, v in enumerate(value))
    if isinstance(value, bool):
        _fail(path, f"expected a number, got {value!r}")
    if isinstance(value, int) and abs(value) < 2**63:
        return value
    return _number(path, value)  # an integer beyond 64 bits as a float; beyond double range refused


def _materials(path, value):
    """``(materials, groups)``: the list form gives ``groups = None``, the mapping form (mesh group
    -> material) the group keys in the order written, one per material."""
    if isinstance(value, Mapping) and value:
        entries, groups = [], []
        for key, m in value.items():
            name = _group_key(f"{path}.{key}", key)
            if name in groups:
                _fail(f"{path}.{key}", f"group {name!r} is given twice")
            groups.append(name)
            entries.append((f"{path}.{name}", m))
    elif isinstance(value, list) and value:
        entries, groups = [(f"{path}[{i}]", m) for i, m in enumerate(value)], None
    else:
        _fail(path, f"expected a non-empty list of {{E, nu, density}}, or a mapping of mesh group names to them, "
              f"got {value!r}")
    out = []
    for p, m in entries:
        _mapping(p, m, ("E", "nu", "density"), required=("E", "nu"))
        E = _number(f"{p}.E", m["E"], low=0.0)
        nu = _number(f"{p}.nu", m["nu"], low=-1.0, high=0.5)
        density = None if m.get("density") is None else _number(f"{p}.density", m["density"], low=0.0)
        out.append(Material(E, nu, density))
    return out, None if groups is None else tuple(groups)


def _regions(path, value, n_materials, groups=None):
    """Regions; with materials keyed by group (``groups``), ``material`` names one of the keys."""
    out = []
    for i, r in enumerate(_list(path, value)):
        p = f"{path}[{i}]"
        _mapping(p, r, ("box", "material"), required=("box", "material"))
        if groups is not None:
            key = _group_key(f"{p}.material", r["material"])
            if key not in groups:
                hint = difflib.get_close_matches(key, list(groups), n=1)
                did = f" (did you mean {hint[0]!r}?)" if hint else ""
                _fail(f"{p}.material", f"unknown material {key!r}{did}; expected one of the keys of scene.materials, "
                      f"{', '.join(groups)}")
            material = groups.index(key)
        else:
            material = _integer(f"{p}.material", r["material"], minimum=0)
            if material >= n_materials:
                _fail(f"{p}.material", f"material index {material} does not exist ({n_materials} material(s) given)")
        out.append({"box": _box(f"{p}.box", r["box"]), "material": material})
    return out


def _model(path, value):
    type_path = f"{path}.type"
    if isinstance(value, str):
        value, type_path = {"type": value}, path
    if not isinstance(value, Mapping):
        _fail(path, f"expected a model name or a mapping with 'type', got {value!r}")
    _mapping(path, value, ("type", "published", "A", "terms", "plane", "correction"), required=("type",))
    name = _choice(type_path, value["type"], MODELS, "model")
    opts = {"published": False, "A": None, "terms": None, "plane": "stress"}
    if name == "baudet_cube":
        from msslib.baudet_correction import READINGS

        opts["correction"] = _choice(f"{path}.correction", value.get("correction", "boundary"), READINGS,
                                     "Baudet correction reading")
    elif "correction" in value:
        _fail(f"{path}.correction", f"only baudet_cube takes correction, not {name}")
    if "published" in value:
        opts["published"] = _boolean(f"{path}.published", value["published"])
    if "A" in value:
        if name != "golec_cube":
            _fail(f"{path}.A", f"only golec_cube takes A, not {name}")
        opts["A"] = _number(f"{path}.A", value["A"], low=0.0)
    if name == "golec_cube" and opts["A"] is None:
        opts["A"] = 1.0
    if "terms" in value:
        if name in FEM_MODELS:
            _fail(f"{path}.terms", f"only MSS models have terms, not {name}")
        available = MSS_MODELS[name][1]
        terms = value["terms"]
        if not isinstance(terms, list) or not terms:
            _fail(f"{path}.terms", f"expected a non-empty list from {', '.join(available)}, got {terms!r}")
        for i, t in enumerate(terms):
            _choice(f"{path}.terms[{i}]", t, available, f"term of {name}")
        if len(set(terms)) != len(terms):
            _fail(f"{path}.terms", f"a term is listed twice: {terms!r}")
        opts["terms"] = tuple(terms)
    elif name in MSS_MODELS:
        opts["terms"] = MSS_MODELS[name][1]
    if "plane" in value:
        if name not in FEM_MODELS:
            _fail(f"{path}.plane", f"MSS models are plane stress; plane applies to the FEM models only, not {name}")
        opts["plane"] = _choice(f"{path}.plane", value["plane"], ("stress", "strain"), "plane")
    return name, opts


def _boundary(path, value):
    out = []
    for i, b in enumerate(_list(path, value)):
        p = f"{path}[{i}]"
        _mapping(p, b, ("select", "fix", "displacement"), required=("select",))
        sel = _selection(f"{p}.select", b["select"])
        fix = b.get("fix", "all")
        if fix == "all":
            axes = None
        else:
            if isinstance(fix, str):
                fix = [fix]
            if not isinstance(fix, list) or not fix:
                _fail(f"{p}.fix", f"expected 'all' or a list of axes such as [x, z], got {fix!r}")
            axes = []
            for j, a in enumerate(fix):
                _choice(f"{p}.fix[{j}]", a, AXES, "axis")
                if a in axes:
                    _fail(f"{p}.fix", f"axis {a!r} listed twice")
                axes.append(a)
        disp = None
        if b.get("displacement") is not None:
            disp = _vector(f"{p}.displacement", b["displacement"], allow_null=True)
            for j, d in enumerate(disp):
                if axes is not None and AXES[j] not in axes and d not in (None, 0.0):
                    _fail(f"{p}.displacement[{j}]", f"displacement {d!r} given on axis {AXES[j]!r}, which is not fixed "
                          f"(fix: {axes})")
        out.append({"select": sel, "fix": axes, "displacement": disp})
    return out


_LOAD_KEYS = {"gravity": ("type", "g"), "traction": ("type", "select", "traction"),
              "nodal_force": ("type", "select", "total")}


def _loads(path, value):
    out = []
    for i, load in enumerate(_list(path, value)):
        p = f"{path}[{i}]"
        if not isinstance(load, Mapping):
            _fail(p, f"expected a mapping with 'type' ({', '.join(LOAD_TYPES)}), got {load!r}")
        if "type" not in load:
            _fail(f"{p}.type", f"required key missing; one of {', '.join(LOAD_TYPES)}")
        kind = _choice(f"{p}.type", load["type"], LOAD_TYPES, "load type")
        keys = _LOAD_KEYS[kind]
        _mapping(p, load, keys, required=keys)
        entry = {"type": kind}
        if kind == "gravity":
            entry["g"] = _vector(f"{p}.g", load["g"])
        else:
            entry["select"] = _selection(f"{p}.select", load["select"])
            key = keys[2]
            entry[key] = _vector(f"{p}.{key}", load[key])
        out.append(entry)
    return out


def _solver(path, value, model):
    value = {"type": "static"} if value is None else value
    if not isinstance(value, Mapping):
        _fail(path, f"expected a mapping with 'type' (static or dynamic), got {value!r}")
    kind = _choice(f"{path}.type", value.get("type", "static"), SOLVER_TYPES, "solver type")
    if kind == "static":
        _mapping(path, value, ("type", "load_steps", "tol", "max_iter", "linear"))
        # linear: one solve with the stiffness at rest (the model's Hessian, or linear FEM)
        linear = {"linear": True} if _boolean(f"{path}.linear", value.get("linear", False)) else {}
        return {**linear,
            "type": "static",
            "load_steps": _integer(f"{path}.load_steps", value.get("load_steps", 1), maximum=MAX_LOAD_STEPS,
                                   why=" (each load step is a Newton solve)"),
            "tol": _number(f"{path}.tol", value.get("tol", 1e-8), low=0.0),
            "max_iter": _integer(f"{path}.max_iter", value.get("max_iter", 50 if model in MSS_MODELS else 30),
                                 maximum=MAX_NEWTON_ITERATIONS, why=" (Newton converges in tens of iterations or not at all)"),
        }
    _mapping(path, value, ("type", "method", "dt", "t_end", "damping", "save_every", "allow_unstable"),
             required=("dt", "t_end"))
    if model in FEM_MODELS:
        _fail(f"{path}.type", f"dynamic runs need an MSS model; {model} is static only")
    damping = value.get("damping", 0.0)
    if isinstance(damping, (list, tuple)):
        if len(damping) != 2:
            _fail(f"{path}.damping", f"expected alpha or [alpha, beta], got {damping!r}")
        damping = tuple(_number(f"{path}.damping[{j}]", d, low=0.0, low_open=False) for j, d in enumerate(damping))
    else:
        damping = _number(f"{path}.damping", damping, low=0.0, low_open=False)
    out = {
        "type": "dynamic",
        "method": _choice(f"{path}.method", value.get("method", "symplectic_euler"), METHODS, "method"),
        "dt": _number(f"{path}.dt", value["dt"], low=0.0),
        "t_end": _number(f"{path}.t_end", value["t_end"], low=0.0),
        "damping": damping,
        "save_every": _integer(f"{path}.save_every", value.get("save_every", 1)),
        "allow_unstable": _boolean(f"{path}.allow_unstable", value.get("allow_unstable", False)),
    }
    n_steps = out["t_end"] / out["dt"]
    if n_steps > MAX_TIME_STEPS:
        _fail(f"{path}.dt", f"t_end / dt = {n_steps:.3g} time steps, more than the {MAX_TIME_STEPS:.0e} a run may take "
              f"(dt = {_show(value['dt'])} s, t_end = {_show(value['t_end'])} s); use a larger dt or a shorter t_end")
    return out


def _output(path, value):
    value = {} if value is None else value
    _mapping(path, value, ("vtu", "history"))
    vtu = value.get("vtu", False)
    if not isinstance(vtu, (bool, str)) or vtu == "":
        _fail(f"{path}.vtu", f"expected true, false or a file name, got {vtu!r}")
    return {"vtu": vtu, "history": _boolean(f"{path}.history", value.get("history", True))}


_DEFAULT_CHECKS = {"inverted": "warn", "coincident_nodes": "merge", "max_memory_gb": None}


def _checks(path, value):
    value = {} if value is None else value
    _mapping(path, value, tuple(_DEFAULT_CHECKS))
    out = dict(_DEFAULT_CHECKS)
    for key, choices in CHECK_CHOICES.items():
        if key in value:
            out[key] = _choice(f"{path}.{key}", value[key], choices, key.replace("_", " ") + " policy")
    if value.get("max_memory_gb") is not None:
        out["max_memory_gb"] = _number(f"{path}.max_memory_gb", value["max_memory_gb"], low=0.0)
    return out


def _saved_states(solver, output) -> float:
    """How many states a dynamic run stores (0 for statics or without history)."""
    if solver["type"] != "dynamic" or not output["history"]:
        return 0.0
    n_steps = math.ceil(solver["t_end"] / solver["dt"] - 1e-9) if solver["t_end"] > 0 else 0
    return float(n_steps // solver["save_every"] + 2)


def _check_size(root, geometry, model, solver, output, checks, n_nodes=None, dim=None):
    """Refuse, before anything is allocated, a run whose estimated memory exceeds the limit."""
    from msslib import resources

    if n_nodes is None:
        n_nodes, _n_cells, dim = resources.generated_mesh_size(geometry["generator"], geometry["args"])
        if not math.isfinite(n_nodes):
            return
        n_nodes *= (2**dim) ** geometry.get("refine", 0)  # about: a refinement multiplies the nodes by 2^dim
    n_saved = _saved_states(solver, output)
    estimate = resources.run_memory(n_nodes, dim, fem=model in FEM_MODELS, n_saved=n_saved)
    history = resources.history_memory(n_saved, n_nodes * dim)
    if history > 0.5 * estimate:
        what = (f"{root}.solver: {n_saved:.3g} saved states of {n_nodes:.3g} nodes (dt = {solver['dt']:g} s, "
                f"t_end = {solver['t_end']:g} s, save_every = {solver['save_every']})")
        hint = "use a larger dt or save_every, or output: {history: false}"
    else:
        what = f"{root}.geometry"
        if "generator" in geometry:
            what += f" ({geometry['generator']} with {', '.join(f'{k}={v}' for k, v in geometry['args'].items())})"
        else:
            what += f".file ({geometry['file'].name})"
        what += f": {n_nodes:.3g} nodes"
        hint = "use fewer elements"
    resources.check_memory(estimate, what, hint + " (or set checks.max_memory_gb)", checks["max_memory_gb"])


def load_scene(source, *, base_dir=None) -> Scene:
    """Read and validate a scene: a path to a YAML file or a ``dict`` with the same structure
    (a :class:`Scene` is returned unchanged).

    Relative mesh files are resolved against the scene file's directory (``base_dir``, default
    the current directory, for a dict).  Raises ValueError naming the key path and the value for
    unknown keys and bad values, FileNotFoundError for a missing scene or mesh file.
    """
    if isinstance(source, Scene):
        return source
    if isinstance(source, Mapping):
        raw = _plain(source)
        path = None
        text = yaml.safe_dump(raw, sort_keys=False)
        base = Path(base_dir) if base_dir is not None else Path.cwd()
    else:
        path = Path(source)
        if not path.is_file():
            raise FileNotFoundError(f"scene file not found: {str(source)!r}")
        text = path.read_text(encoding="utf-8")
        raw = _parse_yaml(text, str(source))
        base = Path(base_dir) if base_dir is not None else path.resolve().parent
    root = "scene"
    if not isinstance(raw, Mapping):
        _fail(root, f"expected a mapping of {', '.join(_TOP_KEYS)}, got {type(raw).__name__}")
    _mapping(root, raw, _TOP_KEYS, required=("geometry", "materials", "model"))

    name = raw.get("name")
    name = _string(f"{root}.name", name) if name is not None else (path.stem if path else "scene")
    description = raw.get("description")
    description = "" if description is None else _string(f"{root}.description", description)
    geometry = _geometry(f"{root}.geometry", raw["geometry"], base)
    materials, material_groups = _materials(f"{root}.materials", raw["materials"])
    if material_groups is not None and "generator" in geometry:
        _fail(f"{root}.materials", f"keyed by mesh group ({', '.join(material_groups)}), but the generated mesh "
              f"({geometry['generator']}) has no groups; allowed: a list of materials (with scene.regions), or "
              f"groups of a mesh file")
    regions = _regions(f"{root}.regions", raw.get("regions"), len(materials), material_groups)
    thickness = None
    if raw.get("thickness") is not None:
        thickness = _number(f"{root}.thickness", raw["thickness"], low=0.0)
        if geometry.get("generator") and GENERATORS[geometry["generator"]] == 3:
            _fail(f"{root}.thickness", f"applies to 2D meshes only; {geometry['generator']} is 3D")
    model, options = _model(f"{root}.model", raw["model"])
    if "generator" in geometry and model in MSS_MODELS:
        dim = GENERATORS[geometry["generator"]]
        if (MSS_MODELS[model][0] in ("triangle", "quad")) != (dim == 2):
            _fail(f"{root}.model", f"{model} needs {MSS_MODELS[model][0]} cells, "
                  f"the generator {geometry['generator']} makes a {dim}D mesh")
    boundary = _boundary(f"{root}.boundary", raw.get("boundary"))
    loads = _loads(f"{root}.loads", raw.get("loads"))
    solver = _solver(f"{root}.solver", raw.get("solver"), model)
    output = _output(f"{root}.output", raw.get("output"))
    checks = _checks(f"{root}.checks", raw.get("checks"))
    if "generator" in geometry:
        _check_size(root, geometry, model, solver, output, checks)
    needs_density = solver["type"] == "dynamic" or any(l["type"] == "gravity" for l in loads)
    if needs_density:
        for i, m in enumerate(materials):
            if m.density is None:
                why = "dynamic runs" if solver["type"] == "dynamic" else "gravity loads"
                where = f"[{i}]" if material_groups is None else f".{material_groups[i]}"
                _fail(f"{root}.materials{where}.density", f"required for {why}")
    return Scene(name=name, description=description, geometry=geometry, materials=materials, model=model,
                 model_options=options, regions=regions, thickness=thickness, boundary=boundary, loads=loads,
                 solver=solver, output=output, checks=checks, text=text, path=path, material_groups=material_groups)


def _plain(value, path="scene"):
    """A dict/list tree of plain Python values (for YAML dumping and validation): numpy scalars and
    arrays become numbers and lists, paths strings; any other object is an error naming its key."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v, f"{path}.{k}") for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{path}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist(), path)
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    _fail(path, f"expected numbers, strings, lists or mappings, got {type(value).__name__} {value!r}")


# --------------------------------------------------------------------------------------------
# prepare: mesh, boundary conditions, loads, model
# --------------------------------------------------------------------------------------------


def _build_mesh(scene: Scene) -> _mesh.Mesh:
    geo = scene.geometry
    if "file" in geo:
        try:
            mesh = _mesh.read(geo["file"], coincident_nodes=scene.checks.get("coincident_nodes", "merge"))
        except ValueError as exc:
            _fail("scene.geometry.file", str(exc))
        _check_size("scene", geo, scene.model, scene.solver, scene.output, scene.checks, n_nodes=mesh.n_nodes,
                    dim=mesh.dim)
        mesh = _mesh.orient(mesh)
    else:
        fn = _generator_function(geo["generator"])
        try:
            mesh = fn(**geo["args"])
        except (ValueError, TypeError) as exc:
            _fail("scene.geometry", f"{geo['generator']}: {exc}")
    if geo.get("refine"):
        from msslib.refine import uniform

        mesh = uniform(mesh, geo["refine"])
    if scene.thickness is not None and mesh.dim == 3:
        _fail("scene.thickness", "applies to 2D meshes only; the mesh is 3D")
    groups = scene.material_groups
    if groups is not None:
        if not mesh.cell_groups:
            what = f"the mesh file {geo['file'].name}" if "file" in geo else f"the generated mesh ({geo['generator']})"
            _fail("scene.materials", f"keyed by mesh group ({', '.join(groups)}), but {what} has no groups of its "
                  f"{mesh.cell_type} cells (its groups: {_group_names(mesh)}); allowed: a list of materials, or a "
                  f"mesh file with physical groups or cell sets of its cells")
        for key in groups:
            if key not in mesh.cell_groups:
                _fail(f"scene.materials.{key}", _no_group(mesh, key, "cell"))
        try:
            material = _mesh.materials_from_groups(mesh, groups, source="scene.materials")
        except ValueError as exc:
            raise ValueError(str(exc)) from None
    else:
        material = mesh.material.copy()
        if len(scene.materials) > 1 and mesh.cell_groups and not scene.regions and not material.any():
            shown = ", ".join(f"{k} ({len(v)} cells)" for k, v in sorted(mesh.cell_groups.items()))
            names = sorted(mesh.cell_groups)
            example = ", ".join([f"{names[0]}: {{E: ..., nu: ...}}"] + [f"{k}: {{...}}" for k in names[1:3]])
            _fail("scene.materials", f"{len(scene.materials)} materials listed, but the mesh gives every cell "
                  f"material 0 (the file has no 'material' cell data, or only zeros) and has the cell groups "
                  f"{shown}; key the materials by group, e.g. materials: {{{example}}}, or assign them with scene.regions")
    if scene.regions:
        centroids = mesh.points[mesh.cells].mean(axis=1)
        for i, region in enumerate(scene.regions):
            inside = _in_box(f"scene.regions[{i}].box", centroids, region["box"], mesh.dim, 1e-12)
            material[inside] = region["material"]
    if mesh.n_cells and material.max() >= len(scene.materials):
        _fail("scene.materials", f"the mesh uses material index {int(material.max())}, "
              f"only {len(scene.materials)} material(s) given")
    if mesh.n_cells and material.min() < 0:
        _fail("scene.geometry", f"the mesh has a negative material index {int(material.min())}")
    return replace(mesh, material=material)  # the groups stay


def _group_names(mesh) -> str:
    """The groups of a mesh, by kind, for messages."""
    parts = [f"{', '.join(sorted(groups))} ({kind})" for kind, groups in
             (("cells", mesh.cell_groups), ("boundary facets", mesh.facet_groups), ("nodes", mesh.node_groups))
             if groups]
    return "; ".join(parts) if parts else "none"


def _no_group(mesh, key, kind=None) -> str:
    """The message for a group ``key`` the mesh lacks (``kind`` "cell": among its cell groups)."""
    pool = list(mesh.cell_groups) if kind == "cell" else [*mesh.facet_groups, *mesh.node_groups, *mesh.cell_groups]
    hint = difflib.get_close_matches(key, pool, n=1)
    did = f" (did you mean {hint[0]!r}?)" if hint else ""
    if not (mesh.cell_groups or mesh.facet_groups or mesh.node_groups):
        return (f"the mesh has no group {key!r}: it has no groups at all (generated meshes have none; a mesh file "
                f"gives its gmsh physical groups, cell sets and node sets)")
    return f"the mesh has no {'cell ' if kind == 'cell' else ''}group {key!r}{did}; its groups: {_group_names(mesh)}"


def _group_members(path, mesh, key):
    """``(kind, members, nodes)`` of the group ``key`` for a selection: its boundary facets
    (``kind`` "facets", ``members`` the facets) or nodes ("nodes", None) when it is a group of
    facets or nodes, else its cells ("cells", the cell indices); ``nodes`` the sorted nodes."""
    in_facets, in_nodes, in_cells = (key in g for g in (mesh.facet_groups, mesh.node_groups, mesh.cell_groups))
    if not (in_facets or in_nodes or in_cells):
        _fail(path, _no_group(mesh, key))
    if in_facets or in_nodes:
        if in_cells:
            from msslib.errors import MsslibWarning

            used = "boundary facets" if in_facets else "nodes"
            warnings.warn(f"{path}: {key!r} names a group of cells and a group of {used} of the mesh; the group of "
                          f"{used} is selected", MsslibWarning, stacklevel=3)
        facets = mesh.facet_groups.get(key)
        parts = ([facets.ravel()] if in_facets else []) + ([mesh.node_groups[key]] if in_nodes else [])
        return ("facets" if in_facets else "nodes"), facets, np.unique(np.concatenate(parts))
    cells = mesh.cell_groups[key]
    return "cells", cells, np.unique(mesh.cells[cells])


def _in_box(path, x, box, dim, tol):
    keep = np.ones(len(x), dtype=bool)
    for corner, sign in zip(box, (1.0, -1.0)):
        if corner is None:
            continue
        if len(corner) != dim:
            _fail(path, f"box corners need {dim} coordinates on a {dim}D mesh, got {list(corner)!r}")
        for d, b in enumerate(corner):
            if b is not None:
                keep &= sign * (x[:, d] - b) >= -tol
    return keep


def _select(path, mesh, sel, default_tol, group=None):
    """Sorted ids of the selected nodes (``group``: the :func:`_group_members` of ``sel["group"]``
    if already looked up)."""
    if sel.get("all"):
        return np.arange(mesh.n_nodes)
    if "group" in sel:
        group = _group_members(f"{path}.group", mesh, sel["group"]) if group is None else group
        if "plane" not in sel and "box" not in sel:
            return group[2]
        nodes = np.intersect1d(_select(path, mesh, {k: v for k, v in sel.items() if k != "group"}, default_tol),
                               group[2])
        if len(nodes) == 0:
            where = " and ".join(f"plane [{sel['plane'][0]}, {sel['plane'][1]:g}]" if k == "plane" else f"box {sel[k]}"
                                 for k in ("plane", "box") if k in sel)
            _fail(path, f"group {sel['group']!r} ({len(group[2])} nodes) has no node in {where}")
        return nodes
    tol = sel.get("tol", default_tol)
    if "plane" in sel and AXES.index(sel["plane"][0]) >= mesh.dim:
        _fail(f"{path}.plane", f"axis {sel['plane'][0]!r} does not exist on a {mesh.dim}D mesh")
    if "box" in sel:
        for i, corner in enumerate(sel["box"]):
            if corner is not None and len(corner) != mesh.dim:
                _fail(f"{path}.box[{i}]", f"needs {mesh.dim} coordinates on a {mesh.dim}D mesh, got {corner!r}")
    try:
        return _mesh.select_nodes(mesh, box=sel.get("box"), plane=sel.get("plane"), tol=tol)
    except ValueError:
        shown = {k: v for k, v in sel.items()}
        lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
        _fail(path, f"selects no node: {shown} (tol {tol:.3g} m; the mesh spans {np.round(lo, 6).tolist()} to "
              f"{np.round(hi, 6).tolist()})")


def _loaded_facets(path, mesh, sel, default_tol, cache):
    """The facets a traction acts on: the facets of a facet group (each must be a boundary facet),
    the boundary facets of the cells of a cell group, else the boundary facets whose nodes are all
    selected; with plane and/or box, only those whose nodes are all in them too."""
    if "boundary" not in cache:
        cache["boundary"] = _mesh.boundary_facets(mesh, return_cells=True)
    candidates, facet_cell = cache["boundary"]
    group = None
    if "group" in sel:
        group = _group_members(f"{path}.group", mesh, sel["group"])
        kind, members, _ = group
        if kind == "facets":
            counts = _mesh.facet_cell_counts(mesh, members)
            bad = np.flatnonzero(counts != 1)
            if len(bad):
                f = members[bad[0]]
                where = "is a face of no cell" if counts[bad[0]] == 0 else "lies between two cells"
                centroid = np.round(mesh.points[f].mean(axis=0), 6).tolist()
                _fail(f"{path}.group", f"{len(bad)} of the {len(members)} facets of group {sel['group']!r} are not on "
                      f"the boundary of the mesh: the facet of nodes {f.tolist()} at {centroid} {where}; allowed: a "
                      f"traction on boundary facets")
            candidates = members
        elif kind == "cells":
            candidates = candidates[np.isin(facet_cell, members)]
    nodes = _select(path, mesh, sel, default_tol, group)
    selected = np.zeros(mesh.n_nodes, dtype=bool)
    selected[nodes] = True
    on = selected[candidates].all(axis=1) if len(candidates) else np.zeros(0, dtype=bool)
    if not on.any():
        of = f" of group {sel['group']!r}" if "group" in sel else ""
        _fail(path, f"no boundary facet{of} has all its nodes selected ({len(nodes)} node(s) selected)")
    return candidates[on]


def _check_dim(path, vec, dim):
    if len(vec) != dim:
        _fail(path, f"expected {dim} values on a {dim}D mesh, got {len(vec)}: {vec!r}")
    return np.asarray(vec, dtype=float)


def prepare(scene: Scene) -> Setup:
    """Build the mesh, boundary conditions, loads and (for MSS) the model of a scene.

    Does not solve; :func:`run_scene` calls it, the ``validate`` command too.  Errors that need
    the mesh (a selection matching no node, a vector of the wrong length, a model whose cell type
    does not fit the mesh) are ValueErrors naming the key path.

    Mesh hygiene: coincident nodes are merged with a warning or refused
    (``checks.coincident_nodes``, :func:`msslib.mesh.resolve_coincident_nodes`), for generated
    meshes too; a material no cell uses is an error; before a static solve, a part of the mesh
    whose fixed dofs leave a rigid-body mode free (floating, or free to slide or turn:
    :func:`msslib.mesh.loose_parts`) is an error naming the part and the mode (dynamic runs may
    move freely).
    """
    policy = scene.checks.get("coincident_nodes", "merge")
    mesh = _mesh.resolve_coincident_nodes(_build_mesh(scene), policy, source="scene.geometry",
                                          hint=" (checks: {coincident_nodes: merge} merges them)")
    used = np.bincount(mesh.material, minlength=len(scene.materials))
    for i in range(len(scene.materials)):
        if used[i] == 0:
            in_use = ", ".join(str(j) for j in np.flatnonzero(used)) or "none"
            _fail(f"scene.materials[{i}]", f"no cell uses material {i} (cells use materials {in_use}); allowed: "
                  f"materials some cell uses (assigned by scene.regions or the mesh file's cell data 'material')")
    n, dim = mesh.n_nodes, mesh.dim
    size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if n else 1.0
    default_tol = max(1e-8 * size, 1e-15)

    fixed = np.zeros((n, dim), dtype=bool)
    prescribed = np.zeros((n, dim))
    owner = np.full((n, dim), -1)
    for i, b in enumerate(scene.boundary):
        p = f"scene.boundary[{i}]"
        nodes = _select(f"{p}.select", mesh, b["select"], default_tol)
        axes = list(range(dim)) if b["fix"] is None else [AXES.index(a) for a in b["fix"]]
        for a in axes:
            if a >= dim:
                _fail(f"{p}.fix", f"axis {AXES[a]!r} does not exist on a {dim}D mesh")
        disp = np.zeros(dim)
        if b["displacement"] is not None:
            if len(b["displacement"]) != dim:
                _fail(f"{p}.displacement", f"expected {dim} values on a {dim}D mesh, got {b['displacement']!r}")
            disp = np.array([0.0 if v is None else v for v in b["displacement"]])
        for a in axes:
            clash = (owner[nodes, a] >= 0) & (prescribed[nodes, a] != disp[a])
            if clash.any():
                j = int(owner[nodes, a][clash][0])
                _fail(f"{p}.displacement", f"node {int(nodes[clash][0])} axis {AXES[a]} is already fixed by "
                      f"scene.boundary[{j}] with displacement {prescribed[nodes[clash][0], a]!r}, here {disp[a]!r}")
            fixed[nodes, a] = True
            prescribed[nodes, a] = disp[a]
            owner[nodes, a] = i
    if not scene.is_dynamic:
        loose = _mesh.loose_parts(mesh, fixed)
        if loose:
            n_modes = 3 if dim == 2 else 6
            more = f" (and {len(loose) - 1} more loose part(s))" if len(loose) > 1 else ""
            fix = (f"fix at least {n_modes} dofs of every part that stop its {n_modes} rigid-body modes"
                   if loose[0].floating else "fix dofs that stop every rigid-body mode of every part")
            _fail("scene.boundary", f"{loose[0].describe(mesh)}{more}; a static solve needs it held: {fix}, "
                  f"or use a dynamic solver (solver: {{type: dynamic, ...}})")

    thickness = 1.0 if dim == 3 else float(scene.thickness or 1.0)
    dens = np.array([np.nan if m.density is None else m.density for m in scene.materials])
    cell_density = dens[mesh.material]
    masses = None
    if mesh.n_cells and np.all(np.isfinite(cell_density)):
        masses = _mesh.lumped_masses(mesh, cell_density, thickness) if dim == 2 else _mesh.lumped_masses(mesh, cell_density)

    surface = np.zeros((n, dim))
    gravity = None
    facet_cache = {}
    for i, load in enumerate(scene.loads):
        p = f"scene.loads[{i}]"
        if load["type"] == "gravity":
            g = _check_dim(f"{p}.g", load["g"], dim)
            gravity = g if gravity is None else gravity + g
        elif load["type"] == "nodal_force":
            total = _check_dim(f"{p}.total", load["total"], dim)
            nodes = _select(f"{p}.select", mesh, load["select"], default_tol)
            surface[nodes] += total / len(nodes)
        else:
            from msslib.terms import Traction

            traction = _check_dim(f"{p}.traction", load["traction"], dim)
            loaded = _loaded_facets(f"{p}.select", mesh, load["select"], default_tol, facet_cache)
            surface += Traction(mesh, loaded, traction, thickness if dim == 2 else 1.0).nodal

    setup = Setup(scene=scene, mesh=mesh, fixed=fixed, prescribed=prescribed, surface_forces=surface,
                  gravity=gravity, cell_density=cell_density, masses=masses)
    if scene.is_fem:
        try:
            _mesh.check_cells(mesh)
        except ValueError as exc:
            _fail("scene.geometry", str(exc))
    else:
        setup.model = _build_model(setup)
    return setup


# --------------------------------------------------------------------------------------------
# MSS model
# --------------------------------------------------------------------------------------------


def _internal_terms(name, mesh, materials, opts, thickness):
    from msslib import model as M

    published = opts["published"]
    builder = {
        "lloyd_triangle": lambda: M.lloyd_triangle_springs(mesh, materials, thickness),
        "van_gelder": lambda: M.van_gelder_springs(mesh, materials, thickness),
        "lloyd_square": lambda: M.lloyd_square_springs(mesh, materials, thickness),
        "lloyd_tetrahedron": lambda: M.lloyd_tet_springs(mesh, materials, volume=False),
        "lloyd_tetrahedron_volume": lambda: M.lloyd_tet_springs(mesh, materials, volume=True, published=published),
        "baudet_cube": lambda: M.baudet_cube_springs(mesh, materials, published=published),
        "golec_cube": lambda: M.golec_cube_springs(mesh, materials, A=opts["A"], published=published),
    }[name]
    return builder()


def _build_model(setup: Setup):
    from msslib.model import Model
    from msslib.terms import Gravity, HexVolume, NodalForces, Springs, TetVolume

    scene, mesh = setup.scene, setup.mesh
    name, opts = scene.model, scene.model_options
    cell_type = MSS_MODELS[name][0]
    if mesh.cell_type != cell_type:
        _fail("scene.model", f"{name} needs {cell_type} cells, the mesh has {mesh.cell_type} cells")
    materials = [(m.E, m.nu) for m in scene.materials]
    wanted = set(opts["terms"])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            internal = []
            if wanted & {"springs", "volume"}:
                for t in _internal_terms(name, mesh, materials, opts, setup.thickness):
                    kind = "springs" if isinstance(t, Springs) else "volume" if isinstance(t, (TetVolume, HexVolume)) else None
                    if kind in wanted:
                        internal.append(t)
            if "correction" in wanted:
                from msslib.baudet_correction import correction_term

                internal.append(correction_term(opts["correction"], mesh, materials, setup.surface_forces,
                                                published=opts["published"]))
    except ValueError as exc:
        _fail("scene.model", f"{name}: {exc}")
    terms = list(internal)
    if np.any(setup.surface_forces != 0):
        terms.append(NodalForces(setup.surface_forces))
    if setup.gravity is not None:
        terms.append(Gravity(setup.masses, setup.gravity))
    damping = scene.solver.get("damping", 0.0) if scene.is_dynamic else 0.0
    return Model(mesh, terms, fixed=setup.fixed, prescribed=setup.prescribed, masses=setup.masses, damping=damping)


# --------------------------------------------------------------------------------------------
# progress
# --------------------------------------------------------------------------------------------


class TextProgress:
    """A one-line text progress bar on ``stream`` (default stderr), ``callable(fraction, text)``.

    Nothing is shown during the first ``delay`` seconds (short runs stay quiet); then the line is
    redrawn at most every ``interval`` seconds on a terminal, and written as a whole line at most
    every 5 s elsewhere (a log file gets no carriage returns).  :meth:`close` ends the line.

    The line shows the elapsed time, the rate since the first report and the time left at that
    rate: ``(3.1 s, 12.3 steps/s, 0:42 left)`` when ``total`` (the number of ``unit`` in the whole
    run) is given, ``(3.1 s, 2.5 %/s, 0:42 left)`` otherwise.
    """

    def __init__(self, label: str = "", stream=None, width: int = 30, delay: float = 0.5, interval: float = 0.1,
                 total: float | None = None, unit: str = "steps"):
        self.label = label
        self.total = total
        self.unit = unit
        self.first = None  # (time, fraction) of the first report: the rate is measured from there
        self.drawn = 0  # length of the line on a terminal
        self.stream = stream
        self.width = width
        self.delay = delay
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -math.inf
        self.shown = False
        self.fraction = 0.0
        self.text = ""

    def __call__(self, fraction: float, text: str = "") -> None:
        self.fraction = min(max(float(fraction), 0.0), 1.0)
        self.text = text
        now = time.perf_counter()
        if self.first is None:
            self.first = (now, self.fraction)
        interval = self.interval if self._tty() else max(self.interval, 5.0)
        if now - self.start < self.delay or now - self.last < interval:
            return
        self.last = now
        self._draw(now)

    def _stream(self):
        return self.stream if self.stream is not None else sys.stderr

    def _tty(self) -> bool:
        try:
            return bool(self._stream().isatty())
        except (AttributeError, ValueError):
            return False

    def _draw(self, now):
        stream = self._stream()
        filled = int(round(self.fraction * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        line = f"{self.label} [{bar}] {100 * self.fraction:5.1f}% {self.text} ({now - self.start:.1f} s{self._pace(now)})"
        if self._tty():
            stream.write("\r" + line.ljust(max(99, self.drawn)))
            self.drawn = len(line)
        else:  # a log file: whole lines, no carriage returns
            stream.write(line + "\n")
        stream.flush()
        self.shown = True

    def _pace(self, now) -> str:
        """``", 12.3 steps/s, 0:42 left"``, or "" before any progress."""
        if self.first is None:
            return ""
        t0, f0 = self.first
        if self.fraction <= f0 or now <= t0:
            return ""
        rate = (self.fraction - f0) / (now - t0)  # fraction per second
        pace = f"{rate * self.total:.3g} {self.unit}/s" if self.total else f"{100 * rate:.3g} %/s"
        if self.fraction >= 1.0:
            return f", {pace}"
        minutes, seconds = divmod(math.ceil((1.0 - self.fraction) / rate), 60)
        hours, minutes = divmod(minutes, 60)
        left = f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"
        return f", {pace}, {left} left"

    def close(self, fraction: float | None = None) -> None:
        if self.shown:
            if fraction is not None:
                self.fraction = fraction
            self._draw(time.perf_counter())
            if self._tty():
                self._stream().write("\n")
                self._stream().flush()
            self.shown = False


# --------------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------------


def _moduli(scene):
    E = [m.E for m in scene.materials]
    nu = [m.nu for m in scene.materials]
    if len(E) == 1:
        return E[0], nu[0]
    return np.array(E), np.array(nu)


def _solve_fem(setup: Setup, report):
    from msslib import fem
    from msslib.solvers import ConvergenceError

    scene, mesh = setup.scene, setup.mesh
    E = [m.E for m in scene.materials]
    nu = [m.nu for m in scene.materials]
    body = None
    if setup.gravity is not None:
        body = setup.cell_density[:, None] * setup.gravity[None, :]
    kw = dict(fixed=setup.fixed, prescribed=setup.prescribed, nodal_forces=setup.surface_forces, body_force=body)
    if mesh.dim == 2:
        kw.update(thickness=setup.thickness, plane=scene.model_options["plane"])
    law = FEM_MODELS[scene.model]
    if law is None or scene.solver.get("linear"):
        res = fem.solve_linear(mesh, E, nu, **kw)
    else:
        s = scene.solver
        try:
            res = fem.solve_nonlinear(mesh, E, nu, law=law, steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"],
                                      progress=lambda k, n: report(k / n, f"load step {k}/{n}"), **kw)
        except RuntimeError as exc:
            raise ConvergenceError(f"{scene.model}: {exc}") from None
    stats = {"type": "static", **res.stats}
    return {"displacement": res.displacement, "reaction": res.reaction, "stats": stats,
            "extra_attrs": {"strain_energy": res.strain_energy}}


def _solve_mss_static(setup: Setup, report):
    from msslib.solvers import static_solve

    model, s = setup.model, setup.scene.solver

    def cb(info):
        report(info["load"], f"load {info['load']:.3g} it {info['iteration']} |r| {info['residual']:.2e}")

    if s.get("linear"):
        return _solve_mss_linear(setup)
    res = static_solve(model, model.x0, load_steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"], progress=cb)
    u = (res.x - model.x0).reshape(-1, model.dim)
    stats = {
        "type": "static", "load_steps": s["load_steps"], "tol": s["tol"], "n_load_steps": res.n_load_steps,
        "n_cuts": res.n_cuts, "iterations": res.iterations, "total_iterations": res.total_iterations,
        "final_residual": res.residuals[-1][-1] if res.residuals and res.residuals[-1] else 0.0,
        "force_scale": res.force_scale, "roundoff_floor": res.roundoff_floor, "threshold": res.threshold,
        "roundoff_steps": res.roundoff_steps, "line_search_merit": res.line_search_merit, "wall_time": res.wall_time,
        "messages": res.messages,
    }
    energy = model.energy(res.x, 1.0)
    extra = {"potential_energy": "None" if energy is None else energy}
    return {"displacement": u, "reaction": model.reaction(res.x, 1.0), "stats": stats, "extra_attrs": extra}


def _solve_mss_linear(setup: Setup):
    """One sparse solve with the model's stiffness (Hessian) at rest: the linearised MSS."""
    from msslib.fem import _solve_sparse

    model, t0 = setup.model, time.perf_counter()
    x = model.apply_prescribed(model.x0, 1.0)
    du, free = x - model.x0, model.free
    K, f = model.stiffness(model.x0, 1.0), model.force(model.x0, 1.0)
    du[free] = _solve_sparse(K[free][:, free], f[free] - K[free][:, ~free] @ du[~free])
    reaction = np.where(free, 0.0, K @ du - f).reshape(-1, model.dim)  # of the linearised forces
    stats = {"type": "static", "linear": True, "wall_time": time.perf_counter() - t0, "solver": "one solve with the "
             "stiffness at rest, scipy.sparse.linalg.spsolve (SuperLU, MMD_AT_PLUS_A ordering)"}
    return {"displacement": du.reshape(-1, model.dim), "reaction": reaction, "stats": stats,
            "extra_attrs": {"potential_energy": "None"}}


def _solve_mss_dynamic(setup: Setup, report):
    from msslib.solvers import integrate

    model, s = setup.model, setup.scene.solver
    x_start = model.apply_prescribed(model.x0, 1.0)

    def cb(info):
        n = max(info["n_steps"], 1)
        report(info["step"] / n, f"t = {info['t']:.4g} s")

    res = integrate(model, x_start, np.zeros(model.n_dof), dt=s["dt"], t_end=s["t_end"], method=s["method"],
                    damping=s["damping"], save_every=s["save_every"], progress=cb,
                    allow_unstable=s.get("allow_unstable", False))
    n, dim = model.n_nodes, model.dim
    u = (res.x_final - model.x0).reshape(n, dim)
    out = {"displacement": u, "reaction": model.reaction(res.x_final, 1.0),
           "stats": {"type": "dynamic", **res.stats}, "extra_attrs": {}}
    if setup.scene.output["history"]:
        n_t = len(res.t)
        out["history"] = {"time": res.t, "displacement": (res.x - model.x0).reshape(n_t, n, dim),
                          "velocity": res.v.reshape(n_t, n, dim),
                          "reaction": np.stack([model.reaction(x, 1.0) for x in res.x]) if n_t else
                          np.zeros((0, n, dim))}
        extra = {"kinetic_energy": (("time",), res.kinetic_energy, {"units": "J", "long_name": "kinetic energy"})}
        if res.potential_energy is not None:
            extra["potential_energy"] = (("time",), res.potential_energy,
                                         {"units": "J", "long_name": "potential energy (internal minus load work)"})
        out["extra_vars"] = extra
    return out


def run_scene(scene, progress=True):
    """Build and solve a scene (a :class:`Scene`, a path or a dict) and return its result dataset.

    ``progress``: True draws a text progress bar on stderr for runs longer than half a second,
    False/None is silent, a callable receives ``(fraction, text)``.  Raises ValueError /
    FileNotFoundError for bad scenes, :class:`msslib.solvers.ConvergenceError` when a static solve
    fails and :class:`msslib.solvers.DivergenceError` when a dynamic run blows up.

    The final state, and every saved state of a dynamic run with ``output.history``, is checked
    for inverted and collapsed cells (:func:`msslib.quality.guard`, for every model and cell type):
    the result records ``inverted_cells``, ``collapsed_cells``, ``min_relative_jacobian``, ... (0
    counts for a clean run) and the cell variables ``cell_state`` and ``relative_jacobian``; a
    flagged state is one :class:`msslib.errors.MsslibWarning`, or with ``checks: {inverted:
    error}`` an :class:`msslib.errors.UnphysicalStateError` (no dataset is returned).
    """
    from msslib.io import make_dataset
    from msslib.quality import guard

    scene = load_scene(scene)
    t0 = time.perf_counter()
    bar = None
    if progress is True:
        total = None
        if scene.is_dynamic:  # time steps per second and the time left
            total = math.ceil(scene.solver["t_end"] / scene.solver["dt"] - 1e-9) if scene.solver["t_end"] > 0 else None
        bar = TextProgress(label=scene.name, total=total, unit="steps")
        report: Callable = bar
    elif callable(progress):
        report = progress
    else:
        def report(_fraction, _text=""):
            return None
    try:
        setup = prepare(scene)
        if scene.is_fem:
            out = _solve_fem(setup, report)
        elif scene.is_dynamic:
            out = _solve_mss_dynamic(setup, report)
        else:
            out = _solve_mss_static(setup, report)
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    hist = out.get("history") or {}
    guard_attrs, guard_vars = guard(
        setup.mesh, out["displacement"], history_displacement=hist.get("displacement"),
        history_time=hist.get("time"), policy=scene.checks["inverted"], label=f"{scene.name} ({scene.model})")

    springs = k = rest = None
    if setup.model is not None:
        from msslib.terms import Springs

        sp = [t for t in setup.model.terms if isinstance(t, Springs)]
        if sp:
            springs = np.concatenate([t.pairs for t in sp])
            k = np.concatenate([t.k for t in sp])
            rest = np.concatenate([t.rest_length for t in sp])
    E, nu = _moduli(scene)
    extra_attrs = dict(out.get("extra_attrs", {}))
    energy = extra_attrs.pop("potential_energy", None)  # static MSS: a number, or "None" without one
    attrs = {"scene_name": scene.name, "scene_description": scene.description,
             "model_published": scene.model_options.get("published", False),
             "model_terms": list(scene.model_options["terms"]) if scene.model_options.get("terms") else None,
             **extra_attrs, **guard_attrs}
    if scene.model_options.get("A") is not None:
        attrs["model_A"] = scene.model_options["A"]
    if scene.model_options.get("correction") is not None:
        attrs["model_correction"] = scene.model_options["correction"]
    extra_vars = {**(out.get("extra_vars") or {}), **guard_vars}
    if energy is not None and not isinstance(energy, str):
        extra_vars["potential_energy"] = ((), float(energy), {
            "units": "J", "long_name": "potential energy of the final state (internal minus load work)"})
    return make_dataset(
        setup.mesh, out["displacement"], model=scene.model, E=E, nu=nu, scene=scene.text,
        density=[m.density for m in scene.materials],
        material_names=None if scene.material_groups is None else list(scene.material_groups),
        thickness=setup.thickness if setup.mesh.dim == 2 else None,
        springs=springs, spring_constant=k, rest_length=rest, reaction=out["reaction"], fixed=setup.fixed,
        history=out.get("history"), solver_stats=out["stats"], wall_time=wall,
        extra_vars=extra_vars, extra_attrs=attrs,
    )

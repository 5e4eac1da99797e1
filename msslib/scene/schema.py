"""The scene schema: :class:`Scene`, :class:`Material` and :func:`load_scene`, which reads a YAML
file (or a dict) and checks every key; the models, their cell types, terms and options come from the
registry of :mod:`msslib.models`."""

from __future__ import annotations

import difflib
import inspect
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from msslib import mesh as _mesh
from msslib import models as _models
from msslib.scene.validate import (
    AXES, MAX_LOAD_STEPS, MAX_NEWTON_ITERATIONS, MAX_TIME_STEPS, _boolean, _box, _choice, _fail, _group_key, _integer,
    _list, _mapping, _number, _parse_yaml, _selection, _show, _string, _vector,
)

GENERATORS = _mesh.cells.GeneratorView({}, "Mesh generators a scene may name, with their dimension: those the cell "
                                       "types declare (msslib.mesh.cells), read at each access.")
"""Mesh generators a scene may name, with their dimension: those the cell types declare
(:attr:`msslib.mesh.cells.CellType.mesh_generators`: ``quad_grid``, ``tet_grid``, ``wedge_grid``,
...), read from the registry at each access, so a new cell type's generators need no edit here."""

#: MSS model name -> (cell type, internal terms it can build), from the registry of msslib.models
MSS_MODELS = {name: (spec.cell_type, spec.terms) for name, spec in _models.registry().items() if spec.kind == "mss"}
#: FEM model name -> material law of :func:`msslib.fem.solve_nonlinear` (None: linear)
FEM_MODELS = {name: spec.law for name, spec in _models.registry().items() if spec.kind == "fem"}
MODELS = tuple(_models.names())

LOAD_TYPES = ("gravity", "nodal_force", "traction", "pressure")
SOLVER_TYPES = ("static", "dynamic")
METHODS = ("symplectic_euler", "velocity_verlet", "implicit_euler")
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
        return self.model in _models.names("fem")

    @property
    def is_dynamic(self) -> bool:
        return self.solver.get("type") == "dynamic"




# --------------------------------------------------------------------------------------------
# load_scene
# --------------------------------------------------------------------------------------------


def _generator_function(name):
    return GENERATORS.function(name)


def mesh_description(mesh) -> str:
    """How a scene's record names an in-memory mesh."""
    return f"in-memory msslib.mesh.Mesh: {mesh.n_nodes} nodes, {mesh.n_cells} {mesh.cell_type} cells"


def _geometry(path, value, base_dir: Path, mesh_obj=None):
    _mapping(path, value, ("generator", "args", "file", "refine", "mesh"))
    if "mesh" in value:  # only through the API: {"mesh": a msslib.mesh.Mesh}
        if mesh_obj is None:
            _fail(f"{path}.mesh", "an in-memory msslib.mesh.Mesh (given through the Python API); a scene file "
                  "names a mesh by 'file' or 'generator'")
        if len(value) != 1 and set(value) != {"mesh", "refine"}:
            _fail(path, "give 'mesh' alone (with an optional 'refine')")
        if mesh_obj.n_cells == 0:
            _fail(f"{path}.mesh", f"the mesh has no cells ({mesh_obj.n_nodes} nodes); allowed: a mesh with cells")
    elif ("generator" in value) == ("file" in value):
        _fail(path, "give exactly one of 'generator' (with 'args') or 'file'")
    has_file = "file" in value
    # uniform midpoint refinements of the mesh (msslib.mesh.refine.uniform); only stored when asked for
    refine = {"refine": _integer(f"{path}.refine", value["refine"], minimum=0, maximum=8,
                                 why=" (each multiplies the cells by 4 or 8)")} if "refine" in value else {}
    if "mesh" in value:
        return {"mesh": mesh_obj, **refine}
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
    """``(name, options)``: options are ``published`` (bool), ``A`` (None unless the model takes it),
    ``terms`` (MSS: the internal terms to build), ``plane`` and the model's own options (its spec in
    :mod:`msslib.models`), each with its default when not given."""
    type_path = f"{path}.type"
    if isinstance(value, str):
        value, type_path = {"type": value}, path
    if not isinstance(value, Mapping):
        _fail(path, f"expected a model name or a mapping with 'type', got {value!r}")
    _mapping(path, value, ("type", "published", "terms", *_models.option_names()), required=("type",))
    name = _choice(type_path, value["type"], _models.names(), "model")  # live: a family added later counts
    spec = _models.get(name)
    opts = {"published": False, "A": None, "terms": None, "plane": "stress"}
    for key in value:
        if key in ("type", "published", "terms") or spec.option(key) is not None:
            continue
        if key == "plane":
            _fail(f"{path}.plane", f"MSS models are plane stress; plane applies to the FEM models only, not {name}")
        takers = [n for n, s in _models.registry().items() if s.option(key) is not None]
        _fail(f"{path}.{key}", f"only {', '.join(takers)} {'takes' if len(takers) == 1 else 'take'} {key}, not {name}")
    for option in spec.options:
        if option.name in value:
            try:
                opts[option.name] = option.parse(value[option.name])
            except _models.OptionError as exc:
                _fail(f"{path}.{option.name}", str(exc))
        else:
            opts[option.name] = option.default
    if "published" in value:
        opts["published"] = _boolean(f"{path}.published", value["published"])
    if "terms" in value:
        if spec.kind != "mss":
            _fail(f"{path}.terms", f"only MSS models have terms, not {name}")
        available = spec.terms
        terms = value["terms"]
        if not isinstance(terms, list) or not terms:
            _fail(f"{path}.terms", f"expected a non-empty list from {', '.join(available)}, got {terms!r}")
        for i, t in enumerate(terms):
            _choice(f"{path}.terms[{i}]", t, available, f"term of {name}")
        if len(set(terms)) != len(terms):
            _fail(f"{path}.terms", f"a term is listed twice: {terms!r}")
        opts["terms"] = tuple(terms)
    elif spec.kind == "mss":
        opts["terms"] = spec.defaults
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
              "nodal_force": ("type", "select", "total"), "pressure": ("type", "select", "pressure", "follow")}


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
        _mapping(p, load, keys, required=keys[:3])
        entry = {"type": kind}
        if kind == "gravity":
            entry["g"] = _vector(f"{p}.g", load["g"])
        elif kind == "pressure":  # Pa, positive into the body; follow: normal to the current surface
            entry["select"] = _selection(f"{p}.select", load["select"])
            entry["pressure"] = _number(f"{p}.pressure", load["pressure"], what="a number (Pa, positive into the body)")
            entry["follow"] = _boolean(f"{p}.follow", load.get("follow", True))
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
            "max_iter": _integer(f"{path}.max_iter", value.get("max_iter", 50 if model in _models.names("mss") else 30),
                                 maximum=MAX_NEWTON_ITERATIONS, why=" (Newton converges in tens of iterations or not at all)"),
        }
    _mapping(path, value, ("type", "method", "dt", "t_end", "damping", "save_every", "allow_unstable", "load_curve"),
             required=("dt", "t_end"))
    if model in _models.names("fem"):
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
        "load_curve": _load_curve(f"{path}.load_curve", value.get("load_curve")),
    }
    n_steps = out["t_end"] / out["dt"]
    if n_steps > MAX_TIME_STEPS:
        _fail(f"{path}.dt", f"t_end / dt = {n_steps:.3g} time steps, more than the {MAX_TIME_STEPS:.0e} a run may take "
              f"(dt = {_show(value['dt'])} s, t_end = {_show(value['t_end'])} s); use a larger dt or a shorter t_end")
    return out


def _load_curve(path, value):
    """``[[t, factor], ...]``: the load factor of a dynamic run against time (None: 1)."""
    if value is None:
        return None
    from msslib.stepping.loads import Curve

    try:
        Curve(value, path)
    except (ValueError, TypeError) as exc:
        text = str(exc) if str(exc).startswith(path) else f"{path}: {exc}"
        _fail(path, text.removeprefix(f"{path}: ") + "; expected rows [t (s), load factor] with increasing t")
    if len(value[0]) != 2:
        _fail(path, f"expected rows [t (s), load factor], got rows of {len(value[0])} numbers")
    return [[float(a) for a in row] for row in value]


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
    from msslib.scene import resources

    if n_nodes is None:
        n_nodes, _n_cells, dim = resources.generated_mesh_size(geometry["generator"], geometry["args"])
        if not math.isfinite(n_nodes):
            return
    refine = int(geometry.get("refine", 0) or 0)
    if refine:  # estimated before refining (a mesh file's too): about 2^dim times the nodes per refinement
        n_nodes, _ = resources.refined_mesh_size(n_nodes, 0, dim, refine)
    n_saved = _saved_states(solver, output)
    estimate = resources.run_memory(n_nodes, dim, fem=model in _models.names("fem"), n_saved=n_saved)
    history = resources.history_memory(n_saved, n_nodes * dim)
    if history > 0.5 * estimate:
        what = (f"{root}.solver: {n_saved:.3g} saved states of {n_nodes:.3g} nodes (dt = {solver['dt']:g} s, "
                f"t_end = {solver['t_end']:g} s, save_every = {solver['save_every']})")
        hint = "use a larger dt or save_every, or output: {history: false}"
    else:
        what = f"{root}.geometry"
        if "generator" in geometry:
            what += f" ({geometry['generator']} with {', '.join(f'{k}={v}' for k, v in geometry['args'].items())})"
        elif "mesh" in geometry:
            what += " (the in-memory mesh)"
        else:
            what += f".file ({geometry['file'].name})"
        if refine:
            what += f" refined {refine} times (refine: {refine})"
        what += f": {n_nodes:.3g} nodes"
        hint = "use a smaller refine or fewer elements" if refine else "use fewer elements"
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
    mesh_obj = None
    if isinstance(source, Mapping):
        geo = source.get("geometry")
        if isinstance(geo, Mapping) and isinstance(geo.get("mesh"), _mesh.Mesh):  # an in-memory mesh (the API)
            mesh_obj = geo["mesh"]
            source = {**source, "geometry": {**geo, "mesh": mesh_description(mesh_obj)}}
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
    geometry = _geometry(f"{root}.geometry", raw["geometry"], base, mesh_obj)
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
    if "generator" in geometry and model in _models.names("mss"):
        dim, spec = GENERATORS[geometry["generator"]], _models.get(model)
        if spec.dim != dim:
            _fail(f"{root}.model", f"{model} needs {spec.cell_type} cells, "
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


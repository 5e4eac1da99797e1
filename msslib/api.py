"""The functions behind ``import msslib`` (see the package docstring for the example).

Everything goes through the scene machinery of :mod:`msslib.scene`: :func:`build_model` turns its
arguments into a scene mapping (the YAML syntax of :mod:`msslib.scene`, in memory), validates it
with :func:`msslib.scene.load_scene` and builds it with :func:`msslib.scene.prepare`;
:func:`solve_static` and :func:`solve_dynamic` run the same mapping, with the solver they are
given, through :func:`msslib.scene.run_scene`.  A model built here is therefore the model
``python -m msslib run`` builds from the same scene, with the same checks and the same messages
(which name the scene key, e.g. ``scene.boundary[0].select``), and a result is the same dataset.

A :class:`msslib.mesh.Mesh` object reaches the scene machinery as the object itself (the scene's
``geometry: {mesh: ...}``, which only the API can give), with its groups, so that materials keyed
by group and selections by group work as from its file; the result's ``scene`` attribute
describes it as an in-memory mesh.  A mesh file path or a scene ``geometry`` mapping
(``{"generator": "hex_grid", "args": {...}}``) is passed on as it is.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from msslib import mesh as _mesh
from msslib import models as _models
from msslib import scene as _scene

__all__ = ["ModelSetup", "read_mesh", "build_model", "spring_constants", "solve_static", "solve_dynamic",
           "write_result", "write_paraview"]


@dataclass(repr=False)
class ModelSetup(_scene.Setup):
    """What :func:`build_model` returns: a :class:`msslib.scene.Setup` (``model`` the
    :class:`msslib.system.Model` of an MSS model, None for a FEM reference; ``mesh``, ``fixed``,
    ``prescribed``, ``surface_forces``, ``gravity``, ``masses``, ``scene``) that remembers the
    scene mapping it was built from (``source``) and its geometry (``geometry``: the Mesh, the
    file or the generator mapping), so that :func:`solve_static` and :func:`solve_dynamic` can
    run it."""

    source: dict = field(default_factory=dict)
    geometry: Any = None
    base_dir: Path | None = None  # the directory a relative mesh file is found from (the cwd at build time)

    def __repr__(self) -> str:
        mesh = self.mesh
        terms = ", ".join(type(t).__name__ for t in self.model.terms) if self.model is not None else "FEM reference"
        return (f"ModelSetup({self.scene.model}: {mesh.n_nodes} nodes, {mesh.n_cells} {mesh.cell_type} cells, "
                f"{int(self.fixed.sum())} fixed dofs; {terms})")


def read_mesh(path, **kwargs) -> _mesh.Mesh:
    """Read any mesh file meshio reads: :func:`msslib.mesh.read` (same keyword arguments)."""
    return _mesh.read(path, **kwargs)


# --------------------------------------------------------------------------------------------
# arguments -> scene mapping
# --------------------------------------------------------------------------------------------


def _material(m):
    if isinstance(m, _scene.Material):
        out = {"E": m.E, "nu": m.nu}
        if m.density is not None:
            out["density"] = m.density
        return out
    return m  # a mapping, or something load_scene refuses naming scene.materials[i]


def _entries(value, wrap=None):
    """None -> [], one entry -> [entry], a list or tuple -> a list; ``wrap`` turns an item into an
    entry."""
    if value is None:
        return []
    items = list(value) if isinstance(value, (list, tuple)) else [value]
    return [wrap(item) if wrap else item for item in items]


def _boundary_entry(item):
    """A boundary entry ``{select, fix, displacement}``, or a selection (all axes fixed)."""
    if isinstance(item, Mapping) and "select" in item:
        return dict(item)
    return {"select": item}


def _source(name, materials, fixed, loads, thickness, solver, checks, options) -> dict:
    if isinstance(materials, Mapping) and materials and not set(materials) <= {"E", "nu", "density"}:
        # keyed by the mesh's groups: {"soft": Material(...), "stiff": {...}}
        materials = {key: _material(m) for key, m in materials.items()}
    elif isinstance(materials, (_scene.Material, Mapping)):
        materials = [materials]
    elif isinstance(materials, tuple):
        materials = list(materials)
    if isinstance(materials, list):
        materials = [_material(m) for m in materials]
    raw = {"name": str(name), "materials": materials, "model": {"type": name, **options}}
    if thickness is not None:
        raw["thickness"] = thickness
    raw["boundary"] = _entries(fixed, _boundary_entry)
    raw["loads"] = _entries(loads)
    if solver is not None:
        raw["solver"] = solver
    if checks is not None:
        raw["checks"] = checks
    return raw


def _with_geometry(raw: dict, geometry) -> dict:
    return {"name": raw["name"], "geometry": geometry, **raw}  # the keys in the order of a scene file


@contextmanager
def _loaded(raw: dict, geometry, base_dir=None):
    """The validated :class:`msslib.scene.Scene` of ``raw`` with ``geometry`` (a relative mesh
    file found from ``base_dir``, default the current directory; a Mesh object is passed as it is,
    with its groups, and the scene's record names it)."""
    if isinstance(geometry, _mesh.Mesh):  # the mesh object itself goes to the scene (no file)
        yield _scene.load_scene(_with_geometry(raw, {"mesh": geometry}), base_dir=base_dir)
    elif isinstance(geometry, (str, os.PathLike)):
        yield _scene.load_scene(_with_geometry(raw, {"file": os.fspath(geometry)}), base_dir=base_dir)
    elif isinstance(geometry, Mapping):
        yield _scene.load_scene(_with_geometry(raw, dict(geometry)), base_dir=base_dir)
    else:
        raise ValueError(f"build_model: mesh must be a msslib.mesh.Mesh, a mesh file path or a scene geometry "
                         f"mapping such as {{'generator': 'hex_grid', 'args': {{...}}}}, got {type(geometry).__name__}")


# --------------------------------------------------------------------------------------------
# build
# --------------------------------------------------------------------------------------------


def build_model(name: str, mesh, materials, *, fixed=None, loads=None, thickness=None, solver=None, checks=None,
                **options) -> ModelSetup:
    """Build a model by its scene name (:data:`msslib.scene.MSS_MODELS`, or a FEM reference of
    :data:`msslib.scene.FEM_MODELS`) on ``mesh`` with ``materials``.

    Parameters (the syntax of the scene keys of :mod:`msslib.scene`)
    ----------------------------------------------------------------
    mesh : a :class:`msslib.mesh.Mesh`, a mesh file path, or a scene ``geometry`` mapping.
    materials : a :class:`Material` (``msslib.Material(E, nu, density=None)``) or a mapping
        ``{E, nu, density}``, or a list of them (material ``i`` for the cells of material index ``i``),
        or a mapping from the mesh's group names to them (``{"soft": Material(...), ...}``).
    fixed : the ``boundary``: a selection (``"all"``, ``{"plane": ["z", 0.0]}``, ``{"box": ...}``),
        whose nodes are fixed along every axis, or an entry ``{"select": ..., "fix": [...],
        "displacement": [...]}``, or a list of either.
    loads : a load entry (``{"type": "gravity", "g": [...]}``, ``{"type": "traction", "select": ...,
        "traction": [...]}``, ``{"type": "nodal_force", "select": ..., "total": [...]}``,
        ``{"type": "pressure", "select": ..., "pressure": p, "follow": True}``: Pa, positive into the
        body, following the deforming surface unless ``"follow": False``) or a list.
    thickness : 2D meshes (m).
    solver : the scene's ``solver`` mapping, the default of :func:`solve_static` /
        :func:`solve_dynamic`; ``{"type": "dynamic", "dt": ..., "t_end": ...}`` lets a body move
        freely (a static model must be held; its damping becomes the model's).
    checks : the scene's ``checks`` mapping.
    **options : the model options ``published`` and ``terms`` (every model) and each model's own:
        {model_options} (:mod:`msslib.scene`, key ``model``, says what each does).

    Returns a :class:`ModelSetup`: ``.model`` is the :class:`msslib.system.Model`.  Bad arguments
    raise a one-line ValueError naming the scene key (``scene.materials[0].nu: must be < 0.5``).
    """
    # the model's own copy of the arguments: editing them afterwards changes nothing
    raw = copy.deepcopy(_source(name, materials, fixed, loads, thickness, solver, checks, options))
    base_dir = Path.cwd()
    if isinstance(mesh, _mesh.Mesh):  # the model's own copy: editing the caller's mesh changes nothing
        from msslib.system import frozen_mesh

        mesh = frozen_mesh(mesh)
    with _loaded(raw, mesh, base_dir) as scene:
        setup = _scene.prepare(scene)
    values = {f.name: getattr(setup, f.name) for f in fields(_scene.Setup)}
    return ModelSetup(**values, source=raw, geometry=mesh, base_dir=base_dir)


def _model_options_text() -> str:
    """The model-specific options with the models that take them, from the model registry."""
    takers: dict[str, list[str]] = {}
    for name in _models.names():
        for option in _models.get(name).options:
            takers.setdefault(option.name, []).append(name)
    return ", ".join(f"``{o}`` ({', '.join(m)})" for o, m in takers.items())


build_model.__doc__ = build_model.__doc__.replace("{model_options}", _model_options_text())


# --------------------------------------------------------------------------------------------
# inspect
# --------------------------------------------------------------------------------------------


def _var(dims, data, units, long_name):
    """``units``: UDUNITS strings as in :mod:`msslib.results.conventions`; None for indices (not quantities)."""
    return (dims, data, {"long_name": long_name} if units is None else {"units": units, "long_name": long_name})


def spring_constants(model):
    """The constants of a model's terms as an :class:`xarray.Dataset` (a table per dimension).

    ``model``: a :class:`ModelSetup` or a :class:`msslib.system.Model`.  Along ``spring`` (every
    spring of every :class:`~msslib.terms.Springs` term): ``node_a``, ``node_b``,
    ``spring_constant`` (N/m), ``rest_length`` (m) and ``rest_distance`` (m, the distance of the
    nodes in the mesh; it differs from ``rest_length`` for prestrained springs); along ``cell``:
    ``k_volume`` (J) and ``rest_volume`` (m^3) of Lloyd's tetrahedron volume term, ``kappa`` (Pa)
    and ``rest_volume`` of Golec's hexahedron volume term, ``correction_factor`` (1) of Baudet's
    correction (either reading), ``k_01`` ... ``c_01_02`` (N m-3) of Delingette's triangle: each term
    declares its per-cell constants (:attr:`msslib.terms.Term.cell_constants`).  The springs as a pandas table:
    ``table[["node_a", "node_b", "spring_constant", "rest_length"]].to_dataframe()``.
    """
    import xarray as xr

    from msslib.system import Model

    name = None
    if isinstance(model, ModelSetup):
        name = model.scene.model
        if model.model is None:
            raise ValueError(f"spring_constants: {name} is a FEM reference; it has no spring constants")
        model = model.model
    if not isinstance(model, Model):
        raise ValueError(f"spring_constants: expected what msslib.build_model returns (or a msslib.system.Model), "
                         f"got {type(model).__name__}")
    mesh = model.mesh
    springs = [t for t in model.terms if t.kind == "springs"]
    pairs = np.concatenate([t.conn for t in springs]) if springs else np.zeros((0, 2), dtype=np.int64)
    k = np.concatenate([t.k for t in springs]) if springs else np.zeros(0)
    rest = np.concatenate([t.rest_length for t in springs]) if springs else np.zeros(0)
    distance = np.linalg.norm(mesh.points[pairs[:, 1]] - mesh.points[pairs[:, 0]], axis=1)
    data = {
        "node_a": _var(("spring",), pairs[:, 0], None, "first end node of the spring"),
        "node_b": _var(("spring",), pairs[:, 1], None, "second end node of the spring"),
        "spring_constant": _var(("spring",), k, "N m-1", "spring constant"),
        "rest_length": _var(("spring",), rest, "m", "spring rest length"),
        "rest_distance": _var(("spring",), distance, "m", "distance of the end nodes in the mesh at rest"),
    }
    by_type: dict = {}  # the terms with per-cell constants (each declares them: Term.cell_constants)
    for t in model.terms:
        if t.cell_constants:
            by_type.setdefault(type(t), []).append(t)
    for cls, terms in by_type.items():
        conn = getattr(terms[0], "conn", mesh.cells)
        if len(terms) > 1 or conn.shape != mesh.cells.shape or not np.array_equal(conn, mesh.cells):
            raise ValueError(f"spring_constants: the model has {len(terms)} {cls.__name__} term(s) on other "
                             f"elements than the mesh's cells; read their constants from model.terms")
        for var, attr, units, long_name in terms[0].cell_constants:
            data[var] = _var(("cell",), np.asarray(getattr(terms[0], attr), dtype=float), units, long_name)
    attrs = {"terms": ", ".join(type(t).__name__ for t in model.terms)}
    if name is not None:
        attrs["model"] = name
    return xr.Dataset(data, attrs=attrs)


# --------------------------------------------------------------------------------------------
# solve
# --------------------------------------------------------------------------------------------


def _run(model, kind: str, given: dict, output: dict | None, progress):
    if not isinstance(model, ModelSetup):
        raise ValueError(f"solve_{kind}: expected what msslib.build_model returns, got {type(model).__name__} "
                         f"(a msslib.system.Model of your own: msslib.solvers.static_solve / integrate)")
    base = model.source.get("solver") or {}
    base = dict(base) if isinstance(base, Mapping) and base.get("type", "static") == kind else {}
    solver = {**base, "type": kind, **{k: v for k, v in given.items() if v is not None}}
    raw = {**model.source, "solver": solver}
    if output:
        raw["output"] = output
    with _loaded(raw, model.geometry, model.base_dir) as scene:
        return _scene.run_scene(scene, progress=progress)


def solve_static(model, *, load_steps=None, tol=None, max_iter=None, progress=True):
    """Solve ``model`` (from :func:`build_model`) statically, as ``run`` solves a scene with
    ``solver: {type: static, ...}`` (the arguments given override the model's ``solver``), and
    return the result dataset (:mod:`msslib.results.conventions`).  ``progress``: see
    :func:`msslib.scene.run_scene`."""
    return _run(model, "static", {"load_steps": load_steps, "tol": tol, "max_iter": max_iter}, None, progress)


def solve_dynamic(model, *, dt=None, t_end=None, method=None, damping=None, save_every=None, allow_unstable=None,
                  history=True, progress=True):
    """Integrate ``model`` (from :func:`build_model`) from rest, as ``run`` does with ``solver:
    {type: dynamic, ...}``; ``dt`` and ``t_end`` (s) are needed here or in the model's ``solver``,
    the other arguments default to the model's ``solver`` and then to the scene defaults
    (``symplectic_euler``, no damping, every step saved).  ``history=False`` keeps only the final
    state.  Returns the result dataset, with ``time``, ``displacement_history`` and
    ``velocity_history``."""
    given = {"dt": dt, "t_end": t_end, "method": method, "damping": damping, "save_every": save_every,
             "allow_unstable": allow_unstable}
    return _run(model, "dynamic", given, {"history": history}, progress)


# --------------------------------------------------------------------------------------------
# write
# --------------------------------------------------------------------------------------------


def _path_and_dataset(function, a, b):
    import xarray as xr

    if isinstance(b, xr.Dataset) and isinstance(a, (str, os.PathLike)):
        return a, b
    if isinstance(a, xr.Dataset) and isinstance(b, (str, os.PathLike)):
        return b, a
    raise ValueError(f"{function}: expected a path and a result dataset, got {type(a).__name__} and {type(b).__name__}")


def write_result(path, ds) -> Path:
    """Write a result atomically as NetCDF (:func:`msslib.results.netcdf.write_result`); the two arguments
    may come in either order."""
    from msslib.results import write_result as _write

    path, ds = _path_and_dataset("write_result", path, ds)
    return _write(path, ds)


def write_paraview(path, ds) -> list[Path]:
    """Write a result for ParaView (:func:`msslib.results.paraview.write`): ``.vtu`` the final state,
    ``.pvd`` every saved state; the two arguments may come in either order."""
    from msslib.results.paraview import write

    path, ds = _path_and_dataset("write_paraview", path, ds)
    return write(path, ds)

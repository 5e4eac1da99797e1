"""msslib: mass-spring systems whose spring constants are derived from FEM, and their FEM references.

A model in five lines (build, solve, write; the same scene machinery as ``python -m msslib run``):

.. code-block:: python

    import msslib
    mesh = msslib.mesh.hex_grid(0.1, 0.1, 0.1, nx=4, ny=4, nz=4)
    model = msslib.build_model("golec_cube", mesh, msslib.Material(E=1e6, nu=0.3, density=1000.0),
                               fixed={"plane": ["z", 0.0]}, loads={"type": "gravity", "g": [0.0, 0.0, -9.81]})
    result = msslib.solve_static(model)
    msslib.write_result("cube.nc", result)

The API (names are imported on first use: ``import msslib`` loads neither numba nor SciPy):

``read_mesh(path, **kwargs) -> Mesh``
    Any mesh file meshio reads (:func:`msslib.mesh.read`); the generators are
    ``msslib.mesh.hex_grid(...)``, ``msslib.mesh.tet_grid(...)``, ``msslib.mesh.quad_grid(...)``, ...
``Material(E, nu, density=None)``
    An isotropic material (Pa, -, kg/m^3).
``build_model(name, mesh, materials, *, fixed=None, loads=None, thickness=None, solver=None, checks=None, **options) -> ModelSetup``
    A model by the names scenes use (:data:`msslib.scene.MSS_MODELS`, or a FEM reference
    ``fem_linear``, ``fem_svk``, ``fem_neohookean``); ``fixed``, ``loads`` and the options in the
    syntax of the scene keys ``boundary``, ``loads`` and ``model`` (:mod:`msslib.scene`).
    ``.model`` is the :class:`msslib.system.Model` (see :mod:`msslib.api`).
``spring_constants(model) -> xarray.Dataset``
    The springs (``node_a``, ``node_b``, ``spring_constant``, ``rest_length``, ``rest_distance``)
    and the per-cell constants of the other terms (volume terms, Baudet's correction).
``solve_static(model, *, load_steps=None, tol=None, max_iter=None, progress=True) -> xarray.Dataset``
``solve_dynamic(model, *, dt, t_end, method=None, damping=None, save_every=None, allow_unstable=None, history=True, progress=True) -> xarray.Dataset``
    The result dataset of :mod:`msslib.results.netcdf` (what ``run`` writes), for the model's scene with
    that solver.
``write_result(path, ds)``, ``read_result(path)``
    NetCDF results, written atomically.
``write_paraview(path, ds)``
    ``.vtu``: the final state; ``.pvd``: every saved state as a ParaView time series
    (:mod:`msslib.results.paraview`).
``Simulator(model, *, dt, method="symplectic_euler", damping=None, load=1.0, engine="auto")``
    Step a model in time (:mod:`msslib.stepping`): ``step(n)``, loads changed between steps
    (``set_load``, ``apply_force``, ``prescribe`` a tool's path), ``x``, ``v``, ``reaction`` read
    without copies, ``reset()``, ``real_time_factor``.
``run_scene(scene_or_path, progress=True) -> xarray.Dataset``, ``load_scene(path_or_dict)``
    Scenes (:mod:`msslib.scene`).
``__version__``
    The version of msslib (``python -m msslib --version``).

Every submodule is reachable as an attribute too (``msslib.mesh``, ``msslib.parameters``,
``msslib.solvers``, ...).  The spring-constant formulas live in :mod:`msslib.parameters`; they call
code generated from the symbolic derivations in ``derivations/`` (see :mod:`msslib.generated`).
"""

import importlib
import importlib.util

__version__ = "0.1.0"

#: public name -> module that defines it (imported on first use)
_LAZY = {
    "read_mesh": "msslib.api",
    "build_model": "msslib.api",
    "ModelSetup": "msslib.api",
    "spring_constants": "msslib.api",
    "solve_static": "msslib.api",
    "solve_dynamic": "msslib.api",
    "write_result": "msslib.api",
    "write_paraview": "msslib.api",
    "Material": "msslib.scene",
    "load_scene": "msslib.scene",
    "run_scene": "msslib.scene",
    "read_result": "msslib.results",
    "Simulator": "msslib.stepping",
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
    elif not name.startswith("_") and importlib.util.find_spec(f"{__name__}.{name}") is not None:
        value = importlib.import_module(f"{__name__}.{name}")  # a submodule: msslib.mesh, ...
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted({*globals(), *_LAZY})

"""The exported model: :class:`MssExport` and its tables (:class:`Table`, :class:`Column`), built
from a scene by :func:`build` (or from a prepared setup by :func:`from_setup`); see
:mod:`msslib.export` for the formats."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from msslib.terms.base import Column, Table, make_column

__all__ = ["SCHEMA", "SCHEMA_VERSION", "C_HEADER_PATH", "c_header_paths", "Column", "Table", "MssExport", "build",
           "from_setup", "not_carried"]

SCHEMA = "msslib-mss-export"
SCHEMA_VERSION = 1
#: the umbrella C header; every module's header is beside it (msslib/generated/c/)
C_HEADER_PATH = Path(__file__).resolve().parents[1] / "generated" / "c" / "msslib_mss.h"


def c_header_paths() -> list[Path]:
    """The C headers the ``c`` format copies: :data:`C_HEADER_PATH` and every header beside it
    (the ones it includes), umbrella first."""
    return [C_HEADER_PATH] + sorted(p for p in C_HEADER_PATH.parent.glob("*.h") if p != C_HEADER_PATH)

AXES = "xyz"
UNITS = {"length": "m", "mass": "kg", "force": "N", "stiffness": "N/m", "pressure": "Pa", "energy": "J",
         "volume": "m^3", "acceleration": "m/s^2", "time": "s", "damping_alpha": "1/s", "damping_beta": "s"}



# --------------------------------------------------------------------------------------------
# tables
# --------------------------------------------------------------------------------------------



# --------------------------------------------------------------------------------------------
# the model
# --------------------------------------------------------------------------------------------


@dataclass
class MssExport:
    """Everything that defines a scene's mass-spring system (SI units, rest configuration).

    ``points`` (n, dim) rest positions (the mesh's); ``masses`` (n,); ``fixed`` (n, dim) bool and
    ``prescribed`` (n, dim) displacements at load factor 1; ``pairs`` (s, 2), ``stiffness`` (s,),
    ``rest_length`` (s,); ``terms`` the model's other exported terms (volume, angular, correction:
    each describes itself, :class:`msslib.terms.Term`); ``loads`` (n, dim) surface loads at load
    factor 1; ``gravity`` (dim,) or None; ``damping`` (alpha, beta) of a dynamic scene.
    """

    scene: object
    setup: object
    model: object
    masses: np.ndarray
    mass_source: str
    fixed: np.ndarray
    prescribed: np.ndarray
    pairs: np.ndarray
    stiffness: np.ndarray
    rest_length: np.ndarray
    terms: list = field(default_factory=list)
    loads: np.ndarray | None = None
    gravity: np.ndarray | None = None
    damping: tuple = (0.0, 0.0)
    _tables: dict | None = field(default=None, repr=False)
    _stability_limit: float | None = field(default=None, repr=False)

    @property
    def points(self) -> np.ndarray:
        """Rest positions (n, dim), the mesh's."""
        return self.setup.mesh.points

    @property
    def dim(self) -> int:
        return self.setup.mesh.dim

    @property
    def n_nodes(self) -> int:
        return self.setup.mesh.n_nodes

    def _term(self, name):
        return next((t for t in self.terms if t.export_name == name), None)

    @property
    def tet_volume(self):
        """The model's term with table ``tet_volume`` (Lloyd's), or None."""
        return self._term("tet_volume")

    @property
    def hex_volume(self):
        """The model's term with table ``hex_volume`` (Golec's), or None."""
        return self._term("hex_volume")

    @property
    def correction(self):
        """The model's term with table ``baudet_correction`` (Baudet's, boundary reading), or None."""
        return self._term("baudet_correction")

    @property
    def volume_terms(self) -> list[str]:
        """One phrase per term of the model that MuJoCo and SOFA cannot carry (volume, angular and
        element-reading correction terms), naming its table."""
        from msslib.export import formats

        mjcf = formats.get("mjcf")
        return [t.export_note("mjcf") for t in self.terms if not mjcf.carries_term(t)]

    def forces(self) -> list[tuple[str, np.ndarray, str]]:
        """``(label, nodal forces at load factor 1, description)`` of the terms that the simulator
        formats carry as constant forces (Baudet's correction)."""
        return [f for t in self.terms for f in t.export_forces()]

    def tables(self) -> dict[str, Table]:
        """The tables of the CSV and JSON outputs, by name (built once)."""
        if self._tables is None:
            self._tables = _tables(self)
        return self._tables


def build(scene) -> MssExport:
    """Load (a path, a dict or a :class:`msslib.scene.Scene`), prepare and collect a scene's MSS.

    ValueError for a FEM scene (there is no mass-spring system to export) and for anything
    :func:`msslib.scene.prepare` refuses."""
    from msslib.scene import load_scene, prepare

    scene = load_scene(scene)
    if scene.is_fem:
        raise ValueError(f"scene.model: {scene.model} is a FEM reference; export writes mass-spring models "
                         f"(the models of msslib.scene.MSS_MODELS)")
    return from_setup(prepare(scene))


def from_setup(setup) -> MssExport:
    """Collect the MSS of a prepared scene (:class:`msslib.scene.Setup`); the model's terms are read
    as they are (a term of an unknown kind is an error: nothing is left out silently)."""
    model = setup.model
    if model is None:
        raise ValueError("the scene has no mass-spring model to export")
    springs, others = [], []
    for t in model.terms:
        if t.kind == "springs":
            springs.append(t)
        elif t.kind == "external" and not t.export_name:
            pass  # the scene's surface loads and gravity, taken from the setup below
        elif t.kind is not None and t.export_name:
            if any(o.export_name == t.export_name for o in others):
                raise ValueError(f"the model has two {type(t).__name__} terms (table {t.export_name}); export "
                                 f"expects one")
            others.append(t)
        else:
            raise ValueError(f"cannot export a term of type {type(t).__name__} (model {setup.scene.model}): it "
                             f"declares no export kind and tables (msslib.terms.Term)")
    dim = model.dim
    pairs = np.concatenate([s.pairs for s in springs]) if springs else np.zeros((0, 2), dtype=np.int64)
    k = np.concatenate([s.k for s in springs]) if springs else np.zeros(0)
    rest = np.concatenate([s.rest_length for s in springs]) if springs else np.zeros(0)
    if setup.masses is not None:
        masses, source = np.asarray(setup.masses, dtype=float), "lumped from the scene's densities"
    else:
        masses, source = np.asarray(model.node_masses, dtype=float), \
            "lumped with unit density (the scene gives no density; only dynamics would use them)"
    scene = setup.scene
    damping = (0.0, 0.0)
    if scene.is_dynamic:
        d = scene.solver.get("damping", 0.0)
        damping = (float(d), 0.0) if np.ndim(d) == 0 else (float(d[0]), float(d[1]))
    gravity = None if setup.gravity is None else np.asarray(setup.gravity, dtype=float)
    return MssExport(scene=scene, setup=setup, model=model,
                     masses=masses, mass_source=source, fixed=np.asarray(setup.fixed, dtype=bool).reshape(-1, dim),
                     prescribed=np.asarray(setup.prescribed, dtype=float).reshape(-1, dim), pairs=pairs,
                     stiffness=k, rest_length=rest, terms=others,
                     loads=np.asarray(setup.surface_forces, dtype=float).reshape(-1, dim), gravity=gravity,
                     damping=damping)


def _tables(exp: MssExport) -> dict[str, Table]:
    dim, n = exp.dim, exp.n_nodes
    axes = AXES[:dim]
    nodes = np.arange(n)
    out = {}
    out["nodes"] = Table("nodes", f"node rest positions and masses ({exp.mass_source})", [
        make_column("node", None, nodes, "node index (0-based)", int),
        *[make_column(a, "m", exp.points[:, i], f"rest position, {a}") for i, a in enumerate(axes)],
        make_column("mass", "kg", exp.masses, "node mass"),
    ])
    out["springs"] = Table("springs", "springs k/2 (|x_j - x_i| - L)^2 between node_i and node_j", [
        make_column("spring", None, np.arange(len(exp.pairs)), "spring index", int),
        make_column("node_i", None, exp.pairs[:, 0], "first node", int),
        make_column("node_j", None, exp.pairs[:, 1], "second node", int),
        make_column("stiffness", "N/m", exp.stiffness, "spring constant k, summed over the elements sharing the pair"),
        make_column("rest_length", "m", exp.rest_length, "rest length L (differs from the node distance for "
                                                  "prestrained springs)"),
    ])
    held = np.flatnonzero(exp.fixed.any(axis=1))
    out["fixed"] = Table("fixed", "nodes with fixed axes (1 fixed, 0 free) and the displacements prescribed "
                                  "on the fixed axes at load factor 1 (0 on free axes)", [
        make_column("node", None, held, "node index", int),
        *[make_column(f"fixed_{a}", None, exp.fixed[held, i].astype(int), f"axis {a} fixed", int) for i, a in enumerate(axes)],
        *[make_column(f"u_{a}", "m", exp.prescribed[held, i], f"prescribed displacement, {a}") for i, a in enumerate(axes)],
    ])
    loaded = np.flatnonzero(np.any(exp.loads != 0, axis=1))
    out["loads"] = Table("loads", "surface loads (tractions and nodal forces of the scene) on the nodes at load "
                                  "factor 1, dead loads (gravity is in table gravity)", [
        make_column("node", None, loaded, "node index", int),
        *[make_column(f"f_{a}", "N", exp.loads[loaded, i], f"force, {a}") for i, a in enumerate(axes)],
    ])
    g = np.zeros(dim) if exp.gravity is None else exp.gravity
    out["gravity"] = Table("gravity", "gravitational acceleration (each node carries its mass times it; zero: "
                                      "no gravity)", [make_column(f"g_{a}", "m/s^2", [g[i]], f"gravity, {a}")
                                                      for i, a in enumerate(axes)])
    for t in exp.terms:
        for table in t.export_tables(exp.setup.mesh):
            out[table.name] = table
    return out


# --------------------------------------------------------------------------------------------
# shared by the writers
# --------------------------------------------------------------------------------------------

def not_carried(exp: MssExport, fmt: str) -> list[str]:
    """What of the model ``fmt`` leaves out (an empty list: all of it): each term says what the
    format leaves out of it (:meth:`msslib.terms.Term.export_note`)."""
    from msslib.export import formats

    form = formats.get(fmt)
    out = [t.export_note(fmt) for t in exp.terms if not form.carries_term(t)]
    if fmt == "mjcf" and exp.damping[1] != 0.0:
        out.append(f"the stiffness-proportional damping beta = {exp.damping[1]!r} s (only the mass-proportional "
                   f"alpha is carried, as joint damping)")
    return out


def _safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "scene"


def _version() -> str:
    from msslib import __version__

    return __version__


def _pad3(a):
    a = np.asarray(a)
    if a.ndim == 2 and a.shape[1] < 3:
        a = np.hstack([a, np.zeros((len(a), 3 - a.shape[1]), dtype=a.dtype)])
    return a

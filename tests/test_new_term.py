"""A new force term is a term module and a model family that uses it (beside its derivation and its
test): nothing else in msslib learns its type.

The test writes both files into a temporary folder, makes the family visible to the model registry
for its duration, and runs the new model through the scene runner (static and dynamic), the
stepping simulator, the stability check and every export format, each against an independent
number. The term: tethers, zero-length springs k_i/2 |x_i - X_i|^2 tying every node to its rest
position (how surgical simulators often hold tissue to its surroundings), here k_i = c m_i. On a body
with no fixed node under gravity g every node carries m_i g, the lattice's springs stay at rest
length and every node sinks by g / c exactly; in dynamics that translation oscillates with
omega = sqrt(c).
"""

from __future__ import annotations

import importlib
import sys
import textwrap
import warnings

import numpy as np
import pytest

import msslib
from msslib import export, models
from msslib.export import files as export_files
from msslib.export.text import read_csv, read_json

TERM = '''
import numpy as np
from msslib.terms import Term
from msslib.terms.base import Column, Table


class Tethers(Term):
    """Zero-length springs from every listed node to its rest position: k_t/2 |x_i - X_i|^2."""

    kind = "tether"
    export_name = "tethers"
    export_label = "tethers to the rest positions"
    export_energy = "k_t/2 |x_i - X_i|^2"
    export_formats = ("csv", "json")

    def __init__(self, nodes, anchors, k):
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.anchors = np.asarray(anchors, dtype=float)
        self.k = np.broadcast_to(np.asarray(k, dtype=float), self.nodes.shape).copy()
        self.dim = self.anchors.shape[1]

    def __len__(self):
        return len(self.nodes)

    def max_node(self):
        return int(self.nodes.max()) if len(self.nodes) else -1

    def held_nodes(self):
        return self.nodes

    def _offset(self, x):
        return x.reshape(-1, self.dim)[self.nodes] - self.anchors

    def energy(self, x):
        return 0.5 * float(np.sum(self.k[:, None] * self._offset(x) ** 2))

    def gradient(self, x):
        g = np.zeros_like(x.reshape(-1, self.dim))
        np.add.at(g, self.nodes, self.k[:, None] * self._offset(x))
        return g.ravel()

    def hessian_pattern(self):
        dofs = (self.nodes[:, None] * self.dim + np.arange(self.dim)).ravel()
        return dofs, dofs

    def hessian_values(self, x):
        return np.repeat(self.k, self.dim)

    def export_tables(self, mesh):
        return [Table("tethers", "zero-length springs to the rest positions", [
            Column("node", None, self.nodes, "tethered node"),
            Column("k_t", "N/m", self.k, "tether stiffness")])]
'''

FAMILY = '''
from msslib.models.lloyd import lloyd_tet_springs
from msslib.models.spec import ModelSpec, Option, positive_number
from tether_term import Tethers


def _build(ctx):
    """Tethers of stiffness rate * node mass (node masses lumped from the option density)."""
    from msslib.mesh import lumped_masses

    springs = lloyd_tet_springs(ctx.mesh, ctx.materials)
    k_t = ctx.options["rate"] * lumped_masses(ctx.mesh, ctx.options["density"])
    out = {"springs": springs}
    if "tethers" in ctx.options["terms"]:
        out["tethers"] = [Tethers(range(ctx.mesh.n_nodes), ctx.mesh.points, k_t)]
    return out


RANK = 90
SPECS = (ModelSpec("tethered_tetrahedron", "tethered", "mss", ("tetra",), 3,
                   "Lloyd's tetrahedron springs held by tethers", "a family written for a test",
                   element="tetrahedron", terms=("springs", "tethers"),
                   options=(Option("rate", positive_number, 1.0e4, "tether stiffness per node mass (N/m/kg)"),
                            Option("density", positive_number, 1000.0, "density for the node masses (kg/m^3)")),
                   build=_build),)
'''

RATE = 1.0e4  # N/m per kg of node mass: every node's tether k_i = RATE m_i
G = 9.81
DENSITY, SIZE, N = 1000.0, 0.02, 2


@pytest.fixture()
def family(tmp_path, monkeypatch):
    """The term and the family as two new files; the family is found by the registry's own scan
    (the scene's module-level tables of the shipped models are built before, and stay as they are)."""
    import msslib.scene  # noqa: F401

    (tmp_path / "tether_term.py").write_text(textwrap.dedent(TERM))
    fam = tmp_path / "families"
    fam.mkdir()
    (fam / "tethered.py").write_text(textwrap.dedent(FAMILY))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(models, "__path__", [*models.__path__, str(fam)])
    for cached in (models.families, models._registry):
        cached.cache_clear()
    yield models.get("tethered_tetrahedron")
    for cached in (models.families, models._registry):
        cached.cache_clear()
    for name in ("tether_term", "msslib.models.tethered"):
        sys.modules.pop(name, None)
    importlib.invalidate_caches()


def _scene(solver):
    return {"name": "tethered", "model": {"type": "tethered_tetrahedron", "rate": RATE, "density": DENSITY},
            "geometry": {"generator": "tet_grid", "args": {"lx": SIZE, "ly": SIZE, "lz": SIZE, "nx": N, "ny": N, "nz": N}},
            "materials": [{"E": 1.0e5, "nu": 0.25, "density": DENSITY}],
            "loads": [{"type": "gravity", "g": [0.0, 0.0, -G]}],
            "solver": solver}


def test_the_registry_and_the_static_solve_take_the_new_term(family):
    assert "tethered_tetrahedron" in models.names("mss") and family.terms == ("springs", "tethers")
    from msslib.scene import load_scene, run_scene

    res = run_scene(load_scene(_scene({"type": "static", "load_steps": 1, "tol": 1e-12})), progress=False)
    u = res["displacement"].transpose("node", "axis").values
    np.testing.assert_allclose(u, np.tile([0.0, 0.0, -G / RATE], (len(u), 1)), rtol=0, atol=1e-9 * G / RATE)


def test_the_simulator_steps_the_new_term_at_its_own_frequency(family):
    """Released from rest under gravity, every node follows -g/c (1 - cos(sqrt(c) t)) (c = RATE):
    tether and weight both scale with the node's mass, the springs stay at rest length. The
    simulator picks the engine that can run a term it does not know."""
    from msslib.scene import load_scene, prepare

    setup = prepare(load_scene(_scene({"type": "dynamic", "dt": 1e-5, "t_end": 1e-3})))
    dt = 1e-5
    sim = msslib.Simulator(setup.model, dt=dt, method="velocity_verlet")
    steps = int(round(2 * np.pi / np.sqrt(RATE) * 0.3 / dt))  # 0.3 of a period
    sim.step(steps)
    u = np.asarray(sim.x).reshape(-1, 3) - setup.model.mesh.points
    expected = -G / RATE * (1 - np.cos(np.sqrt(RATE) * steps * dt))
    np.testing.assert_allclose(u[:, 2], expected, rtol=1e-6)  # Verlet's phase error: (omega dt)^2 / 24
    np.testing.assert_allclose(u[:, :2], 0.0, atol=1e-9 * G / RATE)


def test_every_format_exports_the_new_model_or_names_the_term_it_leaves_out(family, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exp = export.build(_scene({"type": "static"}))
    stem = tmp_path / "m"
    planned = export_files.output_paths(exp, stem, export.formats.names())
    export_files.write_outputs(exp, stem, planned)
    doc, tables = read_json(stem.with_suffix(".json"))
    tethers = tables["tethers"]
    entry = next(t for t in doc["terms"] if t["table"] == "tethers")
    assert entry["energy"] == "k_t/2 |x_i - X_i|^2" and entry["count"] == exp.n_nodes
    assert np.array_equal(np.asarray(tethers["node"]), np.arange(exp.n_nodes))
    np.testing.assert_allclose(np.asarray(tethers["k_t"], dtype=float), RATE * exp.masses, rtol=1e-15)
    csv = read_csv(tmp_path / "m_tethers.csv")
    np.testing.assert_array_equal(np.asarray(csv["k_t"], dtype=float), np.asarray(tethers["k_t"], dtype=float))
    for fmt in export.formats.names():  # the formats the term does not list say that they leave it out
        notes = export.not_carried(exp, fmt)
        assert any("tethers" in n for n in notes) == (fmt not in ("csv", "json")), (fmt, notes)

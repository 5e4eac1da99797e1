"""Shared pieces of the Baudet et al. (2007) studies (not a study itself: studies/*.py import it).

* :func:`block` -- a box of Baudet cubes with symmetry planes x = 0, y = 0, z = 0 (an octant of a
  body twice as large in every direction), a unit load on chosen faces and the correction in one
  of two readings (:data:`READINGS`): built from that load on the loaded boundary faces
  (``boundary``) or for every cube from the forces acting on it from outside (``element``, see
  :mod:`msslib.terms.baudet`); derived factor, or the printed one with ``published=True``;
* :func:`follow` -- load continuation until a measured quantity reaches a target (each equilibrium
  starts from the previous one; the line search judges the residual);
* :func:`write` -- atomic NetCDF output through :func:`msslib.results.netcdf.write_result`.

All quantities SI. Loads are dead loads in the reference configuration (nominal stresses), as in
the paper's definitions (eqs. 1-6: forces over the rest areas, changes over rest lengths).
"""

from __future__ import annotations

import time
from pathlib import Path as _P

import numpy as np

from experiments import script
from experiments.script import LoadSegment
from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib import mesh as M
from msslib import system as MD
from msslib import terms as T
from msslib.solvers import static_solve

E0 = 1.0e3  # Pa: the errors do not depend on E (all spring constants and forces scale with it)
A0 = 0.1  # m, cube edge
NUS = (0.1, 0.2, 0.3, 0.4, 0.499)  # nu = 0.5 of the paper as 0.499 (nu < 1/2 for the FEM-style parameters)
NU_LABELS = tuple(f"{v:g}" for v in NUS)
FACTORS = ("derived", "printed")
READINGS = ("boundary", "element")  # readings of the correction force (msslib.terms.baudet)
STEPS = 40  # load levels per curve (set to 10 by --quick)
# the cantilever's MSS resolutions (its figure and table read these runs: figures/inputs.yaml, tables/inputs.yaml)
CANTILEVER_RES = ("4x1x1", "8x2x2", "16x4x4", "32x8x8")


def parse(doc):
    """A study's command line (:func:`experiments.script.args`: ``--out``, ``--quick``); ``--quick``
    sets :data:`STEPS` to 10."""
    args = script.args(doc)
    global STEPS
    STEPS = 10 if args.quick else 40
    return args


def face_facets(mesh, axis, value):
    """Boundary facets lying in the plane ``x_axis = value``."""
    facets = M.boundary_facets(mesh)
    nodes = M.select_nodes(mesh, plane=(axis, value))
    return facets[np.all(np.isin(facets, nodes), axis=1)]


def block(n, nu, *, published=False, tractions=(), fixed_planes="xyz", fix_all_planes=(), E=E0, a=A0,
          correction=True, reading="boundary"):
    """Box of ``n = (nx, ny, nz)`` cubes of edge ``a``.

    ``tractions``: list of ``(axis, value, traction_vector)``: a dead traction (Pa, at unit load)
    on the boundary face ``x_axis = value``. ``fixed_planes``: axes whose ``= 0`` plane is a
    symmetry plane (normal displacement fixed). ``fix_all_planes``: axes whose ``= 0`` face is
    clamped (all displacements fixed). Returns ``(mesh, model)``; the model has the springs, the
    loads and Baudet's correction computed from those loads (left out with ``correction=False``),
    or with ``reading="element"`` from the forces acting on every cube from outside it.
    """
    mesh = M.hex_grid(a * n[0], a * n[1], a * n[2], *n)
    terms = list(baudet_cube_springs(mesh, [(E, nu)], published=published))
    loads = [T.Traction(mesh, face_facets(mesh, ax, val), vec) for ax, val, vec in tractions]
    terms += loads
    # One correction per loaded face, summed (the correction is linear in the face forces): msslib
    # shares the load of a node among the boundary faces it pushes on, which halves the elongation
    # force at an edge where two loaded faces meet (pressure on a box); built face by face, each
    # face gets exactly its own normal resultant.
    if correction and reading == "element":
        from msslib.models.baudet import element_correction

        terms.append(element_correction(mesh, [(E, nu)], published=published))
    elif correction:
        terms += [baudet_correction(mesh, [(E, nu)], [ld], published=published) for ld in loads]
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    for ax in fixed_planes:
        d = "xyz".index(ax)
        fixed[M.select_nodes(mesh, plane=(ax, 0.0)), d] = True
    for ax in fix_all_planes:
        fixed[M.select_nodes(mesh, plane=(ax, 0.0)), :] = True
    return mesh, MD.Model(mesh, terms, fixed=fixed)


def unit_load_norm(model):
    f = model.external_force(1.0)
    return float(np.linalg.norm(f[model.free]))


def follow(model, measure, target, first_step, *, max_levels=400, tol=1e-10, grow=1.0, n_steps=None):
    """Increase the load factor from 0 in steps until ``|measure(x)| >= target``.

    ``measure(x)`` returns the controlling quantity (e.g. the axial strain) of the flat state ``x``;
    ``first_step`` is the initial load increment; later increments aim at equal increments of the
    measure (``target / 40`` by default through the secant slope), times ``grow``. Returns the list
    of load factors and the list of states (flat positions), the rest state excluded.
    """
    x = model.x0.copy()
    s, ds = 0.0, float(first_step) * 1e-2  # probe: the response may be far softer than expected
    scale = unit_load_norm(model)
    loads, states = [], []
    dq = target / (n_steps or STEPS)
    for _ in range(max_levels):
        s1 = s + ds
        r = static_solve(LoadSegment(model, s, s1, energy=False), x, load_steps=1, tol=tol, max_iter=60,
                         force_scale=max(abs(s1), 1e-300) * scale)
        x, s = r.x, s1
        q = measure(x)
        loads.append(s)
        states.append(x.copy())
        if abs(q) >= target:
            break
        slope = abs(q) / abs(s) if s != 0 else 0.0
        if slope > 0:
            ds = np.sign(ds) * min(dq / slope * grow, 4.0 * abs(ds), abs(s) + abs(ds))
    else:
        raise RuntimeError(f"target {target} not reached after {max_levels} load levels")
    return np.array(loads), states


def split_readings(ds, default="boundary"):
    """Rename every variable with a ``reading`` dimension to ``NAME_by_reading`` and add ``NAME``,
    its ``default`` slice (the names the paper's placeholders used before the readings existed)."""
    for name in [v for v in ds.data_vars if "reading" in ds[v].dims]:
        ds = ds.rename({name: f"{name}_by_reading"})
        ds[name] = ds[f"{name}_by_reading"].sel(reading=default, drop=True)
        ds[name].attrs = {**ds[f"{name}_by_reading"].attrs, "reading": default}
    return ds


def write(ds, out, t0):
    from msslib.results import write_result

    ds.attrs.setdefault("paper", "baudet")
    ds.attrs["wall_time_s"] = time.perf_counter() - t0
    _P(out).parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)


class Reduced:
    """``model`` restricted to positions ``x = x0 + B y`` (``B`` sparse or dense ``(n_dof, r)``):
    the state of the solver is ``y`` (r values, start at 0), forces and stiffness are projected
    (``B^T f``, ``B^T K B``). Used for kinematic ties, e.g. a rigid loading plate."""

    def __init__(self, model, B):
        import scipy.sparse as sp

        self.m, self.B = model, sp.csr_matrix(B)
        self.n_dof = self.B.shape[1]
        self.free = np.ones(self.n_dof, dtype=bool)
        self.symmetric, self.dim = model.symmetric, 1
        self.mass = np.ones(self.n_dof)
        self.s0, self.s1 = 0.0, 1.0

    def x(self, y):
        return self.m.x0 + self.B @ np.asarray(y, dtype=float)

    def _s(self, load):
        return self.s0 + load * (self.s1 - self.s0)

    def force(self, y, load=1.0):
        return self.B.T @ self.m.force(self.x(y), self._s(load))

    def stiffness(self, y, load=1.0):
        import scipy.sparse as sp

        return sp.csr_matrix(self.B.T @ self.m.stiffness(self.x(y), self._s(load)) @ self.B)

    def energy(self, y, load=1.0):
        return None


def follow_reduced(red, measure, target, first_step, *, max_levels=400, tol=1e-10, n_steps=None):
    """:func:`follow` for a :class:`Reduced` problem; ``measure`` gets full positions."""
    y = np.zeros(red.n_dof)
    s, ds = 0.0, float(first_step) * 1e-2
    f1 = red.B.T @ red.m.external_force(1.0)
    scale = float(np.linalg.norm(f1))
    loads, states = [], []
    dq = target / (n_steps or STEPS)
    for _ in range(max_levels):
        red.s0, red.s1 = s, s + ds
        r = static_solve(red, y, load_steps=1, tol=tol, max_iter=60, force_scale=max(abs(s + ds), 1e-300) * scale)
        y, s = r.x, s + ds
        x = red.x(y)
        q = measure(x)
        loads.append(s)
        states.append(x.copy())
        if abs(q) >= target:
            break
        slope = abs(q) / abs(s)
        if slope > 0:
            ds = np.sign(ds) * min(dq / slope, 4.0 * abs(ds), abs(s) + abs(ds))
    else:
        raise RuntimeError(f"target {target} not reached after {max_levels} load levels")
    return np.array(loads), states


def tie_matrix(n_nodes, free_nodes, groups):
    """``B`` for :class:`Reduced`: every node of ``free_nodes`` moves on its own (3 columns each),
    every group (a list of node ids) moves as one rigid translation (3 columns); other nodes are
    fixed. Column order: free nodes, then groups."""
    rows, cols = [], []
    c = 0
    for a in free_nodes:
        for d in range(3):
            rows.append(3 * a + d)
            cols.append(c)
            c += 1
    for g in groups:
        for d in range(3):
            for a in g:
                rows.append(3 * a + d)
                cols.append(c)
            c += 1
    import scipy.sparse as sp

    return sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(3 * n_nodes, c))


# ---- figures ----------------------------------------------------------------------------------

def open_result(path):
    import xarray as xr

    with xr.open_dataset(path) as ds:
        return ds.load()


def section_deflection(ds):
    """Mean vertical (-z) displacement of every cross-section x = const of a result: the
    deflection of the neutral axis for a beam bent about y (x values, deflections, both in m)."""
    X = ds["rest_position"].transpose("node", "axis").values
    u = ds["displacement"].transpose("node", "axis").values
    xs = np.unique(np.round(X[:, 0], 12))
    w = np.array([-u[np.isclose(X[:, 0], v), 2].mean() for v in xs])
    return xs, w

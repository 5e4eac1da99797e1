"""Every model of the registry (msslib.models), tested for free: finite-difference checks of energy,
force and Hessian, equilibrium at rest, the patch test where its derivation claims exactness, the
scene round trip; and the rectangle of any aspect ratio against the bilinear element."""

from __future__ import annotations

import importlib
import re

import numpy as np
import pytest
import yaml

from cell_helpers import example_geometry, example_mesh
from fem_helpers import fem_stiffness
from msslib import mesh as M
from msslib.mesh import cells
from msslib import models
from msslib.system import Model

MSS = models.names("mss")
SPECS = models.registry()
T = 0.1  # membrane thickness (m)


def _mesh(cell, kind="any"):
    """A small mesh of ``cell`` cells, the cell registry's example (equilateral triangles, squares,
    cubes, ...) unless ``kind`` is ``"rectangle"`` (2 x 1 quads, aspect ratio r = b / a = 0.5)."""
    if cell == "quad" and kind == "rectangle":
        return M.quad_grid(3.0, 1.5, 3, 3)
    return example_mesh(cell)


def _options(spec, **given):
    out = {"published": False, "A": None, "plane": "stress", "terms": spec.defaults,
           **{o.name: o.default for o in spec.options}}
    out.update(given)
    return out


def _loads(mesh):
    """Unit-load nodal forces on the top nodes (the load Baudet's correction reads)."""
    f = np.zeros((mesh.n_nodes, mesh.dim))
    top = mesh.points[:, -1] > mesh.points[:, -1].max() - 1e-9
    f[top, -1] = -0.01 / top.sum()
    return f


def _model(name, mesh=None, nu=0.3, E=1.0, terms=None, **opts):
    spec = SPECS[name]
    mesh = _mesh(spec.cell_type) if mesh is None else mesh
    options = _options(spec, **opts)
    if terms is not None:
        options["terms"] = terms
    ctx = models.BuildContext(mesh=mesh, materials=[(E, nu)], options=options, thickness=T,
                              surface_forces=_loads(mesh))
    with np.errstate(all="ignore"):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            built = spec.build(ctx)
    assert set(built) == set(options["terms"]), (name, set(built))
    return Model(mesh, [t for k in spec.terms if k in built for t in built[k]])


def _perturbed(model, seed=0, amount=0.03):
    rng = np.random.default_rng(seed)
    h = np.ptp(model.mesh.points, axis=0).max() / 4
    return model.x0 + amount * h * rng.standard_normal(model.n_dof), rng.standard_normal(model.n_dof)


# ---- the registry ------------------------------------------------------------------------------


def test_registry_is_found_by_scanning_the_package():
    import pkgutil

    declared = [s.name for m in pkgutil.iter_modules(models.__path__)
                for s in getattr(importlib.import_module(f"msslib.models.{m.name}"), "SPECS", ())]
    assert sorted(declared) == sorted(models.names())
    assert len(set(declared)) == len(declared)
    assert {"lloyd_rectangle", "golec_cube", "fem_linear"} <= set(models.names())


def test_scene_tables_come_from_the_registry():
    from msslib import planning, scene

    assert scene.MODELS == models.names()
    assert scene.MSS_MODELS == {n: (s.cell_type, s.terms) for n, s in SPECS.items() if s.kind == "mss"}
    assert scene.FEM_MODELS == {"fem_linear": None, "fem_svk": "svk", "fem_neohookean": "neohookean"}
    assert planning.MODELS["quad"] == ["lloyd_square", "lloyd_rectangle", "fem_linear", "fem_svk"]


def test_baudet_readings_match_the_correction_module():
    from msslib.terms.baudet import READINGS

    assert SPECS["baudet_cube"].option("correction").parse.choices == READINGS


@pytest.mark.parametrize("name", MSS)
def test_spec_names_its_paper_and_generated_element(name):
    spec = SPECS[name]
    # the citation: authors, title, venue and year; an identifier only where one is known for sure
    assert spec.reference and re.search(r"(19|20)\d\d", spec.reference), spec.reference
    assert spec.doi is None or re.fullmatch(r"10\.\d{4,}/\S+", spec.doi), spec.doi
    assert spec.hal is None or re.fullmatch(r"(hal|inria)-\d{8}", spec.hal), spec.hal
    gen = importlib.import_module(f"msslib.generated.{spec.element}")
    assert callable(spec.parameters) and callable(spec.build)
    assert gen.__doc__
    from msslib import parameters

    assert getattr(parameters, spec.parameters.__name__) is spec.parameters


# ---- finite differences ------------------------------------------------------------------------


@pytest.mark.parametrize("name", MSS)
def test_energy_gradient_finite_difference(name):
    spec = SPECS[name]
    conservative = tuple(t for t in spec.defaults if t not in spec.nonconservative)
    model = _model(name, terms=conservative)
    x, d = _perturbed(model)
    eps = 1e-6
    fd = (model.energy(x + eps * d) - model.energy(x - eps * d)) / (2 * eps)
    exact = -model.force(x) @ d
    assert abs(fd - exact) <= 1e-6 * max(abs(exact), 1e-12) + 1e-12, (fd, exact)


@pytest.mark.parametrize("name", MSS)
def test_hessian_finite_difference(name):
    model = _model(name)  # every term, non-conservative ones too: the Hessian is -d force / dx
    x, d = _perturbed(model, seed=1)
    eps = 1e-6
    fd = -(model.force(x + eps * d) - model.force(x - eps * d)) / (2 * eps)
    Kd = model.stiffness(x) @ d
    assert np.linalg.norm(fd - Kd) <= 1e-6 * np.linalg.norm(Kd), np.linalg.norm(fd - Kd) / np.linalg.norm(Kd)


# ---- equilibrium at rest -----------------------------------------------------------------------


def _rest_cases():
    for name in MSS:
        spec = SPECS[name]
        choices = [{}] + [{o.name: c} for o in spec.options for c in getattr(o.parse, "choices", ())
                          if c != o.default]
        for opts in choices:
            yield pytest.param(name, opts, id=f"{name}-{'-'.join(map(str, opts.values())) or 'default'}")


@pytest.mark.parametrize("name, opts", list(_rest_cases()))
def test_equilibrium_at_rest(name, opts):
    spec = SPECS[name]
    kind = "rectangle" if name == "lloyd_rectangle" else "any"
    nu = 1 / 3 if spec.dim == 2 else 0.3
    model = _model(name, mesh=_mesh(spec.cell_type, kind), nu=nu, **opts)
    f0 = model.force(model.x0, 0.0)  # internal forces (load-driven terms such as Baudet's correction at zero load)
    x, _ = _perturbed(model, amount=0.01)
    scale = np.abs(model.force(x, 0.0)).max()  # forces of a 1 % deformation
    if spec.in_equilibrium_at_rest(_options(spec, **opts)):
        assert np.abs(f0).max() <= 1e-12 * scale, np.abs(f0).max() / scale
    else:  # the free rectangle fit at r != 1: the derivation says it is not in equilibrium at rest
        assert np.abs(f0).max() > 1e-3 * scale


# ---- patch tests where the derivation claims exactness -----------------------------------------


def _exact_cases():
    for name in MSS:
        for i, ex in enumerate(SPECS[name].exact):
            yield pytest.param(name, ex, id=f"{name}-{ex.level}-{i}")


def _elasticity(E, nu, dim):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    if dim == 2:  # plane stress, per unit thickness
        lam = 2 * lam * mu / (lam + 2 * mu)
    return lam, mu


@pytest.mark.parametrize("name, ex", list(_exact_cases()))
@pytest.mark.parametrize("nu_free", [0.2, 0.35])
def test_patch_where_exact(name, ex, nu_free):
    spec = SPECS[name]
    nu = ex.nu if ex.nu is not None else nu_free
    E = 2.0
    mesh = _mesh(spec.cell_type)  # equilateral triangles, squares, cubes
    opts = {k: v for k, v in ex.options.items() if k != "terms"}
    model = _model(name, mesh=mesh, nu=nu, E=E, terms=ex.options.get("terms"), **opts)
    K = model.stiffness(model.x0).toarray()
    if ex.level == "element":  # the assembled matrices are equal
        K_fem = fem_stiffness(mesh, E, nu, T)
        assert np.abs(K - K_fem).max() <= 1e-10 * np.abs(K_fem).max()
        return
    # lattice: a homogeneous strain; the virial of the forces is V times the continuum stress
    X = mesh.points
    V = np.prod(np.ptp(X, axis=0)) * (T if mesh.dim == 2 else 1.0)
    lam, mu = _elasticity(E, nu, mesh.dim)
    rng = np.random.default_rng(3)
    for _ in range(3):
        G = rng.standard_normal((mesh.dim, mesh.dim))
        eps = (G + G.T) / 2
        f = (K @ (X @ eps.T).ravel()).reshape(-1, mesh.dim)
        virial = f.T @ X / V
        sigma = lam * np.trace(eps) * np.eye(mesh.dim) + 2 * mu * eps
        assert np.abs(virial - sigma).max() <= 1e-10 * np.abs(sigma).max(), (virial, sigma)


def test_patch_claims_are_not_vacuous():
    """Off the claimed Poisson's ratio the same checks fail: the exact cases mean something."""
    mesh = _mesh("quad")
    K = _model("lloyd_square", mesh=mesh, nu=0.25).stiffness(mesh.points.ravel()).toarray()
    K_fem = fem_stiffness(mesh, 1.0, 0.25, T)
    assert np.abs(K - K_fem).max() > 1e-3 * np.abs(K_fem).max()


# ---- scene round trip --------------------------------------------------------------------------

_GEOMETRY = {cell: example_geometry(cell) for cell in cells.names()}  # the cell registry's examples, 1 cm


@pytest.mark.parametrize("name", MSS)
def test_scene_round_trip(name):
    from msslib.scene import load_scene, run_scene

    spec = SPECS[name]
    dim = spec.dim
    axis = "y" if dim == 2 else "z"
    raw = {"geometry": _GEOMETRY[spec.cell_type], "materials": [{"E": 1.0e6, "nu": 0.3}],
           "model": {"type": name, **{o.name: o.default for o in spec.options}},
           "boundary": [{"select": {"plane": [axis, 0.0]}, "fix": "all"}],
           "loads": [{"type": "nodal_force", "select": {"box": [[None] * dim, [None] * dim]}, "total": [1e-2] * dim}],
           "solver": {"type": "static", "load_steps": 1, "tol": 1e-10}}
    if dim == 2:
        raw["thickness"] = 0.001
    scene = load_scene(raw)
    again = load_scene(yaml.safe_load(scene.text))
    assert (again.model, again.model_options) == (scene.model, scene.model_options)
    ds = run_scene(scene, progress=False)
    assert ds.attrs["model"] == name
    u = ds["displacement"].values
    assert np.all(np.isfinite(u)) and np.abs(u).max() > 0


def test_scene_rejects_options_of_other_models():
    from msslib.scene import load_scene

    raw = {"geometry": _GEOMETRY["quad"], "materials": [{"E": 1.0, "nu": 0.3}], "model": {"type": "lloyd_square",
                                                                                       "fit": "equilibrium"}}
    with pytest.raises(ValueError, match=r"scene\.model\.fit: only lloyd_rectangle takes fit, not lloyd_square"):
        load_scene(raw)
    raw["model"] = {"type": "lloyd_rectangle", "fit": "exact"}
    with pytest.raises(ValueError, match=r"scene\.model\.fit: unknown rectangle fit 'exact'"):
        load_scene(raw)


# ---- the rectangle of any aspect ratio ----------------------------------------------------------


def _one_quad(a, b):
    return M.quad_grid(a, b, 1, 1)


@pytest.mark.parametrize("fit", ["equilibrium", "least_squares"])
def test_rectangle_is_lloyds_square_at_r1(fit):
    mesh = _mesh("quad")
    rect = _model("lloyd_rectangle", mesh=mesh, nu=1 / 3, fit=fit).terms[0]
    square = _model("lloyd_square", mesh=mesh, nu=1 / 3).terms[0]
    order = np.lexsort(rect.pairs.T[::-1])
    ref = np.lexsort(square.pairs.T[::-1])
    assert np.array_equal(rect.pairs[order], square.pairs[ref])
    assert np.allclose(rect.k[order], square.k[ref], rtol=1e-13)
    assert np.allclose(rect.rest_length[order], square.rest_length[ref], rtol=1e-13)


@pytest.mark.parametrize("a, b", [(1.0, 2.0), (2.0, 1.0), (0.3, 0.6)])
def test_rectangle_element_residual_is_the_derived_optimum(a, b):
    """One a x b quad, r = 2 or 1/2: the simulator's stiffness at rest (springs, prestrain, family
    of each pair) differs from the bilinear element by exactly the derivation's least-squares
    residual, ||K_fem - K_mss||_F^2 / ||K_fem||_F^2 = 300/5203 at r = 2 (and r = 1/2: the same
    element turned), nu = 1/3; the fit in equilibrium at rest is further away. No set of springs
    matches the bilinear rectangle for r != 1 (derivations/elements/rectangle.py)."""
    mesh = _one_quad(a, b)
    K_fem = fem_stiffness(mesh, 1.0, 1 / 3, T)

    def rel(fit):
        K = _model("lloyd_rectangle", mesh=mesh, nu=1 / 3, fit=fit).stiffness(mesh.points.ravel()).toarray()
        return np.sum((K - K_fem) ** 2) / np.sum(K_fem**2)

    assert rel("least_squares") == pytest.approx(300 / 5203, rel=1e-10)
    assert rel("equilibrium") > rel("least_squares") * 1.01
    # a perturbed spring set is worse: the simulated constants sit at the optimum
    model = _model("lloyd_rectangle", mesh=mesh, nu=1 / 3, fit="least_squares")
    for factor in (0.99, 1.01):
        model.terms[0].k[:] *= factor
        K = model.stiffness(mesh.points.ravel()).toarray()
        model.terms[0].k[:] /= factor
        assert np.sum((K - K_fem) ** 2) / np.sum(K_fem**2) > 300 / 5203


def test_rectangle_each_quad_its_own_aspect_ratio():
    """A mesh with two column widths: each quad gets the constants of its own r."""
    from msslib.models.lloyd import lloyd_rectangle

    mesh = M.quad_grid(3.0, 1.0, 3, 1)
    mesh.points[mesh.points[:, 0] > 2.5, 0] += 1.0  # columns 1, 1, 2 wide: r = 1, 1, 0.5
    x = mesh.points.copy()
    springs = _model("lloyd_rectangle", mesh=mesh, nu=1 / 3).terms[0]
    mid = np.flatnonzero(np.all(np.isclose(x[springs.pairs, 0], [[1.0, 1.0]]), axis=1))  # the shared vertical edge
    assert len(mid) == 1
    square, wide = lloyd_rectangle(1.0, t=T, r=1.0), lloyd_rectangle(1.0, t=T, r=0.5)
    assert springs.k[mid[0]] == pytest.approx(2 * square.k_v)  # the two unit squares at x = 0..2
    shared = np.flatnonzero(np.all(np.isclose(x[springs.pairs, 0], [[2.0, 2.0]]), axis=1))  # square | wide quad
    assert springs.k[shared[0]] == pytest.approx(square.k_v + wide.k_v)
    assert wide.k_v != pytest.approx(square.k_v)
    last = np.flatnonzero(np.all(np.isclose(x[springs.pairs, 0], [[4.0, 4.0]]), axis=1))
    assert springs.k[last[0]] == pytest.approx(lloyd_rectangle(1.0, t=T, r=0.5).k_v)


def test_rectangle_refuses_quads_that_are_not_rectangles():
    mesh = M.quad_grid(2.0, 1.0, 2, 1)
    mesh.points[4, 0] += 0.2
    with pytest.raises(ValueError, match="not rectangles"):
        _model("lloyd_rectangle", mesh=mesh, nu=1 / 3)

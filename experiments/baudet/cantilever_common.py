"""Shared pieces of the cantilever studies (Baudet Sec. 5, Figs. 9-11; not a study itself).

* :func:`scene` / :func:`run` -- one run of the cantilever of ``experiments/baudet/cantilever.yaml``
  with another model, resolution, density or solver (the experiment file stays the one source of
  the geometry, material and load);
* :func:`lattice_moduli` -- the cubic elastic constants of the assembled Baudet lattice (no
  correction inside a body), its energy under homogeneous strain as ``derivations.elements.cube_baudet``
  derives it;
* :func:`solve_cubic` -- linear elasticity with cubic-symmetric constants (C11, C12, C44), trilinear
  (Q1) or triquadratic (Q2) hexahedra on a ``nx x ny x nz`` box, clamped at x = 0, under a body
  force: the isotropic reference at higher order and the continuum limit of the lattice;
* :func:`error_stats` -- the per-node error statistics under the readings of Baudet's M / SD / MAX.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

EXP = Path(__file__).resolve().parent / "cantilever.yaml"


def base():
    """(L, T, H, E, nu, density, g) of the experiment file (g > 0, acting along -z)."""
    raw = yaml.safe_load(EXP.read_text())
    geo, mat = raw["scene"]["geometry"]["args"], raw["scene"]["materials"][0]
    g = -float(raw["scene"]["loads"][0]["g"][2])
    return (float(geo["lx"]), float(geo["ly"]), float(geo["lz"]), float(mat["E"]), float(mat["nu"]),
            float(mat["density"]), g)


def published():
    """Baudet's M / SD / MAX of the experiment file, as fractions: {"16x4x4": {"mean": 0.0068, ...}}."""
    from msslib.experiment import UNITS

    raw = yaml.safe_load(EXP.read_text())
    return {m.removeprefix("mss_"): {k: float(v[0]) * UNITS[v[1]] for k, v in vals.items()}
            for m, vals in raw["published"]["gravity"].items() if m.startswith("mss_")}


def mass_readings():
    """The printed "mass of 0.0125" read as a density (kg/m^3), a linear density (kg/m) and a
    total mass (kg), each as the density (kg/m^3) of the beam it implies."""
    L, T, H, _, _, rho, _ = base()
    return {"density": rho, "linear_density": rho / (T * H), "total_mass": rho / (L * T * H)}


def scene(model, n, *, density=None, solver=None):
    """Scene dict of the cantilever with ``model`` on ``n = (nx, ny, nz)`` cubes; MSS variants the
    experiment file lists at that resolution keep their solver settings."""
    from msslib.experiment import load_experiment, merge, scene_of

    exp = load_experiment(EXP)
    tag = "x".join(str(int(v)) for v in n)
    if model == "baudet_cube":
        variant = f"mss_{tag}" if f"mss_{tag}" in exp.models else "mss_16x4x4"
    else:
        variant = exp.reference
    sc = scene_of(exp, "gravity", variant)
    over = {"model": model, "geometry": {"args": dict(zip(("nx", "ny", "nz"), (int(v) for v in n)))}}
    if density is not None:
        over["materials"] = [dict(sc["materials"][0], density=float(density))]
    if solver is not None:
        over["solver"] = solver
    return merge(sc, over), exp.base_dir


def run(model, n, **kw):
    """Run :func:`scene` (``msslib.scene.run_scene``) and return the result dataset."""
    from msslib.scene import load_scene, run_scene

    sc, base_dir = scene(model, n, **kw)
    return run_scene(load_scene(sc, base_dir=base_dir), progress=False)


def fields(ds):
    """(rest positions, displacements), both (n_nodes, 3) in m."""
    return (ds["rest_position"].transpose("node", "axis").values, ds["displacement"].transpose("node", "axis").values)


def tip(X, u):
    """Deflection (downwards, m) of the free end: mean -u_z over the nodes of the section x = L."""
    end = np.isclose(X[:, 0], X[:, 0].max())
    return float(-u[end, 2].mean())


# ---- the lattice's elastic constants ------------------------------------------------------------

def lattice_tensor(E, nu, a=1.0):
    """Voigt tensor (6 x 6, Pa) of the assembled uncorrected Baudet lattice: the second-order energy
    of its springs under a homogeneous strain, ``C_ijkl = sum_s k_s r_i r_j r_k r_l / (|r|^2 V)`` over
    one cube's 12 edges and 4 inner diagonals (rest vectors ``r``, per-element constants of
    :func:`msslib.parameters.baudet_cube`, i.e. the derived k_x and k_d), per cube volume ``V = a^3``.
    The same quantity as ``derivations.elements.cube_baudet.assembled_lattice`` (symbolic; checked equal in
    tests/test_baudet_cantilever.py), numerically and in milliseconds."""
    from msslib.parameters import baudet_cube

    p = baudet_cube(E, nu=nu, a=a)
    springs = []
    for ax in range(3):  # 4 parallel edges per axis
        r = np.zeros(3)
        r[ax] = a
        springs += [(p.k_edge, r)] * 4
    for sy in (1, -1):
        for sz in (1, -1):
            springs.append((p.k_diagonal, a * np.array([1.0, sy, sz])))
    C4 = sum(k * np.einsum("i,j,k,l->ijkl", r, r, r, r) / (r @ r) for k, r in springs) / a**3
    voigt = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    return np.array([[C4[i, j, k, m] for k, m in voigt] for i, j in voigt])


def lattice_moduli(E, nu):
    """(C11, C12, C44) of :func:`lattice_tensor` (checked to be of cubic symmetry), its uniaxial
    modulus along a cube axis ``E_axis = 1 / S11`` and Poisson's ratio ``nu_axis = -S12 / S11``."""
    C6 = lattice_tensor(E, nu)
    c11, c12, c44 = C6[0, 0], C6[0, 1], C6[3, 3]
    cubic = np.zeros((6, 6))
    cubic[:3, :3] = c12
    cubic[np.arange(3), np.arange(3)] = c11
    cubic[np.arange(3, 6), np.arange(3, 6)] = c44
    if not np.allclose(C6, cubic, rtol=1e-12, atol=1e-12 * abs(c11)):
        raise ValueError("the lattice tensor is not of cubic symmetry")
    S = np.linalg.inv(C6)
    return {"C11": c11, "C12": c12, "C44": c44, "E_axis": 1.0 / S[0, 0], "nu_axis": -S[0, 1] / S[0, 0]}


def isotropic_moduli(E, nu):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    return {"C11": lam + 2 * mu, "C12": lam, "C44": mu}


# ---- linear elasticity with cubic constants (scikit-fem) -----------------------------------------

class CubicSolution:
    """A solved box: ``displacement_at(points)`` interpolates u with the element's shape functions."""

    def __init__(self, basis, u):
        self.basis, self.u = basis, u

    def displacement_at(self, points):
        P = self.basis.probes(np.asarray(points, dtype=float).T)  # (3 n, n_dofs), component-major
        return (P @ self.u).reshape(3, len(points)).T


def solve_cubic(moduli, n, *, order=1, body_force=None, size=None):
    """Clamped (x = 0) box ``size = (L, T, H)`` of ``n = (nx, ny, nz)`` hexahedra of order 1 (Q1,
    8 nodes) or 2 (Q2, 27 nodes), cubic-symmetric constants ``moduli`` (C11, C12, C44; isotropic
    ones give ordinary linear elasticity), body force per unit volume ``body_force`` (N/m^3;
    default the experiment's weight). Returns a :class:`CubicSolution`."""
    import skfem
    from skfem.helpers import sym_grad

    L, T, H, _, _, rho, g = base()
    size = (L, T, H) if size is None else size
    if body_force is None:
        body_force = (0.0, 0.0, -rho * g)
    xs = [np.linspace(0.0, s, int(k) + 1) for s, k in zip(size, n)]
    mesh = skfem.MeshHex.init_tensor(*xs)
    elem = {1: skfem.ElementHex1(), 2: skfem.ElementHex2()}[order]
    basis = skfem.Basis(mesh, skfem.ElementVector(elem), intorder={1: 2, 2: 4}[order])
    c11, c12, c44 = moduli["C11"], moduli["C12"], moduli["C44"]

    @skfem.BilinearForm
    def stiffness(u, v, w):
        eu, ev = sym_grad(u), sym_grad(v)
        tu, tv = eu[0, 0] + eu[1, 1] + eu[2, 2], ev[0, 0] + ev[1, 1] + ev[2, 2]
        normal = sum(eu[i, i] * ev[i, i] for i in range(3))
        shear = sum(eu[i, j] * ev[i, j] for i in range(3) for j in range(3) if i != j)
        return (c11 - c12) * normal + c12 * tu * tv + 2.0 * c44 * shear

    b = np.asarray(body_force, dtype=float)

    @skfem.LinearForm
    def load(v, w):
        return b[0] * v[0] + b[1] * v[1] + b[2] * v[2]

    K = stiffness.assemble(basis)
    f = load.assemble(basis)
    clamped = basis.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    from msslib.fem import solve_sparse

    u = np.zeros(K.shape[0])
    free = np.setdiff1d(np.arange(K.shape[0]), clamped)
    u[free] = solve_sparse(K[free][:, free], f[free])
    return CubicSolution(basis, u)


# ---- error statistics ----------------------------------------------------------------------------

def error_stats(u, u_ref):
    """Per-node error ``e_i = |u_i - u_ref_i|`` under the readings of Baudet's M / SD / MAX:

    * ``max_*``: e_i / max_j |u_ref_j| (the comparison's convention): mean, SD (population), the
      variance SD^2 and the second moment mean(e^2) (both as fractions), max;
    * ``local_*``: e_i / |u_ref_i| over the nodes that move (the clamped nodes left out): mean, SD,
      variance, second moment, max.
    """
    e = np.linalg.norm(np.asarray(u) - np.asarray(u_ref), axis=1)
    r = np.linalg.norm(np.asarray(u_ref), axis=1)
    out = {}
    for name, rel in (("max", e / r.max()), ("local", e[r > 0] / r[r > 0])):
        out.update({f"{name}_mean": rel.mean(), f"{name}_sd": rel.std(), f"{name}_variance": rel.var(),
                    f"{name}_second_moment": np.mean(rel**2), f"{name}_max": rel.max()})
    return out

"""Least-squares springs with negative summed constants: simulated when the lattice is stable at
rest, refused in one line when it is not. The stability check is compared with the eigenvalues of
the dense stiffness (rigid-body modes counted separately), and a stable lattice with a negative
spring is solved against the FEM."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fem_helpers import jittered
from msslib import mesh as M
from msslib.system import Model
from msslib.models.checks import FormulaValidityWarning
from msslib.models.lsq import (
    _not_positive_definite,
    check_stable_at_rest,
    lsq_tetrahedron_springs,
    lsq_triangle_springs,
    rigid_modes,
)
from msslib.terms import Springs

T = 0.01  # thickness (m)


def _spectrum(springs, mesh):
    """Eigenvalues of the dense stiffness at rest, ascending, scaled by the largest."""
    model = Model(mesh, [springs])
    w = np.linalg.eigvalsh(model.stiffness(model.x0).toarray())
    return w / np.abs(w).max()


def _obtuse_triangle(apex_deg=130.0):
    th = np.radians(apex_deg / 2)
    p = np.array([[-np.sin(th), 0.0], [np.sin(th), 0.0], [0.0, np.cos(th)]])
    return M.Mesh(p, np.array([[0, 1, 2]]), "triangle")


def _grid_with_negative_boundary_spring():
    return jittered(M.triangle_grid_right(1.0, 1.0, 5, 5), 0.04)


def test_rigid_modes_span_the_null_space_of_a_stress_free_lattice():
    for mesh, springs in ((_grid_with_negative_boundary_spring(), None),
                          (jittered(M.tet_grid(1.0, 1.0, 1.0, 2, 2, 2), 0.05), None)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FormulaValidityWarning)
            springs = (lsq_triangle_springs(mesh, [(1.0, 0.3)], T) if mesh.cell_type == "triangle"
                       else lsq_tetrahedron_springs(mesh, [(1.0, 0.3)]))[0]
        model = Model(mesh, [springs])
        K = model.stiffness(model.x0).toarray()
        R = rigid_modes(mesh.points)
        dim = mesh.points.shape[1]
        assert R.shape == (mesh.points.size, 3 if dim == 2 else 6)
        assert np.linalg.matrix_rank(R) == R.shape[1]
        assert np.abs(K @ R).max() <= 1e-10 * np.abs(K).max() * np.abs(R).max()


def test_springs_refuse_negative_constants_unless_signed():
    pairs, rest = np.array([[0, 1], [1, 2]]), np.array([1.0, 1.0])
    with pytest.raises(ValueError, match="1 spring"):
        Springs(pairs, np.array([1.0, -0.5]), rest, 2)
    assert Springs(pairs, np.array([1.0, -0.5]), rest, 2, signed=True).k[1] == -0.5
    with pytest.raises(ValueError, match="non-finite"):
        Springs(pairs, np.array([1.0, np.nan]), rest, 2, signed=True)


def test_a_stable_lattice_with_a_negative_spring_is_built_and_the_check_agrees_with_its_spectrum():
    """The right-triangle grid jittered by 0.2 x the leg: two triangles have a negative constant and
    one boundary spring sums to a negative constant; the lattice is still positive definite apart
    from its three rigid-body modes (dense eigenvalues), so it is built."""
    mesh = _grid_with_negative_boundary_spring()
    with pytest.warns(FormulaValidityWarning, match="lsq_triangle: 2 of 150 per-element spring constants are negative"):
        springs = lsq_triangle_springs(mesh, [(1.0, 1 / 3)], T)[0]
    assert np.count_nonzero(springs.k < 0) == 1
    w = _spectrum(springs, mesh)
    assert np.all(np.abs(w[:3]) < 1e-12) and w[3] > 1e-4


@pytest.mark.parametrize("apex", [110.0, 130.0, 160.0])
def test_an_unstable_fit_is_refused_in_one_line(apex):
    """One isosceles triangle with an obtuse apex: the base spring is negative, and a lone triangle
    with one negative spring is indefinite (one negative eigenvalue, dense check)."""
    mesh = _obtuse_triangle(apex)
    with pytest.warns(FormulaValidityWarning, match="1 of 3"):
        with pytest.raises(ValueError, match=r"lsq_triangle: the fitted lattice is not stable at rest") as err:
            lsq_triangle_springs(mesh, [(1.0, 0.3)], T)
    assert "\n" not in str(err.value)
    # the dense spectrum of the same springs says the same
    signed = Springs(np.array([[0, 1], [1, 2], [0, 2]]), np.array([-1.0, 1.0, 1.0]),
                     np.linalg.norm(mesh.points[[1, 2, 2]] - mesh.points[[0, 1, 0]], axis=1), 2, signed=True)
    assert _spectrum(signed, mesh)[0] < -1e-6


@pytest.mark.parametrize("band_limit", [2e8, 0.0], ids=["banded Cholesky", "sparse LDLT"])
def test_the_check_agrees_with_the_dense_spectrum_on_random_signed_lattices(band_limit, monkeypatch):
    """Random constants of either sign on a jittered tetrahedral grid: the check raises exactly
    when the dense stiffness has an eigenvalue below zero beyond the six rigid-body modes (by
    either factorisation)."""
    from msslib.models import lsq

    monkeypatch.setattr(lsq, "BAND_LIMIT", band_limit)
    mesh = jittered(M.tet_grid(1.0, 1.0, 1.0, 2, 2, 2), 0.05, seed=3)
    pairs = M.unique_edges(mesh).pairs
    rest = np.linalg.norm(mesh.points[pairs[:, 1]] - mesh.points[pairs[:, 0]], axis=1)
    rng = np.random.default_rng(7)
    verdicts = []
    for trial in range(24):
        k = rng.uniform(0.2, 1.0, len(pairs))
        flip = rng.choice(len(pairs), size=trial % 3 + 1, replace=False)
        k[flip] *= -rng.uniform(0.01, 0.5, len(flip))
        springs = Springs(pairs, k, rest, 3, signed=True)
        w = _spectrum(springs, mesh)
        stable = w[6] > 1e-9 and w[0] > -1e-9
        try:
            check_stable_at_rest(springs, points=mesh.points, label="test")
            verdicts.append((stable, True))
        except ValueError:
            verdicts.append((stable, False))
    assert all(a == b for a, b in verdicts)
    assert {v for v, _ in verdicts} == {True, False}  # both outcomes occur


@pytest.mark.parametrize("band_limit", [np.inf, 0.0], ids=["banded Cholesky", "sparse LDLT"])
def test_both_factorisations_tell_positive_definite_matrices_from_the_others(band_limit):
    """Random sparse symmetric matrices shifted to a chosen smallest eigenvalue: both paths (the
    banded Cholesky and, for large bandwidths, SuperLU's symmetric LDL^T) say positive definite
    exactly when the dense smallest eigenvalue is positive, and name the first bad pivot."""
    import scipy.sparse as sps

    rng = np.random.default_rng(11)
    for trial in range(20):
        n = 40 + trial
        B = sps.random(n, n, density=0.08, random_state=trial, format="csr")
        A = (B + B.T + sps.diags(rng.uniform(0.5, 1.0, n))).tocsr()
        lam = np.linalg.eigvalsh(A.toarray())[0]
        shift = -lam + (1.0 if trial % 2 else -0.05) * abs(lam)  # smallest eigenvalue +|lam| or -0.05|lam|
        A = (A + shift * sps.identity(n, format="csr")).tocsr()
        smallest = np.linalg.eigvalsh(A.toarray())[0]
        info = _not_positive_definite(A, "test", band_limit=band_limit)
        assert (info == 0) == (smallest > 0), (trial, smallest, info)
        assert 0 <= info <= n


def test_negative_springs_are_exported_as_they_are_and_mujoco_rests_at_msslibs_equilibrium(tmp_path):
    """Lloyd's gmsh cylinder with least-squares springs (some summed constants negative, lattice
    stable): the JSON and the MuJoCo model carry the negative constants; MuJoCo's forces vanish at
    msslib's static equilibrium (to 1e-9 of the applied forces)."""
    import json

    import yaml

    mujoco = pytest.importorskip("mujoco")
    from msslib import cli
    from msslib import export
    from msslib.solvers import static_solve

    scene = {"name": "lsq_cylinder",
             "geometry": {"generator": "cylinder_mesh", "args": {"radius": 0.01, "height": 0.02, "h": 0.008, "seed": 0}},
             "materials": [{"E": 14630.0, "nu": 0.25, "density": 1000.0}],
             "model": "lsq_tetrahedron",
             "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
             "loads": [{"type": "traction", "select": {"plane": ["z", 0.02]}, "traction": [0.0, 0.0, 200.0]}]}
    path = tmp_path / "lsq.yaml"
    path.write_text(yaml.safe_dump(scene))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FormulaValidityWarning)
        assert cli.main(["export", str(path), "--out", str(tmp_path / "m"), "--format", "json,mjcf"]) == 0
        exp = export.build(path)
    (springs,) = [t for t in exp.model.terms if isinstance(t, Springs)]
    assert np.count_nonzero(springs.k < 0) > 0
    doc = json.loads((tmp_path / "m.json").read_text())
    (k_json,) = [c["values"] for c in doc["tables"]["springs"]["columns"] if c["name"] == "stiffness"]
    np.testing.assert_array_equal(k_json, springs.k)
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "m_mujoco.xml"))
    np.testing.assert_array_equal(m.tendon_stiffness, springs.k)
    res = static_solve(exp.model, exp.model.x0, load_steps=2, tol=1e-12)
    x_star = res.x.reshape(-1, 3)
    start = exp.points + exp.prescribed
    d = mujoco.MjData(m)
    for j in range(m.njnt):
        node, axis = m.joint(j).name[4:].split("_")
        d.qpos[m.jnt_qposadr[j]] = x_star[int(node), "xyz".index(axis)] - start[int(node), "xyz".index(axis)]
    mujoco.mj_forward(m, d)
    residual = d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias
    scale = np.abs(exp.model.external_force(1.0)).sum()
    assert np.abs(x_star - exp.points).max() > 1e-6 and scale > 0
    assert np.abs(residual).max() <= 1e-9 * scale, (np.abs(residual).max(), scale)

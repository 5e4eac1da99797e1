"""Every finite-strain FEM solve checks its equilibria for inverted elements (det F <= 0 at a
quadrature point) after each converged load increment, for every law and cell type.

St Venant-Kirchhoff's energy depends on ``C = F^T F`` only, so a mirror image of a state has its
energy: a block of height 1 (Poisson's ratio 0, so that uniaxial compression is homogeneous) under
a dead compressive traction ``t`` has the nominal stress ``P = E lambda (lambda^2 - 1) / 2`` in its
stretch ``lambda``, which is at least ``-E / (3 sqrt 3) = -0.19 E`` for ``lambda > 0``; above that
load the only equilibria are inverted (``t = 0.4 E``: ``lambda = -1.2756``, ``u_y = -2.2756``).
"""

from __future__ import annotations

import numpy as np
import pytest

from msslib import mesh as M
from msslib.errors import UnphysicalStateError
from msslib.fem import solve_nonlinear
from msslib.fem import solve as fem_solve
from msslib.fem.space import _Geometry

E = 1.0

MESHES = {
    "triangle": lambda: M.triangle_grid_right(1.0, 1.0, 2, 2),
    "quad": lambda: M.quad_grid(1.0, 1.0, 2, 2),
    "tetra": lambda: M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1),
    "hexahedron": lambda: M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1),
    "wedge": lambda: M.wedge_grid(1.0, 1.0, 1.0, 1, 1, 1),
}


def _block(cell_type):
    """A unit block, its bottom (y = 0) held, and its top facets."""
    mesh = MESHES[cell_type]()
    d = mesh.dim
    y = mesh.points[:, 1]
    fixed = np.zeros((mesh.n_nodes, d), dtype=bool)
    fixed[np.isclose(y, 0.0)] = True
    if cell_type == "wedge":
        return mesh, fixed, None
    bf = M.boundary_facets(mesh)
    return mesh, fixed, bf[np.isclose(y[bf], 1.0).all(axis=1)]


def _compress(cell_type, t, order=1, law="svk", **kw):
    mesh, fixed, top = _block(cell_type)
    traction = np.zeros(mesh.dim)
    traction[1] = -t
    extra = {"plane": "strain"} if mesh.dim == 2 else {}
    if cell_type == "wedge":  # facets of two types: the top quad's consistent nodal forces, a quarter each
        forces = np.zeros((mesh.n_nodes, 3))
        forces[np.isclose(mesh.points[:, 1], 1.0)] = traction / 4
        extra["nodal_forces"] = forces
    else:
        extra["tractions"] = [(top, traction)]
    return mesh, solve_nonlinear(mesh, E, 0.0, fixed=fixed, law=law, order=order, **extra, **kw)


def _stretch(t):
    """The SVK uniaxial stretch in (1/sqrt 3, 1] under the compressive nominal stress ``t``."""
    roots = np.roots([0.5 * E, 0.0, -0.5 * E, t])
    return float(max(r.real for r in roots if abs(r.imag) < 1e-12 and 3**-0.5 < r.real <= 1.0))


CASES = [("triangle", 1), ("quad", 1), ("triangle", 2), ("quad", 2), ("tetra", 1), ("hexahedron", 1), ("wedge", 1),
         ("tetra", 2), ("hexahedron", 2)]


@pytest.mark.parametrize("cell_type,order", CASES)
def test_svk_under_strong_compression_is_refused_naming_load_element_and_det_f(cell_type, order):
    """Before the check the solve returned the inverted equilibrium (u_y = -2.2756 on the quads)."""
    with pytest.raises(UnphysicalStateError) as info:
        _compress(cell_type, 0.4, order)
    exc = info.value
    text = str(exc)
    assert "\n" not in text
    assert exc.det_F <= 0.0 and 0.0 <= exc.load_reached < exc.load <= 1.0
    # the last admissible load is below the limit load 0.19 E / 0.4 E, the inverted one above it
    assert exc.load_reached * 0.4 < 1 / (3 * np.sqrt(3)) < exc.load * 0.4
    assert (f"equilibrium found at load factor {exc.load:.6g} inverts element {exc.cell} (det F = {exc.det_F:.4g} "
            in text)
    assert "det F > 0 is required at every quadrature point" in text
    assert text.endswith(f"load factor reached with every det F > 0: {exc.load_reached:.6g}")


@pytest.mark.parametrize("cell_type,order", CASES)
def test_moderate_compression_is_not_refused_and_is_the_exact_uniaxial_state(cell_type, order):
    t = 0.1
    mesh, r = _compress(cell_type, t, order)
    top = np.isclose(mesh.points[:, 1], 1.0)
    assert np.allclose(r.displacement[top, 1], _stretch(t) - 1.0, rtol=1e-9, atol=0)  # -0.121115
    assert np.abs(r.displacement[:, [i for i in range(mesh.dim) if i != 1]]).max() < 1e-9


def test_the_check_sees_each_increments_solution(monkeypatch):
    """The state checked after the last increment is the solution returned, at load factor 1."""
    seen = []
    real = fem_solve._check_inversion

    def spy(parts, u_dofs, load, reached, law):
        seen.append((u_dofs.copy(), load, reached))
        return real(parts, u_dofs, load, reached, law)

    monkeypatch.setattr(fem_solve, "_check_inversion", spy)
    _, r = _compress("quad", 0.1, 2, steps=4)
    assert [s[1] for s in seen] == r.stats["load_factors"]
    assert [s[2] for s in seen] == [0.0] + r.stats["load_factors"][:-1]
    assert np.array_equal(seen[-1][0], r.dof_displacement)


@pytest.mark.parametrize("law", ["svk", "neohookean"])
def test_every_law_is_checked(monkeypatch, law):
    """The check runs for neo-Hookean too (whose law refuses det F <= 0 inside Newton as well): a
    solution made to look inverted is refused."""
    monkeypatch.setattr(fem_solve, "_min_jacobian", lambda geometries, u: (-0.5, 3, 1))
    with pytest.raises(UnphysicalStateError, match=r"at load factor 0\.1 inverts element 3 \(det F = -0\.5 at a "
                                                   r"quadrature point; 1 element\(s\) with det F <= 0\)"):
        _compress("quad", 0.01, law=law)


@pytest.mark.parametrize("cell_type,order", CASES)
def test_min_jacobian_of_a_mirror_image_and_of_a_stretch(cell_type, order):
    """u = (-2 x, 0, ...) mirrors the body: det F = -1 at every quadrature point of every cell;
    u = (x, 0, ...) doubles it: det F = 2."""
    mesh = MESHES[cell_type]()
    geo = _Geometry(mesh, order)
    u = np.zeros_like(geo.points)
    u[:, 0] = -2.0 * geo.points[:, 0]
    J, cell, n_bad = fem_solve._min_jacobian([geo], u)
    assert J == pytest.approx(-1.0, abs=1e-12) and n_bad == len(mesh.cells) and 0 <= cell < len(mesh.cells)
    u[:, 0] = geo.points[:, 0]
    J, _, n_bad = fem_solve._min_jacobian([geo], u)
    assert J == pytest.approx(2.0, abs=1e-12) and n_bad == 0

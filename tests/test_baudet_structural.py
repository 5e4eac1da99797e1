"""Pieces of the Baudet studies ``bending_column`` (the pure-bending column at equal resolution) and
``structural`` (the cantilever's neutral axis against eq. 10): the consistent end forces carry the
exact moment, trilinear FEM on the column converges to the exact curvature, and the axis measure
is zero on eq. 10's own profile and the relative offset of a scaled one."""

import numpy as np
import pytest
import xarray as xr

from experiments.baudet.studies import bending_column as B
from experiments.baudet.studies import structural as S


@pytest.mark.parametrize("n", [1, 2, 4, 8])
def test_consistent_end_forces_carry_the_moment(n):
    z, w0, w1 = B.hat_moments(n)
    assert w0.sum() == pytest.approx(B.H, rel=1e-13)  # the nodal weights of a constant
    # sum_j z_j * (integral of z N_j) = integral of z^2 (z interpolated exactly by the hats) = H^3 / 12
    assert (w1 * z).sum() == pytest.approx(B.H ** 3 / 12, rel=1e-13)
    assert w1.sum() == pytest.approx(0.0, abs=1e-15)  # no net axial force
    inertia = B.H ** 4 / 12
    moment = sum(B.M / inertia * wy * wz * zj for wy in w0 for wz, zj in zip(w1, z))
    assert moment == pytest.approx(B.M, rel=1e-12)


def test_q1_column_converges_to_the_exact_pure_bending_curvature():
    """The supports leave the anticlastic contraction free and the end forces are consistent, so
    trilinear FEM approaches Saint-Venant's curvature M / (E I) as the square of the element size
    (a support or a load that did not match the exact solution would leave a floor)."""
    kappa = B.M / (B.E * B.H ** 4 / 12)
    s = [1 - B.curvature(B.run("fem_linear", n)) / kappa for n in (2, 4)]
    assert 0 < s[1] < s[0] < 0.2
    assert s[0] / s[1] > 3.3


def _beam(w_of_x):
    """A cantilever-shaped result (4 x 1 x 1 cubes over the experiment's box) whose every node
    moves down by ``w_of_x(x)``."""
    import yaml

    geo = yaml.safe_load(S.experiment_path("cantilever").read_text())["scene"]["geometry"]["args"]
    L, T, H = float(geo["lx"]), float(geo["ly"]), float(geo["lz"])
    X = np.array([(x, y, z) for z in (0.0, H) for y in (0.0, T) for x in np.linspace(0.0, L, 5)])
    u = np.zeros_like(X)
    u[:, 2] = -w_of_x(X[:, 0])
    return xr.Dataset({"rest_position": (("node", "axis"), X), "displacement": (("node", "axis"), u)}), L


def _eq10(L):
    import yaml

    raw = yaml.safe_load(S.experiment_path("cantilever").read_text())
    geo, mat = raw["scene"]["geometry"]["args"], raw["scene"]["materials"][0]
    T, H, E = float(geo["ly"]), float(geo["lz"]), float(mat["E"])
    q = float(mat["density"]) * T * H * -float(raw["scene"]["loads"][0]["g"][2])
    return lambda x: q / (24 * E * T * H ** 3 / 12) * (6 * L ** 2 * x ** 2 - 4 * L * x ** 3 + x ** 4)


def test_eq10_axis_is_zero_on_eq10_and_relative_when_scaled():
    _, L = _beam(lambda x: 0 * x)
    w = _eq10(L)
    exact, _ = _beam(w)
    tip, largest = S.eq10_axis(exact)
    assert tip == pytest.approx(0.0, abs=1e-12) and largest == pytest.approx(0.0, abs=1e-12)
    stiff, _ = _beam(lambda x: 0.9 * w(x))
    tip, largest = S.eq10_axis(stiff)
    assert tip == pytest.approx(-0.1, rel=1e-12)  # 10 % too small at the tip, signed
    assert largest == pytest.approx(0.1, rel=1e-12)  # the tip holds the largest deflection


def test_loaded_edge_nodes_of_the_l_block():
    """At n = 8 (cubes of 0.5 m) the six loaded edges hold 2 x (9 + 5 + 5) nodes, and every node the
    line load of make_l_block acts on is among them."""
    from experiments.baudet import make_l_block as LB
    from msslib.scene import load_scene
    from msslib.scene.prepare import prepare

    sc, base = S.scene("l_block", "fem_linear", 8)
    setup = prepare(load_scene(sc, base_dir=base))
    X = setup.mesh.points
    on = S.loaded_edge_nodes(X)
    assert on.sum() == 2 * (9 + 5 + 5)
    loaded = np.zeros(len(X), bool)
    for load in LB.loads(8):
        lo, hi = (np.array(p) for p in load["select"]["box"])
        loaded |= np.all((X >= lo - 1e-9) & (X <= hi + 1e-9), axis=1)
    assert loaded.sum() == 2 * (8 + 5 + 4)  # the base nodes of the two edges reaching z = 0 carry no force
    assert np.all(on[loaded])

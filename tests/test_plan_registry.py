"""Tests of the process-wide memo of sparsity plans (msslib.solvers.memo): models of one pattern
share their free-dof plans and band ordering, other patterns, free masks, geometries or settings
do not, the solutions are those computed without the memo, and the memo keeps its bounds."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import csgraph

from msslib.models.golec import golec_cube_springs
from msslib import mesh as M
from msslib import solvers as S
from msslib.system import Model
from msslib.solvers import direct, memo, submatrices as plans
from msslib.solvers.context import ATTRIBUTE
from msslib.terms import Gravity


def gravity_block(nx=4, ny=3, nz=3, *, clamp="x0", scale=1.0):
    """A Golec cube lattice of nx x ny x nz cells of 1 cm (times ``scale``) under gravity, clamped
    at x = 0 (``clamp="x0"``) or at z = 0 (``"z0"``)."""
    h = 0.01 * scale
    mesh = M.hex_grid(h * nx, h * ny, h * nz, nx, ny, nz)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    axis = {"x0": 0, "z0": 2}[clamp]
    fixed[mesh.points[:, axis] < 1e-12] = True
    terms = golec_cube_springs(mesh, [(1e4, 0.3)], 1.0) + [Gravity(masses, [0.0, 0.0, -9.81])]
    return Model(mesh, terms, fixed=fixed, masses=masses)


@pytest.fixture
def fresh_memo(monkeypatch):
    """An empty memo for the test (the plans of other tests stay out); returns the list of the
    reverse Cuthill-McKee orderings computed (one item each)."""
    monkeypatch.setattr(plans, "PLANS", memo.PatternMemo())
    calls = []
    rcm = csgraph.reverse_cuthill_mckee

    def counting_rcm(*args, **kw):
        calls.append(1)
        return rcm(*args, **kw)

    monkeypatch.setattr(csgraph, "reverse_cuthill_mckee", counting_rcm)
    return calls


def solve(model):
    r = S.static_solve(model, model.x0, linear_solver="direct")
    return r, getattr(model, ATTRIBUTE)


def band(ctx):
    (entry,) = ctx.plans.bands
    return entry["plan"]


def free_plan(ctx):
    (entry,) = [e for e in ctx.plans.entries if e.get("kind") is None]
    return entry


def test_two_models_of_one_pattern_share_the_ordering(fresh_memo):
    rcm_calls = fresh_memo
    r1, c1 = solve(gravity_block())
    assert len(rcm_calls) == 1 and band(c1) is not None
    r2, c2 = solve(gravity_block())  # a new model, built anew: same pattern, mask and geometry
    assert len(rcm_calls) == 1  # no ordering computed for it
    assert band(c2)["perm"] is band(c1)["perm"] and band(c2)["bw"] == band(c1)["bw"]
    assert free_plan(c2)["sub_indices"] is free_plan(c1)["sub_indices"]
    assert c2.plans is not c1.plans and c2.plans.bands is not c1.plans.bands  # each context owns its plans
    np.testing.assert_array_equal(r2.x, r1.x)


@pytest.mark.parametrize("other", [{"nx": 5}, {"clamp": "z0"}, {"scale": 2.0}],
                         ids=["other pattern", "other free mask", "other geometry"])
def test_other_pattern_mask_or_geometry_gets_its_own_ordering(fresh_memo, other, monkeypatch):
    rcm_calls = fresh_memo
    _, c1 = solve(gravity_block())
    model = gravity_block(**other)
    _, c2 = solve(model)
    assert len(rcm_calls) == 2  # computed for the second model too
    assert band(c2)["perm"] is not band(c1)["perm"]
    # the free-dof plan depends on the pattern and the mask only
    shared = free_plan(c2)["sub_indices"] is free_plan(c1)["sub_indices"]
    assert shared == ("scale" in other)
    # the ordering found is the one computed for that model alone (a context without plans and
    # a memo that keeps nothing)
    monkeypatch.setattr(plans, "PLANS", memo.PatternMemo(size=0))
    alone = direct._band_plan(c2["K"], dict(c2))
    np.testing.assert_array_equal(band(c2)["perm"], alone["perm"])


def test_band_cost_limit_is_part_of_the_key(fresh_memo, monkeypatch):
    _, c1 = solve(gravity_block())
    assert band(c1) is not None
    limit = direct.BAND_COST_MAX
    monkeypatch.setattr(direct, "BAND_COST_MAX", 0.0)  # no banded factorisation at all
    _, c2 = solve(gravity_block())
    assert band(c2) is None
    monkeypatch.setattr(direct, "BAND_COST_MAX", limit)
    _, c3 = solve(gravity_block())
    assert band(c3) is not None and band(c3)["perm"] is band(c1)["perm"]


def test_solution_with_the_memo_equals_the_one_without(monkeypatch):
    models = [gravity_block(), gravity_block(), gravity_block(clamp="z0")]
    monkeypatch.setattr(plans, "PLANS", memo.PatternMemo(size=0))  # keeps nothing
    without = [solve(m)[0].x for m in models]
    monkeypatch.setattr(plans, "PLANS", memo.PatternMemo())
    with_memo = [solve(m)[0].x for m in [gravity_block(), gravity_block(), gravity_block(clamp="z0")]]
    for a, b in zip(with_memo, without):
        np.testing.assert_array_equal(a, b)  # the same plans: the same arithmetic


def test_memo_stays_within_its_bounds():
    m = memo.PatternMemo(size=3, max_bytes=10_000)
    keys = [np.arange(k, k + 100, dtype=np.int64) for k in range(10)]  # 800 bytes each
    for k in keys:
        m.put("t", (k,), {"plan": np.zeros(50)})  # 400 bytes of plan: 1200 per entry
        assert len(m) <= 3 and m.nbytes <= 10_000
    assert len(m) == 3 and m.nbytes == 3 * 1200
    assert m.get("t", (keys[0],)) is memo.MISSING  # the oldest went first
    assert m.get("t", (keys[-1],)) is not memo.MISSING
    m.get("t", (keys[-3],))  # used: now the most recent
    m.put("t", (np.arange(-5, 95),), {"plan": np.zeros(50)})
    assert m.get("t", (keys[-3],)) is not memo.MISSING and m.get("t", (keys[-2],)) is memo.MISSING
    small = memo.PatternMemo(size=100, max_bytes=3500)  # the byte bound binds: two entries
    for k in keys:
        small.put("t", (k,), {"plan": np.zeros(50)})
    assert len(small) == 2 and small.nbytes == 2400
    small.put("t", (np.arange(1000),), None)  # larger than a quarter of the budget: not kept
    assert len(small) == 2 and small.get("t", (np.arange(1000),)) is memo.MISSING


def test_memo_compares_arrays_on_a_hit(monkeypatch):
    monkeypatch.setattr(memo, "_fingerprint", lambda a: 0)  # every pattern collides
    m = memo.PatternMemo()
    a, b = np.arange(10), np.arange(10)[::-1].copy()
    assert m.get_or_compute("t", (a,), lambda: "plan of a") == "plan of a"
    assert m.get_or_compute("t", (b,), lambda: "plan of b") == "plan of b"
    assert m.get("t", (b,)) == "plan of b" and m.get("t", (a,)) is memo.MISSING  # one entry per key
    assert m.get("u", (b,)) is memo.MISSING and m.get("t", (b,), settings=(1,)) is memo.MISSING
    # the key arrays are copies: changing the caller's array does not change the entry
    c = np.arange(10)
    m.put("t", (c,), "plan of 0..9")
    c[0] = 99
    assert m.get("t", (c,)) is memo.MISSING and m.get("t", (np.arange(10),)) == "plan of 0..9"

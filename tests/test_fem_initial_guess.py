"""The finite-strain FEM starts Newton from a guess of the solution (the reference of plan: the
coarser level's solution at the finer level's nodes): the same solution in fewer iterations;
a guess of the wrong shape, non-finite, or with load steps is refused naming ``initial``."""

import numpy as np
import pytest

from msslib import fem
from msslib import mesh as M
from msslib.mesh.refine import uniform


def _bar(mesh):
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    return dict(fixed=fixed, body_force=[0.0, 0.0, -3e4], law="neohookean", steps=1, order=2, tol=1e-10)


def test_a_coarse_solution_as_guess_gives_the_same_solution_in_fewer_iterations():
    coarse = M.tet_grid(0.1, 0.02, 0.02, 5, 1, 1)
    fine = uniform(coarse, 1)
    rc = fem.solve_nonlinear(coarse, 1e5, 0.3, **_bar(coarse))
    # the coarse quadratic dofs are the fine mesh's nodes
    idx = [int(np.argmin(np.linalg.norm(rc.dof_points - p, axis=1))) for p in fine.points]
    assert np.allclose(rc.dof_points[idx], fine.points, rtol=0, atol=1e-12)
    guess = rc.dof_displacement[idx]
    cold = fem.solve_nonlinear(fine, 1e5, 0.3, **_bar(fine))
    warm = fem.solve_nonlinear(fine, 1e5, 0.3, initial=guess, **_bar(fine))
    scale = np.abs(cold.dof_displacement).max()
    assert np.abs(warm.dof_displacement - cold.dof_displacement).max() <= 1e-7 * scale
    assert sum(warm.stats["iterations"]) < sum(cold.stats["iterations"])
    assert abs(cold.displacement[:, 2].min()) > 0.05 * 0.1  # a large deflection: Newton has work to do


@pytest.mark.parametrize("guess, steps, words", [
    (np.zeros((3, 3)), 1, "initial must be None or finite displacements of shape"),
    ("nan", 1, "with non-finite values"),
    ("zeros", 2, "initial is a guess of the solution: it needs steps=1, got steps=2"),
])
def test_a_bad_guess_is_refused(guess, steps, words):
    m = M.tet_grid(0.1, 0.02, 0.02, 2, 1, 1)
    g = np.zeros((m.n_nodes, 3))
    if isinstance(guess, str) and guess == "nan":
        g[0, 0] = np.nan
    elif not isinstance(guess, str):
        g = guess
    kw = _bar(m)
    kw["steps"] = steps
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        fem.solve_nonlinear(m, 1e5, 0.3, initial=g, **kw)

"""The wrinkle of Golec's beam without face diagonals against its deflection
(experiments/golec/studies/wrinkle_size.py): at twice the gravity of the experiment file the
symmetric equilibrium is unstable, the wrinkled state is an equilibrium of lower energy with a
stable tangent, and the beam released from rest comes to rest wrinkled as well, not on the
symmetric path. Every check is against the model's own equilibrium conditions, not stored numbers."""

import numpy as np
import pytest

from experiments.golec.studies.wrinkle_size import DAMPING, DT, setup_of
from experiments.golec.studies.wrinkles import min_eigen, relax
from msslib.stepping import Simulator
from msslib.solvers import static_solve


@pytest.fixture(scope="module")
def bent():
    st = setup_of(2.0, quick=False)
    model = st.model
    s = st.scene.solver
    x = static_solve(model, model.x0, load_steps=2 * s["load_steps"], tol=s["tol"], max_iter=s["max_iter"]).x
    return model, x


def test_gravity_factor_scales_the_load():
    f1 = setup_of(1.0, quick=True).model.force(setup_of(1.0, quick=True).model.x0, 1.0)
    m2 = setup_of(2.0, quick=True).model
    f2 = m2.force(m2.x0, 1.0)
    assert np.abs(f2).max() > 0
    np.testing.assert_allclose(f2, 2.0 * f1, rtol=1e-12, atol=1e-15)


def test_wrinkled_state_is_a_stable_equilibrium_far_from_the_symmetric_one(bent):
    model, x = bent
    lam, vec = min_eigen(model, x)
    assert lam < 0  # the symmetric bend is a saddle
    deflection = -(x - model.x0).reshape(-1, 3)[:, 2].min()
    xp = x.copy()
    xp[model.free] += 1e-4 * vec / np.abs(vec).max()
    xw, _ = relax(model, xp)
    f = model.force(xw, 1.0)[model.free]
    f_ref = np.abs(model.force(model.x0, 1.0)[model.free]).max()
    assert np.abs(f).max() < 1e-6 * f_ref  # an equilibrium
    assert model.energy(xw, 1.0) < model.energy(x, 1.0)
    assert min_eigen(model, xw)[0] > -1e-8 * abs(lam)  # a stable one
    wrinkle = np.linalg.norm((xw - x).reshape(-1, 3), axis=1).max()
    assert wrinkle > 0.05 * deflection


def test_released_beam_comes_to_rest_wrinkled(bent):
    model, x = bent
    sim = Simulator(model, dt=DT, method="velocity_verlet", damping=DAMPING)
    sim.step(round(3.0 / DT))
    xd = np.asarray(sim.x).reshape(-1)
    assert sim.kinetic_energy() < 1e-9
    f_ref = np.abs(model.force(model.x0, 1.0)[model.free]).max()
    assert np.abs(model.force(xd, 1.0)[model.free]).max() < 1e-3 * f_ref  # at rest in equilibrium
    deflection = -(x - model.x0).reshape(-1, 3)[:, 2].min()
    assert np.linalg.norm((xd - x).reshape(-1, 3), axis=1).max() > 0.05 * deflection
    assert model.energy(xd, 1.0) < model.energy(x, 1.0)

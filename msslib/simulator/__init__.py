"""Stepping a model in time with loads that change between steps: :class:`Simulator`.

The engines: :class:`msslib.solvers.dynamics.Integrator` (every model and scheme) and
:class:`msslib.simulator.network.NetworkStepper` (symplectic Euler on 3D spring networks with the
fused kernel of :mod:`msslib.explicit.network`); time functions in :mod:`msslib.simulator.loads`.
"""

from msslib.simulator.core import ENGINES, Simulator
from msslib.simulator.loads import Curve, time_function

__all__ = ["Simulator", "ENGINES", "Curve", "time_function"]

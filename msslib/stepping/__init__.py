"""Time stepping, in one place: the :class:`Simulator` face, the :class:`Stepper` protocol its
engines follow, and the engines side by side.

Face: :class:`Simulator` (:mod:`msslib.stepping.simulator`): steps, loads that change between
steps, tool paths, reactions, ``reset()``; time functions in :mod:`msslib.stepping.loads`.
:func:`integrate` runs a whole trajectory with the generic engine (what ``msslib run`` does for a
dynamic scene through the Simulator).

Engines (each a :class:`Stepper`, :mod:`msslib.stepping.protocol`):

- ``generic``: :class:`~msslib.stepping.generic.Integrator`, every model, every scheme
  (symplectic Euler, velocity Verlet, implicit Euler), :mod:`msslib.stepping.generic`;
- ``network``: :class:`~msslib.stepping.network.NetworkStepper`, symplectic Euler on 3D spring
  networks with the fused kernel of :mod:`msslib.stepping.network_kernels`;
- ``jax``: :class:`~msslib.stepping.accelerated.JaxStepper`, the explicit schemes on JAX
  (:mod:`msslib.stepping.jax_backend`, CPU or GPU);
- structured hexahedral lattices: :class:`~msslib.stepping.lattice.LatticeExplicit` (kernels in
  :mod:`msslib.stepping.lattice_kernels`, a JAX twin in :mod:`msslib.stepping.jax_backend`).

Layering: the package builds on :mod:`msslib.solvers` (stability limit, linear solves of
implicit Euler), :mod:`msslib.terms` and :mod:`msslib.mesh`; nothing in it imports the scene,
planning or command-line layers (a test checks it).
"""

from msslib.stepping.generic import Integrator, integrate
from msslib.stepping.lattice import LatticeExplicit
from msslib.stepping.loads import Curve, time_function
from msslib.stepping.protocol import Stepper
from msslib.stepping.simulator import ENGINES, Simulator

__all__ = ["Simulator", "ENGINES", "Stepper", "Integrator", "integrate", "LatticeExplicit", "Curve", "time_function"]

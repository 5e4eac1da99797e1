"""A JAX backend of the explicit steps: general 3D spring networks (:class:`JaxNetwork`, the
scheme of :mod:`msslib.stepping.network_kernels`) and structured lattices (:class:`JaxLattice`, that of
:class:`msslib.stepping.LatticeExplicit`), on the first GPU JAX sees, else on its CPU, where the
same code is tested against the numba kernels.

``available()`` says whether JAX runs here and on what; :func:`network_engine` and
:func:`lattice_engine` take ``backend="jax"`` and fall back to the numba CPU path with a
:class:`msslib.errors.MsslibWarning` naming the reason when JAX is missing.  Importing this
package does not import JAX; JAX is imported when a backend object is built.
"""

from .device import available, default_device, has_gpu, use_jax
from .lattice import JaxLattice, lattice_engine
from .network import CpuNetwork, JaxNetwork, network_arrays, network_engine

__all__ = ["available", "default_device", "has_gpu", "use_jax", "JaxNetwork", "CpuNetwork", "JaxLattice",
           "network_engine", "lattice_engine", "network_arrays"]

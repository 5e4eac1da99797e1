"""Explicit dynamics kernels: :class:`LatticeExplicit`, structured hexahedral lattices
(:mod:`msslib.explicit.lattice`, its numba kernels in :mod:`msslib.explicit.kernels`), and the
fused step of general 3D spring networks (:mod:`msslib.explicit.network`, which the stepping API
:class:`msslib.simulator.Simulator` runs)."""

from msslib.explicit.lattice import LatticeExplicit

__all__ = ["LatticeExplicit"]

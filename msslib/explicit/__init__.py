"""Explicit dynamics of structured hexahedral lattices: :class:`LatticeExplicit` (the integrator,
:mod:`msslib.explicit.lattice`) and its numba kernels (:mod:`msslib.explicit.kernels`)."""

from msslib.explicit.lattice import LatticeExplicit

__all__ = ["LatticeExplicit"]

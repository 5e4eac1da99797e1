"""Energy-term kernels for the simulator, one module per family of terms, found by
:mod:`derivations.registry` (each declares ``derive()``; code is generated as for the elements)."""

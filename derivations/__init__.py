"""Symbolic derivations of mass-spring parameters (SymPy).

The engine (:mod:`.elasticity`, :mod:`.fem`, :mod:`.mss`, :mod:`.match`, :mod:`.lattice`) is used by one
notebook-as-module per element family in ``derivations/elements/`` and by the energy-term kernels in
``derivations/terms/``; :mod:`.registry` finds them and :mod:`.codegen` turns their results into
``msslib/generated``. ``derivations/analyses/`` holds analyses that generate no code.
"""

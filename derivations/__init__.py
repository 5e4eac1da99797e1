"""Symbolic derivations of mass-spring parameters (SymPy).

The engine (:mod:`.elasticity`, :mod:`.fem`, :mod:`.mss`, :mod:`.match`, :mod:`.lattice`) is used by one
notebook-as-module per element family (``triangle``, ``square``, ``tetrahedron``, ``cube_baudet``,
``cube_golec``, ``rectangle``). :mod:`.codegen` turns their results into ``msslib/generated``.
"""

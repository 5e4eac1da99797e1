"""msslib: mass-spring systems whose spring constants are derived from FEM, and their FEM references.

The spring-constant formulas live in :mod:`msslib.parameters`; they call code generated from the
symbolic derivations in ``derivations/`` (see :mod:`msslib.generated`).
"""

__version__ = "0.1.0"

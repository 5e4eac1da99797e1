"""Analyses that use the engine but generate no code (e.g. counting a paper's equations)."""

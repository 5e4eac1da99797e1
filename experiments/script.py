"""The command line and the table output shared by the figure and table scripts of
experiments/<paper>/{figures,tables}/ (run as ``python -m experiments.<paper>.<kind>.<name> --out ...``),
and the load-continuation step shared by studies."""

import argparse
from pathlib import Path

import numpy as np

from msslib.results import write_text


def args(doc, argv=None):
    """The script's arguments: ``--out``, the output stem of a figure (STEM.png and STEM.pdf) or the
    Markdown file of a table; ``doc`` is the script's docstring (its first line describes it)."""
    ap = argparse.ArgumentParser(description=doc.strip().splitlines()[0] if doc else None)
    ap.add_argument("--out", required=True, help="figure: output stem (writes STEM.png and STEM.pdf); table: FILE.md")
    return ap.parse_args(argv)


def number(v, spec, scale=1, missing="-"):
    """A table cell: ``scale * v`` formatted by ``spec`` (e.g. ``".3g"``), or ``missing`` where ``v``
    is not finite."""
    v = float(v)
    return format(scale * v, spec) if np.isfinite(v) else missing


def row(*cells):
    """One row of a Markdown table, its ``cells`` formatted as in an f-string."""
    return "| " + " | ".join(format(c) for c in cells) + " |"


def head(caption, columns):
    """The first lines of a Markdown table: ``caption``, a blank line, the header row of ``columns`` and
    the separator row."""
    return [caption, "", row(*columns), "|" + "---|" * len(columns)]


def write_table(out, lines):
    """Write the Markdown ``lines`` to ``out`` (atomically, creating its folder)."""
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    write_text(out, "\n".join(lines) + "\n")


class LoadSegment:
    """One step of a load continuation: ``model`` (the problem protocol of :func:`msslib.solvers.static_solve`)
    with the solver's load factor 0..1 mapped onto the model's load factors ``a``..``b``, so that each
    equilibrium starts from the previous one. ``energy=False`` hides the model's energy: the solver's
    line search then judges the residual."""

    def __init__(self, model, a, b, energy=True):
        self.model, self.a, self.b, self.with_energy = model, float(a), float(b), energy
        self.n_dof, self.free, self.dim = model.n_dof, model.free, model.dim
        self.symmetric, self.mass = model.symmetric, model.mass

    def load(self, load):
        """The model's load factor at the solver's ``load``."""
        return self.a + load * (self.b - self.a)

    def force(self, x, load=1.0):
        return self.model.force(x, self.load(load))

    def stiffness(self, x, load=1.0):
        return self.model.stiffness(x, self.load(load))

    def energy(self, x, load=1.0):
        return self.model.energy(x, self.load(load)) if self.with_energy else None

    def apply_prescribed(self, x, load=1.0):
        return self.model.apply_prescribed(x, self.load(load))


def rows(ds, dim):
    """The entries of ``ds`` along ``dim``, one dataset each, in order (a table's rows)."""
    return (ds.isel({dim: i}) for i in range(ds.sizes[dim]))

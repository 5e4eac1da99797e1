"""The command line shared by every study, figure and table of experiments/<paper>/{studies,figures,tables}/
(``python -m experiments.<paper>.<kind>.<name> --out PATH [--quick]``), the inputs a figure or table
script declares (``inputs.yaml`` beside it), the table output, and the load-continuation step shared by
studies."""

import argparse
from pathlib import Path

import numpy as np

from msslib.results import write_text


def parse(doc, argv=None, *, extra=None):
    """The one command line of every study, figure and table of experiments/: ``--out`` (a study's
    NetCDF file, a figure's output stem: STEM.png and STEM.pdf, a table's Markdown file) and
    ``--quick`` (the reduced version of the CI build; figures and tables accept it and draw what they
    find). ``doc`` is the script's docstring (its first line describes it); ``extra(parser)`` may add
    arguments of its own. Returns the parser (for ``parser.error``) and the arguments."""
    ap = argparse.ArgumentParser(description=doc.strip().splitlines()[0] if doc else None)
    if extra is not None:
        extra(ap)
    ap.add_argument("--out", required=True,
                    help="study: FILE.nc; figure: output stem (writes STEM.png and STEM.pdf); table: FILE.md")
    ap.add_argument("--quick", action="store_true", help="reduced version (CI); figures and tables draw what they find")
    return ap, ap.parse_args(argv)


def args(doc, argv=None):
    """The arguments of :func:`parse` (``--out``, ``--quick``)."""
    return parse(doc, argv)[1]


def inputs(path):
    """The result files the figure or table script at ``path`` (its ``__file__``) reads, as declared in
    ``inputs.yaml`` beside it (``name: [file, ...]``; the workflow reads the same file, without running
    the script)."""
    import yaml

    path = Path(path)
    listing = path.with_name("inputs.yaml")
    declared = yaml.safe_load(listing.read_text(encoding="utf-8")) or {}
    if path.stem not in declared:
        raise KeyError(f"{listing}: {path.stem} is not declared (list the results {path.name} reads)")
    return list(declared[path.stem])


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

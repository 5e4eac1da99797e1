"""The command line and the table output shared by the figure and table scripts of
experiments/<paper>/{figures,tables}/ (run as ``python -m experiments.<paper>.<kind>.<name> --out ...``)."""

import argparse
from pathlib import Path

from msslib.io import write_text


def args(doc, argv=None):
    """The script's arguments: ``--out``, the output stem of a figure (STEM.png and STEM.pdf) or the
    Markdown file of a table; ``doc`` is the script's docstring (its first line describes it)."""
    ap = argparse.ArgumentParser(description=doc.strip().splitlines()[0] if doc else None)
    ap.add_argument("--out", required=True, help="figure: output stem (writes STEM.png and STEM.pdf); table: FILE.md")
    return ap.parse_args(argv)


def write_table(out, lines):
    """Write the Markdown ``lines`` to ``out`` (atomically, creating its folder)."""
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    write_text(out, "\n".join(lines) + "\n")


def rows(ds, dim):
    """The entries of ``ds`` along ``dim``, one dataset each, in order (a table's rows)."""
    return (ds.isel({dim: i}) for i in range(ds.sizes[dim]))

"""Run a derivation module (a jupytext percent-format notebook) cell by cell into Markdown.

    python -m derivations.notebook triangle --out triangle.md
    python -m experiments.paper notebook triangle --out paper/build/derivations/triangle.html

A module is named as :func:`derivations.registry.resolve` accepts it: ``triangle``,
``elements/triangle`` or ``derivations/elements/triangle.py``, wherever it lives.
The module's cells run in order in one namespace, as ``__main__`` (as in Jupyter). A markdown cell
(``# %% [markdown]``) becomes Markdown text; a code cell becomes a code block followed by what it
showed: the math of :mod:`derivations.show` as ``$$...$$`` and its printed output as a text block.
The paper stage (``python -m experiments.paper notebook``) turns the Markdown into one self-contained HTML
page by the same path as the paper's HTML (pandoc, math as MathML, no script), beside the paper
(``paper/build/derivations/``), so that the paper links them as ``derivations/<name>.html``. This
module imports nothing of msslib: the derivations come first in the workflow.
"""

from __future__ import annotations

import argparse
import io
import re
import sys
from contextlib import redirect_stdout
from pathlib import Path

from derivations import registry, show

HERE = Path(__file__).resolve().parent
CELL = re.compile(r"^# %%(.*)$")


def cells(source: str):
    """``(kind, text, first_line)`` of each cell (``kind`` is ``"markdown"`` or ``"code"``; lines
    count from 1). Text before the first cell (the jupytext header) is left out."""
    out, kind, lines, start = [], None, [], 0
    for n, line in enumerate(source.splitlines(), 1):
        m = CELL.match(line)
        if m:
            if kind is not None:
                out.append((kind, lines, start))
            kind = "markdown" if "[markdown]" in m.group(1) else "code"
            lines, start = [], n + 1
        elif kind is not None:
            lines.append(line)
    if kind is not None:
        out.append((kind, lines, start))
    result = []
    for kind, lines, start in out:
        if kind == "markdown":
            text = "\n".join(re.sub(r"^# ?", "", ln) if ln.startswith("#") else ln for ln in lines)
        else:
            text = "\n".join(lines)
        if text.strip():
            result.append((kind, text.strip("\n"), start))
    return result


class _Capture(io.TextIOBase):
    """Stdout that appends ``("text", ...)`` to the list the show helpers collect into, so that
    printed and shown output keep their order."""

    def __init__(self, items):
        self.items = items

    def writable(self):
        return True

    def write(self, s):
        self.items.append(("text", s))
        return len(s)


def _fence(text: str, info: str = "") -> str:
    ticks = "```"
    while ticks in text:
        ticks += "`"
    return f"{ticks}{info}\n{text}\n{ticks}"


def _outputs(items) -> list[str]:
    """Markdown blocks from the collected items: runs of printed text become one text block."""
    blocks, text = [], []
    for kind, s in items + [("end", "")]:
        if kind == "text":
            text.append(s)
            continue
        joined = "".join(text).strip("\n")
        if joined.strip():
            blocks.append(_fence(joined, "text"))
        text = []
        if kind == "md":
            blocks.append(s)
    return blocks


def find(module: str) -> Path | None:
    """The source file of a derivation module, or None when there is none."""
    try:
        return registry.path(module)
    except KeyError:
        return None


def to_markdown(module: str) -> str:
    """Run a derivation module (e.g. ``triangle``) cell by cell and return the notebook as Markdown."""
    path = registry.path(module)
    source = path.read_text(encoding="utf-8")
    namespace = {"__name__": "__main__", "__file__": str(path), "__builtins__": __builtins__}
    parts = []
    for kind, text, start in cells(source):
        if kind == "markdown":
            parts.append(text)
            continue
        parts.append(_fence(text, "python"))
        code = compile("\n" * (start - 1) + text + "\n", str(path), "exec")  # tracebacks name the module's lines
        items: list = []
        with show.collecting(items), redirect_stdout(_Capture(items)):
            exec(code, namespace)
        parts += _outputs(items)
    return "\n\n".join(parts) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m derivations.notebook", description=__doc__.splitlines()[0])
    p.add_argument("module", help="derivation module, e.g. triangle")
    p.add_argument("--out", "-o", required=True, help="Markdown file")
    args = p.parse_args(argv)
    if find(args.module) is None:
        print(f"no derivation module {args.module!r} in derivations/elements/, terms/ or analyses/", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(to_markdown(args.module), encoding="utf-8")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

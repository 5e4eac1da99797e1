"""Build the paper: Markdown sources with placeholders filled from results, rendered to HTML.

Placeholders (in ``paper/*.md.in`` and the files they include):

``{{include PATH}}``
    the text of ``PATH`` (relative to the paper directory), itself expanded;
``{{figure NAME | CAPTION}}``
    the figure ``figures/NAME.png`` (made by the workflow) with its caption and a PDF link;
``{{value FILE VAR [DIM=LABEL ...] [scale=S] [fmt=F]}}``
    a number read from the NetCDF result ``FILE`` (relative to the project root): variable or
    attribute ``VAR``, selected by labels, multiplied by ``S``, formatted with ``F`` (default .3g).

Numbers in the text therefore come from results: a missing file, variable or label is an error,
never a blank. ``python -m msslib paper paper/paper.md.in --out paper/build/paper.html``.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

from msslib.io import write_text

PLACEHOLDER = re.compile(r"\{\{\s*(include|figure|value)\s+(.*?)\s*\}\}", re.S)


def _value(root: Path, spec: str) -> str:
    import xarray as xr

    parts = spec.split()
    if len(parts) < 2:
        raise ValueError(f"{{{{value {spec}}}}}: expected FILE VAR [DIM=LABEL ...]")
    path, var, rest = root / parts[0], parts[1], parts[2:]
    if not path.is_file():
        raise FileNotFoundError(f"{{{{value {spec}}}}}: no result file {parts[0]!r}")
    scale, fmt, sel = 1.0, ".3g", {}
    for p in rest:
        k, _, v = p.partition("=")
        if k == "scale":
            scale = float(v)
        elif k == "fmt":
            fmt = v
        else:
            sel[k] = v
    with xr.open_dataset(path) as ds:
        for k, v in list(sel.items()):  # labels are text in the template: match the coordinate's type
            if k in ds.coords and ds[k].dtype.kind in "fiu":
                sel[k] = ds[k].dtype.type(float(v))
        if var in ds.variables:
            val = ds[var].sel(sel) if sel else ds[var]
            val = float(val.values)
        elif var in ds.attrs:
            val = float(ds.attrs[var])
        else:
            raise KeyError(f"{{{{value {spec}}}}}: {var!r} is neither a variable nor an attribute of {parts[0]}")
    return format(val * scale, fmt)


def expand(text: str, paper_dir: Path, root: Path, depth: int = 0) -> str:
    if depth > 10:
        raise RecursionError("includes nested too deeply")

    def repl(m):
        kind, arg = m.group(1), m.group(2)
        if kind == "include":
            p = paper_dir / arg
            if not p.is_file():
                raise FileNotFoundError(f"{{{{include {arg}}}}}: no such file")
            return expand(p.read_text(encoding="utf-8"), paper_dir, root, depth + 1)
        if kind == "figure":
            name, _, caption = (s.strip() for s in arg.partition("|"))
            if not (paper_dir / "figures" / f"{name}.png").is_file():
                raise FileNotFoundError(f"{{{{figure {name}}}}}: figures/{name}.png has not been made")
            return (f'<figure><img src="../figures/{name}.png" alt="{html.escape(caption)}" style="max-width:100%">'
                    f'<figcaption>{caption} (<a href="../figures/{name}.pdf">PDF</a>)</figcaption></figure>')
        return _value(root, arg)

    return PLACEHOLDER.sub(repl, text)


def render_html(markdown_text: str, title: str) -> str:
    from markdown_it import MarkdownIt

    md = MarkdownIt("commonmark", {"html": True}).enable("table")
    body = md.render(markdown_text)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<script>window.MathJax = {{tex: {{inlineMath: [['$', '$']]}}}};</script>
<script async src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-chtml.js"></script>
<style>body{{max-width:60rem;margin:2rem auto;font-family:sans-serif;line-height:1.5;padding:0 1rem}}
table{{border-collapse:collapse;font-size:0.9em}}td,th{{border:1px solid #bbb;padding:0.2em 0.5em}}
figure{{margin:1.5em 0}}figcaption{{font-size:0.9em;color:#333}}</style></head>
<body>
{body}
</body></html>
"""


def build(source, out) -> Path:
    source, out = Path(source), Path(out)
    paper_dir = source.parent
    root = paper_dir.parent
    text = expand(source.read_text(encoding="utf-8"), paper_dir, root)
    title = next((line.lstrip("# ").strip() for line in text.splitlines() if line.startswith("# ")), "msslib")
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, render_html(text, title))
    write_text(out.with_suffix(".md"), text)
    return out

"""Build the paper: Markdown sources with placeholders filled from results, rendered to a
self-contained HTML file and a PDF.

Placeholders (in ``paper/*.md.in`` and the files they include):

``{{include PATH}}``
    the text of ``PATH`` (relative to the paper directory), itself expanded;
``{{figure NAME | CAPTION}}``
    the figure ``figures/NAME.png`` (made by the workflow) with its caption;
``{{value FILE VAR [DIM=LABEL ...] [scale=S] [fmt=F]}}``
    a number read from the NetCDF result ``FILE`` (relative to the project root): variable or
    attribute ``VAR``, selected by labels, multiplied by ``S``, formatted with ``F`` (default .3g;
    ``fmt=text``: a text attribute as it is, e.g. a status word the results computed);
``{{notebooks}}``
    links to the executed notebook page of every derivation module (from the derivation registry);
``{{expr EXPRESSION [| FMT]}}``
    a number computed from result values, e.g. a difference or a ratio: ``EXPRESSION`` is
    arithmetic as in a claim's condition (below), formatted with ``FMT`` (default .3g);
``{{claim CONDITION | TEXT}}``
    ``TEXT`` (which may hold ``{{value ...}}`` placeholders), after checking that ``CONDITION``
    holds; ``{{claim CONDITION}}`` checks and prints nothing. ``CONDITION`` compares numbers:
    ``[FILE VAR DIM=LABEL ... scale=S]`` is a result value as in ``{{value}}`` (unformatted),
    with number literals, ``+ - * /``, ``abs``, ``min``, ``max``, the comparisons (chained:
    ``a > b > c``), ``and``, ``or`` and ``not``; e.g. ``abs([f.nc E]/[f.nc E_ref] - 1) < 0.05``.

Numbers in the text therefore come from results: a missing file, variable or label is an error,
never a blank. A sentence that interprets numbers ("the error halves with every refinement") is
written as a claim, so a change of the results that makes it false fails the build. The one
exception is a quick build (``--config quick=1``), whose reduced runs make some claims vacuous (one
resolution for three): a false claim whose result files, or the run files beside them, carry the
attribute ``quick = 1`` is printed with the mark "[not met by the reduced quick-build results]" instead. The filled Markdown (``paper/build/paper.md``, figures linked as
``../figures/NAME.png``) is then rendered twice::

    python -m experiments.paper fill paper/paper.md.in --out paper/build/paper.md
    python -m experiments.paper html paper/build/paper.md --out paper/build/paper.html
    python -m experiments.paper pdf paper/build/paper.md --out paper/build/paper.pdf

Math is ``$...$`` (inline) and ``$$...$$`` (display) TeX and is converted at build time, so the
outputs load nothing: no script, no font or style from the network.

Toolchain. pandoc, from the ``pypandoc_binary`` wheel (34 MB download, 155 MB installed: a static
pandoc 3 binary, no system package, no network), parses the Markdown once with a math-aware reader
(CommonMark with dollar math, pipe tables and figures), so TeX is never touched by Markdown escapes,
and writes both outputs: HTML with the math as MathML (``--mathml``; Chromium and Firefox display
it natively) and every figure and style embedded (``--embed-resources``: one file that opens
anywhere, offline), and Typst, which the ``typst`` wheel (34 MB download, 81 MB installed: the
compiler with its fonts built in; system fonts are ignored, so the PDF is the same file on every
machine) compiles to PDF. pandoc's TeX reader (texmath) converts ``\\begin{matrix}``/``pmatrix``,
``\\left[ ... \\right]``, ``\\frac``, ``\\sqrt``, ``\\text{}``, ``\\lVert``, ``gathered``/``aligned``
and sub/superscripts to MathML and to Typst math alike (all formulas of the paper, the derivation
matrices included, convert without a warning; ``tests/test_paper.py`` checks them); markdown-it
with latex2mathml would need a second toolchain for the PDF and handles fewer environments.
Anything pandoc cannot convert (unknown TeX, a missing figure) fails the build instead of leaving
raw TeX in the paper.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

from msslib.results import write_text

PLACEHOLDER = re.compile(r"\{\{\s*(include|figure|value)\s+(.*?)\s*\}\}", re.S)
#: a claim, matched after the other placeholders (including those in its text) are filled
CLAIM = re.compile(r"\{\{\s*claim\s+(.*?)\s*\}\}", re.S)
#: {{expr EXPRESSION | FMT}}: a number computed from result values (expanded before the claims)
#: {{notebooks}}: links to the notebook page of every derivation module that generates code
NOTEBOOKS = re.compile(r"\{\{\s*notebooks\s*\}\}")
#: what a {{value}} shows for a number that the reduced quick build does not compute
QUICK_NA = "n/a (quick build)"
EXPR = re.compile(r"\{\{\s*expr\s+(.*?)\s*\}\}", re.S)
#: a result value in a claim's condition: ``[FILE VAR DIM=LABEL ...]``
CLAIM_VALUE = re.compile(r"\[([^\[\]]+)\]")
#: mark of a false claim on quick results
QUICK_MARK = " [not met by the reduced quick-build results]"

#: pandoc's Markdown reader: CommonMark (what the sources are written in) with dollar math, pipe
#: tables, attributes and figures (an image alone in a paragraph, its alt text the caption); list
#: and super/subscript extensions that could misread hard-wrapped prose are off.
READER = "commonmark_x+implicit_figures-fancy_lists-definition_lists-superscript-subscript-emoji"

#: style of the HTML (pandoc's default page style, wider for tables; long display math scrolls)
CSS = """
body { max-width: 52em; }
table { display: block; overflow-x: auto; font-size: 0.85em; margin: 1em 0; }
th, td { padding: 0.15em 0.6em; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; height: auto; }
figcaption { font-size: 0.9em; }
math { font-family: "STIX Two Math", "Latin Modern Math", "Cambria Math", "DejaVu Math TeX Gyre", math; }
math[display="block"] { overflow-x: auto; overflow-y: hidden; max-width: 100%; padding: 0.2em 0; }
"""

#: set before pandoc's default Typst template: no date in the PDF (the same sources give the same
#: file), tables in smaller type with a rule under the header, and display equations wider than
#: the text scaled down to fit
TYPST_HEADER = """
#set document(date: none)
#set table(stroke: (x, y) => if y == 0 { (bottom: 0.6pt) }, inset: (x: 4pt, y: 3pt))
#show figure.where(kind: table): set text(size: 0.8em)
#show table: set par(justify: false)
#show math.equation.where(block: true): eq => layout(size => {
  let w = measure(eq).width
  if w <= size.width { eq } else { scale(x: size.width / w * 100%, y: size.width / w * 100%, reflow: true, eq) }
})
"""


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
    if path.suffix == ".json":  # a key path into a JSON document (paper/derivations.json: MODULE.checks.NAME)
        if sel:
            raise ValueError(f"{{{{value {spec}}}}}: a JSON value takes scale= and fmt= only")
        return format(_json_value(path, var, spec) * scale, fmt)
    with xr.open_dataset(path) as ds:
        for k, v in list(sel.items()):  # labels are text in the template: match the coordinate's type
            if k in ds.coords and ds[k].dtype.kind in "fiu":
                sel[k] = ds[k].dtype.type(float(v))
        if var in ds.variables:
            try:
                val = float((ds[var].sel(sel) if sel else ds[var]).values)
            except KeyError:  # a label the reduced quick build does not run (e.g. fewer ratios)
                val = None
        elif var in ds.attrs and fmt == "text":  # a word the results computed (e.g. "resolved")
            return str(ds.attrs[var])
        elif var in ds.attrs:
            val = float(ds.attrs[var])
        else:
            raise KeyError(f"{{{{value {spec}}}}}: {var!r} is neither a variable nor an attribute of {parts[0]}")
    if val is None:
        if _is_quick(path):
            return QUICK_NA
        raise KeyError(f"{{{{value {spec}}}}}: no such label in {parts[0]}")
    if math.isnan(val):  # (infinity is a value: e.g. a budget with no upper end)
        if _is_quick(path):  # a quantity the reduced quick build does not compute
            return QUICK_NA
        raise ValueError(f"{{{{value {spec}}}}}: the result is {val} (a number the paper needs is missing)")
    return format(val * scale, fmt)


def _json_value(path: Path, key: str, spec: str) -> float:
    import json

    node = json.loads(path.read_text(encoding="utf-8"))
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            raise KeyError(f"{{{{value {spec}}}}}: no key {part!r} on the path {key!r} in {path.name}")
        node = node[part]
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise ValueError(f"{{{{value {spec}}}}}: {key!r} in {path.name} is not a number")
    return float(node)


def _is_quick(path: Path) -> bool:
    """Whether ``path`` holds quick-build results: its attribute ``quick``, or that of the run
    files beside it (a comparison file is made from the runs in its directory)."""
    import xarray as xr

    if path.suffix != ".nc":  # derived facts (paper/derivations.json) have no quick version
        return False
    for f in [path, *sorted(path.parent.glob("*.nc"))]:
        with xr.open_dataset(f) as ds:
            if "quick" in ds.attrs:
                return bool(int(ds.attrs["quick"]))
    return False


def _evaluate(node, values):
    """Evaluate the condition's syntax tree: numbers, value names, arithmetic, abs/min/max,
    comparisons and boolean operators; anything else is an error."""
    import ast
    import operator as op

    binary = {ast.Add: op.add, ast.Sub: op.sub, ast.Mult: op.mul, ast.Div: op.truediv}
    compare = {ast.Lt: op.lt, ast.LtE: op.le, ast.Gt: op.gt, ast.GtE: op.ge, ast.Eq: op.eq, ast.NotEq: op.ne}
    if isinstance(node, ast.Expression):
        return _evaluate(node.body, values)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id in values:
        return values[node.id]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return -_evaluate(node.operand, values)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        return not _evaluate(node.operand, values)
    if isinstance(node, ast.BinOp) and type(node.op) in binary:
        return binary[type(node.op)](_evaluate(node.left, values), _evaluate(node.right, values))
    if isinstance(node, ast.BoolOp):
        results = [_evaluate(v, values) for v in node.values]
        return all(results) if isinstance(node.op, ast.And) else any(results)
    if isinstance(node, ast.Compare) and all(type(o) in compare for o in node.ops):
        left = _evaluate(node.left, values)
        for o, c in zip(node.ops, node.comparators):
            right = _evaluate(c, values)
            if not compare[type(o)](left, right):
                return False
            left = right
        return True
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("abs", "min", "max")
            and node.args and not node.keywords):
        args = [_evaluate(a, values) for a in node.args]
        return {"abs": abs, "min": min, "max": max}[node.func.id](*args)
    raise ValueError(f"not allowed in a claim: {ast.dump(node)[:80]}")


def _compute(root: Path, expression: str, kind: str):
    """Evaluate ``expression`` (result values in brackets, see the module's docstring): its value,
    the values read and the files they came from."""
    import ast

    values, files = {}, []

    def name(m):
        spec = m.group(1).strip()
        parts = spec.split()
        if len(parts) < 2:
            raise ValueError(f"{{{{{kind} {expression}}}}}: [{spec}]: expected [FILE VAR DIM=LABEL ...]")
        files.append(root / parts[0])
        key = f"_v{len(values)}"
        text = _value(root, spec + " fmt=.17g")
        values[key] = math.nan if text == QUICK_NA else float(text)
        return key

    try:
        tree = ast.parse(CLAIM_VALUE.sub(name, expression), mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"{{{{{kind} {expression}}}}}: not an expression ({exc.msg})") from None
    try:
        return _evaluate(tree, values), values, files
    except ZeroDivisionError as exc:
        if any(_is_quick(f) for f in files):  # a quick build's reduced run (e.g. the reference on the mesh itself)
            return math.nan, values, files
        raise ValueError(f"{{{{{kind} {expression}}}}}: {exc}") from None
    except ValueError as exc:
        raise ValueError(f"{{{{{kind} {expression}}}}}: {exc}") from None


def _expr(root: Path, arg: str) -> str:
    """The value of an arithmetic expression of result values, formatted (default ``.3g``)."""
    expression, _, fmt = (s.strip() for s in arg.partition("|"))
    value, _, files = _compute(root, expression, "expr")
    if isinstance(value, bool):
        raise ValueError(f"{{{{expr {expression}}}}}: a comparison, not a number (write it as a claim)")
    if math.isnan(value):
        if any(_is_quick(f) for f in files):
            return QUICK_NA
        raise ValueError(f"{{{{expr {expression}}}}}: the result is {value}")
    return format(value, fmt or ".3g")


def _claim(root: Path, arg: str) -> str:
    """Check a claim's condition (see the module's docstring) and return its text."""

    condition, _, text = (s.strip() for s in arg.partition("|"))
    holds, values, files = _compute(root, condition, "claim")
    if isinstance(holds, float) and math.isnan(holds):  # no value (a quick build's division by zero): not met
        holds = False
    if holds is True or (holds is not False and bool(holds)):
        return text
    shown = ", ".join(f"[{m.group(1).strip()}] = {values[f'_v{i}']:.6g}"
                      for i, m in enumerate(CLAIM_VALUE.finditer(condition)))
    if any(_is_quick(f) for f in files):
        print(f"claim not met by quick results: {condition} ({shown})", file=sys.stderr)
        return text + QUICK_MARK if text else ""
    raise ValueError(f"false claim: {{{{claim {condition}}}}} with {shown or 'no result values'}"
                     + (f"; text: {text!r}" if text else ""))


def _notebook_links(root: Path) -> str:
    """``[title](derivations/<name>.html)`` for every module the derivation registry generates code
    from, titled as in ``paper/derivations.json``; the pages are built beside the paper."""
    import json

    from derivations import registry

    titles = json.loads((root / "paper" / "derivations.json").read_text(encoding="utf-8"))
    links = [f"[{titles.get(name, {}).get('title', name)}](derivations/{name}.html)" for name in registry.generated()]
    return "; ".join(links)


def _figure(paper_dir: Path, arg: str) -> str:
    name, _, caption = (s.strip() for s in arg.partition("|"))
    if not (paper_dir / "figures" / f"{name}.png").is_file():
        raise FileNotFoundError(f"{{{{figure {name}}}}}: figures/{name}.png has not been made")
    if caption.count("[") != caption.count("]") or "\n\n" in caption:
        raise ValueError(f"{{{{figure {name}}}}}: the caption must be one paragraph with balanced brackets")
    # alone in its paragraph, an image is a figure with its text as the caption (HTML and PDF);
    # the path is relative to paper/build/, where the filled Markdown is written
    return f"\n\n![{caption}](../figures/{name}.png){{#fig-{name}}}\n\n"


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
            return _figure(paper_dir, arg)
        return _value(root, arg)

    text = PLACEHOLDER.sub(repl, text)
    text = NOTEBOOKS.sub(lambda m: _notebook_links(root), text)
    text = EXPR.sub(lambda m: _expr(root, m.group(1)), text)
    return CLAIM.sub(lambda m: _claim(root, m.group(1)), text)


def title_of(markdown_text: str, default: str = "msslib") -> str:
    """The text of the first level-1 heading."""
    return next((line[2:].strip() for line in markdown_text.splitlines() if line.startswith("# ")), default)


def pandoc_path() -> str:
    try:
        import pypandoc
    except ImportError as exc:  # pragma: no cover - a dependency of msslib
        raise RuntimeError("the paper needs pandoc: python3 -m pip install pypandoc_binary") from exc
    return pypandoc.get_pandoc_path()


def pandoc(text: str, *args: str, reader: str = READER) -> str:
    """Run pandoc on ``text`` (Markdown read as :data:`READER`, or ``reader``) and return its
    output. Every warning is an error (TeX it cannot convert, a figure it cannot find, ...)."""
    # --columns: a pipe table wider than this gets column widths from its dashes (all equal in
    # generated tables); wider than any table, the columns size to their content instead
    cmd = [pandoc_path(), "--from", reader, "--fail-if-warnings", "--columns=100000", *args]
    proc = subprocess.run(cmd, input=text, capture_output=True, text=True, encoding="utf-8")
    if proc.returncode != 0:
        raise RuntimeError(f"pandoc failed ({proc.returncode}):\n{proc.stderr.strip()}")
    return proc.stdout


def render_html(markdown_text: str, title: str | None = None, resource_dir=None) -> str:
    """A standalone HTML page: math as MathML, no script. With ``resource_dir`` (the directory the
    Markdown's relative paths start from) the figures are embedded as data URIs, so the page opens
    anywhere; without it they stay links relative to the page."""
    title = title or title_of(markdown_text)
    args = ["--to", "html5", "--standalone", "--mathml", "--shift-heading-level-by=-1",
            "--metadata", f"pagetitle={title}", "--variable", f"header-includes=<style>{CSS}</style>"]
    if resource_dir is not None:
        args += ["--embed-resources", f"--resource-path={resource_dir}"]
    return pandoc(markdown_text, *args)


#: a table cell's first word that Typst reads as markup when a space follows ("/ a: b" is a
#: term list and a syntax error without the colon, "= x" a heading, "- x", "+ x", "1. x" lists);
#: pandoc escapes it only at the start of a paragraph, so :func:`render_typst` guards table cells
_CELL_MARKUP = re.compile(r"/|=+|-|\+|\d+\.")

#: tables whose cells' text is longer than this (characters per row) get column widths
#: proportional to their content in the PDF (Typst's automatic widths squeeze long columns)
WIDE_TABLE = 90


def _table_rows(table):
    _, _, _, head, bodies, foot = table["c"]
    return head[1], [row for body in bodies for row in body[2] + body[3]] + foot[1]


def _text_length(node) -> int:
    """Characters of the text in a pandoc syntax tree (math counts by half its TeX)."""
    if isinstance(node, list):
        return sum(_text_length(n) for n in node)
    if isinstance(node, dict):
        kind, content = node.get("t"), node.get("c")
        if kind == "Str":
            return len(content)
        if kind in ("Space", "SoftBreak"):
            return 1
        if kind == "Code":
            return len(content[1])
        if kind == "Math":
            return len(content[1]) // 2
        return _text_length(content)
    return 0


def _words(node):
    """The words (``Str``) of a pandoc syntax tree."""
    if isinstance(node, list):
        for item in node:
            yield from _words(item)
    elif isinstance(node, dict):
        if node.get("t") == "Str":
            yield node["c"]
        else:
            yield from _words(node.get("c"))


def _prepare_table(table) -> None:
    """Guard cells that start like Typst markup with an empty Typst string (``#""``, which prints
    nothing), and give a wide table column widths from its content (changed in place)."""
    head, body = _table_rows(table)
    for row in head + body:
        for cell in row[1]:
            block = next((b for b in cell[4] if b["t"] in ("Plain", "Para")), None)
            inlines = block["c"] if block else []
            if (inlines and inlines[0]["t"] == "Str" and _CELL_MARKUP.fullmatch(inlines[0]["c"])
                    and (len(inlines) == 1 or inlines[1]["t"] in ("Space", "SoftBreak"))):
                inlines.insert(0, {"t": "RawInline", "c": ["typst", '#""']})
    colspecs = table["c"][2]
    natural = [0] * len(colspecs)  # longest body cell, at least the longest header word
    for row in body:
        for i, cell in enumerate(row[1][:len(natural)]):
            natural[i] = max(natural[i], _text_length(cell[4]))
    for row in head:
        for i, cell in enumerate(row[1][:len(natural)]):
            natural[i] = max(natural[i], *(len(w) for w in _words(cell[4])), 1)
    if sum(natural) > WIDE_TABLE:
        weights = [min(n, 40) + 2 for n in natural]  # a long note wraps rather than take the page
        for spec, w in zip(colspecs, weights):
            spec[1] = {"t": "ColWidth", "c": w / sum(weights)}


def _prepare_tables(node) -> None:
    if isinstance(node, list):
        for item in node:
            _prepare_tables(item)
    elif isinstance(node, dict):
        if node.get("t") == "Table":
            _prepare_table(node)
        for value in node.values():
            _prepare_tables(value)


def render_typst(markdown_text: str, title: str | None = None) -> str:
    """The Typst source of the PDF (pandoc's default Typst template, A4)."""
    title = title or title_of(markdown_text)
    tree = json.loads(pandoc(markdown_text, "--to", "json"))
    _prepare_tables(tree["blocks"])
    return pandoc(json.dumps(tree), "--to", "typst", "--standalone", "--wrap=none", "--shift-heading-level-by=-1",
                  "--metadata", f"pagetitle={title}", "--variable", "papersize=a4",
                  "--variable", "fontsize=10pt", "--variable", "page-numbering=1",
                  "--variable", f"header-includes={TYPST_HEADER}", reader="json")


def compile_typst(typ: Path, pdf: Path) -> Path:
    """Compile the Typst file ``typ`` to ``pdf`` with the fonts built into the compiler only;
    a warning (a missing glyph or font, ...) is an error. Images are read relative to ``typ``."""
    import typst

    images = [(typ.parent / p).resolve() for p in re.findall(r'image\("([^"]+)"', typ.read_text(encoding="utf-8"))]
    root = Path(os.path.commonpath([typ.parent.resolve(), *images]))
    tmp = pdf.with_name(f".{pdf.name}.tmp")
    try:
        try:
            _, warnings = typst.compile_with_warnings(str(typ), output=str(tmp), root=str(root),
                                                      ignore_system_fonts=True)
        except typst.TypstError as exc:
            raise RuntimeError(f"typst: {getattr(exc, 'diagnostic', None) or exc}") from None
        if warnings:
            raise RuntimeError("typst: " + "; ".join(w.message for w in warnings))
        os.replace(tmp, pdf)
    finally:
        tmp.unlink(missing_ok=True)
    return pdf


def fill(source, out) -> Path:
    """Expand ``source`` into the Markdown ``out``."""
    source, out = Path(source), Path(out)
    paper_dir = source.parent
    text = expand(source.read_text(encoding="utf-8"), paper_dir, paper_dir.parent)
    out.parent.mkdir(parents=True, exist_ok=True)
    return write_text(out, text)


def html_from_markdown(markdown, out) -> Path:
    markdown, out = Path(markdown), Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    return write_text(out, render_html(markdown.read_text(encoding="utf-8"), resource_dir=markdown.parent))


def notebook_html(module, out) -> Path:
    """A derivation module (e.g. ``triangle``, wherever it lives in ``derivations/``) as a notebook
    page: its cells run in order (:func:`derivations.notebook.to_markdown`), rendered like the paper's HTML."""
    from derivations.notebook import find, to_markdown

    if find(module) is None:
        raise ValueError(f"no derivation module {module!r} in derivations/elements/, terms/ or analyses/")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    return write_text(out, render_html(to_markdown(module)))


def pdf_from_markdown(markdown, out) -> Path:
    """The PDF, through a Typst file written beside the Markdown (``paper.typ``)."""
    markdown, out = Path(markdown), Path(out)
    typ = markdown.with_suffix(".typ")
    write_text(typ, render_typst(markdown.read_text(encoding="utf-8")))
    out.parent.mkdir(parents=True, exist_ok=True)
    return compile_typst(typ, out)


def build(source, out, pdf=None) -> Path:
    """Fill ``source`` and write the HTML ``out``, its Markdown twin beside it and, if asked, the PDF."""
    out = Path(out)
    markdown = fill(source, out.with_suffix(".md"))
    html_from_markdown(markdown, out)
    if pdf is not None:
        pdf_from_markdown(markdown, pdf)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m experiments.paper", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="step", required=True)
    for step, src, dst in [("fill", "main source, e.g. paper/paper.md.in", "filled Markdown"),
                           ("html", "filled Markdown", "HTML file"), ("pdf", "filled Markdown", "PDF file"),
                           ("notebook", "derivation module, e.g. triangle", "HTML file")]:
        s = sub.add_parser(step, help=f"{src} -> {dst}")
        s.add_argument("source", help=src)
        s.add_argument("--out", "-o", required=True, help=dst)
    args = p.parse_args(argv)
    step = {"fill": fill, "html": html_from_markdown, "pdf": pdf_from_markdown, "notebook": notebook_html}[args.step]
    try:
        step(args.source, args.out)
    except (OSError, ValueError, KeyError, RuntimeError) as exc:
        print(f"python -m experiments.paper {args.step}: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Tables of the documentation generated from the registries when the site is built.

``.. msslib-models::`` is the table of :func:`msslib.models.registry` (one row per model: name,
family, kind, cells, derivation module, options, where it is exact); ``.. msslib-elements::`` the
table of the derivation modules of :mod:`derivations.registry` (elements, then term kernels, with
the page the workflow renders for each). Nothing here is written by hand, so a model or an element
added to its registry appears in the site at the next build.
"""

from __future__ import annotations

from docutils import nodes
from docutils.parsers.rst import Directive

MODEL_HEADER = ("model", "family", "kind", "cells", "derivation", "terms (default)", "options", "exact where")
ELEMENT_HEADER = ("module", "kind", "cell", "models", "title", "notebook")


def _exactness(spec) -> str:
    if spec.kind == "fem":
        return "reference"
    out = []
    for e in spec.exact:
        nu = "any nu" if e.nu is None else f"nu = {e.nu:.4g}"
        opts = ", ".join(f"{k}={v}" for k, v in e.options.items())
        out.append(f"{e.level}, {e.mesh} cells, {nu}" + (f" ({opts})" if opts else ""))
    return "; ".join(out) or "not claimed (approximate)"


def model_rows() -> list[tuple[str, ...]]:
    """One row per model of :func:`msslib.models.registry`, in the registry's order."""
    from msslib.models import registry

    rows = []
    for name, spec in registry().items():
        terms = ", ".join(t if t in spec.defaults else f"({t})" for t in spec.terms) or "-"
        options = ", ".join(f"{o.name} (default {o.default!r})" for o in spec.options) or "-"
        rows.append((name, spec.family, spec.kind, ", ".join(spec.cells), spec.element or "-", terms, options,
                     _exactness(spec)))
    return rows


def _title(path) -> str:
    """The notebook's title: its first Markdown heading (``# # Title`` in the percent format)."""
    for line in path.read_text().splitlines():
        if line.startswith("# # "):
            return line[4:].strip()
    return "-"


def element_rows() -> list[tuple[str, ...]]:
    """One row per module codegen derives (:func:`derivations.registry.generated`), in its order."""
    from derivations import registry

    rows = []
    for name in registry.generated():
        kind = registry.kind(name)
        decl = registry.element(name) if kind == "elements" else None
        rows.append((name, kind, decl.cell if decl else "-", ", ".join(decl.models) if decl else "-",
                     _title(registry.path(name)), f"../derivations/{name}.html"))
    return rows


def _table(header, rows, link_column=None) -> nodes.table:
    table = nodes.table()
    group = nodes.tgroup(cols=len(header))
    table += group
    group.extend(nodes.colspec(colwidth=1) for _ in header)

    def row(cells, literal_first):
        out = nodes.row()
        for i, text in enumerate(cells):
            entry = nodes.entry()
            if i == link_column and text != "-":
                para = nodes.paragraph()
                para += nodes.reference("", "notebook", refuri=text)
                entry += para
            elif i == 0 and literal_first:
                entry += nodes.paragraph("", "", nodes.literal(text=text))
            else:
                entry += nodes.paragraph(text=text)
            out += entry
        return out

    thead = nodes.thead()
    thead += row(header, False)
    tbody = nodes.tbody()
    tbody.extend(row(r, True) for r in rows)
    group += thead
    group += tbody
    return table


class ModelTable(Directive):
    def run(self):
        table = _table(MODEL_HEADER, model_rows())
        table["classes"].append("msslib-models")
        return [table]


class ElementTable(Directive):
    def run(self):
        table = _table(ELEMENT_HEADER, element_rows(), link_column=ELEMENT_HEADER.index("notebook"))
        table["classes"].append("msslib-elements")
        return [table]


def setup(app):
    app.add_directive("msslib-models", ModelTable)
    app.add_directive("msslib-elements", ElementTable)
    app.add_directive("msslib-examples", ExampleScripts)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


def example_files() -> list:
    """The worked examples: every script of ``experiments/examples/`` (by name)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    return sorted(p for p in (root / "experiments" / "examples").glob("*.py") if not p.stem.startswith("_"))


class ExampleScripts(Directive):
    """Each example script: a section with its docstring's first line as title, then the source."""

    def run(self):
        import ast

        out = []
        for path in example_files():
            source = path.read_text()
            doc = ast.get_docstring(ast.parse(source)) or path.stem
            section = nodes.section(ids=[f"example-{path.stem}"])
            section += nodes.title(text=f"experiments/examples/{path.name}")
            section += nodes.paragraph(text=doc.split("\n\n", 1)[0].replace("\n", " "))
            block = nodes.literal_block(source, source, language="python")
            section += block
            out.append(section)
        return out

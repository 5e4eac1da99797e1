"""The derivation modules as notebooks (derivations.show, derivations.notebook): rendered with
typeset math, and still importable and runnable as scripts. One render of the triangle (~10 s)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

from derivations import notebook, show

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def triangle_markdown():
    return notebook.to_markdown("triangle")


@pytest.fixture(scope="module")
def triangle_html(triangle_markdown):
    from experiments.paper import render_html
    return render_html(triangle_markdown)


def test_cells_split_markdown_and_code():
    cells = notebook.cells((ROOT / "derivations" / "elements" / "triangle.py").read_text())
    kinds = [c[0] for c in cells]
    assert kinds[0] == "markdown" and cells[0][1].startswith("# Triangle")  # header left out, "# " stripped
    assert "code" in kinds and kinds.count("markdown") >= 3
    assert not any("jupytext" in text for _, text, _ in cells)
    source = (ROOT / "derivations" / "elements" / "triangle.py").read_text().splitlines()
    kind, text, start = next(c for c in cells if c[0] == "code")
    assert source[start - 1] == text.splitlines()[0]  # line numbers for tracebacks


def test_show_collects_markdown_and_prints_plain(capsys):
    M = sp.Matrix([[1, sp.Symbol("nu")], [0, sp.Rational(1, 2)]])
    with show.collecting() as items:
        show.matrix(r"K_{\text{FEM}}", M)
        show.check(r"x = 1", True)
    assert items[0] == ("md", rf"$$K_{{\text{{FEM}}}} = {sp.latex(M)}$$")
    assert ("md", "$$x = 1$$") in items and capsys.readouterr().out == ""
    show.matrix(r"K_{\text{FEM}}", M)  # as a script: plain text
    show.check(r"\frac{a}{b} = c", False)
    out = capsys.readouterr().out
    assert out.startswith("K_FEM =\n") and "ν" in out and "$" not in out and "\\" not in out
    assert "check: (a)/(b) = c: FAILS" in out


def test_show_displays_math_in_jupyter(monkeypatch):
    display = pytest.importorskip("IPython.display")
    shown = []
    monkeypatch.setattr(show, "_in_jupyter", lambda: True)
    monkeypatch.setattr(display, "display", lambda obj: shown.append(obj))
    show.math("k", sp.sqrt(3) / 4)
    assert isinstance(shown[0], display.Math) and shown[0].data == r"k = \frac{\sqrt{3}}{4}"


def test_show_block_of_a_big_matrix():
    M = sp.Matrix(24, 24, lambda i, j: i * 24 + j)
    with show.collecting() as items:
        show.matrix("K", M, rows=slice(0, 3), cols=slice(0, 6))
    assert "Rows 1-3, columns 1-6 of the 24 x 24 matrix $K$" in items[0][1]
    assert sp.latex(M[0:3, 0:6]) in items[1][1]


def test_triangle_notebook_shows_the_matrices(triangle_markdown):
    from derivations.elements import triangle
    md = triangle_markdown
    assert md.startswith("# Triangle")
    assert f"$$K_{{\\text{{FEM}}}} = {sp.latex(triangle.K_fem())}$$" in md
    assert f"$$K_{{\\text{{MSS}}}} = {sp.latex(triangle.K_mss())}$$" in md
    assert "21 distinct equations" in md and "```python" in md
    (s,) = triangle.exact().solutions
    assert f"k_{{01}} &= {sp.latex(s[triangle.k[0]])}" in md
    assert md.count("Check (holds)") == 4 and "FAILS" not in md
    assert r"\text{(Lloyd eq. 8)}" in md  # the published constant, checked against the derived one
    assert "Equilateral triangle, plane stress" in md  # printed output of the last cell (the summary)


def test_triangle_notebook_html_has_mathml(triangle_html):
    html = triangle_html
    assert "<math" in html and "$" not in html
    assert "<script" not in html
    # K_FEM, K_MSS, the equations, the solution, the matrix at the solution, the lattice tensor
    assert len(re.findall(r"<mtable", html)) >= 6
    for name in ("FEM", "MSS"):  # "K_FEM = [matrix]" and "K_MSS = [matrix]", as MathML
        label = rf"<msub><mi>K</mi><mtext[^>]*>{name}</mtext></msub><mo>=</mo>"
        assert re.search(label + r"<mrow><mo[^>]*>\[</mo><mtable>", html), name
    assert "<title>Triangle: plane-stress CST against three springs</title>" in html


def test_notebook_commands_write_markdown_and_html(tmp_path, monkeypatch):
    from experiments import paper

    monkeypatch.setattr(notebook, "to_markdown", lambda m: "# T\n\n$$x = \\frac{1}{2}$$\n")
    md = tmp_path / "t.md"
    assert notebook.main(["triangle", "--out", str(md)]) == 0
    assert md.read_text() == "# T\n\n$$x = \\frac{1}{2}$$\n"
    assert notebook.main(["no_such_module", "--out", str(md)]) == 2
    for name in ("elements/triangle", "derivations/elements/triangle.py", "derivations.elements.triangle"):
        assert notebook.main([name, "--out", str(md)]) == 0  # the module wherever it lives
    out = tmp_path / "derivations" / "t.html"
    assert paper.main(["notebook", "triangle", "--out", str(out)]) == 0
    assert "<math" in out.read_text()
    assert paper.main(["notebook", "no_such_module", "--out", str(out)]) == 1


def test_derivations_import_nothing_downstream():
    """The workflow's one direction: the derivations import neither msslib nor the experiments."""
    import ast

    for path in sorted((ROOT / "derivations").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            assert not any(n.split(".")[0] in ("msslib", "experiments") for n in names), (path.name, names)


def test_triangle_imports_silently_and_runs_as_script():
    r = subprocess.run([sys.executable, "-c", "import derivations.elements.triangle"], capture_output=True, text=True,
                       timeout=120, cwd=ROOT)
    assert r.returncode == 0 and r.stdout == "", r.stderr
    r = subprocess.run([sys.executable, "-m", "derivations.elements.triangle"], capture_output=True, text=True,
                       timeout=120, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert "K_FEM =" in r.stdout and "check: K_FEM - K_MSS = 0 at the solution: holds" in r.stdout
    assert "FAILS" not in r.stdout and "(Lloyd eq. 8): holds" in r.stdout

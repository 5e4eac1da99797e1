"""The paper build (experiments.paper): math rendered at build time, offline HTML, PDF, and the LaTeX
of the derivation findings. Each test builds a small paper in tmp_path (a second or two)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

from derivations import report
from experiments import paper

ROOT = Path(__file__).resolve().parent.parent

# Formulas that Markdown alone mangles: backslash escapes (\\, \{), underscores that pair up as
# emphasis across two formulas, a matrix, a fraction, \nu, \sqrt, \text{} and identifiers with
# underscores (k_{\text{face}}).
SECTION = r"""## Springs

The edge spring $k_{e} = \frac{5 E t}{16}$ and the face spring $k_{\text{face}} = \sqrt{2}\, k_{e}$
hold for $\nu = \frac{1}{3}$; measured: {{value results/demo.nc E_error level=eps10 scale=100 fmt=.2f}} %.

$$C = \left[\begin{matrix}\frac{9 E}{8} & \frac{3 E}{8} & 0\\\frac{3 E}{8} & \frac{9 E}{8} & 0\\0 & 0 & \frac{3 E}{8}\end{matrix}\right],\quad
\begin{pmatrix}a_{1}\\ a_{2}\end{pmatrix},\quad \{1\},\quad \text{none for any}\ \nu$$

| spring | constant |
|---|---|
| edge | $\frac{5 E t}{16}$ |
| diagonal | $\frac{7 E t}{16}$ |

{{figure demo_plot | A test figure: error of $E$ against $\nu$.}}
"""

SOURCE = """# A small paper

*Built for the test.*

{{include sections/springs.md}}
"""

N_FORMULAS = 8  # inline: 3 in the text, 2 in the table, 2 in the caption; display: 1


def make_paper(tmp_path: Path, section: str = SECTION) -> Path:
    """A project in tmp_path: paper/paper.md.in, a section, a figure and a result file."""
    import numpy as np
    import xarray as xr
    from PIL import Image

    (tmp_path / "paper" / "sections").mkdir(parents=True)
    (tmp_path / "paper" / "figures").mkdir()
    (tmp_path / "results").mkdir()
    (tmp_path / "paper" / "sections" / "springs.md").write_text(section, encoding="utf-8")
    (tmp_path / "paper" / "paper.md.in").write_text(SOURCE, encoding="utf-8")
    img = Image.new("RGB", (60, 40), "white")
    img.paste((200, 30, 30), (10, 10, 50, 30))
    img.save(tmp_path / "paper" / "figures" / "demo_plot.png")
    xr.Dataset({"E_error": ("level", np.array([0.0123, 0.0456]))},
               coords={"level": ["eps05", "eps10"]}).to_netcdf(tmp_path / "results" / "demo.nc")
    return tmp_path / "paper" / "paper.md.in"


def visible_text(page: str) -> str:
    """The HTML without its style, the TeX annotations of the MathML and the tags."""
    page = re.sub(r"<style.*?</style>", "", page, flags=re.S)
    page = re.sub(r"<annotation.*?</annotation>", "", page, flags=re.S)
    return re.sub(r"<[^>]+>", " ", page)


def assert_math_rendered(page: str, n_formulas: int) -> None:
    text = visible_text(page)
    assert "$" not in text, "raw $ left in the HTML: " + text[max(0, text.find("$") - 80):text.find("$") + 80]
    assert "merror" not in page
    for tex in ("\\frac", "\\nu", "\\text", "\\begin", "\\left"):
        assert tex not in text, f"raw TeX {tex} in the HTML"
    assert page.count("<math") == n_formulas


def assert_offline(page: str) -> None:
    assert "<script" not in page
    assert not re.search(r"<link\b", page), "a linked resource"
    assert not re.search(r"url\(\s*['\"]?(https?:)?//", page), "a style loads from the network"
    sources = re.findall(r"\bsrc\s*=\s*[\"']([^\"']*)", page)
    assert all(s.startswith("data:") for s in sources), sources


def test_small_paper_html_renders_math_offline(tmp_path):
    source = make_paper(tmp_path)
    out = paper.build(source, tmp_path / "paper" / "build" / "paper.html")
    page = out.read_text(encoding="utf-8")
    assert_math_rendered(page, N_FORMULAS)
    assert_offline(page)
    # the constructs are MathML, not text
    assert page.count("<mtable") == 2  # the matrix and the pmatrix
    assert "<mfrac>" in page and "<msqrt>" in page and "<mi>ν</mi>" in page
    assert re.search(r"<mtext[^>]*>face</mtext>", page)  # \text in a subscript
    assert re.search(r"<td[^>]*>\s*<math", page)  # math in a table cell
    # the figure is embedded, with its caption; the number comes from the result file
    assert re.search(r'<img [^>]*src="data:image/png;base64,', page)
    assert re.search(r"<figcaption[^>]*>A test figure", page)
    assert "4.56 %" in visible_text(page)
    assert "<title>A small paper</title>" in page
    # the filled Markdown is kept beside the HTML, with the figure relative to it
    markdown = out.with_suffix(".md").read_text(encoding="utf-8")
    assert "](../figures/demo_plot.png)" in markdown and "{{" not in markdown


def test_small_paper_pdf(tmp_path):
    source = make_paper(tmp_path)
    build = tmp_path / "paper" / "build"
    paper.build(source, build / "paper.html", pdf=build / "paper.pdf")
    typ = (build / "paper.typ").read_text(encoding="utf-8")
    assert 'image("../figures/demo_plot.png")' in typ
    assert "mat(" in typ and "frac(" in typ and "nu" in typ and "\\frac" not in typ
    pdf = (build / "paper.pdf").read_bytes()
    assert pdf.startswith(b"%PDF-")
    assert re.search(rb"/Subtype\s*/Image", pdf)  # the figure
    assert b"NewCMMath" in pdf  # math typeset with the compiler's math font
    assert not list(build.glob(".*.tmp"))


def test_tables_in_the_pdf(tmp_path):
    """Cells that start like Typst markup ("/ max |g|" was a syntax error, "- x" a list) print as
    text, and a wide table gets column widths from its content."""
    note = "a long note that would take a fair share of the width and more " * 2
    markdown = ("# Tables\n\n| figure | value | unit |\n|---|---|---|\n| error | 2.6e-15 | / max g |\n"
                "| ratio | - | = 1 |\n| step | + 3 | 1. of 2 |\n\n"
                f"| a | b | c |\n|---|---|---|\n| 1 | 2 | {note} |\n")
    typ = paper.render_typst(markdown)
    for text in ("/ max g", "-", "= 1", "+ 3", "1. of 2"):
        assert f'[#""{text}]' in typ, text
    assert "[2.6e-15]" in typ  # a number is no list
    widths = re.findall(r"#table\(\s*columns: \(([^)]*)\)", typ)
    assert len(widths) == 1  # only the wide table
    assert [float(w.rstrip("%")) for w in widths[0].split(", ")][2] > 50  # the note gets the room
    (tmp_path / "t.typ").write_text(typ, encoding="utf-8")
    pdf = paper.compile_typst(tmp_path / "t.typ", tmp_path / "t.pdf")
    assert pdf.read_bytes().startswith(b"%PDF-")


def test_tex_that_cannot_be_converted_fails_the_build(tmp_path):
    source = make_paper(tmp_path, SECTION + "\nA broken formula $\\frac{1}{\\undefinedmacro}$.\n")
    with pytest.raises(RuntimeError, match="undefinedmacro"):
        paper.build(source, tmp_path / "paper" / "build" / "paper.html")


def test_missing_figure_fails_the_build(tmp_path):
    source = make_paper(tmp_path)
    (tmp_path / "paper" / "figures" / "demo_plot.png").unlink()
    with pytest.raises(FileNotFoundError, match="demo_plot"):
        paper.build(source, tmp_path / "paper" / "build" / "paper.html")


def _formulas(markdown: str) -> list[str]:
    return re.findall(r"\$\$.+?\$\$|\$[^$\n]+\$", markdown, flags=re.S)


def test_derivation_findings_and_errata_render():
    """The real derivation matrices and errata, as the workflow writes them, convert without a
    warning (pandoc fails on any) and leave no raw TeX."""
    markdown = "\n\n".join((ROOT / "paper" / name).read_text(encoding="utf-8") for name in ("derivations.md", "errata.md"))
    formulas = _formulas(markdown)
    assert len(formulas) > 50
    page = paper.render_html("# Derivations\n\n" + markdown)
    assert_math_rendered(page, len(formulas))
    assert page.count("<mtable") >= 8  # the lattice matrices
    # words are text and nu is a Greek letter, not the letters n and u
    assert not re.search(r"<mi>n</mi>\s*<mi>u</mi>", page)
    assert not re.search(r"(<mi>[a-z]</mi>\s*){4}", page), "a word typeset as a product of variables"


def test_findings_split_only_at_top_level():
    tex = (r"f_0 = \left(a,\ b\right),\ C = \left[\begin{matrix}1 & 2\\3 & 4\end{matrix}\right],\ "
           r"r\ \text{(see a,\ b)},\ \{x,\ y\}")
    assert report._split_top_level(tex) == [r"f_0 = \left(a,\ b\right)",
                                            r"C = \left[\begin{matrix}1 & 2\\3 & 4\end{matrix}\right]",
                                            r"r\ \text{(see a,\ b)}", r"\{x,\ y\}"]


def test_findings_math_inline_or_display():
    assert report._finding_math(r"\nu = \frac{1}{3}") == r"$\nu = \frac{1}{3}$"
    long = ",\\ ".join(f"k_{i} = \\frac{{E t (r^{{2}} + {i})}}{{16 r (r^{{4}} + 4 r^{{2}} + 1)}}" for i in range(3))
    assert report._finding_math(long) == " ".join(
        f"$$k_{i} = \\frac{{E t (r^{{2}} + {i})}}{{16 r (r^{{4}} + 4 r^{{2}} + 1)}}{',' if i < 2 else ''}$$"
        for i in range(3))
    matrix = r"\left[\begin{matrix}1 & 0\\0 & 1\end{matrix}\right]"
    assert report._finding_math(matrix) == f"$${matrix}$$"


def _check_render():
    spec = importlib.util.spec_from_file_location("check_render", ROOT / "paper" / "check_render.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_pdf_pages_render(tmp_path):
    source = make_paper(tmp_path)
    build = tmp_path / "paper" / "build"
    paper.build(source, build / "paper.html", pdf=build / "paper.pdf")
    pages = _check_render().pages(build / "paper.typ", tmp_path / "render", ppi=30)
    assert [p.name for p in pages] == ["page-1.png"]


@pytest.mark.skipif(_check_render().find_browser() is None, reason="no Chromium or Chrome installed")
def test_html_screenshot_offline(tmp_path):
    from PIL import Image

    source = make_paper(tmp_path)
    html = paper.build(source, tmp_path / "paper" / "build" / "paper.html")
    png = _check_render().screenshot(html, tmp_path / "shot.png", width=800, height=900)
    with Image.open(png) as img:
        gray = img.convert("L")
        assert gray.size == (800, 900)
        # text and the embedded red figure are drawn: dark pixels and red pixels
        assert gray.getextrema()[0] < 80
        assert (200, 30, 30) in {c for _, c in img.convert("RGB").getcolors(maxcolors=1 << 20)}


CLAIMS = """## Claims

{{claim [results/demo.nc E_error level=eps10] > [results/demo.nc E_error level=eps05] | The error at 10 % strain,
{{value results/demo.nc E_error level=eps10 scale=100 fmt=.2f}} %, exceeds that at 5 %.}}
{{claim abs([results/demo.nc E_error level=eps05 scale=100] - 1.23) < 0.01 and 0 < 1 < 2}}
"""


def test_claim_that_holds_prints_its_text(tmp_path):
    source = make_paper(tmp_path, CLAIMS)
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert "The error at 10 % strain,\n4.56 %, exceeds that at 5 %." in text
    assert "claim" not in text and "[results" not in text and "{{" not in text


@pytest.mark.parametrize("condition", [
    "[results/demo.nc E_error level=eps10] < [results/demo.nc E_error level=eps05]",
    "abs([results/demo.nc E_error level=eps05] / 0.0456 - 1) < 0.05",
    "0.01 < [results/demo.nc E_error level=eps05] < 0.012",
])
def test_false_claim_fails_the_build(tmp_path, condition):
    source = make_paper(tmp_path, f"{{{{claim {condition} | A sentence.}}}}\n")
    with pytest.raises(ValueError, match="false claim"):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")
    assert paper.main(["fill", str(source), "--out", str(tmp_path / "out.md")]) == 1


@pytest.mark.parametrize("directive, argument", [
    # a claim's condition is restricted
    ("claim", "__import__('os').getcwd() == 0"),
    ("claim", "[results/demo.nc E_error level=eps05].real > 0"),
    ("claim", "[results/demo.nc E_error level=eps05] ** 2 > 0"),
    ("claim", "[results/demo.nc] > 0"),
    ("claim", "[results/demo.nc E_error level=eps05] >"),
    # an expr is a number or an error
    ("expr", "[results/demo.nc E_error level=eps05] > 0"),
    ("expr", "[results/demo.nc E_error level=eps05] / 0"),
    ("expr", "open('x')"),
])
def test_claim_conditions_and_exprs_are_restricted(tmp_path, directive, argument):
    source = make_paper(tmp_path, f"{{{{{directive} {argument}}}}}\n")
    with pytest.raises(ValueError):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")


def test_expr_computes_differences_and_ratios(tmp_path):
    # demo values: E_error 0.0123 at 5 %, 0.0456 at 10 % strain
    source = make_paper(tmp_path, "d = {{expr ([results/demo.nc E_error level=eps10] - [results/demo.nc E_error "
                                  "level=eps05]) * 100 | +.2f}}, r = {{expr [results/demo.nc E_error level=eps10] / "
                                  "[results/demo.nc E_error level=eps05]}}\n"
                                  "{{claim 1 < 2 | in a claim: {{expr 2 * [results/demo.nc E_error level=eps05] | .4f}}}}\n")
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert "d = +3.33, r = 3.71" in text
    assert "in a claim: 0.0246" in text


def test_a_missing_number_fails_the_build_but_not_the_quick_build(tmp_path):
    import xarray as xr

    source = make_paper(tmp_path, "x = {{value results/demo.nc E_error level=eps10}}, "
                                  "d = {{expr [results/demo.nc E_error level=eps10] * 2}}\n")
    path = tmp_path / "results" / "demo.nc"
    with xr.open_dataset(path) as ds:
        ds = ds.load()
    ds["E_error"][:] = np.nan
    ds.to_netcdf(path)
    with pytest.raises(ValueError, match="missing"):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")
    ds.attrs["quick"] = 1
    ds.to_netcdf(path)
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert f"x = {paper.QUICK_NA}, d = {paper.QUICK_NA}" in text


def _mark_quick(tmp_path):
    """Mark the demo result as the reduced quick build's (its attribute ``quick = 1``)."""
    import xarray as xr

    path = tmp_path / "results" / "demo.nc"
    with xr.open_dataset(path) as ds:
        ds = ds.load()
    ds.attrs["quick"] = 1
    ds.to_netcdf(path)


def test_a_label_the_quick_build_does_not_run_is_marked_not_an_error(tmp_path):
    """A quick study runs fewer points (e.g. fewer spring ratios): a value at a point it did not
    run is "n/a (quick build)" and a claim on it is marked; in a full build it is an error."""
    source = make_paper(tmp_path, "x = {{value results/demo.nc E_error level=eps99}}\n"
                                  "{{claim [results/demo.nc E_error level=eps99] < 1 | Small.}}\n")
    with pytest.raises(KeyError, match="no such label"):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")
    _mark_quick(tmp_path)
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert f"x = {paper.QUICK_NA}" in text
    assert "Small." + paper.QUICK_MARK in text


def test_false_claim_on_quick_results_is_marked(tmp_path):
    source = make_paper(tmp_path, "{{claim [results/demo.nc E_error level=eps10] < 0 | Negative.}}\n")
    _mark_quick(tmp_path)
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert "Negative." + paper.QUICK_MARK in text


def test_a_division_by_zero_fails_the_build_but_is_marked_in_the_quick_build(tmp_path):
    """A quick build may run a reference on the model's own mesh (an error of exactly 0): a ratio
    over it is "n/a (quick build)" and a claim on it is marked, never met; in a full build the
    division by zero fails the build."""
    source = make_paper(tmp_path, "r = {{expr [results/demo.nc E_error level=eps10] / "
                                  "([results/demo.nc E_error level=eps10] * 0)}}\n"
                                  "{{claim [results/demo.nc E_error level=eps10] / ([results/demo.nc E_error "
                                  "level=eps10] * 0) > 1 | Large.}}\n")
    with pytest.raises(ValueError, match="division by zero"):
        paper.fill(source, tmp_path / "paper" / "build" / "paper.md")
    _mark_quick(tmp_path)
    text = paper.fill(source, tmp_path / "paper" / "build" / "paper.md").read_text(encoding="utf-8")
    assert f"r = {paper.QUICK_NA}" in text
    assert "Large." + paper.QUICK_MARK in text


def test_values_and_claims_read_derived_facts_from_json(tmp_path):
    """``[paper/derivations.json MODULE.checks.NAME]``: a number the derivation computed; a missing
    key, a non-number and a false claim on it fail with one line."""
    import json

    (tmp_path / "paper").mkdir()
    (tmp_path / "paper" / "derivations.json").write_text(json.dumps(
        {"cube": {"checks": {"isotropic": 1.0, "E_axis": 1.0476190476190477}, "title": "a cube"}}))
    expand = paper.expand
    assert expand("{{value paper/derivations.json cube.checks.E_axis fmt=.4f}}", tmp_path / "paper", tmp_path) == "1.0476"
    assert expand("{{claim [paper/derivations.json cube.checks.isotropic] == 1 | Isotropic.}}", tmp_path / "paper",
                  tmp_path) == "Isotropic."
    with pytest.raises(ValueError, match="false claim"):
        expand("{{claim [paper/derivations.json cube.checks.E_axis] < 1 | Softer.}}", tmp_path / "paper", tmp_path)
    with pytest.raises(KeyError, match="no key 'shear'"):
        expand("{{value paper/derivations.json cube.checks.shear}}", tmp_path / "paper", tmp_path)
    with pytest.raises(ValueError, match="not a number"):
        expand("{{value paper/derivations.json cube.title}}", tmp_path / "paper", tmp_path)
    # the project's own derivation: the element-reading lattice is isotropic, the boundary reading's is not
    root = Path(__file__).resolve().parents[1]
    checks = json.loads((root / "paper" / "derivations.json").read_text())["cube_baudet"]["checks"]
    assert checks["element_reading_isotropic"] == 1 and checks["boundary_reading_isotropic"] == 0
    assert checks["boundary_reading_E_axis_at_nu_0_3"] == pytest.approx(2 * (4 * 0.3 + 1) / (4 * 0.3 + 3))

"""The documentation: every list it shows equals its registry, and the site builds with warnings as errors.

The site (``paper/docs`` -> HTML, Sphinx) is built once into a temporary folder (about 6 s); its
model and element tables are generated from the registries, and these tests read them back from
the HTML. The hand-written lists (the scene docstring's model table, the README's element list,
the API docstring's options) are compared with the registries directly.
"""

from __future__ import annotations

import html
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import msslib
import msslib.api
import msslib.scene
from derivations import registry as derivations
from msslib.models import names as model_names
from msslib.models import option_names

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    try:
        import sphinx  # noqa: F401  (a dependency of msslib: the workflow builds the site)
    except ImportError:
        pytest.fail("Sphinx is missing: python3 -m pip install -e '.[docs]'")
    out = tmp_path_factory.mktemp("docs")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html", str(ROOT / "paper" / "docs"),
                          str(out)], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert run.returncode == 0, f"the documentation does not build with -W:\n{run.stdout}\n{run.stderr}"
    return out


def _first_column(page: Path, css_class: str) -> list[str]:
    text = page.read_text()
    match = re.search(rf'<table[^>]*class="[^"]*\b{css_class}\b[^"]*"[^>]*>(.*?)</table>', text, re.S)
    assert match, f"{page.name} has no table of class {css_class}"
    body = match.group(1).split("<tbody>", 1)[1]
    rows = re.findall(r"<tr[^>]*>\s*<td[^>]*>\s*<p>\s*<code[^>]*>\s*<span[^>]*>([^<]+)</span>", body)
    assert len(rows) == body.count("<tr"), "every row starts with its name as code"
    return [html.unescape(r) for r in rows]


def test_site_builds_and_model_table_is_the_registry(site):
    assert _first_column(site / "models.html", "msslib-models") == list(model_names())
    # the registry holds every model its family modules declare (read here from their SPECS lists)
    from msslib.models import families
    assert len(model_names()) == sum(len(m.SPECS) for m in families())


def test_element_table_is_the_derivation_registry(site):
    listed = _first_column(site / "elements.html", "msslib-elements")
    assert listed == derivations.generated()
    assert set(derivations.names("elements")) <= set(listed)
    page = (site / "elements.html").read_text()
    for name in listed:  # each row links the page the workflow renders for it
        assert f'href="../derivations/{name}.html"' in page


def test_api_pages_cover_the_package_faces(site):
    faces = ["msslib", "msslib.mesh", "msslib.models", "msslib.terms", "msslib.solvers", "msslib.scene",
             "msslib.results", "msslib.export", "msslib.fem", "msslib.planning", "msslib.compare",
             "msslib.parameters", "msslib.metrics", "msslib.cli"]
    for face in faces:
        page = site / "api" / f"{face}.html"
        assert page.is_file(), face
        assert f'id="module-{face}"' in page.read_text(), face
    # a function of a face is documented with its docstring
    assert 'id="msslib.build_model"' in (site / "api" / "msslib.html").read_text()


def test_examples_page_shows_readme_sections_and_every_example_script(site):
    page = html.unescape(re.sub(r"<[^>]+>", "", (site / "examples.html").read_text()))
    assert "python3 -m msslib export bar.yaml" in page  # quick start
    assert "python3 -m msslib compare bar_mss.nc bar_fem.nc" in page  # your model against FEM
    scripts = sorted(p.name for p in (ROOT / "experiments" / "examples").glob("*.py") if not p.name.startswith("_"))
    assert scripts
    for name in scripts:
        assert f"experiments/examples/{name}" in page
    scene = html.unescape(re.sub(r"<[^>]+>", "", (site / "scene.html").read_text()))
    assert "Syntax reference" in scene and "SELECTION" in scene


def _scene_row(name: str, fmt: str = "{:28s} {:12s} {:s}") -> str:
    """The row of model ``name`` in the scene docstring's table: name, cell types, terms."""
    from msslib.models import get

    spec = get(name)
    return fmt.format(f"``{name}``", ", ".join(spec.cells), ", ".join(f"``{t}``" for t in spec.terms)).rstrip()


def test_scene_docstring_names_every_model():
    doc = msslib.scene.__doc__
    table = re.search(r"\n( *)=+ =+ =+\n\s*model\s+cells.*?\n *=+ =+ =+\n(.*?)\n *=+ =+ =+\n", doc, re.S)
    assert table, "the scene docstring has its table of mass-spring models"
    rows = [line.strip() for line in table.group(2).splitlines()]
    if [re.sub(r"\s+", " ", r) for r in rows] != [_scene_row(n, "{:s} {:s} {:s}") for n in model_names("mss")]:
        pytest.fail("the scene docstring's model table (msslib/scene/__init__.py) is not the registry; its rows "
                    "should read:\n" + "\n".join(table.group(1) + _scene_row(n) for n in model_names("mss")))
    for name in model_names("fem"):
        assert f"``{name}``" in doc


def test_readme_element_list_is_the_derivation_registry():
    readme = (ROOT / "README.md").read_text()
    bullet = re.search(r"^\* \*\*Derivations\*\*(.*?)^\* \*\*", readme, re.S | re.M)
    assert bullet
    # the bare names in backticks (paths and commands have / . or spaces)
    listed = re.findall(r"`([a-z_]+)`", bullet.group(1))
    assert sorted(listed) == sorted(derivations.names("elements"))


def test_api_docstring_lists_every_build_model_option():
    doc = msslib.api.build_model.__doc__
    keywords = [p.name for p in inspect.signature(msslib.api.build_model).parameters.values()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    assert keywords == ["fixed", "loads", "thickness", "solver", "checks"]
    missing = [k for k in keywords if not re.search(rf"^\s*{k} :", doc, re.M)]
    options = ["published", "terms", *option_names()]
    missing += [o for o in options if f"``{o}``" not in doc]
    assert not missing, f"build_model's docstring does not name {missing}"


def _chromium() -> str:
    """Debian's chromium, installed with apt-get where missing (as root); else one clear failure."""
    import os
    import shutil

    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found:
        return found
    if os.geteuid() != 0 or not shutil.which("apt-get"):
        pytest.fail("the headless-browser check needs chromium: install Debian's package (apt-get install -y chromium)")
    from system_packages import apt_install

    run = apt_install(["chromium"])  # one installing test at a time, waiting for dpkg's lock
    found = shutil.which("chromium")
    if run.returncode != 0 or not found:
        pytest.fail(f"apt-get install -y chromium failed (exit {run.returncode}): {run.stderr.strip()[-300:]}")
    return found


def test_site_renders_in_headless_chromium(site, tmp_path):
    browser = _chromium()
    flags = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1200,900"]
    dom = subprocess.run([*flags, "--dump-dom", (site / "models.html").as_uri()], capture_output=True, text=True,
                         timeout=120).stdout
    table = re.search(r'<table[^>]*msslib-models.*?</table>', dom, re.S)
    assert table, "the browser's DOM of models.html has no model table"
    for name in model_names():
        assert f">{name}<" in table.group(0), name
    shot = tmp_path / "index.png"
    subprocess.run([*flags, f"--screenshot={shot}", (site / "index.html").as_uri()], capture_output=True, timeout=120)
    data = shot.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height) == (1200, 900)
    assert len(data) > 10_000  # a rendered page, not a blank one (a blank 1200x900 PNG is a few kB)

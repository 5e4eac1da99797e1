"""Sphinx configuration of the msslib documentation (sources here, site in paper/build/docs/).

Build: ``python3 -m sphinx -W -b html paper/docs paper/build/docs`` from the repository root.
The docstrings are reStructuredText (``code``, :func: roles), read by autodoc as they are; the
model and element tables are generated from the registries by ``_ext/registry_tables.py``.
"""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path[:0] = [str(ROOT), str(HERE / "_ext")]

project = "msslib"
author = "msslib authors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon", "registry_tables"]
napoleon_google_docstring = False  # the few sectioned docstrings are numpy style (Parameters / -----)
autosummary_generate = False  # the module pages are the files of api/; autosummary only lists them
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the docstrings say what each argument is
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path = []
html_title = "msslib documentation"
# no link to a network resource: the site opens offline
html_theme_options = {"show_powered_by": False, "page_width": "95%", "body_max_width": "none"}  # the tables are wide

# The reST of the package's docstrings is the package's own: a docstring whose markup docutils
# reads with a complaint (an indented continuation it takes for a block quote, say) still renders,
# and its complaint is listed after the build (``DOCSTRING_NOTES``) instead of failing it.  Every
# other warning (a page of this site, a missing include, a table directive, a duplicate object)
# stays an error under ``-W``.
DOCSTRING_NOTES = []


def _docstring_notes(record):
    import logging

    where = str(getattr(record, "location", "") or "")
    if record.levelno >= logging.WARNING and "docstring of " in where and getattr(record, "type", None) == "docutils":
        note = f"{where}: {record.getMessage()}"
        if note not in DOCSTRING_NOTES:  # each handler of the logger sees the record
            DOCSTRING_NOTES.append(note)
        return False
    return True


def _report(app, exception):
    if DOCSTRING_NOTES:
        print(f"msslib docs: {len(DOCSTRING_NOTES)} docutils notes on package docstrings (rendered as written):")
        for note in DOCSTRING_NOTES:
            print(f"  {note}")


def setup(app):
    import logging

    for handler in logging.getLogger("sphinx").handlers:
        handler.filters.insert(0, _docstring_notes)
    app.connect("build-finished", _report)

"""Show a derivation's intermediate results as typeset math.

The element modules call these helpers where their matrices, equations, solutions and checks exist
(inside ``if __name__ == "__main__":`` cells, so that importing a module derives nothing). One call
works in three places:

- in Jupyter (IPython with a kernel), it displays ``IPython.display.Math`` (and ``Markdown`` for
  prose); IPython is imported only there;
- as a script (``python -m derivations.elements.triangle``), it prints a readable plain form
  (``sympy.pretty``);
- while :mod:`derivations.notebook` renders a module (inside :func:`collecting`), it appends
  Markdown with ``$$...$$`` display math (``sympy.latex``) to the collected output.

Labels are LaTeX (``K_{\\text{FEM}}``); the plain form drops the markup.
"""

from __future__ import annotations

import re
from contextlib import contextmanager

import sympy as sp

#: the list that collects ``("md", text)`` items while a module is rendered; ``None`` otherwise
_collected: list | None = None

#: equations listed before "... and N more" (a cube's exact match has dozens)
MAX_EQUATIONS = 12


@contextmanager
def collecting(items: list | None = None):
    """Collect what the helpers show, as Markdown items ``("md", text)`` in ``items``, instead of
    displaying or printing it."""
    global _collected
    previous, _collected = _collected, ([] if items is None else items)
    try:
        yield _collected
    finally:
        _collected = previous


def _in_jupyter() -> bool:
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def plain(tex: str) -> str:
    """A LaTeX label as plain text: ``K_{\\text{FEM}}`` -> ``K_FEM``."""
    s = re.sub(r"\\(?:text|mathrm|operatorname)\{([^{}]*)\}", r"\1", tex)
    for _ in range(3):  # nested fractions and roots, innermost first
        s = re.sub(r"\\[td]?frac\{([^{}]*)\}\{([^{}]*)\}", r"(\1)/(\2)", s)
        s = re.sub(r"\\sqrt\{([^{}]*)\}", r"sqrt(\1)", s)
    s = re.sub(r"\\([A-Za-z]+)", r"\1", s).replace("\\,", " ").replace("\\ ", " ")
    return s.replace("{", "").replace("}", "")


def _tex(expr) -> str:
    return expr if isinstance(expr, str) else sp.latex(expr)


def _emit(tex: str, text: str) -> None:
    """Display math ``tex`` (Jupyter, rendering) or print ``text`` (script)."""
    if _collected is not None:
        _collected.append(("md", f"$${tex}$$"))
    elif _in_jupyter():
        from IPython.display import Math, display
        display(Math(tex))
    else:
        print(text)


def note(markdown: str) -> None:
    """A sentence of prose (Markdown; ``$...$`` math allowed) beside the math."""
    if _collected is not None:
        _collected.append(("md", markdown))
    elif _in_jupyter():
        from IPython.display import Markdown, display
        display(Markdown(markdown))
    else:
        print(markdown)


def math(label: str, expr) -> None:
    """``label = expr`` (``expr`` a SymPy object or a LaTeX string; ``label`` LaTeX, may be empty)."""
    tex = f"{label} = {_tex(expr)}" if label else _tex(expr)
    if isinstance(expr, str):
        text = f"{plain(label)} = {plain(expr)}" if label else plain(expr)
    else:
        pretty = sp.pretty(expr, use_unicode=True, wrap_line=False)
        text = f"{plain(label)} =\n{pretty}" if label and "\n" in pretty else (f"{plain(label)} = {pretty}" if label else pretty)
    _emit(tex, text)


def matrix(label: str, M: sp.Matrix, rows=None, cols=None, what: str | None = None) -> None:
    """A matrix, or its block ``M[rows, cols]`` (slices) with a sentence saying which block of how
    big a matrix it is (``what`` adds to the sentence)."""
    if rows is None and cols is None:
        if what:
            note(what)
        math(label, M)
        return
    rows, cols = rows or slice(None), cols or slice(None)
    block = M[rows, cols]
    r0, c0 = rows.start or 0, cols.start or 0
    note(f"Rows {r0 + 1}-{r0 + block.rows}, columns {c0 + 1}-{c0 + block.cols} of the "
         f"{M.rows} x {M.cols} matrix ${label}$" + (f": {what}" if what else "") + ".")
    math(label + f"[{r0 + 1}{{:}}{r0 + block.rows},\\ {c0 + 1}{{:}}{c0 + block.cols}]", block)


def equations(label: str, eqs, limit: int = MAX_EQUATIONS) -> None:
    """A system ``e = 0`` for each ``e`` in ``eqs`` (the first ``limit``, and how many more)."""
    eqs = list(eqs)
    shown = eqs[:limit]
    tex = "\\begin{aligned}" + " \\\\ ".join(f"{sp.latex(e)} &= 0" for e in shown) + "\\end{aligned}"
    more = len(eqs) - len(shown)
    if _collected is None and not _in_jupyter():
        print(f"{plain(label)}: {len(eqs)} equations")
        for e in shown:
            print(f"  {sp.sstr(e)} = 0")
        if more:
            print(f"  ... and {more} more")
        return
    note(f"${label}$: {len(eqs)} distinct equations" + (f", the first {len(shown)} shown" if more else "") + ":")
    _emit(tex, "")


def solution(label: str, sol: dict) -> None:
    """A solution ``{symbol: value}``, one line per symbol."""
    if _collected is None and not _in_jupyter():
        print(f"{plain(label)}:")
        for key, v in sol.items():
            print(f"  {key} = {sp.sstr(v)}")
        return
    note(f"${label}$:")
    _emit("\\begin{aligned}" + " \\\\ ".join(f"{sp.latex(key)} &= {sp.latex(v)}" for key, v in sol.items())
          + "\\end{aligned}", "")


def check(statement: str, holds: bool) -> None:
    """A check: the LaTeX ``statement`` and whether it holds."""
    mark = "holds" if holds else "FAILS"
    if _collected is None and not _in_jupyter():
        print(f"check: {plain(statement)}: {mark}")
        return
    note(f"Check ({mark}):")
    _emit(statement, "")


def summary(derivation):
    """Print what a module's ``derive()`` hands on (its title and findings, one line each) and
    return it: the closing cell of every derivation module."""
    print(derivation.title)
    for label, text in derivation.findings:
        print(f"  {label}: {text}")
    return derivation

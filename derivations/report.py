"""Write the derivations' errata and findings for the paper (``paper/errata.md``,
``paper/derivations.md``, ``paper/derivations.json``)."""

from __future__ import annotations

import json
from pathlib import Path

import sympy as sp

from derivations import registry

ROOT = Path(__file__).resolve().parent.parent


def _errata_md(derivations) -> str:
    out = ["## Errata in the founding papers", "",
           "Generated from `derivations/` by `python -m derivations.codegen`; do not edit. Each entry names the "
           "test that proves it.", ""]
    n = 0
    for m, d in derivations.items():
        for e in d.errata:
            n += 1
            out += [f"### {n}. {e.paper}, {e.where}", "",
                    f"- printed: ${e.printed}$", f"- derived: ${e.correct}$", "",
                    e.explanation, "", f"Proof: `{e.proof}` (derivation `{registry.relpath(m)}`).", ""]
    return "\n".join(out)


def _split_top_level(tex: str, sep: str = ",\\ ") -> list[str]:
    """``tex`` cut at every ``sep`` outside braces, brackets and parentheses (so that a matrix, a
    ``\\left( ... \\right)`` or a ``\\text{...}`` is never cut)."""
    parts, depth, start, i = [], 0, 0, 0
    while i < len(tex):
        c = tex[i]
        if c == "\\":  # a command or an escaped symbol: only \\{ and \\} group (a set)
            depth += {"{": 1, "}": -1}.get(tex[i + 1:i + 2], 0)
            i += 2
            continue
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        elif depth == 0 and tex.startswith(sep, i):
            parts.append(tex[start:i])
            start = i = i + len(sep)
            continue
        i += 1
    return parts + [tex[start:]]


DISPLAY_LENGTH = 90  # findings longer than this (in LaTeX characters) are set as display math


def _finding_math(tex: str) -> str:
    """A finding's LaTeX as Markdown math: inline when short, else display math, one equation
    per line (an inline formula cannot break across lines in a browser)."""
    if len(tex) <= DISPLAY_LENGTH and "\\begin{" not in tex:
        return f"${tex}$"
    parts = [p.strip() for p in _split_top_level(tex)]
    lines = [p + "," for p in parts[:-1]] + parts[-1:]
    return " ".join(f"$${line}$$" for line in lines)


def _findings_md(derivations) -> str:
    out = ["## Derivation results", "", "Generated from `derivations/`; do not edit.", ""]
    for m, d in derivations.items():
        if not d.findings:
            continue
        out += [f"### {d.title}", "", f"Source: `{registry.relpath(m)}`", ""]
        for label, text in d.findings:
            is_tex = "\\" in text or "=" in text  # LaTeX (words in \\text{}); else plain words
            out.append(f"- **{label}**: {_finding_math(text)}" if is_tex else f"- **{label}**: {text}")
        out.append("")
    return "\n".join(out)


def write(derivations) -> None:
    paper = ROOT / "paper"
    paper.mkdir(exist_ok=True)
    (paper / "errata.md").write_text(_errata_md(derivations))
    (paper / "derivations.md").write_text(_findings_md(derivations))
    data = {m: {"title": d.title,
                "formulas": {f.name: {k: sp.srepr(v) for k, v in f.outputs.items()} for f in d.formulas if registry.kind(m) == "elements"},
                "findings": dict(d.findings),
                "checks": {k: float(v) for k, v in d.checks.items()},
                "errata": [e.__dict__ for e in d.errata]} for m, d in derivations.items()}
    data["summary"] = {"errata": float(sum(len(d.errata) for d in derivations.values()))}
    (paper / "derivations.json").write_text(json.dumps(data, indent=1, sort_keys=True))

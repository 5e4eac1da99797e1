"""Write the derivations' errata and findings for the paper (``paper/errata.md``,
``paper/derivations.md``, ``paper/derivations.json``)."""

from __future__ import annotations

import json
from pathlib import Path

import sympy as sp

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
                    e.explanation, "", f"Proof: `{e.proof}` (derivation `derivations/{m}.py`).", ""]
    return "\n".join(out)


def _findings_md(derivations) -> str:
    out = ["## Derivation results", "", "Generated from `derivations/`; do not edit.", ""]
    for m, d in derivations.items():
        if not d.findings:
            continue
        out += [f"### {d.title}", "", f"Source: `derivations/{m}.py`", ""]
        for label, text in d.findings:
            out.append(f"- **{label}**: ${text}$" if "\\" in text or "=" in text else f"- **{label}**: {text}")
        out.append("")
    return "\n".join(out)


def write(derivations) -> None:
    paper = ROOT / "paper"
    paper.mkdir(exist_ok=True)
    (paper / "errata.md").write_text(_errata_md(derivations))
    (paper / "derivations.md").write_text(_findings_md(derivations))
    data = {m: {"title": d.title,
                "formulas": {f.name: {k: sp.srepr(v) for k, v in f.outputs.items()} for f in d.formulas if m != "kernels"},
                "findings": dict(d.findings),
                "errata": [e.__dict__ for e in d.errata]} for m, d in derivations.items()}
    (paper / "derivations.json").write_text(json.dumps(data, indent=1, sort_keys=True))

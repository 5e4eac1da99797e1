"""Generate ``msslib/generated/`` from the derivations.

    python -m derivations.codegen            # (re)write the generated modules
    python -m derivations.codegen --check    # exit 1 when a generated module is stale or edited
    python -m derivations.codegen --check --full   # re-derive everything and compare the text

Every generated module records the SHA-256 of the derivation sources it came from (the engine and
the element module) and of its own body. ``--check`` recomputes both: a changed derivation or a
hand edit makes it fail, without re-deriving. ``--full`` re-derives and compares byte for byte.
The errata collected from the derivations are written to ``paper/errata.md`` and the symbolic
findings to ``paper/derivations.md``.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import sys
from pathlib import Path

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "msslib" / "generated"
ENGINE = ["__init__.py", "elasticity.py", "fem.py", "mss.py", "match.py", "lattice.py", "records.py", "codegen.py"]
MODULES = ["triangle", "square", "rectangle", "tetrahedron", "cube_baudet", "cube_golec", "kernels"]


def source_hash(module: str) -> str:
    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in ENGINE + [f"{module}.py"]:
        h.update(name.encode())
        h.update((here / name).read_bytes())
    return h.hexdigest()


class _Printer(NumPyPrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": False})


def _function_code(f) -> str:
    printer = _Printer()
    names = list(f.outputs)
    exprs = [f.outputs[n] for n in names]
    subs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_c"), optimizations="basic")
    args = ", ".join(str(a) for a in f.args)
    lines = [f"def {f.name}({args}):", f'    """{f.doc}', "", f"    Returns ({', '.join(names)}).", '    """']
    for s, e in subs:
        lines.append(f"    {s} = {printer.doprint(e)}")
    if len(names) == 1:
        lines.append(f"    return {printer.doprint(reduced[0])}")
    else:
        lines.append("    return (")
        for e in reduced:
            lines.append(f"        {printer.doprint(e)},")
        lines.append("    )")
    return "\n".join(lines)


def render(module: str, derivation=None) -> str:
    mod = importlib.import_module(f"derivations.{module}")
    d = derivation or mod.derive()
    body = [f'"""{d.title}.', "", f"Generated from derivations/{module}.py by `python -m derivations.codegen`; do not edit.",
            '"""', "", "from numpy import sqrt  # noqa: F401", ""]
    body += ["", f"OUTPUTS = {{{', '.join(repr(f.name) + ': ' + repr(tuple(f.outputs)) for f in d.formulas + d.published)}}}", ""]
    for f in d.formulas:
        body += ["", _function_code(f), ""]
    for f in d.published:
        body += ["", _function_code(f), ""]
    text = "\n".join(body).rstrip() + "\n"
    digest = hashlib.sha256(text.encode()).hexdigest()
    header = (f"# Generated from derivations/{module}.py by `python -m derivations.codegen`. Do not edit.\n"
              f"# source-sha256: {source_hash(module)}\n# body-sha256: {digest}\n")
    return header + text


def _read_header(path: Path):
    lines = path.read_text().splitlines(keepends=True)
    src = lines[1].split(":", 1)[1].strip() if len(lines) > 2 else ""
    body = lines[2].split(":", 1)[1].strip() if len(lines) > 2 else ""
    return src, body, "".join(lines[3:])


def check(full: bool = False) -> list[str]:
    problems = []
    for m in MODULES:
        path = OUT / f"{m}.py"
        if not path.exists():
            problems.append(f"{path.relative_to(ROOT)} is missing")
            continue
        src, body, text = _read_header(path)
        if src != source_hash(m):
            problems.append(f"{path.relative_to(ROOT)} is stale: derivations/{m}.py or the engine changed")
        if body != hashlib.sha256(text.encode()).hexdigest():
            problems.append(f"{path.relative_to(ROOT)} was edited by hand")
        if full and path.read_text() != render(m):
            problems.append(f"{path.relative_to(ROOT)} differs from a fresh derivation")
    return problems


def write_all(modules=MODULES) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    init = OUT / "__init__.py"
    init.write_text('"""Code generated from ``derivations/`` by ``python -m derivations.codegen``; do not edit."""\n')
    derivations = {}
    for m in modules:
        mod = importlib.import_module(f"derivations.{m}")
        derivations[m] = mod.derive()
        (OUT / f"{m}.py").write_text(render(m, derivations[m]))
        print(f"wrote msslib/generated/{m}.py", flush=True)
    if set(modules) == set(MODULES):
        from derivations import report
        report.write(derivations)
    else:  # the paper's errata and findings need every module: leave them to a full run
        print("paper/errata.md and paper/derivations.* not rewritten (only some modules derived)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m derivations.codegen", description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="fail when generated code is stale or edited")
    p.add_argument("--full", action="store_true", help="with --check: re-derive and compare the text")
    p.add_argument("modules", nargs="*", help="only these derivation modules")
    args = p.parse_args(argv)
    if args.check:
        problems = check(args.full)
        for pr in problems:
            print(pr, file=sys.stderr)
        if problems:
            print("run `python -m derivations.codegen` to regenerate", file=sys.stderr)
            return 1
        print("generated code is up to date")
        return 0
    write_all(args.modules or MODULES)
    return 0


if __name__ == "__main__":
    sys.exit(main())

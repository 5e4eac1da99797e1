"""Generate ``msslib/generated/`` from the derivations.

    python -m derivations.codegen            # (re)write the generated modules
    python -m derivations.codegen --check    # exit 1 when a generated module is stale or edited
    python -m derivations.codegen --check --full   # re-derive everything and compare the text

Every generated module records the SHA-256 of the derivation sources it came from (the engine and
the element module) and of its own body. ``--check`` recomputes both: a changed derivation or a
hand edit makes it fail, without re-deriving. ``--full`` re-derives and compares byte for byte.
The errata collected from the derivations are written to ``paper/errata.md`` and the symbolic
findings to ``paper/derivations.md``.

A full run also writes one C99 header, ``msslib/generated/msslib_mss.h`` (:data:`C_HEADER`): every
formula of every module (spring constants, rest-length factors, volume coefficients, and the
energy, gradient and Hessian kernels) printed from the same SymPy expressions and the same common
subexpressions as the Python modules, by SymPy's C99 printer. Its functions are ``static inline``
unless ``MSSLIB_API`` is defined before the header is included (define it empty to compile the
header into a library). It carries the same two hash lines, over the engine and every module, and
``--check`` checks it like the Python modules.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import sys
from pathlib import Path

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "msslib" / "generated"
ENGINE = ["__init__.py", "elasticity.py", "fem.py", "mss.py", "match.py", "lattice.py", "records.py", "codegen.py"]
MODULES = ["triangle", "square", "rectangle", "tetrahedron", "cube_baudet", "cube_golec", "kernels"]
C_HEADER = "msslib_mss.h"  # in OUT; generated from every module in MODULES


def source_hash(module: str) -> str:
    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in ENGINE + [f"{module}.py"]:
        h.update(name.encode())
        h.update((here / name).read_bytes())
    return h.hexdigest()


def c_source_hash() -> str:
    """SHA-256 of the engine and of every module the C header is printed from."""
    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in ENGINE + [f"{m}.py" for m in MODULES]:
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


class _CPrinter(C99CodePrinter):
    """SymPy's C99 printer without the non-standard ``M_SQRT2``-style macros."""

    def __init__(self):
        super().__init__({"math_macros": {}})


def _c_comment(text: str) -> str:
    return " ".join(text.split()).replace("*/", "* /").replace("/*", "/ *")


def _c_function_code(f, prefix: str = "msslib_") -> str:
    """One C function from a :class:`~derivations.records.Formula`, with the common subexpressions
    of the Python module (same ``sp.cse`` call). A single output is returned; several are written
    to ``out[0..n-1]`` in the order of ``f.outputs``."""
    printer = _CPrinter()
    names = list(f.outputs)
    exprs = [f.outputs[n] for n in names]
    subs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_c"), optimizations="basic")
    args = [f"double {a}" for a in f.args]
    doc = [f"/* {f.name}: {_c_comment(f.doc)}"]
    if len(names) == 1:
        doc.append(f" * Returns {names[0]}. */")
        head = f"MSSLIB_API double {prefix}{f.name}({', '.join(args)})"
    else:
        doc.append(f" * Writes out[0..{len(names) - 1}] = ({', '.join(names)}). */")
        head = f"MSSLIB_API void {prefix}{f.name}({', '.join(args + ['double *out'])})"
    lines = doc + [head, "{"]
    for sym, e in subs:
        lines.append(f"    const double {sym} = {printer.doprint(e)};")
    if len(names) == 1:
        lines.append(f"    return {printer.doprint(reduced[0])};")
    else:
        for i, e in enumerate(reduced):
            lines.append(f"    out[{i}] = {printer.doprint(e)};")
    lines.append("}")
    return "\n".join(lines)


def _c_index_macros(f, prefix: str = "MSSLIB_") -> list[str]:
    """``#define`` of the output count and (for named outputs, not g0/h0 kernel entries) of each
    output's index."""
    names = list(f.outputs)
    if len(names) == 1:
        return []
    base = f"{prefix}{f.name.upper()}"
    out = [f"#define {base}_N_OUT {len(names)}"]
    if not all(n[:1] in "gh" and n[1:].isdigit() for n in names):
        out += [f"#define {base}_{n.upper()} {i}" for i, n in enumerate(names)]
    return out


def render_c_header(derivations=None) -> str:
    """The text of :data:`C_HEADER` (``derivations``: module name -> ``derive()``, default: derive)."""
    derivations = dict(derivations or {})
    for m in MODULES:
        if m not in derivations:
            derivations[m] = importlib.import_module(f"derivations.{m}").derive()
    guard = "MSSLIB_MSS_H"
    body = ["/* Spring constants, rest-length factors, volume coefficients and the energy, gradient and",
            " * Hessian kernels of msslib's mass-spring models, in C99.",
            " *",
            " * Printed by SymPy's C99 printer from the expressions that the Python modules of",
            " * msslib/generated are printed from (the modules of derivations/), with the same common",
            " * subexpressions; `python -m derivations.codegen` writes both, do not edit.",
            " * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,",
            " * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).",
            " * Functions are `static inline` unless MSSLIB_API is defined before this header is",
            " * included (define it empty to compile them with external linkage, e.g. into a library).",
            " * Link with -lm. */",
            f"#ifndef {guard}", f"#define {guard}", "", "#include <math.h>", "",
            "#ifndef MSSLIB_API", "#define MSSLIB_API static inline", "#endif", "",
            "#ifdef __cplusplus", 'extern "C" {', "#endif"]
    seen = set()
    for m in MODULES:
        d = derivations[m]
        body += ["", f"/* ---- derivations/{m}.py: {_c_comment(d.title)} ---- */"]
        for f in d.formulas + d.published:
            if f.name in seen:
                raise ValueError(f"formula {f.name!r} is defined twice; C names must be unique")
            seen.add(f.name)
            macros = _c_index_macros(f)
            body += [""] + macros + ([""] if macros else []) + [_c_function_code(f)]
    body += ["", "#ifdef __cplusplus", "}", "#endif", "", f"#endif /* {guard} */"]
    text = "\n".join(body) + "\n"
    digest = hashlib.sha256(text.encode()).hexdigest()
    header = ("// Generated from derivations/ by `python -m derivations.codegen`. Do not edit.\n"
              f"// source-sha256: {c_source_hash()}\n// body-sha256: {digest}\n")
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
    path = OUT / C_HEADER
    if not path.exists():
        problems.append(f"{path.relative_to(ROOT)} is missing")
    else:
        src, body, text = _read_header(path)
        if src != c_source_hash():
            problems.append(f"{path.relative_to(ROOT)} is stale: a derivation module or the engine changed")
        if body != hashlib.sha256(text.encode()).hexdigest():
            problems.append(f"{path.relative_to(ROOT)} was edited by hand")
        if full and path.read_text() != render_c_header():
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
        (OUT / C_HEADER).write_text(render_c_header(derivations))
        print(f"wrote msslib/generated/{C_HEADER}", flush=True)
        from derivations import report
        report.write(derivations)
    else:  # the paper's errata and findings and the C header need every module: leave them to a full run
        print(f"paper/errata.md, paper/derivations.* and msslib/generated/{C_HEADER} not rewritten "
              f"(only some modules derived)")


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

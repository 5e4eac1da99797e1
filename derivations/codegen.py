"""Generate ``msslib/generated/`` from the derivation modules that :mod:`derivations.registry` finds.

    python -m derivations.codegen            # (re)write every generated file and the paper's derivation files
    python -m derivations.codegen rectangle  # (re)write one module's generated files only
    python -m derivations.codegen --check    # exit 1 when a generated file is stale, edited or orphaned
    python -m derivations.codegen --check --full   # re-derive everything and compare the text

Every module of ``derivations/elements/`` and ``derivations/terms/`` becomes
``msslib/generated/<name>.py`` (numpy functions) and ``msslib/generated/c/msslib_<name>.h`` (C99).
Each of the two records the SHA-256 of the derivation sources it came from, the engine (every file
directly in ``derivations/``, :func:`derivations.registry.engine_files`) and its own module, and
of its own body. ``--check`` recomputes both: a changed derivation or a hand edit makes it fail,
without re-deriving. Adding a module changes no other module's hash. ``--full`` re-derives and
compares byte for byte. The errata collected from the derivations are written to
``paper/errata.md`` and the symbolic findings to ``paper/derivations.md`` (full runs only).

The C headers (:func:`render_c`) print every formula of a module (spring constants, rest-length
factors, volume coefficients, and the energy, gradient and Hessian kernels) from the same SymPy
expressions and the same common subexpressions as the Python modules, by SymPy's C99 printer.
What every header shares is written once, to ``msslib/generated/c/msslib_api.h`` (:data:`C_API`,
:func:`render_c_api`): ``<math.h>``, the linkage macro and the ``extern "C"`` brackets. Functions
are ``static inline`` unless ``MSSLIB_API`` is defined before a header is included (define it
empty to compile them into a library). ``msslib/generated/c/msslib_mss.h`` (:data:`C_UMBRELLA`)
includes every module's header; it lists module names only (no hash) and is rewritten by every
run, so adding a module rewrites it. ``--check`` compares both files with their text.
"""

from __future__ import annotations

import argparse
import hashlib
import re
import sys
from pathlib import Path

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter

from derivations import registry

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "msslib" / "generated"
C_DIR = "c"  # the C headers, in OUT
C_UMBRELLA = "msslib_mss.h"  # in OUT / C_DIR: includes every module's header
C_API = "msslib_api.h"  # in OUT / C_DIR: what every module's header shares (included by each)


def c_header(module: str) -> str:
    """File name of a module's C header (in ``OUT / C_DIR``)."""
    return f"msslib_{module}.h"


def source_hash(module: str) -> str:
    """SHA-256 of the engine files and of the module's own source."""
    h = hashlib.sha256()
    for path in registry.engine_files() + [registry.path(module)]:
        h.update(path.relative_to(registry.ROOT).as_posix().encode())
        h.update(path.read_bytes())
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


def _derive(module: str, derivation=None):
    return derivation if derivation is not None else registry.module(module).derive()


def render(module: str, derivation=None) -> str:
    """The text of ``msslib/generated/<module>.py`` (``derivation``: its ``derive()``, default: derive)."""
    module = registry.resolve(module)
    d = _derive(module, derivation)
    src = registry.relpath(module)
    body = [f'"""{d.title}.', "", f"Generated from {src} by `python -m derivations.codegen`; do not edit.",
            '"""', "", "from numpy import sqrt  # noqa: F401", ""]
    if registry.kind(module) == "elements":
        body += ["", "# the simulator models whose parameters come from this module (its ELEMENT declaration)",
                 f"MODELS = {tuple(registry.element(module).models)!r}", ""]
    body += ["", f"OUTPUTS = {{{', '.join(repr(f.name) + ': ' + repr(tuple(f.outputs)) for f in d.formulas + d.published)}}}", ""]
    for f in d.formulas:
        body += ["", _function_code(f), ""]
    for f in d.published:
        body += ["", _function_code(f), ""]
    text = "\n".join(body).rstrip() + "\n"
    digest = hashlib.sha256(text.encode()).hexdigest()
    header = (f"# Generated from {src} by `python -m derivations.codegen`. Do not edit.\n"
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


def _c_index_enum(f, prefix: str = "MSSLIB_") -> list[str]:
    """One ``enum`` line: the index of each named output (not of g0/h0 kernel entries) and the
    output count ``..._N_OUT``; nothing for a single output."""
    names = list(f.outputs)
    if len(names) == 1:
        return []
    base = f"{prefix}{f.name.upper()}"
    if all(n[:1] in "gh" and n[1:].isdigit() for n in names):
        return [f"enum {{ {base}_N_OUT = {len(names)} }};"]
    return [f"enum {{ {', '.join(f'{base}_{n.upper()}' for n in names)}, {base}_N_OUT }};"]


def render_c_api() -> str:
    """The text of :data:`C_API`, included by every module's header (fixed: no hash)."""
    lines = ["// Generated by `python -m derivations.codegen`. Do not edit.",
             "/* What every C header of msslib/generated/c shares.",
             " * The headers are printed by SymPy's C99 printer from the expressions that the Python",
             " * modules of msslib/generated are printed from, with the same common subexpressions.",
             " * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,",
             " * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).",
             " * Functions are `static inline` unless MSSLIB_API is defined before a header is",
             " * included (define it empty to compile them with external linkage, e.g. into a library).",
             " * Link with -lm. */",
             "#ifndef MSSLIB_API_H", "#define MSSLIB_API_H", "", "#include <math.h>", "",
             "#ifndef MSSLIB_API", "#define MSSLIB_API static inline", "#endif", "",
             "#ifdef __cplusplus",
             '#define MSSLIB_BEGIN_DECLS extern "C" {',
             "#define MSSLIB_END_DECLS }",
             "#else",
             "#define MSSLIB_BEGIN_DECLS",
             "#define MSSLIB_END_DECLS",
             "#endif", "", "#endif /* MSSLIB_API_H */"]
    return "\n".join(lines) + "\n"


def render_c(module: str, derivation=None) -> str:
    """The text of ``msslib/generated/c/msslib_<module>.h`` (``derivation`` as for :func:`render`)."""
    module = registry.resolve(module)
    d = _derive(module, derivation)
    src = registry.relpath(module)
    guard = f"MSSLIB_{module.upper()}_H"
    body = [f"/* {_c_comment(d.title)}, in C99 (units and linkage: {C_API}).",
            f" * Printed from the expressions of msslib/generated/{module}.py ({src}). */",
            f"#ifndef {guard}", f"#define {guard}", "", f'#include "{C_API}"', "", "MSSLIB_BEGIN_DECLS"]
    seen = set()
    for f in d.formulas + d.published:
        if f.name in seen:
            raise ValueError(f"formula {f.name!r} is defined twice in {src}; C names must be unique")
        seen.add(f.name)
        body += [""] + _c_index_enum(f) + [_c_function_code(f)]
    body += ["", "MSSLIB_END_DECLS", "", f"#endif /* {guard} */"]
    text = "\n".join(body) + "\n"
    digest = hashlib.sha256(text.encode()).hexdigest()
    header = (f"// Generated from {src} by `python -m derivations.codegen`. Do not edit.\n"
              f"// source-sha256: {source_hash(module)}\n// body-sha256: {digest}\n")
    return header + text


def render_c_umbrella(modules=None) -> str:
    """The text of :data:`C_UMBRELLA`: one ``#include`` per generated module (names only, no hash)."""
    modules = registry.generated() if modules is None else modules
    lines = ["// Generated from the modules of derivations/elements/ and derivations/terms/ by",
             "// `python -m derivations.codegen`. Do not edit; rewritten when a module is added.",
             "/* Every C header of msslib/generated/c: spring constants, rest-length factors, volume",
             " * coefficients and the energy, gradient and Hessian kernels of msslib's mass-spring models.",
             " * Each header also stands alone. */",
             "#ifndef MSSLIB_MSS_H", "#define MSSLIB_MSS_H", ""]
    lines += [f'#include "{c_header(m)}"' for m in modules]
    lines += ["", "#endif /* MSSLIB_MSS_H */"]
    return "\n".join(lines) + "\n"


_C_FUNCTION = re.compile(r"^MSSLIB_API (?:double|void) (\w+)\(", flags=re.M)


def _read_header(path: Path):
    lines = path.read_text().splitlines(keepends=True)
    src = lines[1].split(":", 1)[1].strip() if len(lines) > 2 else ""
    body = lines[2].split(":", 1)[1].strip() if len(lines) > 2 else ""
    return src, body, "".join(lines[3:])


def _check_file(path: Path, module: str, fresh, full: bool) -> list[str]:
    rel = path.relative_to(ROOT)
    if not path.exists():
        return [f"{rel} is missing"]
    problems = []
    src, body, text = _read_header(path)
    if src != source_hash(module):
        problems.append(f"{rel} is stale: {registry.relpath(module)} or the engine changed")
    if body != hashlib.sha256(text.encode()).hexdigest():
        problems.append(f"{rel} was edited by hand")
    if full and path.read_text() != fresh():
        problems.append(f"{rel} differs from a fresh derivation")
    return problems


def check(full: bool = False) -> list[str]:
    """What is wrong with ``msslib/generated/`` (empty: up to date)."""
    problems = []
    modules = registry.generated()
    c_dir = OUT / C_DIR
    derived = {}

    def fresh(m, fn):
        def text():
            if m not in derived:
                derived[m] = registry.module(m).derive()
            return fn(m, derived[m])
        return text

    for m in modules:
        problems += _check_file(OUT / f"{m}.py", m, fresh(m, render), full)
        problems += _check_file(c_dir / c_header(m), m, fresh(m, render_c), full)
    expected = {f"{m}.py" for m in modules} | {"__init__.py"}
    for path in sorted(OUT.glob("*.py")):
        if path.name not in expected:
            problems.append(f"{path.relative_to(ROOT)} has no derivation module (remove it)")
    expected = {c_header(m) for m in modules} | {C_UMBRELLA, C_API}
    for path in sorted(c_dir.glob("*.h")):
        if path.name not in expected:
            problems.append(f"{path.relative_to(ROOT)} has no derivation module (remove it)")
    for name, text, wrong in ((C_UMBRELLA, render_c_umbrella(modules), "does not include exactly the generated modules"),
                              (C_API, render_c_api(), "differs from what the code generator writes")):
        path = c_dir / name
        if not path.exists():
            problems.append(f"{path.relative_to(ROOT)} is missing")
        elif path.read_text() != text:
            problems.append(f"{path.relative_to(ROOT)} {wrong}")
    owner = {}
    for m in modules:  # every header goes into one translation unit: C names must be unique
        path = c_dir / c_header(m)
        for name in _C_FUNCTION.findall(path.read_text()) if path.exists() else []:
            if name in owner:
                problems.append(f"C function {name} is defined by both {owner[name]} and {m}")
            owner[name] = m
    return problems


def write_all(modules=None) -> None:
    """Write the generated files of ``modules`` (default: every module, and then the paper files)."""
    everything = registry.generated()
    modules = everything if not modules else [registry.resolve(m) for m in modules]
    unknown = [m for m in modules if m not in everything]
    if unknown:
        raise SystemExit(f"not a generated module (derivations/elements/ or derivations/terms/): {', '.join(unknown)}")
    c_dir = OUT / C_DIR
    c_dir.mkdir(parents=True, exist_ok=True)
    init = OUT / "__init__.py"
    init.write_text('"""Code generated from ``derivations/`` by ``python -m derivations.codegen``; do not edit."""\n')
    derivations = {}
    for m in modules:
        derivations[m] = registry.module(m).derive()
        (OUT / f"{m}.py").write_text(render(m, derivations[m]))
        (c_dir / c_header(m)).write_text(render_c(m, derivations[m]))
        print(f"wrote msslib/generated/{m}.py and msslib/generated/{C_DIR}/{c_header(m)}", flush=True)
    (c_dir / C_UMBRELLA).write_text(render_c_umbrella(everything))
    (c_dir / C_API).write_text(render_c_api())
    print(f"wrote msslib/generated/{C_DIR}/{C_UMBRELLA} and {C_API}", flush=True)
    if set(modules) == set(everything):
        from derivations import report

        for m in registry.names("analyses"):  # analyses generate no code; their results go to the paper files
            derivations[m] = registry.module(m).derive()
            print(f"derived the analysis {m}", flush=True)
        report.write(derivations)
    else:  # the paper's errata and findings need every module: leave them to a full run
        print("paper/errata.md and paper/derivations.* not rewritten (only some modules derived)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m derivations.codegen", description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="fail when generated code is stale or edited")
    p.add_argument("--full", action="store_true", help="with --check: re-derive and compare the text")
    p.add_argument("modules", nargs="*", help="only these derivation modules (names, e.g. rectangle)")
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
    write_all(args.modules)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The spring-constant formulas cannot be called with their arguments in the wrong order.

The generated C functions take their arguments in the derivation's order (``msslib_lloyd_tetrahedron_volume(E,
nu, l, out)``) and the Python functions their own (``lloyd_tetrahedron_volume(E, l=..., nu=...)``): every
public function of :mod:`msslib.parameters` takes only its first argument by position, so that a call
in the C order fails instead of returning a wrong constant, and the values by keyword agree with the C
functions compiled from the shipped headers.
"""

from __future__ import annotations

import ctypes
import inspect
import re
import shutil
import subprocess
import warnings
from dataclasses import fields, is_dataclass

import numpy as np
import pytest

from msslib import parameters
from msslib import export

#: the public functions of msslib.parameters (its classes and tables left out)
FUNCTIONS = {name: getattr(parameters, name) for name in parameters.__all__
             if inspect.isfunction(getattr(parameters, name))}
#: C argument name -> Python keyword, where they differ
C_NAMES = {"van_gelder_triangle": {"A_e": "area", "l": "length"}, "equivalent_edge_length": {"V": "volume"}}


def test_there_are_formulas_to_check():
    assert {"lloyd_tetrahedron_volume", "lloyd_tetrahedron", "golec_cube", "baudet_cube", "lloyd_triangle",
            "lsq_triangle", "delingette_triangle"} <= set(FUNCTIONS)


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_only_the_first_argument_is_positional(name):
    f = FUNCTIONS[name]
    params = list(inspect.signature(f).parameters.values())
    assert params[0].kind is inspect.Parameter.POSITIONAL_OR_KEYWORD, name
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params[1:]), (name, params)
    with pytest.raises(TypeError, match="positional argument"):
        f(1.0e6, 0.3, 1.0)


def test_the_c_order_raises_instead_of_a_wrong_constant():
    # the call that used to return k 117 times too large (E = 1e6 Pa, nu = 0.3, l = 0.01 m)
    with pytest.raises(TypeError, match="positional argument"):
        parameters.lloyd_tetrahedron_volume(1.0e6, 0.3, 0.01)
    k = parameters.lloyd_tetrahedron_volume(1.0e6, nu=0.3, l=0.01).k
    assert k == parameters.lloyd_tetrahedron_volume(1.0e6, l=0.01, nu=0.3).k
    # 2 sqrt(2) E l / (21 (1 + nu)) by hand
    assert k == pytest.approx(2.0 * np.sqrt(2.0) * 1.0e6 * 0.01 / (21.0 * 1.3), rel=1e-14)


def _outputs(result):
    if is_dataclass(result):
        return {f.name: getattr(result, f.name) for f in fields(result)}
    if isinstance(result, dict):  # a formula of many named constants (an exact element's)
        return dict(result)
    return {None: result}


@pytest.mark.parametrize("name, kwargs", [
    ("lloyd_triangle", dict(t=0.01, nu=0.3)),
    ("van_gelder_triangle", dict(t=0.01, area=0.5, length=1.2, nu=0.3)),
    ("lloyd_square", dict(t=0.01, nu=0.3)),
    ("lloyd_rectangle", dict(t=0.01, r=0.5, nu=0.3, fit="least_squares")),
    ("lloyd_tetrahedron", dict(l=0.02, nu=0.3)),
    ("lloyd_tetrahedron_volume", dict(l=0.02, nu=0.3, published=False)),
    ("baudet_cube", dict(nu=0.3, a=0.1, published=True)),
    ("golec_cube", dict(nu=0.3, a=0.1, A=0.7, published=False)),
    ("lsq_triangle", dict(nu=0.3, t=0.1, a=1.5, x2=0.4, y2=1.1)),
    ("delingette_triangle", dict(nu=0.3, t=0.1, a=1.5, x2=0.4, y2=1.1)),
    ("lsq_tetrahedron", dict(nu=0.3, points=np.array([[0, 0, 0], [1, 0, 0], [0.2, 0.9, 0], [0.3, 0.2, 1.1]]))),
    ("check_material", dict(nu=0.3, model="lloyd_triangle")),
])
def test_keyword_order_does_not_matter(name, kwargs):
    f = FUNCTIONS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", parameters.FormulaValidityWarning)
        forward = _outputs(f(2.0e6, **kwargs))
        backward = _outputs(f(2.0e6, **dict(reversed(list(kwargs.items())))))
    assert forward.keys() == backward.keys()
    for key in forward:
        np.testing.assert_array_equal(forward[key], backward[key])


def _compiled(tmp_path):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler (cc or gcc) on this machine")
    header = export.C_HEADER_PATH
    src = tmp_path / "formulas.c"
    src.write_text('#include "msslib_mss.h"\n')
    lib = tmp_path / "libformulas.so"
    subprocess.run([cc, "-std=c99", "-O1", "-fPIC", "-shared", "-DMSSLIB_API=", f"-I{header.parent}", str(src),
                    "-o", str(lib), "-lm"], check=True, capture_output=True)
    text = "\n".join(p.read_text(encoding="utf-8") for p in export.c_header_paths())
    return ctypes.CDLL(str(lib)), text


def _c_declaration(text, name):
    """``(argument names, output names)`` of ``msslib_NAME`` from its declaration and comment."""
    m = re.search(r"\* (?:Returns (\w+)\.|Writes out\[0\.\.\d+\] = \(([\w, ]+)\)\.) \*/\nMSSLIB_API (?:double|void) "
                  rf"msslib_{name}\(([^)]*)\)", text)
    if m is None:
        return None
    args = [a.split()[-1] for a in m.group(3).split(",") if "*" not in a]
    outputs = [m.group(1)] if m.group(1) else [s.strip() for s in m.group(2).split(",")]
    return args, outputs


def test_python_values_equal_the_c_functions(tmp_path):
    lib, text = _compiled(tmp_path)
    rng = np.random.default_rng(7)
    checked = []
    for name, f in FUNCTIONS.items():
        decl = _c_declaration(text, name)
        if decl is None:
            continue
        c_args, outputs = decl
        names = [C_NAMES.get(name, {}).get(a, a) for a in c_args]
        params = inspect.signature(f).parameters
        assert all(n in params for n in names), (name, names, list(params))
        cf = getattr(lib, f"msslib_{name}")
        cf.argtypes = [ctypes.c_double] * len(c_args) + ([ctypes.POINTER(ctypes.c_double)] if len(outputs) > 1 else [])
        cf.restype = ctypes.c_double if len(outputs) == 1 else None
        for _ in range(5):
            values = [float(rng.uniform(0.05, 0.45)) if a == "nu" else float(rng.uniform(-0.5, 0.5)) if a == "x2"
                      else float(rng.uniform(0.5, 2.0)) for a in c_args]
            if len(outputs) == 1:
                c = [cf(*values)]
            else:
                buf = (ctypes.c_double * len(outputs))()
                cf(*values, buf)
                c = list(buf)
            kwargs = dict(zip(names[1:], values[1:]))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", parameters.FormulaValidityWarning)
                got = _outputs(f(values[0], **kwargs))
            py = [got[None]] if None in got else [got[o] for o in outputs]
            np.testing.assert_allclose(py, c, rtol=1e-13, err_msg=name)
        checked.append(name)
    assert {"lloyd_tetrahedron_volume", "lloyd_tetrahedron", "lloyd_triangle", "van_gelder_triangle", "lloyd_square",
            "equivalent_edge_length", "baudet_cube", "golec_cube", "lsq_triangle", "delingette_triangle"} <= set(checked)

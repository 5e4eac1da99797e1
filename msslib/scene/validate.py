"""Validation helpers of the scene schema: strict YAML (duplicate keys are errors) and checks of
values whose every error names the key path (``scene.loads[1].traction: ...``)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping

import numpy as np
import yaml

AXES = ("x", "y", "z")


# --------------------------------------------------------------------------------------------
# YAML loading (duplicate keys are errors)
# --------------------------------------------------------------------------------------------


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader that rejects duplicate keys in a mapping."""


def _construct_mapping(loader, node, deep=False):
    seen = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                "while constructing a mapping", node.start_mark, f"found duplicate key {key!r}", key_node.start_mark)
        seen[key] = True
    return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)


_StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _parse_yaml(text: str, source: str):
    try:
        return yaml.load(text, Loader=_StrictLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        what = " ".join(str(x) for x in (exc.context, exc.problem) if x)
        raise ValueError(f"{source}{where}: invalid YAML: {what}") from None
    except yaml.YAMLError as exc:
        detail = " ".join(str(exc).split())
        raise ValueError(f"{source}: invalid YAML: {detail}") from None


# --------------------------------------------------------------------------------------------
# validation helpers: every error names the key path
# --------------------------------------------------------------------------------------------


def _fail(path: str, message: str):
    raise ValueError(f"{path}: {message}")


def _mapping(path, value, allowed, required=()):
    if not isinstance(value, Mapping):
        _fail(path, f"expected a mapping with keys {', '.join(sorted(allowed))}, got {value!r}")
    for key in value:
        if key not in allowed:
            hint = difflib.get_close_matches(str(key), list(allowed), n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            _fail(f"{path}.{key}", f"unknown key; expected one of {', '.join(sorted(allowed))}{did}")
    for key in required:
        if key not in value:
            _fail(f"{path}.{key}", "required key missing")
    return value


def _show(value) -> str:
    """A value as the user wrote it (numbers written as strings such as 1e6 without quotes)."""
    if isinstance(value, str):
        try:
            float(value)
            return value
        except ValueError:
            return repr(value)
    return repr(value)


def _number(path, value, *, low=None, high=None, low_open=True, high_open=True, what="a number"):
    if isinstance(value, bool) or value is None:
        _fail(path, f"expected {what}, got {value!r}")
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            _fail(path, f"expected {what}, got {value!r}")
    elif isinstance(value, (int, float, np.integer, np.floating)):
        try:
            number = float(value)
        except OverflowError:  # an integer beyond double precision
            number = math.inf
    else:
        _fail(path, f"expected {what}, got {value!r}")
    if not math.isfinite(number):
        _fail(path, f"expected a finite number, got {_show(value)}")
    if low is not None and (number <= low if low_open else number < low):
        _fail(path, f"must be {'>' if low_open else '>='} {low:g}, got {_show(value)}")
    if high is not None and (number >= high if high_open else number > high):
        _fail(path, f"must be {'<' if high_open else '<='} {high:g}, got {_show(value)}")
    return number


def _integer(path, value, minimum=1, maximum=None, why=""):
    number = _number(path, value, what="an integer")
    if number != int(number) or number < minimum:
        _fail(path, f"must be an integer >= {minimum}, got {_show(value)}")
    if maximum is not None and number > maximum:
        _fail(path, f"must be at most {maximum:g}{why}, got {_show(value)}")
    return int(number)


#: the most load steps, Newton iterations and time steps a scene may ask for: beyond them a run
#: cannot end in any useful time (a typo such as load_steps: 1e30 fails at once instead)
MAX_LOAD_STEPS = 10**5
MAX_NEWTON_ITERATIONS = 10**4
MAX_TIME_STEPS = 10**9


def _boolean(path, value):
    if not isinstance(value, bool):
        _fail(path, f"expected true or false, got {value!r}")
    return value


def _string(path, value):
    if not isinstance(value, str):
        _fail(path, f"expected a string, got {value!r}")
    return value


def _choice(path, value, choices, what):
    if not isinstance(value, str) or value not in choices:
        hint = difflib.get_close_matches(str(value), list(choices), n=1)
        did = f" (did you mean {hint[0]!r}?)" if hint else ""
        _fail(path, f"unknown {what} {value!r}; expected one of {', '.join(choices)}{did}")
    return value


def _vector(path, value, *, allow_null=False, length=None):
    if not isinstance(value, (list, tuple)) or not value:
        _fail(path, f"expected a list of numbers, got {value!r}")
    if length is not None and len(value) != length:
        _fail(path, f"expected {length} values, got {len(value)}: {value!r}")
    if len(value) not in (2, 3):
        _fail(path, f"expected 2 or 3 values (one per axis), got {len(value)}: {value!r}")
    out = []
    for i, v in enumerate(value):
        if v is None and allow_null:
            out.append(None)
        else:
            out.append(_number(f"{path}[{i}]", v))
    return out


def _list(path, value):
    if value is None:
        return []
    if not isinstance(value, list):
        _fail(path, f"expected a list, got {value!r}")
    return value


def _box(path, value):
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        _fail(path, f"expected [[min...], [max...]] (null for unbounded), got {value!r}")
    corners = []
    for i, corner in enumerate(value):
        corners.append(None if corner is None else _vector(f"{path}[{i}]", corner, allow_null=True))
    if corners[0] is not None and corners[1] is not None and len(corners[0]) != len(corners[1]):
        _fail(path, f"both corners need the same number of coordinates, got {value!r}")
    return corners


def _group_key(path, value):
    """A mesh group named in a scene: a name, or the number of a group without name."""
    if isinstance(value, bool) or not isinstance(value, (str, int)) or value == "":
        _fail(path, f"expected the name of a mesh group (or the number of an unnamed one), got {value!r}")
    return str(value)


def _selection(path, value):
    if value == "all":
        return {"all": True}
    if not isinstance(value, Mapping):
        _fail(path, f"expected 'all' or a mapping with plane, box and/or group, got {value!r}")
    _mapping(path, value, ("plane", "box", "group", "tol"))
    if "plane" not in value and "box" not in value and "group" not in value:
        _fail(path, "give plane, box and/or group (or write select: all)")
    out = {}
    if "group" in value:
        out["group"] = _group_key(f"{path}.group", value["group"])
    if "plane" in value:
        plane = value["plane"]
        if not isinstance(plane, (list, tuple)) or len(plane) != 2:
            _fail(f"{path}.plane", f"expected [axis, value] such as [z, 0.0], got {plane!r}")
        axis = plane[0]
        if axis in (0, 1, 2) and not isinstance(axis, bool):
            axis = AXES[axis]
        _choice(f"{path}.plane[0]", axis, AXES, "axis")
        out["plane"] = (axis, _number(f"{path}.plane[1]", plane[1]))
    if "box" in value:
        out["box"] = _box(f"{path}.box", value["box"])
    if "tol" in value:
        out["tol"] = _number(f"{path}.tol", value["tol"], low=0.0)
    return out


"""What meshio prints while it reads a file, collected for the reading thread alone.

meshio speaks through its helpers ``info``, ``warn`` and ``error`` (a rich console on
``sys.stderr``) and one ``print`` of its format dispatcher; :func:`collected` gathers those
messages as text while it is active, in the current thread (a :class:`contextvars.ContextVar`),
and leaves ``sys.stdout`` and ``sys.stderr`` alone: several threads may read files at once while
others print.  To that end the helpers are replaced, once, in every meshio module that imported
them, by wrappers that pass a message to the collector of the calling thread when it has one and
to meshio's own helper otherwise (so meshio used outside :func:`collected` prints as before).
"""

from __future__ import annotations

import builtins
import contextvars
import sys
import threading
from contextlib import contextmanager

_COLLECTOR: contextvars.ContextVar[list | None] = contextvars.ContextVar("msslib_meshio_messages", default=None)
_LOCK = threading.Lock()
_HELPERS = {"info": "Info", "warn": "Warning", "error": "Error"}  # meshio helper -> its label
_installed = False


def _routed(original, label):
    """``original`` (a meshio helper, or ``print``) sending its text to the active collector."""

    def helper(*args, **kwargs):
        messages = _COLLECTOR.get()
        if messages is None:
            return original(*args, **kwargs)
        if label is None:
            text = " ".join(str(a) for a in args)
        else:
            text = f"{label}: {args[0] if args else kwargs.get('string', '')}"
        messages.append(text)
        return None

    helper.__msslib_routed__ = original
    return helper


def _install() -> None:
    """Route meshio's helpers (idempotent; meshio imports all its format modules on import)."""
    global _installed
    if _installed:
        return
    import meshio  # noqa: F401 - loads every format module

    try:
        from meshio import _common
    except ImportError:  # pragma: no cover - a meshio without these helpers: nothing to route
        _installed = True
        return

    with _LOCK:
        if _installed:
            return
        originals = {}
        for name in _HELPERS:
            fn = getattr(_common, name, None)
            originals[name] = getattr(fn, "__msslib_routed__", fn)
        routed = {name: _routed(fn, _HELPERS[name]) for name, fn in originals.items() if fn is not None}
        for mod_name, mod in list(sys.modules.items()):
            if mod is None or not (mod_name == "meshio" or mod_name.startswith("meshio.")):
                continue
            for name, fn in originals.items():
                current = getattr(mod, name, None)
                if current is fn and fn is not None:
                    setattr(mod, name, routed[name])
            if mod_name == "meshio._helpers" and not hasattr(mod.__dict__.get("print"), "__msslib_routed__"):
                mod.print = _routed(builtins.print, None)  # the ReadError its dispatcher prints
        _installed = True


@contextmanager
def collected():
    """Collect what meshio says in this thread: yields the list of its messages (one string each,
    ``"Warning: ..."``, ``"Error: ..."``, ``"Info: ..."`` or the text it printed)."""
    _install()
    messages: list[str] = []
    token = _COLLECTOR.set(messages)
    try:
        yield messages
    finally:
        _COLLECTOR.reset(token)

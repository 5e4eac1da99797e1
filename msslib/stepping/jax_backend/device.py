"""Where the JAX backend runs: whether JAX is there (:func:`available`), the device it uses
(:func:`default_device`: the first GPU JAX sees, else its CPU), the scoped double-precision switch
(:func:`x64`) and the choice between the JAX backend and the numba CPU path (:func:`use_jax`)."""

from __future__ import annotations

import contextlib
import warnings

import numpy as np

from msslib.errors import MsslibWarning

PRECISIONS = {"double": np.float64, "single": np.float32}
BACKENDS = ("jax", "numba")


def available() -> tuple[bool, str]:
    """``(ok, reason)``: whether the JAX backend can run here, and a line that says on what
    (``"jax 0.10.2 on gpu (NVIDIA H100 80GB HBM3)"``) or why not (JAX missing or without a device)."""
    try:
        import jax
    except Exception as e:  # ImportError, or a broken install (missing jaxlib, CUDA plugin errors)
        return False, f"jax cannot be imported ({type(e).__name__}: {e}); install it with pip install jax"
    try:
        dev = default_device()
    except Exception as e:
        return False, f"jax {jax.__version__} has no usable device ({type(e).__name__}: {e})"
    return True, f"jax {jax.__version__} on {describe(dev)}"


def default_device(kind: str | None = None):
    """The JAX device of the backend: ``kind`` ``"gpu"`` (ValueError when JAX sees none),
    ``"cpu"``, or None: the first GPU when JAX sees one, else the CPU."""
    import jax

    if kind not in (None, "gpu", "cpu"):
        raise ValueError(f"device must be None, 'gpu' or 'cpu', got {kind!r}")
    if kind in (None, "gpu"):
        try:
            gpus = jax.devices("gpu")
        except RuntimeError:  # no GPU backend in this JAX install
            gpus = []
        if gpus:
            return gpus[0]
        if kind == "gpu":
            raise ValueError("device='gpu': JAX sees no GPU here (devices: "
                             f"{', '.join(str(d) for d in jax.devices())}); use device=None or 'cpu'")
    return jax.devices("cpu")[0]


def describe(dev) -> str:
    """``"gpu (NVIDIA H100 80GB HBM3)"``, ``"cpu"``: the platform and the device's kind."""
    kind = getattr(dev, "device_kind", "") or str(dev)
    return dev.platform if kind == dev.platform else f"{dev.platform} ({kind})"


def has_gpu() -> bool:
    ok, _ = available()
    return ok and default_device().platform == "gpu"


def x64():
    """A context in which JAX computes in double precision, scoped to the ``with`` block: the
    backend never flips JAX's global flag (a program that imports msslib keeps JAX's default).
    JAX >= 0.5 has ``jax.enable_x64``; 0.4 has ``jax.experimental.enable_x64``."""
    import jax

    state = getattr(jax, "enable_x64", None)
    if state is not None and callable(state):
        return state(True)
    try:
        from jax.experimental import enable_x64
    except ImportError:  # pragma: no cover - a JAX without either: the global flag, said in the docstrings
        jax.config.update("jax_enable_x64", True)
        return contextlib.nullcontext()
    return enable_x64()


def check_precision(precision: str):
    if precision not in PRECISIONS:
        raise ValueError(f"precision must be 'double' or 'single', got {precision!r}")
    return np.dtype(PRECISIONS[precision])


def use_jax(backend: str) -> bool:
    """Whether a caller that asks for ``backend`` (``"jax"`` or ``"numba"``) runs the JAX backend:
    ``"jax"`` without JAX falls back to the numba CPU path with a
    :class:`msslib.errors.MsslibWarning` naming the reason."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(map(repr, BACKENDS))}, got {backend!r}")
    if backend == "numba":
        return False
    ok, reason = available()
    if not ok:
        warnings.warn(f"backend 'jax' is not available ({reason}): running the numba CPU path instead",
                      MsslibWarning, stacklevel=3)
    return ok

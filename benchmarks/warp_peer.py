"""The peer of the stepping benchmark: a plain NVIDIA Warp kernel on its CPU device.

One kernel over the springs (force of each spring added to both nodes with atomics), one over the
nodes (symplectic Euler on the free dofs, the force reset), launched once per step: what a user
writes first in Warp.  The kernels are defined when first used (Warp compiles them, once, into
its own cache)."""


import time

import numpy as np

_KERNELS = {}


def _kernels(wp, precision):
    if precision in _KERNELS:
        return _KERNELS[precision]
    real = wp.float64 if precision == "double" else wp.float32
    vec = wp.vec3d if precision == "double" else wp.vec3f

    @wp.kernel
    def springs(x: wp.array(dtype=vec), a: wp.array(dtype=wp.int32), b: wp.array(dtype=wp.int32),
                k: wp.array(dtype=real), rest: wp.array(dtype=real), f: wp.array(dtype=vec)):
        s = wp.tid()
        i = a[s]
        j = b[s]
        d = x[j] - x[i]
        length = wp.length(d)
        fs = d * (k[s] * (length - rest[s]) / length)
        wp.atomic_add(f, i, fs)
        wp.atomic_sub(f, j, fs)

    @wp.kernel
    def update(x: wp.array(dtype=vec), v: wp.array(dtype=vec), f: wp.array(dtype=vec), fext: wp.array(dtype=vec),
               w: wp.array(dtype=vec), h: real):
        i = wp.tid()
        vi = v[i] + wp.cw_mul(w[i], f[i] + fext[i])
        v[i] = vi
        x[i] = x[i] + h * vi
        f[i] = vec(real(0.0), real(0.0), real(0.0))

    _KERNELS[precision] = (springs, update, real, vec)
    return _KERNELS[precision]


def run_warp(wp, x0, conn, k, rest, mass, free, fext, h, n_steps, precision="double"):
    """``(wall, positions)`` after ``n_steps`` steps from rest (positions as float64)."""
    wp.config.quiet = True
    wp.init()
    springs, update, real, vec = _kernels(wp, precision)
    dtype = np.float64 if precision == "double" else np.float32
    dev = "cpu"
    nn = x0.size // 3
    x = wp.array(x0.reshape(-1, 3).astype(dtype), dtype=vec, device=dev)
    v = wp.zeros(nn, dtype=vec, device=dev)
    f = wp.zeros(nn, dtype=vec, device=dev)
    fe = wp.array(fext.reshape(-1, 3).astype(dtype), dtype=vec, device=dev)
    w = wp.array((h / mass * free).reshape(-1, 3).astype(dtype), dtype=vec, device=dev)
    a = wp.array(conn[:, 0].astype(np.int32), dtype=wp.int32, device=dev)
    b = wp.array(conn[:, 1].astype(np.int32), dtype=wp.int32, device=dev)
    kk = wp.array(k.astype(dtype), dtype=real, device=dev)
    ll = wp.array(rest.astype(dtype), dtype=real, device=dev)
    hh = real(h)
    s = len(k)
    wp.launch(springs, dim=s, inputs=[x, a, b, kk, ll, f], device=dev)  # compile or load (not timed)
    f.zero_()
    wp.synchronize()
    t = time.perf_counter()
    for _ in range(n_steps):
        wp.launch(springs, dim=s, inputs=[x, a, b, kk, ll, f], device=dev)
        wp.launch(update, dim=nn, inputs=[x, v, f, fe, w, hh], device=dev)
    wp.synchronize()
    return time.perf_counter() - t, x.numpy().astype(np.float64).ravel()

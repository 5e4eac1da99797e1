"""MuJoCo as a peer of the stepping benchmark: the network's springs as spatial tendons between
slide-joint bodies (as :mod:`msslib.export` writes MJCF), gravity, no contacts, Euler integrator
at the same step."""

from __future__ import annotations

import numpy as np


def _f(v) -> str:
    return repr(float(v))


def mjcf(model, dt: float) -> str:
    springs = [t for t in model.terms if t.kind == "springs"]
    conn = np.concatenate([t.conn for t in springs])
    k = np.concatenate([t.k for t in springs])
    rest = np.concatenate([t.rest_length for t in springs])
    p = model.x0.reshape(-1, 3)
    fixed = np.asarray(model.fixed).reshape(-1, 3)
    m = model.node_masses
    lines = ['<mujoco model="network">', f'<option timestep="{_f(dt)}" gravity="0 0 -9.81" integrator="Euler">',
             '<flag contact="disable"/></option>', "<worldbody>"]
    for i in range(len(p)):
        lines.append(f'<body name="n{i}" pos="{_f(p[i, 0])} {_f(p[i, 1])} {_f(p[i, 2])}">')
        if not fixed[i].all():
            lines.append(f'<inertial pos="0 0 0" mass="{_f(m[i])}" diaginertia="1e-12 1e-12 1e-12"/>')
            for a, axis in enumerate(("1 0 0", "0 1 0", "0 0 1")):
                if not fixed[i, a]:
                    lines.append(f'<joint name="n{i}_{a}" type="slide" axis="{axis}"/>')
        lines.append(f'<site name="n{i}" size="1e-4"/></body>')
    lines.append("</worldbody><tendon>")
    for (i, j), kk, ll in zip(conn, k, rest):
        lines.append(f'<spatial stiffness="{_f(kk)}" springlength="{_f(ll)}" width="1e-5"><site site="n{i}"/>'
                     f'<site site="n{j}"/></spatial>')
    lines.append("</tendon></mujoco>")
    return "\n".join(lines)

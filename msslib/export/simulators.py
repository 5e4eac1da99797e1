"""The simulator formats of ``msslib export``: a MuJoCo model (MJCF) and a SOFA scene.

Both carry the springs, node masses, fixed and prescribed dofs, loads and gravity of an
:class:`msslib.export.model.MssExport` (see :mod:`msslib.export.model` for the mapping of each); neither can
carry a volume term, and both files say so in a comment when the model has one.  The MJCF sizes
MuJoCo's arena from the model (``<size memory>``, :func:`mjcf_memory`).
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from msslib.errors import MsslibWarning
from msslib.mesh import cells as _cells
from msslib.export.model import AXES, MssExport, _pad3, _safe_name, _version, not_carried

__all__ = ["SOFA_COMPONENTS", "SOFA_TARGET", "MJCF_SAFETY", "MJCF_ARENA_BYTES_PER_ELEMENT", "MJCF_ARENA_MIN",
           "MjcfStep", "time_step", "stability_limit", "mjcf_time_step", "mjcf_memory", "mjcf_text", "sofa_text"]

#: SOFA components and the attributes the scene uses, for SOFA v24.06 and later: for each component
#: class the plugin that registers it, its Data names (the XML attributes, as declared by
#: ``initData`` in the SOFA sources) and the source file that declares them (sofa-framework/sofa).
#: For example SpringForceField's Data ``spring`` holds ``m1 m2 ks kd initpos`` per spring
#: (LinearSpring), FixedProjectiveConstraint's ``indices``. :func:`sofa_text` writes nothing else.
SOFA_TARGET = "SOFA v24.06 or later"
_SRC = "Sofa/Component/"
SOFA_COMPONENTS = {
    "Node": {"plugin": None, "attributes": ("name", "gravity", "dt"),
             "source": "Sofa/framework/Core/src/sofa/core/objectmodel/Context.cpp"},
    "RequiredPlugin": {"plugin": None, "attributes": ("name",),
                       "source": "Sofa/framework/Simulation/Core/src/sofa/simulation/RequiredPlugin.cpp"},
    "DefaultAnimationLoop": {"plugin": "Sofa.Simulation.Core", "attributes": ("name",),
                             "source": "Sofa/framework/Simulation/Core/src/sofa/simulation/DefaultAnimationLoop.cpp"},
    "StaticSolver": {"plugin": "Sofa.Component.ODESolver.Backward",
                     "attributes": ("name", "newton_iterations", "relative_residual_tolerance_threshold",
                                    "absolute_residual_tolerance_threshold", "relative_correction_tolerance_threshold",
                                    "absolute_correction_tolerance_threshold"),
                     "source": _SRC + "ODESolver/Backward/src/sofa/component/odesolver/backward/StaticSolver.cpp"},
    "EulerImplicitSolver": {"plugin": "Sofa.Component.ODESolver.Backward",
                            "attributes": ("name", "rayleighMass", "rayleighStiffness"),
                            "source": _SRC + "ODESolver/Backward/src/sofa/component/odesolver/backward/"
                                             "EulerImplicitSolver.cpp"},
    "CGLinearSolver": {"plugin": "Sofa.Component.LinearSolver.Iterative",
                       "attributes": ("name", "iterations", "tolerance", "threshold"),
                       "source": _SRC + "LinearSolver/Iterative/src/sofa/component/linearsolver/iterative/"
                                        "CGLinearSolver.inl"},
    "MeshTopology": {"plugin": "Sofa.Component.Topology.Container.Constant",
                     "attributes": ("name", "position", "triangles", "quads", "tetrahedra", "hexahedra"),
                     "source": _SRC + "Topology/Container/Constant/src/sofa/component/topology/container/constant/"
                                      "MeshTopology.cpp"},
    "MechanicalObject": {"plugin": "Sofa.Component.StateContainer",
                         "attributes": ("name", "template", "position", "rest_position"),
                         "source": _SRC + "StateContainer/src/sofa/component/statecontainer/MechanicalObject.inl"},
    "DiagonalMass": {"plugin": "Sofa.Component.Mass", "attributes": ("name", "vertexMass"),
                     "source": _SRC + "Mass/src/sofa/component/mass/DiagonalMass.inl"},
    "SpringForceField": {"plugin": "Sofa.Component.SolidMechanics.Spring", "attributes": ("name", "spring"),
                         "source": _SRC + "SolidMechanics/Spring/src/sofa/component/solidmechanics/spring/"
                                          "SpringForceField.inl"},
    "FixedProjectiveConstraint": {"plugin": "Sofa.Component.Constraint.Projective", "attributes": ("name", "indices"),
                                  "source": _SRC + "Constraint/Projective/src/sofa/component/constraint/projective/"
                                                   "FixedProjectiveConstraint.inl"},
    "PartialFixedProjectiveConstraint": {"plugin": "Sofa.Component.Constraint.Projective",
                                         "attributes": ("name", "indices", "fixedDirections"),
                                         "source": _SRC + "Constraint/Projective/src/sofa/component/constraint/"
                                                          "projective/PartialFixedProjectiveConstraint.inl"},
    "ConstantForceField": {"plugin": "Sofa.Component.MechanicalLoad", "attributes": ("name", "indices", "forces"),
                           "source": _SRC + "MechanicalLoad/src/sofa/component/mechanicalload/ConstantForceField.inl"},
}


# --------------------------------------------------------------------------------------------
# MuJoCo
# --------------------------------------------------------------------------------------------


def _f(v) -> str:
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"cannot export the non-finite value {v!r}")
    return repr(v)


def _vec(v) -> str:
    return " ".join(_f(x) for x in v)


def _springs_only_model(exp: MssExport):
    from msslib.system import Model
    from msslib.terms import Springs

    # a non-positive constant here comes from a model that accepted it after checking its
    # lattice's stability (least-squares springs, msslib.models.lsq): carried as it is
    signed = bool(np.any(np.asarray(exp.stiffness) <= 0))
    return Model(exp.setup.mesh, [Springs(exp.pairs, exp.stiffness, exp.rest_length, exp.dim, signed=signed)],
                 fixed=exp.fixed, masses=exp.masses)


#: the MuJoCo model steps at this fraction of the stability limit 2/omega_max of its springs
MJCF_SAFETY = 0.5
#: bytes of MuJoCo's arena (``<size memory>``) per degree of freedom, tendon, body and actuator:
#: exported spring models (about 4 tendons per degree of freedom, contacts off) use about 190 bytes
#: of stack and arena per degree of freedom when stepped (MuJoCo 4, 0.9 k to 12 k degrees of
#: freedom), so this leaves a margin of 3 or more.  Without it MuJoCo sizes the arena itself, in
#: proportion to the tendons times the degrees of freedom, and cannot allocate it from about 50 k
#: springs up.
MJCF_ARENA_BYTES_PER_ELEMENT = 128
#: the smallest arena the MJCF asks for [bytes]
MJCF_ARENA_MIN = 8 << 20


def mjcf_memory(n_dofs: int, n_tendons: int, n_bodies: int, n_actuators: int) -> int:
    """The ``<size memory>`` [bytes, a whole number of MiB] of an MJCF model of that size:
    :data:`MJCF_ARENA_BYTES_PER_ELEMENT` per element, at least :data:`MJCF_ARENA_MIN`."""
    need = MJCF_ARENA_BYTES_PER_ELEMENT * (n_dofs + n_tendons + n_bodies + n_actuators)
    mib = 1 << 20
    return max(MJCF_ARENA_MIN, -(-need // mib) * mib)


@dataclass(frozen=True)
class MjcfStep:
    """The time step written in the MuJoCo model: ``step`` (s), ``limit`` the stability limit
    ``2/omega_max`` (s) of its springs at rest with the node masses (inf without springs or free
    dofs), ``scene_dt`` the scene's step (None for a static scene), ``note`` one sentence saying
    which step was written and why (in the file; a warning when it is not the scene's)."""

    step: float
    limit: float
    scene_dt: float | None
    note: str

    @property
    def reduced(self) -> bool:
        """Whether the scene's own step was replaced by a smaller one."""
        return self.scene_dt is not None and self.step < self.scene_dt


def time_step(exp: MssExport) -> float:
    """The scene's time step (dynamic scenes), else half the explicit stability limit ``2/omega_max``
    of the springs with the node masses at rest (:func:`msslib.solvers.explicit_stability_limit`):
    the SOFA scene's ``dt`` (its dynamic solver, EulerImplicitSolver, is implicit)."""
    if exp.scene.is_dynamic:
        return float(exp.scene.solver["dt"])
    return mjcf_time_step(exp).step


def stability_limit(exp: MssExport) -> float:
    """``2/omega_max`` (s) of the springs with the node masses at rest and the prescribed
    displacements applied (:func:`msslib.solvers.explicit_stability_limit`); inf without springs
    or free dofs."""
    if exp._stability_limit is None:
        from msslib.solvers import explicit_stability_limit

        if len(exp.pairs) == 0 or not (~exp.fixed).any():
            exp._stability_limit = math.inf
        else:
            model = _springs_only_model(exp)
            exp._stability_limit = float(explicit_stability_limit(model, model.apply_prescribed(model.x0, 1.0)))
    return exp._stability_limit


def mjcf_time_step(exp: MssExport) -> MjcfStep:
    """The MuJoCo model's step. MuJoCo integrates tendon spring forces explicitly (its implicit
    integrators take only velocity derivatives, here the joint damping, implicitly), so it is
    stable only below ``2/omega_max`` of the springs: the scene's ``dt`` when it is at most
    :data:`MJCF_SAFETY` times that limit, else that fraction of the limit (the same for static
    scenes, which have no step; 1 ms without springs or free dofs)."""
    limit = stability_limit(exp)
    safe = MJCF_SAFETY * limit if math.isfinite(limit) and limit > 0 else 1e-3
    why = (f"MuJoCo integrates the tendon springs explicitly and is stable only below 2/omega_max = {limit:.4g} s "
           f"(omega_max^2 the largest eigenvalue of M^-1 K of the springs at rest)")
    if not exp.scene.is_dynamic:
        note = (f"timestep {safe:.4g} s = {MJCF_SAFETY} x the stability limit: {why}" if math.isfinite(limit)
                else f"timestep {safe:.4g} s: the model has no springs between free nodes (no stability limit)")
        return MjcfStep(safe, limit, None, note)
    dt = float(exp.scene.solver["dt"])
    if dt <= safe:
        return MjcfStep(dt, limit, dt, f"timestep {dt:.4g} s, the scene's dt, at most {MJCF_SAFETY} x the stability "
                                       f"limit: {why}")
    return MjcfStep(safe, limit, dt, f"timestep {safe:.4g} s = {MJCF_SAFETY} x the stability limit, NOT the scene's "
                                     f"dt = {dt:.4g} s ({dt / limit:.3g} times the limit; msslib's "
                                     f"{exp.scene.solver.get('method')} steps it stably, MuJoCo would blow up): {why}")


def _header_lines(exp: MssExport, fmt: str) -> list[str]:
    scene = exp.scene
    lines = [f"Generated by `msslib export` (msslib {_version()}) from scene {scene.name!r}, model {scene.model}; "
             f"SI units (m, kg, s, N). Node i is body/site node{{i}}, spring s is tendon spring{{s}} "
             f"(0-based, the rows of the CSV/JSON tables)." if fmt == "mjcf" else
             f"Generated by `msslib export` (msslib {_version()}) from scene {scene.name!r}, model {scene.model}; "
             f"SI units (m, kg, s, N); written for {SOFA_TARGET}. Node indices are those of the CSV/JSON tables."]
    missing = not_carried(exp, fmt)
    if missing:
        lines.append("NOT CARRIED (cannot be expressed here; this file holds the rest of the model, which is "
                     "therefore NOT the scene's model): " + "; ".join(missing) + ". The CSV/JSON export carries "
                     "them.")
    else:
        lines.append("This file carries the whole mass-spring system of the scene.")
    return lines


def mjcf_text(exp: MssExport) -> str:
    """The MuJoCo model (MJCF XML) of the MSS; see the module docstring for the mapping."""
    dim, n = exp.dim, exp.n_nodes
    lengths = exp.rest_length if len(exp.rest_length) else np.array([1.0])
    h = float(np.min(lengths))
    root = ET.Element("mujoco", model=_safe_name(exp.scene.name))
    for line in _header_lines(exp, "mjcf"):
        root.append(ET.Comment(f" {_xml_comment(line)} "))
    root.append(ET.Comment(" Springs: spatial tendons with stiffness k (N/m) and springlength L (m): force "
                           "k (|x_j - x_i| - L) along the spring. Nodes: bodies with a point mass (the "
                           "rotational inertia is immaterial, the bodies only slide) and one slide joint per "
                           "free axis; a node fixed on every axis has no joint (welded to the world). "
                           "Prescribed displacements (load factor 1) are in the bodies' positions. Loads at "
                           "load factor 1 are general actuators with a constant force (gainprm 0, affine "
                           "biasprm F 0 0). The scene's static solve ramps the loads; MuJoCo reaches the same "
                           "equilibrium when damped to rest. "))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    size = ET.SubElement(root, "size")  # memory: set below, from the model's size
    g = np.zeros(3)
    if exp.gravity is not None:
        g[:dim] = exp.gravity
    step = mjcf_time_step(exp)
    root.append(ET.Comment(f" Time step: {_xml_comment(step.note)}. Integrator implicitfast: the joint damping "
                           f"is implicit, the springs are not. "))
    if step.reduced:
        warnings.warn(f"{exp.scene.name}: the mjcf output steps at {step.step:.4g} s instead of the scene's dt = "
                      f"{step.scene_dt:.4g} s: MuJoCo integrates the tendon springs explicitly and is stable only "
                      f"below 2/omega_max = {step.limit:.4g} s, {step.scene_dt / step.limit:.3g} times smaller than "
                      f"dt (said in the file)", MsslibWarning, stacklevel=2)
    option = ET.SubElement(root, "option", timestep=_f(step.step), gravity=_vec(g), integrator="implicitfast")
    ET.SubElement(option, "flag", contact="disable")
    world = ET.SubElement(root, "worldbody")
    pos = _pad3(exp.points + exp.prescribed)
    alpha = exp.damping[0]
    for i in range(n):
        body = ET.SubElement(world, "body", name=f"node{i}", pos=_vec(pos[i]))
        m = float(exp.masses[i])
        free = ~exp.fixed[i]
        if free.any() and not m > 0:
            raise ValueError(f"node {i} has free axes but mass {m!r} kg: MuJoCo needs a positive mass")
        if m > 0:
            inertia = max(m * (0.1 * h) ** 2, 1e-12)
            ET.SubElement(body, "inertial", pos="0 0 0", mass=_f(m), diaginertia=_vec([inertia] * 3))
        for a in range(dim):
            if free[a]:
                attrs = {"name": f"node{i}_{AXES[a]}", "type": "slide", "axis": _vec(np.eye(3)[a])}
                if alpha:
                    attrs["damping"] = _f(alpha * m)
                ET.SubElement(body, "joint", **attrs)
        ET.SubElement(body, "site", name=f"node{i}", size=_f(0.05 * h))
    if dim == 2:
        world.append(ET.Comment(" 2D model: the nodes slide in the x-y plane only (no z joint) "))
    if len(exp.pairs):
        tendon = ET.SubElement(root, "tendon")
        for s, ((i, j), k, L) in enumerate(zip(exp.pairs, exp.stiffness, exp.rest_length)):
            sp = ET.SubElement(tendon, "spatial", name=f"spring{s}", stiffness=_f(k), springlength=_f(L),
                               width=_f(0.01 * h))
            ET.SubElement(sp, "site", site=f"node{int(i)}")
            ET.SubElement(sp, "site", site=f"node{int(j)}")
    forces = [("load", exp.loads)] + [(label, F) for label, F, _ in exp.forces()]
    actuators = []
    for label, F in forces:
        for i in range(n):
            for a in range(dim):
                if F[i, a] != 0.0 and not exp.fixed[i, a]:
                    actuators.append(dict(name=f"{label}_node{i}_{AXES[a]}", joint=f"node{i}_{AXES[a]}", gainprm="0",
                                          biastype="affine", biasprm=f"{_f(F[i, a])} 0 0"))
    n_dofs = int(sum(int((~exp.fixed[i]).sum()) for i in range(n)))
    memory = mjcf_memory(n_dofs, len(exp.pairs), n + 1, len(actuators))
    size.set("memory", f"{memory >> 20}M")
    root.insert(list(root).index(size), ET.Comment(
        f" MuJoCo's arena: {memory >> 20} MiB for {n_dofs} degrees of freedom, {len(exp.pairs)} tendons, {n + 1} "
        f"bodies and {len(actuators)} actuators ({MJCF_ARENA_BYTES_PER_ELEMENT} bytes each, at least "
        f"{MJCF_ARENA_MIN >> 20} MiB); MuJoCo's default grows with tendons times degrees of freedom "))
    if actuators:
        act = ET.SubElement(root, "actuator")
        act.append(ET.Comment(" constant forces (N) at load factor 1: surface loads (load_*), dead pressures "
                              "(pressure_I_*, the scene's loads[I]) and Baudet's correction (baudet_correction_*) "))
        for attrs in actuators:
            ET.SubElement(act, "general", **attrs)
    ET.indent(root, space=" ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _xml_comment(text: str) -> str:
    return " ".join(text.split()).replace("--", "- -")


# --------------------------------------------------------------------------------------------
# SOFA
# --------------------------------------------------------------------------------------------


def _sofa(parent, tag, **attrs):
    spec = SOFA_COMPONENTS.get(tag)
    if spec is None:
        raise ValueError(f"SOFA component {tag!r} is not in SOFA_COMPONENTS")
    bad = [a for a in attrs if a not in spec["attributes"]]
    if bad:
        raise ValueError(f"SOFA component {tag}: attributes {bad} are not in SOFA_COMPONENTS")
    return ET.SubElement(parent, tag, **attrs) if parent is not None else ET.Element(tag, **attrs)


def _ints(v) -> str:
    return " ".join(str(int(x)) for x in v)


def sofa_text(exp: MssExport) -> str:
    """The SOFA scene (XML ``.scn``) of the MSS; every component and attribute is one of
    :data:`SOFA_COMPONENTS`."""
    dim, n = exp.dim, exp.n_nodes
    scene = exp.scene
    g = np.zeros(3)
    if exp.gravity is not None:
        g[:dim] = exp.gravity
    root = _sofa(None, "Node", name="root", gravity=_vec(g), dt=_f(time_step(exp)))
    for line in _header_lines(exp, "sofa"):
        root.append(ET.Comment(f" {_xml_comment(line)} "))
    _sofa(root, "DefaultAnimationLoop", name="animation")
    node = _sofa(root, "Node", name="mss")
    if scene.is_dynamic:
        alpha, beta = exp.damping
        node.append(ET.Comment(f" dynamic scene ({scene.solver.get('method')} in msslib): implicit Euler with "
                               f"the scene's Rayleigh damping C = alpha M + beta K "))
        _sofa(node, "EulerImplicitSolver", name="ode", rayleighMass=_f(alpha), rayleighStiffness=_f(beta))
    else:
        s = scene.solver
        node.append(ET.Comment(" static scene: Newton (StaticSolver) at the full load in one step; msslib ramps the "
                               "loads and prescribed displacements over load_steps to the same equilibrium "))
        _sofa(node, "StaticSolver", name="ode", newton_iterations=str(int(s.get("max_iter", 50))),
              relative_residual_tolerance_threshold=_f(s.get("tol", 1e-8)),
              absolute_residual_tolerance_threshold="-1", relative_correction_tolerance_threshold="-1",
              absolute_correction_tolerance_threshold="-1")
    _sofa(node, "CGLinearSolver", name="linear", iterations=str(max(1000, 10 * dim * n)), tolerance="1e-20",
          threshold="1e-30")
    mesh = exp.setup.mesh
    topo = {"name": "topology", "position": _vec(exp.points.ravel())}
    sofa_cells = _cells.get(mesh.cell_type).sofa
    if sofa_cells is not None:
        topo[sofa_cells] = _ints(mesh.cells.ravel())
    else:
        node.append(ET.Comment(f" the topology lists no cells: this export writes no {mesh.cell_type} cells for SOFA; "
                               f"the springs below carry the whole model "))
    _sofa(node, "MeshTopology", **topo)
    template = f"Vec{dim}d"
    node.append(ET.Comment(" position: rest positions moved by the prescribed displacements (load factor 1) "))
    _sofa(node, "MechanicalObject", name="dofs", template=template, position=_vec((exp.points + exp.prescribed).ravel()),
          rest_position=_vec(exp.points.ravel()))
    node.append(ET.Comment(f" node masses (kg), {exp.mass_source} "))
    _sofa(node, "DiagonalMass", name="mass", vertexMass=_vec(exp.masses))
    node.append(ET.Comment(" springs: i j ks kd L per spring (N/m, damping 0, rest length m) "))
    spring = " ".join(f"{int(i)} {int(j)} {_f(k)} 0 {_f(L)}"
                      for (i, j), k, L in zip(exp.pairs, exp.stiffness, exp.rest_length))
    _sofa(node, "SpringForceField", name="springs", spring=spring)
    full = np.flatnonzero(exp.fixed.all(axis=1))
    if len(full):
        _sofa(node, "FixedProjectiveConstraint", name="fixed", indices=_ints(full))
    partial = exp.fixed.any(axis=1) & ~exp.fixed.all(axis=1)
    for mask in sorted({tuple(r) for r in exp.fixed[partial].tolist()}):
        idx = np.flatnonzero(partial & np.all(exp.fixed == np.array(mask), axis=1))
        label = "".join(a for a, m in zip(AXES, mask) if m)
        _sofa(node, "PartialFixedProjectiveConstraint", name=f"fixed_{label}", indices=_ints(idx),
              fixedDirections=_ints(mask))
    forces = [("loads", exp.loads, "surface loads (N) at load factor 1")] + exp.forces()
    for name, F, what in forces:
        on = np.flatnonzero(np.any(F != 0, axis=1))
        if len(on):
            node.append(ET.Comment(f" {what} "))
            _sofa(node, "ConstantForceField", name=name, indices=_ints(on), forces=_vec(F[on].ravel()))
    # the plugins of the components used (DefaultAnimationLoop's is always loaded)
    used = {e.tag for e in root.iter() if isinstance(e.tag, str)}
    plugins = sorted({SOFA_COMPONENTS[t]["plugin"] for t in used} - {None, "Sofa.Simulation.Core"})
    first = next(i for i, e in enumerate(root) if e.tag == "DefaultAnimationLoop")
    for k, p in enumerate(plugins):
        root.insert(first + k, _sofa(None, "RequiredPlugin", name=p))
    ET.indent(root, space=" ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"

"""Which model for my mesh and my error budget? ``plan`` on a liver-like gmsh mesh.

An ellipsoid cut flat at the bottom (physical surface ``base``, clamped), its curved surface
(``capsule``) pressed by a traction, with a stiff spherical inclusion: two physical volumes,
``liver`` (nu = 0.45) and ``inclusion``.  ``plan`` measures every tetrahedron model on the mesh
and its uniform refinements against a quadratic-element neo-Hookean reference (locking-free at
this nu), prints the reference's own error estimate beside the choice, and picks the cheapest
model within the budget.

    python -m experiments.examples.liver_plan [OUT_DIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

import yaml

SCENE = {
    "name": "liver",
    "description": "liver-like ellipsoid with a stiff inclusion, clamped at its base, pressed on its capsule",
    "geometry": {"file": "liver.msh"},
    "materials": {"liver": {"E": 5.0e3, "nu": 0.45}, "inclusion": {"E": 5.0e4, "nu": 0.45}},
    "model": "fem_linear",
    "boundary": [{"select": {"group": "base"}, "fix": "all"}],
    "loads": [{"type": "traction", "select": {"group": "capsule"}, "traction": [0.0, 0.0, -50.0]}],
    "solver": {"type": "static", "load_steps": 1},
}


def write_mesh(path, size: float = 0.045) -> Path:
    """The gmsh mesh (msh 4.1) of the liver-like body: semi-axes 0.1, 0.07, 0.05 m, cut at
    z = -0.03, an inclusion of radius 0.02 m; ``size`` the largest element size (m)."""
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("liver")
        occ = gmsh.model.occ
        body = occ.addSphere(0, 0, 0, 1.0)
        occ.dilate([(3, body)], 0, 0, 0, 0.1, 0.07, 0.05)
        cut = occ.addBox(-0.2, -0.2, -0.2, 0.4, 0.4, 0.17)  # everything below z = -0.03
        (body_dimtags, _) = occ.cut([(3, body)], [(3, cut)])
        inclusion = occ.addSphere(0.02, 0.0, 0.0, 0.02)
        out, _ = occ.fragment(body_dimtags, [(3, inclusion)])
        occ.synchronize()
        volumes = [t for d, t in out if d == 3]
        small = min(volumes, key=lambda t: occ.getMass(3, t))
        gmsh.model.addPhysicalGroup(3, [t for t in volumes if t != small], name="liver")
        gmsh.model.addPhysicalGroup(3, [small], name="inclusion")
        outer = [t for d, t in gmsh.model.getBoundary([(3, t) for t in volumes if t != small], oriented=False)
                 if d == 2 and t not in [s for _, s in gmsh.model.getBoundary([(3, small)], oriented=False)]]
        flat = [t for t in outer if abs(occ.getCenterOfMass(2, t)[2] + 0.03) < 1e-9]
        gmsh.model.addPhysicalGroup(2, flat, name="base")
        gmsh.model.addPhysicalGroup(2, [t for t in outer if t not in flat], name="capsule")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(3)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return Path(path)


def main(out_dir=".", levels="1,2", max_error="0.3"):
    from msslib.cli import main as cli

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_mesh(out / "liver.msh")
    (out / "liver.yaml").write_text(yaml.safe_dump(SCENE, sort_keys=False))
    return cli(["plan", str(out / "liver.yaml"), "--max-error", max_error, "--levels", levels, "--repeats", "1"])


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))

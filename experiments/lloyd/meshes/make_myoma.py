"""Write experiments/lloyd/meshes/myoma.msh, the synthetic myoma of Lloyd et al. Sec. 5.9 (run by hand
after a change; not part of the workflow).

Lloyd et al. show a myoma of their hysteroscopy simulator (Fig. 19), a mesh of 391 tetrahedra, but
give neither its shape nor its size. The synthetic stand-in: a ball of radius R whose centre lies
C above the uterine wall (the plane z = 0), the part above the wall kept (a sessile myoma, a dome
of height R + C on a disc of radius sqrt(R^2 - C^2)). The dome's top, the cap above
z = C + CAP * R, is a separate surface of the geometry, so that its boundary circle is made of mesh
edges and a traction can be put on exactly the cap's facets (selected by a box z >= C + CAP R).
The element size is the one (from 6 mm down to 3 mm in steps of 0.1 mm, the coarsest on a tie) whose
mesh has the number of tetrahedra closest to the paper's 391.

    python -m experiments.lloyd.meshes.make_myoma
"""

from pathlib import Path

import numpy as np

from msslib import mesh as M
from msslib.mesh import unstructured

R = 0.01  # m, radius of the ball
C = 0.005  # m, height of its centre above the wall
CAP = 0.75  # the loaded cap lies above z = C + CAP * R
TARGET = 391  # tetrahedra of the paper's mesh
OUT = Path(__file__).resolve().parent / "myoma.msh"


def myoma_mesh(radius: float, centre_height: float, cap: float, h: float, seed: int = 0) -> M.Mesh:
    """The dome (ball of ``radius`` centred ``centre_height`` above z = 0, cut at z = 0), its top cap
    above ``z = centre_height + cap * radius`` fragmented off as its own volume (same material),
    meshed with tetrahedra of size about ``h`` (gmsh, deterministic)."""
    if not 0 <= centre_height < radius or not 0 < cap < 1:
        raise ValueError("need 0 <= centre_height < radius and 0 < cap < 1")
    with unstructured._gmsh_session(h, seed, "myoma") as gmsh:
        occ = gmsh.model.occ
        ball = occ.addSphere(0, 0, centre_height, radius)
        big = 4 * radius
        below = occ.addBox(-big, -big, -big, 2 * big, 2 * big, big)
        (dome,), _ = occ.cut([(3, ball)], [(3, below)])
        z_cap = centre_height + cap * radius
        top = occ.addBox(-big, -big, z_cap, 2 * big, 2 * big, big)
        occ.fragment([dome], [(3, top)])
        occ.synchronize()
        # drop what lies outside the dome (the rest of the fragmenting box)
        for dim, tag in gmsh.model.getEntities(3):
            z1 = gmsh.model.getBoundingBox(dim, tag)[5]
            if z1 > centre_height + 2 * radius:  # the box reaches 4 radii above the cap
                gmsh.model.removeEntities([(dim, tag)], recursive=False)
        return unstructured._gmsh_extract(gmsh, 3)


def main():
    best = None
    for h10 in range(60, 29, -1):  # h from 6 mm down to 3 mm in steps of 0.1 mm
        mesh = myoma_mesh(R, C, CAP, h10 * 1e-4)
        if best is None or abs(mesh.n_cells - TARGET) < abs(best[1].n_cells - TARGET):
            best = (h10, mesh)
    h10, mesh = best
    import meshio

    OUT.parent.mkdir(parents=True, exist_ok=True)
    meshio.write(OUT, meshio.Mesh(mesh.points, [("tetra", mesh.cells)]), file_format="gmsh22", binary=False)
    z = mesh.points[:, 2]
    print(f"h = {h10 * 1e-4:.4g} m: {mesh.n_nodes} nodes, {mesh.n_cells} tetrahedra, base nodes "
          f"{int(np.sum(np.abs(z) < 1e-9))}, cap nodes {int(np.sum(z >= C + CAP * R - 1e-9))}; written {OUT}")


if __name__ == "__main__":
    main()

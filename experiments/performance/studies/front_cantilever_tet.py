"""Speed against error: the cantilever scene on Kuhn tetrahedra (six per cube of the hexahedral scene) on
nested meshes (levels = uniform refinements), every tetrahedron model variant (MSS non-linear and linear, linear
and non-linear FEM) against a quadratic-element reference."""

from experiments.performance.front import main

if __name__ == "__main__":
    main("cantilever_tet.yaml", levels=(0, 1, 2, 3))

"""Speed against error: the cantilever scene on nested meshes (levels = uniform refinements), every model
variant (MSS non-linear and linear, linear and non-linear FEM) against a quadratic-element reference."""

from experiments.performance.front import main

if __name__ == "__main__":
    main("cantilever.yaml", levels=(0, 1, 2, 3, 4))  # level 4: 56 k dofs, where the solve, not the set-up, is timed

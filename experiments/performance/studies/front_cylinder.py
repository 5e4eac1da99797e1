"""Speed against error: the cylinder scene on nested meshes (levels = uniform refinements), every model
variant (MSS non-linear and linear, linear and non-linear FEM) against a quadratic-element reference."""

from experiments.performance.front import main

if __name__ == "__main__":
    main("cylinder.yaml", levels=(0, 1, 2))

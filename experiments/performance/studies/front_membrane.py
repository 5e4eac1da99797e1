"""Speed against error: the membrane scene on nested meshes (levels = uniform refinements), every model
variant (MSS non-linear and linear, linear and non-linear FEM) against a quadratic-element reference."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from front import main  # noqa: E402

if __name__ == "__main__":
    main("membrane.yaml", levels=(0, 1, 2, 3, 4), below=0)

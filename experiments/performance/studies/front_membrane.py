"""Speed against error: the membrane scene at several resolutions, every model, vs converged non-linear FEM."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from front import main  # noqa: E402

if __name__ == "__main__":
    main("membrane.yaml", levels=(1, 2, 3))

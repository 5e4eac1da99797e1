"""A nearly incompressible material (nu = 0.49): ``plan`` on a clamped cube pressed on its top.

Linear-element FEM locks here (its top settlement grows by a factor of about 1.5 from 2^3 to 8^3
hexahedra); ``plan`` detects the nu and measures every model against a quadratic reference whose
volumetric term is integrated with the reduced rule (locking-free), so the errors it prints are the
models' own.

    python -m experiments.examples.incompressible_cube [OUT_DIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

import yaml


def scene(nu: float = 0.49, n: int = 2) -> dict:
    """A 0.1 m cube of ``n^3`` hexahedra, clamped at z = 0, a 1 kPa traction down on z = 0.1."""
    return {
        "name": "incompressible_cube",
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": n, "ny": n, "nz": n}},
        "materials": [{"E": 1.0e6, "nu": nu}],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["z", 0.1]}, "traction": [0.0, 0.0, -1.0e3]}],
    }


def main(out_dir=".", levels="1,2", max_error="0.3"):
    from msslib.cli import main as cli

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "cube.yaml").write_text(yaml.safe_dump(scene(), sort_keys=False))
    return cli(["plan", str(out / "cube.yaml"), "--max-error", max_error, "--levels", levels, "--repeats", "1"])


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))

"""Scenes shared by the input-guard tests."""

from __future__ import annotations


def pressed_cube(name: str, cells: int = 2, **changes) -> dict:
    """A fresh scene dict: a 0.1 m cube of ``cells`` x ``cells`` x ``cells`` hexahedra (E = 1 MPa,
    nu = 0.3, Golec's model), fixed at z = 0 and pressed down 1 mm at z = 0.1; ``changes`` replace
    top-level keys."""
    scene = {
        "name": name,
        "geometry": {"generator": "hex_grid",
                     "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": cells, "ny": cells, "nz": cells}},
        "materials": [{"E": 1.0e6, "nu": 0.3}],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"},
                     {"select": {"plane": ["z", 0.1]}, "fix": ["z"], "displacement": [None, None, -0.001]}],
    }
    scene.update(changes)
    return scene

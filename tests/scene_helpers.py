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


def pulled_sheet(**changes) -> dict:
    """A fresh scene dict: a 0.1 m square sheet (1 cm thick) of 2 x 2 quads (E = 1 MPa, nu = 1/3,
    Lloyd's square), clamped at x = 0 and pulled by 1 N along x at x = 0.1; ``changes`` replace
    top-level keys."""
    scene = {
        "name": "sheet",
        "geometry": {"generator": "quad_grid", "args": {"lx": 0.1, "ly": 0.1, "nx": 2, "ny": 2}},
        "materials": [{"E": 1.0e6, "nu": 1 / 3}],
        "thickness": 0.01,
        "model": "lloyd_square",
        "boundary": [{"select": {"plane": ["x", 0.0]}}],
        "loads": [{"type": "nodal_force", "select": {"plane": ["x", 0.1]}, "total": [1.0, 0.0]}],
    }
    scene.update(changes)
    return scene


def swinging_bar(save_every: int = 5, **changes) -> dict:
    """A fresh scene dict: an 8 cm bar of 4 Golec cubes (E = 0.1 MPa, 1000 kg/m^3) clamped at
    x = 0, swinging down under gravity for 2 ms (dynamic, dt 0.1 ms, every ``save_every``-th state
    saved); ``changes`` replace top-level keys."""
    scene = {
        "name": "swing",
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.08, "ly": 0.02, "lz": 0.02, "nx": 4, "ny": 1, "nz": 1}},
        "materials": [{"E": 1.0e5, "nu": 0.3, "density": 1000.0}],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["x", 0.0]}}],
        "loads": [{"type": "gravity", "g": [0.0, 0.0, -9.81]}],
        "solver": {"type": "dynamic", "dt": 1.0e-4, "t_end": 2.0e-3, "save_every": save_every},
    }
    scene.update(changes)
    return scene

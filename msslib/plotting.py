"""Plotting helpers for result datasets (:mod:`msslib.io` schema): deformed meshes, error maps.

The figures of the papers draw the mass-spring system as a wireframe over the reference
deformation; this module provides the pieces, for 2D meshes (triangles, quads) and for 3D meshes
(tetrahedra, hexahedra: their boundary faces, orthographically projected on a coordinate plane):

* :func:`figure` -- a :class:`matplotlib.figure.Figure` with readable default fonts, made without
  :mod:`matplotlib.pyplot` (works with any backend, no window is ever opened);
* :func:`deformed_mesh` -- the deformed (or rest) mesh of a result as a wireframe, optionally
  filled and coloured by the displacement magnitude or any per-node field;
* :func:`node_error` and :func:`error_map` -- the per-node distance between a result and a
  reference (interpolated when the meshes differ), and a map of it;
* :func:`comparison_figure` -- the usual layout: one column per load case, the variant's wireframe
  over the reference coloured by ``|u|`` on top, the error map below;
* :func:`save` -- write ``STEM.png`` (150 dpi) and ``STEM.pdf`` atomically.

Lengths are drawn in ``length_unit`` (``"m"``, ``"cm"`` or ``"mm"``; default cm, the unit of the
papers) and displacements / errors coloured in ``value_unit`` (default mm).  In 3D, ``plane``
names the two axes drawn (horizontal first), e.g. ``"yz"``: the view looks along the third axis,
from the side ``cross(e_h, e_v)`` points to (``"yz"``: from +x, ``"xz"``: from -y), and only the
boundary faces turned towards the viewer are drawn, back to front.

Example::

    from msslib import plotting
    from msslib.io import read_result

    mss, fem = read_result("shear__mss.nc"), read_result("shear__fem.nc")
    fig = plotting.figure(figsize=(5, 4))
    ax = fig.add_subplot()
    im = plotting.deformed_mesh(ax, fem, color="k", colorby="displacement")
    plotting.deformed_mesh(ax, mss, color="tab:red")
    fig.colorbar(im, ax=ax, label="|u| (mm)")
    plotting.save(fig, "paper/figures/example")
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

__all__ = ["LENGTH_UNITS", "figure", "deformed_mesh", "node_error", "error_map", "comparison_figure", "save"]

#: Scale factors from metres to the supported drawing units.
LENGTH_UNITS = {"m": 1.0, "cm": 1e2, "mm": 1e3}
AXES = "xyz"

RC = {
    "font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10, "legend.fontsize": 9,
    "xtick.labelsize": 9, "ytick.labelsize": 9, "figure.titlesize": 12,
}

# local faces of 3D cells (VTK node order); the orientation is fixed later from the cell centroid
_FACES = {
    "tetra": [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)],
    "hexahedron": [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)],
}
_EDGES_2D = {"triangle": [(0, 1), (1, 2), (2, 0)], "quad": [(0, 1), (1, 2), (2, 3), (3, 0)]}


# ---------------------------------------------------------------------------------------------
# figures and files
# ---------------------------------------------------------------------------------------------

def figure(**kwargs):
    """A new :class:`matplotlib.figure.Figure` (keyword arguments passed on, e.g. ``figsize``)
    with this module's font sizes and ``constrained`` layout.  No pyplot, no backend needed."""
    import matplotlib as mpl
    from matplotlib.figure import Figure

    kwargs.setdefault("layout", "constrained")
    with mpl.rc_context(RC):
        fig = Figure(**kwargs)
    fig._msslib_rc = dict(RC)  # noqa: SLF001 - remembered for the axes created later
    return fig


def _unit(length_unit: str) -> float:
    if length_unit not in LENGTH_UNITS:
        raise ValueError(f"length_unit must be one of {sorted(LENGTH_UNITS)}, got {length_unit!r}")
    return LENGTH_UNITS[length_unit]


def save(fig, stem, *, dpi: int = 150) -> tuple[Path, Path]:
    """Write ``STEM.png`` (``dpi``) and ``STEM.pdf``; each file is written to a temporary name
    in the same directory and then renamed, so a reader never sees a partial file.  Creates the
    directory if needed and returns the two paths."""
    import matplotlib as mpl

    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    out = []
    for ext in ("png", "pdf"):
        path = stem.with_name(f"{stem.name}.{ext}")
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        try:
            with mpl.rc_context({"pdf.fonttype": 42}):
                fig.savefig(tmp, format=ext, dpi=dpi)
            os.replace(tmp, path)
        finally:
            if tmp.exists():
                tmp.unlink()
        out.append(path)
    return out[0], out[1]


# ---------------------------------------------------------------------------------------------
# geometry of a result
# ---------------------------------------------------------------------------------------------

def _arrays(ds):
    X = np.asarray(ds["rest_position"].transpose("node", "axis").values, dtype=float)
    u = np.asarray(ds["displacement"].transpose("node", "axis").values, dtype=float)
    cells = np.asarray(ds["cells"].transpose("cell", "cell_node").values, dtype=np.int64)
    return X, u, cells, str(ds["cells"].attrs.get("cell_type", ""))


def _plane_axes(plane: str, dim: int):
    if dim == 2:
        return 0, 1, None
    if len(plane) != 2 or plane[0] not in AXES or plane[1] not in AXES or plane[0] == plane[1]:
        raise ValueError(f"plane must name two different axes of 'xyz', e.g. 'yz', got {plane!r}")
    a, b = AXES.index(plane[0]), AXES.index(plane[1])
    toward = np.cross(np.eye(3)[a], np.eye(3)[b])
    return a, b, toward


def _boundary_faces(cells: np.ndarray, cell_type: str, x: np.ndarray) -> np.ndarray:
    """Boundary faces ``(n_faces, nv)`` of a 3D mesh, ordered so that their normal (right-hand
    rule) points out of the cell they belong to, at positions ``x``."""
    if cell_type not in _FACES:
        raise ValueError(f"no faces known for cell type {cell_type!r}")
    local = np.asarray(_FACES[cell_type])
    faces = cells[:, local]  # (m, nf, nv)
    owner = np.repeat(np.arange(len(cells)), local.shape[0])
    faces = faces.reshape(-1, local.shape[1])
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    faces, owner = faces[once], owner[once]
    p = x[faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    outward = np.einsum("ij,ij->i", normal, p.mean(axis=1) - x[cells[owner]].mean(axis=1)) >= 0
    faces[~outward] = faces[~outward][:, ::-1]
    return faces


def _visible_faces(cells, cell_type, x, toward):
    """Front-facing boundary faces, sorted back to front."""
    faces = _boundary_faces(cells, cell_type, x)
    p = x[faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    front = normal @ toward > 0
    faces = faces[front]
    depth = (x[faces] @ toward).mean(axis=1)
    return faces[np.argsort(depth, kind="stable")]


def _edges(faces_or_cells: np.ndarray) -> np.ndarray:
    """Unique edges of polygons given by their node loops ``(n, nv)``."""
    e = np.stack([faces_or_cells, np.roll(faces_or_cells, -1, axis=1)], axis=2).reshape(-1, 2)
    return np.unique(np.sort(e, axis=1), axis=0)


def _node_values(colorby, u):
    if colorby is None:
        return None
    if isinstance(colorby, str):
        if colorby != "displacement":
            raise ValueError(f"colorby must be 'displacement', a per-node array or None, got {colorby!r}")
        return np.linalg.norm(u, axis=1)
    values = np.asarray(colorby, dtype=float).ravel()
    if values.shape != (len(u),):
        raise ValueError(f"colorby must have one value per node ({len(u)}), got shape {values.shape}")
    return values


def _label_axes(ax, a, b, length_unit):
    ax.set_xlabel(f"{AXES[a]} ({length_unit})")
    ax.set_ylabel(f"{AXES[b]} ({length_unit})")
    ax.set_aspect("equal")


# ---------------------------------------------------------------------------------------------
# drawing
# ---------------------------------------------------------------------------------------------

def deformed_mesh(ax, ds, *, color="tab:red", colorby=None, deformed: bool = True, plane: str = "yz",
                  length_unit: str = "cm", value_scale: float = 1e3, cmap="viridis", vmin=None, vmax=None,
                  linewidth: float = 0.8, alpha: float = 1.0, label: str | None = None, zorder: float = 2.0):
    """Draw the mesh of result ``ds`` on ``ax`` and return the artist that carries the colours.

    Parameters
    ----------
    ax : a 2D matplotlib axes.
    ds : a result dataset (``rest_position``, ``displacement``, ``cells``).
    color : colour of the wireframe (``None`` draws no edges, only the filling).
    colorby : ``None`` (wireframe only), ``"displacement"`` (fill coloured by ``|u|``) or an array
        with one value per node (e.g. :func:`node_error`).
    deformed : draw the deformed (``X + u``) or the rest configuration.
    plane : for 3D meshes, the two axes drawn (see the module docstring); ignored in 2D.
    length_unit : ``"m"``, ``"cm"`` or ``"mm"`` for the coordinates.
    value_scale : factor applied to the colour values (default 1e3: metres to millimetres).
    cmap, vmin, vmax : colour map and limits (in scaled units) of the filling.
    linewidth, alpha, label : of the wireframe; ``label`` appears in legends.
    zorder : drawing order of the wireframe; the filling is drawn just below it.

    Returns the filling (a :class:`~matplotlib.cm.ScalarMappable`, for ``fig.colorbar``) when
    ``colorby`` is given, else the wireframe's :class:`~matplotlib.collections.LineCollection`.
    """
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import Normalize
    from matplotlib.tri import Triangulation

    X, u, cells, cell_type = _arrays(ds)
    dim = X.shape[1]
    s = _unit(length_unit)
    x = X + u if deformed else X
    values = _node_values(colorby, u)
    if values is not None:
        values = values * value_scale
    a, b, toward = _plane_axes(plane, dim)
    mappable = None
    if dim == 2:
        if cell_type not in _EDGES_2D:
            raise ValueError(f"unsupported 2D cell type {cell_type!r}")
        polys = cells
        if values is not None:
            tris = cells if cell_type == "triangle" else np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
            tri = Triangulation(x[:, 0] * s, x[:, 1] * s, tris)
            mappable = ax.tripcolor(tri, values, shading="gouraud", cmap=cmap, vmin=vmin, vmax=vmax,
                                     zorder=zorder - 0.5)
    else:
        polys = _visible_faces(cells, cell_type, x, toward)
        if values is not None:
            verts = x[polys][:, :, [a, b]] * s
            fv = values[polys].mean(axis=1)
            norm = Normalize(vmin=np.min(fv) if vmin is None else vmin, vmax=np.max(fv) if vmax is None else vmax)
            mappable = PolyCollection(verts, array=fv, cmap=cmap, norm=norm, edgecolors="none",
                                       zorder=zorder - 0.5)
            ax.add_collection(mappable)
    lines = None
    if color is not None:
        edges = _edges(polys)
        segs = x[edges][:, :, [a, b]] * s
        lines = LineCollection(segs, colors=color, linewidths=linewidth, alpha=alpha, label=label, zorder=zorder)
        ax.add_collection(lines)
    ax.autoscale_view()
    _label_axes(ax, a, b, length_unit)
    return mappable if mappable is not None else lines


def node_error(ds, ref_ds) -> np.ndarray:
    """Euclidean distance (m) between the displacements of ``ds`` and ``ref_ds`` at every node of
    ``ds``; when the rest meshes differ, the reference is interpolated at ``ds``'s nodes with its
    own shape functions (:func:`msslib.experiment.interpolate`)."""
    X, u, _, _ = _arrays(ds)
    Xr, ur, _, _ = _arrays(ref_ds)
    if not (X.shape == Xr.shape and np.allclose(X, Xr, atol=1e-12 * max(np.abs(Xr).max(), 1e-300))):
        from msslib.experiment import interpolate
        from msslib.io import mesh_from_result

        ur = interpolate(mesh_from_result(ref_ds), ur, X)
    return np.linalg.norm(u - ur, axis=1)


def error_map(ax, ds, ref_ds, *, plane: str = "yz", length_unit: str = "cm", value_scale: float = 1e3,
              cmap="magma_r", vmax=None, deformed: bool = True, edgecolor="0.6"):
    """Map of :func:`node_error` (scaled by ``value_scale``, default mm) drawn on the (deformed)
    mesh of ``ds`` with thin ``edgecolor`` edges; returns the mappable for a colour bar.  The
    colour scale starts at 0 and ends at ``vmax`` (default: the largest error)."""
    err = node_error(ds, ref_ds)
    vmax = float(err.max() * value_scale) if vmax is None else vmax
    return deformed_mesh(ax, ds, color=edgecolor, colorby=err, deformed=deformed, plane=plane,
                         length_unit=length_unit, value_scale=value_scale, cmap=cmap, vmin=0.0,
                         vmax=max(vmax, 1e-30), linewidth=0.3)


def comparison_figure(pairs: dict, *, plane: str = "yz", length_unit: str = "cm", variant_label: str = "MSS",
                      reference_label: str = "FEM", title: str | None = None, panel_width: float = 3.2,
                      show_rest: bool = True):
    """One column per load case: top, the variant's wireframe (red) over the reference coloured
    by ``|u|`` (mm) and the rest shape (grey); bottom, the per-node error map (mm).

    ``pairs`` maps a column title (e.g. ``"a) stretch"``) to ``(variant_ds, reference_ds)``.  The
    displacement colours share one scale (colour bar on the right); every error map has its own
    colour bar below it, from 0 to its largest error.  Returns the figure.
    """
    from matplotlib.lines import Line2D

    n = len(pairs)
    if n == 0:
        raise ValueError("pairs is empty")
    fig = figure(figsize=(panel_width * n + 1.2, 2 * panel_width + 1.2))
    axes = fig.subplots(2, n, squeeze=False, sharex="col", sharey="col")
    umax = max(float(np.linalg.norm(r["displacement"].values, axis=-1).max()) for _, r in pairs.values()) * 1e3
    im = None
    for j, (name, (var, ref)) in enumerate(pairs.items()):
        top, bottom = axes[0, j], axes[1, j]
        if show_rest:
            deformed_mesh(top, ref, color="0.7", deformed=False, plane=plane, length_unit=length_unit,
                          linewidth=0.5, zorder=0.5)
        im = deformed_mesh(top, ref, color="k", colorby="displacement", plane=plane, length_unit=length_unit,
                           vmin=0.0, vmax=umax, linewidth=0.4)
        deformed_mesh(top, var, color="tab:red", plane=plane, length_unit=length_unit, linewidth=1.0, zorder=3)
        top.set_title(name)
        top.set_xlabel("")
        em = error_map(bottom, var, ref, plane=plane, length_unit=length_unit)
        fig.colorbar(em, ax=bottom, location="bottom", shrink=0.8, aspect=25,
                     label=f"|u$_{{{variant_label}}}$ - u$_{{{reference_label}}}$| (mm)")
        if j:
            top.set_ylabel("")
            bottom.set_ylabel("")
    fig.colorbar(im, ax=axes[0, :].tolist(), label=f"{reference_label} |u| (mm)", shrink=0.9)
    handles = [Line2D([], [], color="tab:red", lw=1.0, label=variant_label),
               Line2D([], [], color="k", lw=0.6, label=f"{reference_label} (colour: |u|)")]
    if show_rest:
        handles.append(Line2D([], [], color="0.7", lw=0.6, label="rest shape"))
    fig.legend(handles=handles, loc="outside upper center", ncol=len(handles), frameon=False)
    if title:
        fig.suptitle(title)
    return fig

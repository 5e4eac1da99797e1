"""Plotting helpers for result datasets (:mod:`msslib.results.netcdf` schema): deformed meshes, error maps.

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
* :func:`node_map` -- per-node values as coloured dots on the nodes (over a thin wireframe);
* :func:`curves_figure` -- a study's error curves, one per Poisson's ratio, one panel per
  selection of the study's other coordinates (one vertical scale for all panels);
* :func:`shared_limits`, :func:`pareto_front`, :func:`label_log_axis`, :func:`unique_legend` --
  one colour scale for compared panels, the non-dominated points of a speed/error plot, log axes
  whose ticks all carry a plain-number label, legends without duplicate entries;
* :func:`save` -- write ``STEM.png`` (150 dpi) and ``STEM.pdf`` atomically.

Lengths are drawn in ``length_unit`` (``"m"``, ``"cm"`` or ``"mm"``; default cm, the unit of the
papers) and displacements / errors coloured in ``value_unit`` (default mm).  In 3D, ``plane``
names the two axes drawn (horizontal first), e.g. ``"yz"``: the view looks along the third axis,
from the side ``cross(e_h, e_v)`` points to (``"yz"``: from +x, ``"xz"``: from -y), and only the
boundary faces turned towards the viewer are drawn, back to front.

Example::

    from experiments import plotting
    from msslib.results import read_result

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

__all__ = ["LENGTH_UNITS", "figure", "deformed_mesh", "node_error", "error_map", "node_map", "comparison_figure",
           "curves_figure", "NU_COLORS", "shared_limits", "pareto_front", "label_log_axis", "unique_legend", "save"]

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
# scales, fronts, axes, legends
# ---------------------------------------------------------------------------------------------

def shared_limits(*arrays, symmetric: bool = False, zero: bool = False) -> tuple[float, float]:
    """One ``(vmin, vmax)`` over the finite values of all ``arrays``, for panels that are compared
    on one colour scale.  ``zero=True`` starts the scale at 0 (errors, magnitudes);
    ``symmetric=True`` centres it on 0 (signed values).  A constant (or empty) set of values gives
    a non-empty interval, so a colour bar can always be drawn."""
    vals = [np.asarray(a, dtype=float).ravel() for a in arrays]
    v = np.concatenate(vals) if vals else np.empty(0)
    v = v[np.isfinite(v)]
    lo, hi = (float(v.min()), float(v.max())) if v.size else (0.0, 0.0)
    if symmetric:
        m = max(abs(lo), abs(hi))
        lo, hi = -m, m
    elif zero:
        lo, hi = min(lo, 0.0), max(hi, 0.0)
    if hi <= lo:
        pad = abs(hi) * 1e-3 or 1e-30
        lo, hi = (lo - pad if not zero or lo < 0 else lo), hi + pad
    return lo, hi


def pareto_front(x, y) -> np.ndarray:
    """Indices of the non-dominated points when both ``x`` (e.g. time) and ``y`` (e.g. error) are
    to be small, in increasing ``x``: point i is kept unless another point is no worse in both
    and better in one.  Non-finite points are ignored; exact duplicates are kept once."""
    x, y = np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()
    if x.shape != y.shape:
        raise ValueError(f"x and y must have the same length, got {x.shape} and {y.shape}")
    idx = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    idx = idx[np.lexsort((y[idx], x[idx]))]  # by x, ties by y
    front, best = [], np.inf
    for i in idx:
        if y[i] < best:
            front.append(i)
            best = y[i]
    return np.asarray(front, dtype=np.int64)


def _plain(v, _pos=None):
    if v == 0 or not np.isfinite(v):
        return "0"
    e = int(np.floor(np.log10(abs(v)) + 1e-9))
    if -3 <= e <= 4:
        return f"{v:.0f}" if e >= 3 else f"{v:.3g}"
    m = v / 10.0 ** e
    return f"$10^{{{e}}}$" if np.isclose(m, 1) else f"${m:.3g}\\cdot10^{{{e}}}$"


def label_log_axis(ax, which: str = "both"):
    """Give the log-scaled axes ``which`` (``"x"``, ``"y"`` or ``"both"``) labelled ticks only:
    the decades (unlabelled minor ticks between them) when the axis spans two decades or more,
    1, 2 and 5 times the decades when it spans less, evenly spaced round numbers when it spans
    less than 0.7 decades (so that at least two ticks are always labelled); labels are plain
    numbers (0.01, 0.5, 10, 15.5) or powers of ten beyond 10^4.  Call after the data are drawn
    and the limits are set."""
    from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter, NullLocator

    for name in ("x", "y") if which == "both" else (which,):
        axis = getattr(ax, f"{name}axis")
        if axis.get_scale() != "log":
            continue
        lo, hi = sorted(getattr(ax, f"get_{name}lim")())
        span = np.log10(hi / lo) if lo > 0 else np.inf
        if span >= 2:
            axis.set_major_locator(LogLocator(base=10, subs=(1.0,)))
            axis.set_minor_locator(LogLocator(base=10, subs=np.arange(2, 10)))
        elif span >= 0.7:
            axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_minor_locator(NullLocator())
        else:  # less than a decade: evenly spaced round numbers
            axis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
            axis.set_minor_locator(NullLocator())
        axis.set_major_formatter(FuncFormatter(_plain))
        axis.set_minor_formatter(NullFormatter())


def unique_legend(target, handles=None, labels=None, **kwargs):
    """A legend on ``target`` (axes or figure) with one entry per label: the first handle with
    a given label is kept, labels starting with ``_`` (matplotlib's "no label") are dropped.
    Without ``handles``, they are collected from ``target`` (all its axes for a figure)."""
    if handles is None:
        axes = target.axes if hasattr(target, "axes") and isinstance(target.axes, list) else [target]
        handles, labels = [], []
        for ax in axes:
            h, lab = ax.get_legend_handles_labels()
            handles += h
            labels += lab
    elif labels is None:
        labels = [h.get_label() for h in handles]
    seen, h_out, l_out = set(), [], []
    for h, lab in zip(handles, labels):
        if not lab or lab.startswith("_") or lab in seen:
            continue
        seen.add(lab)
        h_out.append(h)
        l_out.append(lab)
    return target.legend(h_out, l_out, **kwargs)


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
    own shape functions (:func:`msslib.compare.interpolate`)."""
    X, u, _, _ = _arrays(ds)
    Xr, ur, _, _ = _arrays(ref_ds)
    if not (X.shape == Xr.shape and np.allclose(X, Xr, atol=1e-12 * max(np.abs(Xr).max(), 1e-300))):
        from msslib.compare import interpolate
        from msslib.results import mesh_from_result

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


def node_map(ax, ds, values, *, plane: str = "yz", length_unit: str = "cm", value_scale: float = 1e3,
             cmap="magma_r", vmin=None, vmax=None, deformed: bool = True, magnify: float = 1.0,
             edgecolor="0.7", size: float = 18.0):
    """Per-node ``values`` (one per node of ``ds``, times ``value_scale``) as dots coloured by
    value, on the nodes of the (deformed, displacements times ``magnify``) mesh of ``ds`` over a
    thin ``edgecolor`` wireframe; in 3D only the nodes of the boundary faces turned towards the
    viewer are drawn, back to front.  Returns the scatter (for a colour bar)."""
    X, u, cells, cell_type = _arrays(ds)
    v = np.asarray(values, dtype=float).ravel()
    if v.shape != (len(X),):
        raise ValueError(f"values must have one value per node ({len(X)}), got shape {v.shape}")
    x = X + magnify * u if deformed else X
    shown = ds.copy()
    shown["displacement"] = ds["displacement"] * (magnify if deformed else 0.0)
    if edgecolor is not None:
        deformed_mesh(ax, shown, color=edgecolor, plane=plane, length_unit=length_unit, linewidth=0.4, zorder=1)
    a, b, toward = _plane_axes(plane, X.shape[1])
    if toward is None:
        nodes = np.arange(len(X))
    else:
        nodes = np.unique(_visible_faces(cells, cell_type, x, toward))
        nodes = nodes[np.argsort(x[nodes] @ toward, kind="stable")]
    s = _unit(length_unit)
    sc = ax.scatter(x[nodes, a] * s, x[nodes, b] * s, c=v[nodes] * value_scale, cmap=cmap, vmin=vmin, vmax=vmax,
                    s=size, edgecolors="0.3", linewidths=0.3, zorder=3)
    ax.autoscale_view()
    _label_axes(ax, a, b, length_unit)
    return sc


def comparison_figure(pairs: dict, *, plane: str = "yz", length_unit: str = "cm", variant_label: str = "MSS",
                      reference_label: str = "FEM", title: str | None = None, panel_width: float = 3.2,
                      panel_height: float | None = None, show_rest: bool = True, magnify: float = 1.0,
                      node_errors: bool = False):
    """One column per load case: top, the variant's wireframe (red) over the reference coloured
    by ``|u|`` (mm) and the rest shape (grey); bottom, the per-node error map (mm).

    ``pairs`` maps a column title (e.g. ``"a) stretch"``) to ``(variant_ds, reference_ds)``.  The
    panels of a row are compared, so each row has one colour scale and one colour bar: ``|u|``
    from 0 to the largest reference displacement, the error from 0 to the largest error of all
    columns.  ``magnify`` multiplies the drawn displacements (the colours stay true values);
    ``node_errors=True`` draws the error as one coloured dot per node (:func:`node_map`, on the
    variant's shape drawn as in the top row) instead of an interpolated filling.  Returns the
    figure.
    """
    from matplotlib.lines import Line2D

    n = len(pairs)
    if n == 0:
        raise ValueError("pairs is empty")
    ph = panel_width if panel_height is None else panel_height
    fig = figure(figsize=(panel_width * n + 1.4, 2 * ph + 1.2))
    axes = fig.subplots(2, n, squeeze=False, sharex="col", sharey="col")
    umax = max(float(np.linalg.norm(r["displacement"].values, axis=-1).max()) for _, r in pairs.values()) * 1e3
    errs = {name: node_error(var, ref) for name, (var, ref) in pairs.items()}
    _, emax = shared_limits(*(e * 1e3 for e in errs.values()), zero=True)
    im = em = None

    def shown(ds):
        if magnify == 1.0:
            return ds
        out = ds.copy()
        out["displacement"] = ds["displacement"] * magnify
        return out

    for j, (name, (var, ref)) in enumerate(pairs.items()):
        top, bottom = axes[0, j], axes[1, j]
        if show_rest:
            deformed_mesh(top, ref, color="0.7", deformed=False, plane=plane, length_unit=length_unit,
                          linewidth=0.5, zorder=0.5)
        u_ref = np.linalg.norm(ref["displacement"].transpose("node", "axis").values, axis=1)
        im = deformed_mesh(top, shown(ref), color="k", colorby=u_ref, plane=plane, length_unit=length_unit,
                           vmin=0.0, vmax=umax, linewidth=0.4)
        deformed_mesh(top, shown(var), color="tab:red", plane=plane, length_unit=length_unit, linewidth=1.0,
                      zorder=3)
        top.set_title(name)
        top.set_xlabel("")
        if node_errors:
            em = node_map(bottom, var, errs[name], plane=plane, length_unit=length_unit, vmin=0.0, vmax=emax,
                          magnify=magnify)
        else:
            em = deformed_mesh(bottom, var, color="0.6", colorby=errs[name], plane=plane, length_unit=length_unit,
                               cmap="magma_r", vmin=0.0, vmax=emax, linewidth=0.3)
        if j:
            top.set_ylabel("")
            bottom.set_ylabel("")
    fig.colorbar(im, ax=axes[0, :].tolist(), label=f"{reference_label} |u| (mm)", shrink=0.9)
    fig.colorbar(em, ax=axes[1, :].tolist(), shrink=0.9,
                 label=f"|u$_{{{variant_label}}}$ - u$_{{{reference_label}}}$| (mm)" + (" per node" if node_errors else ""))
    mag = f", displacement x{magnify:g}" if magnify != 1.0 else ""
    handles = [Line2D([], [], color="tab:red", lw=1.0, label=f"{variant_label}{mag}"),
               Line2D([], [], color="k", lw=0.6, label=f"{reference_label}{mag} (fill colour: |u|)")]
    if show_rest:
        handles.append(Line2D([], [], color="0.7", lw=0.6, label="rest shape"))
    fig.legend(handles=handles, loc="outside upper center", ncol=len(handles), frameon=False)
    if title:
        fig.suptitle(title)
    return fig


# ---------------------------------------------------------------------------------------------
# a study's error curves
# ---------------------------------------------------------------------------------------------

#: one colour per Poisson's ratio, the same in every figure of curves
NU_COLORS = {"0.1": "tab:blue", "0.2": "tab:orange", "0.25": "tab:brown", "0.3": "tab:green", "0.4": "tab:red",
             "0.499": "tab:purple"}
# one marker per Poisson's ratio on the solid curves, so that curves lying on each other (nu = 0.4 and
# 0.499 in several of Baudet's panels) stay apart by their markers, not by colour alone
NU_MARKERS = {"0.1": "o", "0.2": "s", "0.25": "^", "0.3": "v", "0.4": "D", "0.499": "P"}


def curves_figure(da, x, *, xlabel, ylabel, panels, xscale=100.0, yscale=100.0, absolute=False, dashed=None,
                  ylog=False, marks=None, band=None, height=None):
    """Curves of ``da`` over ``x`` (drawn times ``xscale``), one per value of its coordinate ``nu``,
    in one panel per entry of ``panels`` (``{title: selection}`` of ``da``'s other coordinates),
    values times ``yscale``. ``dashed``: a second selection drawn dashed in the same panels
    (``{label: selection}``); ``marks``: published points ``{title: [(x, y, nu label), ...]}``,
    black-edged; ``band``: a signed logarithmic axis, linear within +-band, with the band shaded;
    ``height``: the figure's height (inches). One vertical scale for all panels."""
    import matplotlib.ticker
    from matplotlib.lines import Line2D

    n = len(panels)
    fig = figure(figsize=(3.6 * n + 0.4, 3.4))
    # one vertical scale for all panels: the panels compare readings and factors directly
    axes = fig.subplots(1, n, squeeze=False, sharey=True)[0]
    # with a second selection the solid curves are wide and pale and the dashed ones thin with markers
    # on top, so that a dashed curve lying on its solid one stays visible
    solid = {"lw": 3.0, "alpha": 0.45} if dashed else {}
    every = max(len(x) // 8, 1)
    for ax, (title, sel) in zip(axes, panels.items()):
        for i, nu in enumerate(da["nu"].values):
            y = da.sel(**sel, nu=nu).values * yscale
            # markers staggered along x by the curve's index: on coinciding curves they do not cover each other
            start = (i * max(every // 3, 1)) % every
            ax.plot(x * xscale, np.abs(y) if absolute else y, color=NU_COLORS.get(str(nu)), label=f"nu = {nu}",
                    marker=NU_MARKERS.get(str(nu), "o"), ms=4.5, mfc="none", mew=1.0, markevery=(start, every), **solid)
            for sel2 in (dashed or {}).values():
                y2 = da.sel(**{**sel, **sel2}, nu=nu).values * yscale
                ax.plot(x * xscale, np.abs(y2) if absolute else y2, color=NU_COLORS.get(str(nu)), ls="--", lw=1.1,
                        marker="x", ms=3.5, markevery=(start, every))
        for (px, py, nu) in (marks or {}).get(title, []):
            ax.plot(px, py, "o", mfc=NU_COLORS.get(nu, "k"), mec="k", ms=6)
        ax.set_title(title)
        ax.set_xlabel(xlabel)
        ax.grid(alpha=0.3)
        if ylog:
            ax.set_yscale("log")
    axes[0].set_ylabel(ylabel)
    handles, labels = axes[0].get_legend_handles_labels()
    if dashed:
        handles += [Line2D([], [], color="k", ls="-", label="solid: " + next(iter(panels.values())).get("geometry", ""),
                           **solid),
                    Line2D([], [], color="k", ls="--", lw=1.1, marker="x", ms=3.5, label="dashed: " + ", ".join(dashed))]
    if marks:
        handles.append(Line2D([], [], ls="", marker="o", mfc="w", mec="k", label="published (text)"))
    fig.legend(handles=handles, loc="outside upper center", ncol=min(len(handles), 5), frameon=False)
    if height is not None:
        fig.set_size_inches(fig.get_size_inches()[0], height)
    if band is not None:
        lo = min(ax.get_ylim()[0] for ax in fig.axes)
        hi = max(ax.get_ylim()[1] for ax in fig.axes)
        ticks = [t for t in (-200, -100, -50, -20, -10, -5, 0, 5, 10, 20, 50, 100, 200) if lo <= t <= hi]
        for ax in fig.axes:
            # signed log scale: linear within the band (readable), logarithmic beyond
            ax.set_yscale("symlog", linthresh=band, linscale=0.6)
            ax.set_ylim(lo, hi)  # one scale for all panels
            ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
            ax.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
            ax.axhspan(-band, band, color="0.9", zorder=0)
            ax.axhline(0.0, color="0.4", lw=0.6, zorder=0)
            for sign in (1, -1):
                ax.axhline(sign * band, color="k", ls=":", lw=1.0, zorder=1)
                ax.annotate(f"{sign * band:+g} %", (0.0, sign * band), xycoords=("axes fraction", "data"),
                            xytext=(3, 1 if sign > 0 else -1), textcoords="offset points", ha="left",
                            va="bottom" if sign > 0 else "top", fontsize=8)
    return fig

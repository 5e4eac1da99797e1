"""Curves figures (experiments.plotting.curves_figure): curves of different Poisson's ratios that lie
on each other (Baudet's nu = 0.4 and 0.499) stay apart by their markers, placed at different x."""

import numpy as np
import xarray as xr

from experiments import plotting


def test_coinciding_curves_get_distinct_markers_at_distinct_points():
    x = np.linspace(0.0, 0.2, 40)
    nus = ["0.1", "0.2", "0.25", "0.3", "0.4", "0.499"]
    y = np.tile(x, (len(nus), 2, 1))  # every curve the same: the worst case
    da = xr.DataArray(y, dims=("nu", "geometry", "strain"), coords={"nu": nus, "geometry": ["cube", "beam"]})
    fig = plotting.curves_figure(da, x, xlabel="x", ylabel="y", panels={"a": {"geometry": "cube"}},
                                 dashed={"beam": {"geometry": "beam"}})
    ax = fig.axes[0]
    solid = [line for line in ax.get_lines() if line.get_linestyle() == "-"]
    dashed = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert len(solid) == len(dashed) == len(nus)
    markers = [line.get_marker() for line in solid]
    assert len(set(markers)) == len(nus)
    assert markers[nus.index("0.4")] != markers[nus.index("0.499")]
    starts = [line.get_markevery()[0] for line in solid]
    assert starts[nus.index("0.4")] != starts[nus.index("0.499")]
    assert [line.get_markevery() for line in dashed] == [line.get_markevery() for line in solid]

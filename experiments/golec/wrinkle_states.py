"""Shared by the Golec figures: the states the wrinkles study stores, as result-like datasets
that experiments.plotting draws."""

import numpy as np
import xarray as xr


def positions_dataset(rest, x, cells):
    """A minimal result-like dataset (rest_position, displacement, cells) for experiments.plotting."""
    ds = xr.Dataset({"rest_position": (("node", "axis"), np.asarray(rest)),
                     "displacement": (("node", "axis"), np.asarray(x) - np.asarray(rest)),
                     "cells": (("cell", "cell_node"), np.asarray(cells))})
    ds["cells"].attrs["cell_type"] = "hexahedron"
    return ds


def study_state(ds, experiment, state):
    """The rest and deformed node positions of the no-face-diagonal MSS stored by the wrinkles study."""
    return positions_dataset(ds[f"{experiment}_rest"].values, ds[f"{experiment}_{state}"].values,
                             ds[f"{experiment}_cells"].values)

"""Results on disk: NetCDF (CF-1.11 / UGRID-1.0) results, the ParaView files, and the staged,
all-or-nothing writing every output of msslib goes through.

* :mod:`msslib.results.netcdf`: build (:func:`make_dataset`), write (:func:`write_result`,
  :func:`stage_result`) and read (:func:`read_result`, :func:`mesh_from_result`) results;
* :mod:`msslib.results.conventions`: the schema of a result (dimensions, variables, attributes);
* :mod:`msslib.results.staging`: :class:`StagedOutputs`, several files written as one, and the
  clean-up of temporary files on errors, SIGINT and SIGTERM;
* :mod:`msslib.results.paraview`: a result as one VTU file or a ``.pvd`` series.
"""

from msslib.results.conventions import CONVENTIONS, SCHEMA_VERSION
from msslib.results.netcdf import (
    git_commit,
    make_dataset,
    mesh_from_result,
    read_result,
    stage_result,
    write_result,
    write_text,
)
from msslib.results.staging import StagedOutputs, Terminated, remove_stale_temporaries, terminate_raises

__all__ = ["CONVENTIONS", "SCHEMA_VERSION", "git_commit", "make_dataset", "mesh_from_result", "read_result",
           "stage_result", "write_result", "write_text", "StagedOutputs", "Terminated",
           "remove_stale_temporaries", "terminate_raises"]

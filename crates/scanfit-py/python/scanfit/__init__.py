"""scanfit: B-spline curves and surfaces fitted to point clouds, numpy in, numpy out.

A thin layer over the scanfit Rust library (every computation is the library's;
the GIL is released while it runs). Every pipeline of the ``scanfit`` command line
is one function with the command's defaults as keyword defaults, returning its
report as a dict:

- points: ``read_cloud``, ``write_cloud``, ``Cloud``, ``normals``, ``hpr``, ``boundary``,
  ``PointChunks`` (a file's rows a bounded chunk at a time), ``up_axis``
- surfaces: ``fit_surface``, ``mba``, ``coons``, ``turntable``, ``reconstruct``
- curves: ``fit_curve``, ``compare_curves``
- results: ``Surface``, ``Curve``, ``Model`` (evaluate, derivatives, project, export)

Errors are ``ScanfitError`` (a ``ValueError``) with the library's message.

Example::

    >>> import scanfit
    >>> cloud = scanfit.read_cloud("examples/data/terrain_50k.xyz")
    >>> fit = scanfit.fit_surface(cloud, ctrl=(30, 30))
    >>> fit["quality"]["rmse_distance"]          # doctest: +SKIP
    >>> fit["surface"].to_step("terrain.stp")
"""

from ._scanfit import (
    Cloud,
    Curve,
    Model,
    PointChunks,
    ScanfitError,
    Surface,
    __version__,
    boundary,
    coons,
    compare_curves,
    fit_curve,
    fit_surface,
    hpr,
    mba,
    normals,
    read_cloud,
    reconstruct,
    turntable,
    up_axis,
    write_cloud,
)

__all__ = [
    "Cloud",
    "Curve",
    "Model",
    "PointChunks",
    "ScanfitError",
    "Surface",
    "__version__",
    "boundary",
    "coons",
    "compare_curves",
    "fit_curve",
    "fit_surface",
    "hpr",
    "mba",
    "normals",
    "read_cloud",
    "reconstruct",
    "turntable",
    "up_axis",
    "write_cloud",
]

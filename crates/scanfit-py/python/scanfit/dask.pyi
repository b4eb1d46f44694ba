"""Type stubs of scanfit.dask: mba and fit_surface on a dask.distributed cluster."""

from os import PathLike
from typing import Any, Literal, Optional, Sequence, Tuple, Union

Pair = Union[int, Tuple[int, int]]
# a Dask array (N, 3) chunked by rows, or point files the workers read
PointsArg = Union[Any, Sequence[Union[str, PathLike]]]

FAN_IN: int
UP_SAMPLE: int

def mba(
    points: PointsArg,
    levels: int = 6,
    base: Optional[Pair] = None,
    tolerance: Optional[float] = None,
    hjelle: bool = False,
    adjust: bool = False,
    alpha: float = 1.49,
    weight: Literal["moon", "aza04", "as05", "axis4"] = "moon",
    adjust_steps: int = 5,
    start: Optional[Literal["fitted", "mean"]] = None,
    up: Literal["auto", "x", "y", "z"] = "auto",
    *,
    domain: Optional[Tuple[float, float, float, float]] = None,
    chunk_points: int = 1_000_000,
    task_points: Optional[int] = None,
    client: Optional[Any] = None,
) -> dict[str, Any]:
    """scanfit.mba's surface, computed by the workers' partial sums.

    Returns ``surface``, ``up``, ``tasks``, ``cells``, ``levels``, ``vertical``,
    ``points``, ``passes``, ``seconds``, ``broadcast_bytes``.
    """

def fit_surface(
    points: PointsArg,
    ctrl: Optional[Pair] = None,
    degree: Optional[Pair] = None,
    params: Literal["plane", "uv"] = "plane",
    uv: Optional[Any] = None,
    knots: Literal["distribution", "uniform"] = "distribution",
    smooth: Optional[float] = None,
    periodic_u: bool = False,
    correct: int = 0,
    *,
    chunk_points: int = 1_000_000,
    task_points: Optional[int] = None,
    client: Optional[Any] = None,
) -> dict[str, Any]:
    """scanfit.fit_surface's surface, computed by the workers' partial sums.

    Returns ``surface``, ``smoothing``, ``points``, ``tasks``, ``errors``,
    ``rounds``, ``passes``, ``seconds``, ``equation_bytes``, ``projection``
    (with ``params="plane"``: the single-process fit's choice, from the same
    seeded sample; else None).
    """

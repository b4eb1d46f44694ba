"""Type stubs of the scanfit package (the native module scanfit._scanfit)."""

from os import PathLike
from typing import Any, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
Pair = Union[int, Tuple[int, int]]
Vec3 = Tuple[float, float, float]
StrPath = Union[str, PathLike]
Points = Union["Cloud", ArrayLike]

class ScanfitError(ValueError):
    """An error of the scanfit library: bad input, a setting it refuses or a fit it cannot do."""

class Cloud:
    """A point cloud: positions and named per-point attributes."""

    def __init__(self, positions: ArrayLike, attributes: Optional[dict[str, ArrayLike]] = None) -> None: ...
    @property
    def positions(self) -> F64:
        """(N, 3) float64 positions (a new array on each access)."""
    @property
    def attributes(self) -> dict[str, F64]:
        """name -> float64 array of length N."""
    @property
    def path(self) -> Optional[str]: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def dropped_non_finite(self) -> int: ...
    @property
    def bounds(self) -> F64:
        """(2, 3): the bounding box's min and max corners."""
    def with_attribute(self, name: str, values: ArrayLike) -> "Cloud": ...
    def info(self, spacing: bool = True) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

class Surface:
    """A tensor-product B-spline (or NURBS) surface S(u, v)."""

    def evaluate(self, u: ArrayLike, v: ArrayLike) -> F64:
        """Points S(u, v), shape u.shape + (3,)."""
    def derivatives(self, u: ArrayLike, v: ArrayLike, order: int = 1) -> F64:
        """Shape u.shape + (order + 1, order + 1, 3); [..., k, l, :] = d^(k+l)S / du^k dv^l."""
    def normal(self, u: ArrayLike, v: ArrayLike) -> F64: ...
    def project(self, points: ArrayLike) -> Tuple[F64, F64, F64]:
        """Orthogonal projection: (u, v, distance)."""
    @property
    def control_points(self) -> F64:
        """(count_u, count_v, 3)."""
    @property
    def weights(self) -> Optional[F64]: ...
    @property
    def knots(self) -> Tuple[F64, F64]: ...
    @property
    def degree(self) -> Tuple[int, int]: ...
    @property
    def counts(self) -> Tuple[int, int]: ...
    @property
    def periodic(self) -> Tuple[bool, bool]: ...
    @property
    def domain(self) -> Tuple[Tuple[float, float], Tuple[float, float]]: ...
    @overload
    def to_json(self, path: None = None) -> str: ...
    @overload
    def to_json(self, path: StrPath) -> None: ...
    @classmethod
    def from_json(cls, text: str) -> "Surface": ...
    @classmethod
    def read_json(cls, path: StrPath) -> "Surface": ...
    @overload
    def to_step(self, path: None = None) -> str: ...
    @overload
    def to_step(self, path: StrPath) -> None: ...
    @overload
    def to_iges(self, path: None = None) -> str: ...
    @overload
    def to_iges(self, path: StrPath) -> None: ...
    def mesh(self, samples: Optional[Pair] = None) -> dict[str, npt.NDArray[Any]]:
        """vertices (V, 3), normals (V, 3), uv (V, 2), triangles (T, 3) uint32."""
    def to_mesh(self, path: StrPath, samples: Optional[Pair] = None) -> None:
        """OBJ, PLY or glb by extension."""

class Curve:
    """A B-spline (or NURBS) curve C(u)."""

    def evaluate(self, u: ArrayLike) -> F64: ...
    def derivatives(self, u: ArrayLike, order: int = 1) -> F64:
        """Shape u.shape + (order + 1, 3)."""
    def project(self, points: ArrayLike, samples_per_span: int = 16) -> Tuple[F64, F64]:
        """Closest points: (u, distance)."""
    @property
    def control_points(self) -> F64: ...
    @property
    def weights(self) -> Optional[F64]: ...
    @property
    def knots(self) -> F64: ...
    @property
    def degree(self) -> int: ...
    @property
    def periodic(self) -> bool: ...
    @property
    def domain(self) -> Tuple[float, float]: ...
    def length(self, samples_per_span: int = 64) -> float: ...
    @overload
    def to_json(self, path: None = None) -> str: ...
    @overload
    def to_json(self, path: StrPath) -> None: ...
    @classmethod
    def from_json(cls, text: str) -> "Curve": ...
    @classmethod
    def read_json(cls, path: StrPath) -> "Curve": ...
    @overload
    def to_step(self, path: None = None) -> str: ...
    @overload
    def to_step(self, path: StrPath) -> None: ...
    @overload
    def to_iges(self, path: None = None) -> str: ...
    @overload
    def to_iges(self, path: StrPath) -> None: ...

class Model:
    """Patches that share their edge curves (reconstruct's result)."""

    @property
    def surfaces(self) -> list[Tuple[int, Surface]]: ...
    @property
    def edge_curves(self) -> list[Curve]: ...
    @property
    def closed(self) -> bool: ...
    @overload
    def to_json(self, path: None = None) -> str: ...
    @overload
    def to_json(self, path: StrPath) -> None: ...
    @overload
    def to_step(self, path: None = None) -> str: ...
    @overload
    def to_step(self, path: StrPath) -> None: ...
    @overload
    def to_iges(self, path: None = None) -> str: ...
    @overload
    def to_iges(self, path: StrPath) -> None: ...

def read_cloud(
    path: StrPath,
    format: Optional[Literal["ply", "pcd", "las", "laz", "text", "xyz", "csv"]] = None,
    drop_non_finite: bool = False,
) -> Cloud: ...
def write_cloud(
    path: StrPath,
    cloud: Points,
    attributes: Optional[dict[str, ArrayLike]] = None,
    ascii: bool = False,
) -> None: ...

class PointChunks:
    """Rows start..stop of a point file, chunk_points rows at a time, as (points, uv)."""

    def __init__(
        self,
        path: StrPath,
        chunk_points: int = 1_000_000,
        uv: bool = False,
        start: int = 0,
        stop: Optional[int] = None,
    ) -> None: ...
    def __iter__(self) -> "PointChunks": ...
    def __next__(self) -> Tuple[F64, Optional[F64]]:
        """points (n, 3) and, with uv=True, the u, v columns (n, 2)."""
    @property
    def bounded(self) -> bool:
        """Whether memory is bounded by chunk_points (not the whole file read)."""
    @property
    def rows_read(self) -> int: ...

def up_axis(points: Points) -> Literal["x", "y", "z"]:
    """The axis up="auto" takes: the thin axis of a sheet, else "z"."""
def normals(
    points: Points,
    k: int = 16,
    orient: Literal["mst", "view", "none"] = "mst",
    hint: Vec3 = (0.0, 0.0, 1.0),
    viewpoint: Optional[Vec3] = None,
) -> dict[str, Any]: ...
def hpr(points: Points, viewpoint: Vec3, gamma: float = 2.0) -> dict[str, Any]: ...
def boundary(
    points: Points,
    alpha: Optional[float] = None,
    alpha_factor: float = 2.5,
    corners: int = 4,
    criterion: Literal["angle", "curvature"] = "angle",
    corner_offset: Optional[int] = None,
    min_separation: float = 0.03,
    corner_at: Optional[Sequence[int]] = None,
) -> dict[str, Any]: ...
def fit_surface(
    points: Points,
    ctrl: Optional[Pair] = None,
    degree: Optional[Pair] = None,
    params: Literal["plane", "uv"] = "plane",
    uv: Optional[ArrayLike] = None,
    knots: Literal["distribution", "uniform"] = "distribution",
    smooth: Optional[float] = None,
    periodic_u: bool = False,
    correct: int = 0,
) -> dict[str, Any]: ...
def mba(
    points: Points,
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
) -> dict[str, Any]: ...
def coons(
    points: Points,
    pde: Optional[Pair] = None,
    ctrl: Optional[Pair] = None,
    degree: Optional[Pair] = None,
    smooth: Optional[float] = None,
    rigidity: float = 1.0,
    export_tolerance: Optional[float] = None,
    params: Optional[Literal["grid", "closest"]] = None,
    h: float = 0.001,
    epsilon: Optional[float] = None,
    corners: Optional[Sequence[int]] = None,
    sides: int = 4,
    criterion: Literal["angle", "curvature"] = "angle",
    alpha: Optional[float] = None,
    alpha_factor: float = 2.5,
    curves: Literal["lsq", "interpolate"] = "lsq",
    curve_ctrl: Optional[int] = None,
) -> dict[str, Any]: ...
def turntable(
    points: Points,
    axis: Union[None, Literal["auto", "x", "y", "z"], Vec3] = None,
    views: int = 4,
    grid: int = 32,
    layers: int = 40,
    weight: Literal["moon", "aza04", "as05", "axis4"] = "moon",
    rounds: int = 10,
    refine: int = 2,
    margin: float = 0.03,
    ends: Literal["exclude", "extend"] = "exclude",
    ctrl: Optional[Pair] = None,
    compare_weights: bool = False,
    compare_rounds: int = 5,
) -> dict[str, Any]: ...
def fit_curve(
    points: ArrayLike,
    degree: int = 3,
    method: Optional[str] = None,
    ctrl: Optional[int] = None,
    closed: bool = False,
    free_ends: bool = False,
    smooth: float = 0.0,
    end_tangents: Optional[Tuple[Vec3, Vec3]] = None,
) -> dict[str, Any]: ...
def compare_curves(
    points: ArrayLike,
    degree: int = 3,
    methods: Optional[Sequence[str]] = None,
) -> list[dict[str, Any]]: ...
def reconstruct(
    points: Points,
    labels: Optional[str] = None,
    ignore: Optional[Sequence[int]] = None,
    fit: Literal["pde", "bspline"] = "pde",
    pde: Optional[Pair] = None,
    ctrl: Optional[Pair] = None,
    contact: float = 3.0,
    export_tolerance: Optional[float] = None,
) -> dict[str, Any]: ...

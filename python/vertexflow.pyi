"""Type stub of the vertexflow extension module (python/vertexflow_module.cpp).

Meshes are numpy arrays, libigl-style: V is (n, 3) float64 (other dtypes and orders are
converted; C-contiguous float64 is used as it is), F is (m, 3) integer vertex indices. Bad arrays
and options raise ValueError, file problems OSError. Heavy calls release the GIL and take
threads (0: all cores). Nothing is printed; progress goes to the optional callback.
"""

import os
from typing import Any, Callable, Iterable, Literal, NamedTuple, Sequence, overload

import numpy as np
import numpy.typing as npt

__version__: str
FLOW_OPTIONS: tuple[str, ...]

_Path = str | os.PathLike[str]
_Vertices = npt.ArrayLike
_Faces = npt.ArrayLike
_Mesh = tuple[_Vertices, _Faces]

class PrincipalCurvatures(NamedTuple):
    k1: npt.NDArray[np.float64]
    k2: npt.NDArray[np.float64]
    T1: npt.NDArray[np.float64]
    T2: npt.NDArray[np.float64]
    N: npt.NDArray[np.float64]

def as_vertices(V: _Vertices) -> npt.NDArray[np.float64]: ...
def as_faces(F: _Faces, num_vertices: int) -> npt.NDArray[np.int64]: ...
@overload
def read_mesh(
    path: _Path, *, comments: Literal[False] = False
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]: ...
@overload
def read_mesh(
    path: _Path, *, comments: Literal[True]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], list[str]]: ...
def write_mesh(
    path: _Path, V: _Vertices, F: _Faces, *, ascii: bool = False, comments: Sequence[str] | None = None
) -> None: ...
def principal_curvatures(
    V: _Vertices, F: _Faces, *, smoothing_rounds: int = 0, threads: int = 0
) -> PrincipalCurvatures: ...
def enhance(
    V: _Vertices,
    F: _Faces,
    *,
    lam: float = 1.0,
    mu: float = 0.5,
    iterations: int = 1,
    pins: npt.ArrayLike | None = None,
    surface: Literal["input", "smooth"] = "input",
    reference: _Mesh | None = None,
    epsilon: float = 1e-6,
    sliver: float = 0.02,
    fairness_target: Literal["input-normal", "zero"] = "input-normal",
    d_percentile: float = 99.0,
    project_to_input: bool = True,
    feature_angle: float = 40.0,
    fix_boundary: bool = True,
    refuse_non_manifold: bool = False,
    max_halvings: int = 30,
    min_quality: float = 0.3,
    sliver_floor: float = 0.5,
    curvature_smoothing_rounds: int = 0,
    normal_weighting: Literal["max1999", "area", "angle"] = "max1999",
    solver: Literal["automatic", "direct", "iterative", "multilevel"] = "automatic",
    solver_tolerance: float = 1e-7,
    density_passes: int = 0,
    density_exponent: float = 2.0,
    density_epsilon: float = 0.1,
    density_step: float = 0.5,
    max_rounds: int | None = None,
    reference_method: Literal["fit", "flow"] = "fit",
    assume_on_surface: bool = False,
    provenance: Sequence[str] | None = None,
    threads: int = 0,
    progress: Callable[[str], Any] | None = None,
) -> tuple[npt.NDArray[np.float64], dict[str, Any]]: ...
def compare(
    V_result: _Vertices,
    F_result: _Faces,
    V_input: _Vertices,
    F_input: _Faces,
    *,
    reference: _Mesh | None = None,
    threads: int = 0,
) -> dict[str, Any]: ...
def simplify(
    V: _Vertices, F: _Faces, *, faces: int = 0, ratio: float = 0.1, keep_boundary: bool = True, threads: int = 0
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]: ...
def remesh(
    V: _Vertices,
    F: _Faces,
    *,
    target_vertices: int = 6000,
    tolerance: float = 0.05,
    max_attempts: int = 6,
    iterations: int = 10,
    threads: int = 0,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]: ...
def feature_lines(
    V: _Vertices,
    F: _Faces,
    *,
    direction: Sequence[float] | None = None,
    eye: Sequence[float] | None = None,
    contours: bool = True,
    suggestive_contours: bool = True,
    ridges: bool = True,
    valleys: bool = True,
    suggestive_threshold: float = 20.0,
    ridge_threshold: float = 25.0,
    smoothing_scale: float = 0.0,
    length_scale: float = 0.0,
    threads: int = 0,
) -> list[dict[str, Any]]: ...
def line_drawing(
    V: _Vertices,
    F: _Faces,
    *,
    width: int = 800,
    height: int = 600,
    view: Literal["front", "side", "top", "iso", "custom"] = "iso",
    azimuth: float = 30.0,
    elevation: float = 20.0,
    contours: bool = True,
    suggestive_contours: bool = True,
    ridges: bool = True,
    valleys: bool = True,
    suggestive_threshold: float = 20.0,
    ridge_threshold: float = 25.0,
    smoothing_scale: float = 0.0,
    length_scale: float = 0.0,
    hidden_line_removal: bool = True,
    line_width: float = 1.5,
    threads: int = 0,
) -> dict[str, Any]: ...
def compare_lines(
    V_coarse: _Vertices,
    F_coarse: _Faces,
    V_dense: _Vertices,
    F_dense: _Faces,
    *,
    views: int = 8,
    elevation: float = 15.0,
    width: int = 800,
    height: int = 600,
    match_pixels: float = 2.0,
    threads: int = 0,
) -> dict[str, Any]: ...
def render(
    V: _Vertices,
    F: _Faces,
    *,
    width: int = 800,
    height: int = 600,
    view: Literal["front", "side", "top", "iso", "custom"] = "iso",
    color: Literal["none", "mean", "gauss", "quality", "displacement"] = "none",
    shading: Literal["smooth", "flat", "exaggerated"] = "smooth",
    wireframe: bool = False,
    azimuth: float = 30.0,
    elevation: float = 20.0,
    displacement_reference: _Vertices | None = None,
    color_bar: bool = True,
    samples: int = 4,
    threads: int = 0,
) -> npt.NDArray[np.uint8]: ...
def enhance_file(
    input: _Path,
    output: _Path,
    *,
    force: bool = False,
    metrics: bool = True,
    threads: int = 0,
    **flow_options: Any,
) -> dict[str, Any]: ...
def batch(
    inputs: _Path | Iterable[_Path],
    output_dir: _Path,
    *,
    jobs: int = 1,
    threads: int = 0,
    force: bool = False,
    metrics: bool = True,
    progress: Callable[[dict[str, Any]], Any] | None = None,
    **flow_options: Any,
) -> dict[str, Any]: ...

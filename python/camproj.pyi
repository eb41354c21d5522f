"""camproj: fit OpenGL/OpenCV cameras to 2D-3D correspondences, and convert between
intrinsics, pose, look-at, frustum and OpenGL matrices.

Conventions (frames, pixel origin, clip depth, units) are the C++ library's, stated once in
docs/conventions.md; names carry them (cam_from_world, points_in_world, fovy_deg,
clip_from_gl_eye). Python specifics: image sizes are (width, height) tuples; matrices are numpy
arrays indexed M[row, column] (upload a GL matrix M as M.T with transpose=GL_FALSE, or M with
GL_TRUE); pixel_origin and depth are the strings "center" | "corner" and "no" | "zo".

Errors: ``TypeError`` / ``ValueError`` for an argument of the wrong type / value (the message
names it), ``InputError`` (a ValueError)
for a malformed file (names the file, line and column), ``SceneError`` (one subclass per reason)
when the points cannot determine the requested camera, with the command line's message.
"""
import os
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Mat = npt.NDArray[np.float64]
ImageSize = Tuple[int, int]  # (width, height) in pixels

EXPORT_FORMATS: Tuple[str, ...]  # "gl", "glm", "opencv-yaml", "colmap", "three", "json", "glsl", "distortion-mesh"

class SceneError(RuntimeError):
    """The points cannot determine the requested camera; the message says why and what to change
    (exit code 3 of `camproj fit`, which prints ``why`` after "cannot fit:" and ``fix`` after
    "to fix:" on a line of its own). ``str(error)`` is ``why + ". " + fix`` where ``fix`` is not
    empty, else ``why``."""
    why: str  # what the points show
    fix: str  # what to do about it, standing alone ("" where the refusal says it within `why`)

class TooFewPointsError(SceneError):
    """Too few points: fewer equations (2 per distinct point) than the requested camera has
    unknowns, or fewer than its start needs."""
class CollinearPointsError(SceneError):
    """The points lie on one line: no camera is determined."""
class PlanarUnderdeterminedError(SceneError):
    """Coplanar points determine at most 2 intrinsics (besides distortion); more are free."""
class NonFiniteInputError(SceneError):
    """A point or pixel is NaN or infinite, or the coordinates are too large for double
    precision (the message names the point, or says which units to change)."""
class PointsBehindCameraError(SceneError):
    """The camera that fits has points behind it, or a given near / far plane is past every
    point."""
class MirroredWorldError(SceneError):
    """The points fit only a camera seen through a mirror: the world frame is left-handed
    (flip one axis)."""
class DegenerateError(SceneError):
    """The points admit no unique camera (e.g. a plane seen head-on with the focal free)."""
class ContaminatedError(SceneError):
    """Some points disagree with the rest, and the rest cannot say which (default path)."""
class InconsistentError(SceneError):
    """The best camera's residuals are larger than the pixel noise allows; the message names
    the worst points (default path)."""
class AmbiguousError(SceneError):
    """Two different cameras explain the points about equally well."""
class NumericalError(SceneError):
    """The fit failed numerically (a bug if it happens on well-formed input: please report)."""

class InputError(ValueError):
    """A malformed input file: the message names the file, the line and column or the key."""

class Intrinsics:
    """Pinhole intrinsics in px (cx, cy in the pixel origin of the call that made them, OpenCV's by
    default) with OpenCV's lens on normalized coordinates: radial k1, k2, k3, tangential p1, p2."""
    def __init__(self, fx: float, fy: float, cx: float, cy: float, skew: float = 0.0,
                 k1: float = 0.0, k2: float = 0.0, p1: float = 0.0, p2: float = 0.0,
                 k3: float = 0.0) -> None: ...
    fx: float
    fy: float
    cx: float
    cy: float
    skew: float
    k1: float
    k2: float
    p1: float
    p2: float
    k3: float
    @property
    def K(self) -> Mat:
        """[[fx, skew, cx], [0, fy, cy], [0, 0, 1]] (3x3, a new array)."""
    @staticmethod
    def from_K(K: ArrayLike) -> "Intrinsics": ...
    def __eq__(self, other: object) -> bool:
        """Field by field (Intrinsics, Frustum and Perspective alike); all three pickle."""

class Frustum:
    """glFrustum's near-plane window (left, right, bottom, top) at distance ``near`` in gl_eye
    units, and ``far`` (> near, or math.inf)."""
    def __init__(self, left: float, right: float, bottom: float, top: float, near: float,
                 far: float) -> None: ...
    left: float
    right: float
    bottom: float
    top: float
    near: float
    far: float
    def __eq__(self, other: object) -> bool: ...

class Perspective:
    """gluPerspective: full vertical field of view in degrees, width/height aspect, near, far."""
    def __init__(self, fovy_deg: float, aspect: float, near: float, far: float) -> None: ...
    fovy_deg: float
    aspect: float
    near: float
    far: float
    def __eq__(self, other: object) -> bool: ...

class LeftOutPoint:
    index: int          # 0-based, into the fitted points
    residual_px: float  # |predicted - observed| against the returned camera
    rms_with_px: float  # RMS of the same model refitted from the returned camera with the point put back

class FitReport:
    """What `camproj fit` reports (fit.h's FitResult); pixels are px, angles degrees."""
    rms_px: float
    median_px: float
    max_px: float
    model: str                  # e.g. "pose+focal+principal-point"
    criterion: str              # "BIC" | "AIC" ("" for a robust-loss fit)
    start_method: str
    planar: bool
    free_parameters: list[str]
    outliers: list[int]         # 0-based indices of the points left out of the fit
    outlier_method: str
    left_out: list[LeftOutPoint]
    jacobian_condition: float
    iterations: int
    time_ms: float
    pixel_sigma: float          # px per axis, used for the sigmas
    pixel_sigma_estimated: bool
    @property
    def residuals_px(self) -> Mat:
        """(N, 2) predicted - observed per input point, px (inf for a point behind the camera)."""
    @property
    def covariance(self) -> Optional[Mat]: ...
    @property
    def sigmas(self) -> dict[str, Tuple[float, float, str]]:
        """name -> (value, 1-sigma, unit), e.g. "fx" -> (2300.1, 4.2, "px")."""
    @property
    def left_out_parameters(self) -> list[Tuple[str, str]]:
        """Intrinsics the model selection left out, with the reason."""
    @property
    def fixed_parameters(self) -> list[Tuple[str, str]]: ...
    @property
    def consistency(self) -> str: ...
    @property
    def determination(self) -> str: ...
    @property
    def reliability(self) -> Optional[dict[str, Any]]:
        """The least checked point (fit.h PointReliability): point (0-based index), redundancy
        (the fraction of a mis-click of it along direction that its residual keeps), direction
        (unit, image axes), summary; None for a fit without the automatic pipeline."""
    @property
    def linearity(self) -> Optional[dict[str, Any]]:
        """Whether the covariance's linearization holds out to the 99.99 % region (fit.h
        LinearityCheck): linear, level, worst_deviation, bound, worst_direction, summary; None
        without a covariance."""

class Camera:
    """A camera: image size, intrinsics (cx, cy in OpenCV's origin), the cam_from_world pose and
    the GL depth range (near, far). target_distance (> 0, finite) places the look-at target."""
    def __init__(self, image_size: ImageSize, K: ArrayLike, R: ArrayLike, t: ArrayLike,
                 k1: float = 0.0, k2: float = 0.0, near: float = 0.1, far: float = 100.0,
                 target_distance: float = 1.0) -> None: ...
    @staticmethod
    def from_look_at(image_size: ImageSize, K: ArrayLike, eye: ArrayLike, target: ArrayLike,
                     up: ArrayLike, near: float = 0.1, far: float = 100.0) -> "Camera":
        """The pose gluLookAt(eye, target, up) describes (world units)."""
    @property
    def image_size(self) -> ImageSize: ...
    @property
    def intrinsics(self) -> Intrinsics: ...
    @property
    def K(self) -> Mat: ...
    @property
    def R(self) -> Mat:
        """cam_from_world rotation (3x3), a read-only view that keeps the camera alive."""
    @property
    def t(self) -> Mat:
        """cam_from_world translation (3,), world units, a read-only view."""
    @property
    def near(self) -> float: ...
    @property
    def far(self) -> float: ...
    @property
    def projection(self) -> str:
        """"perspective" or "orthographic"."""
    @property
    def eye(self) -> Mat:
        """Camera centre in world."""
    @property
    def target(self) -> Mat:
        """eye + gaze * target distance (a fit's: the points' median depth)."""
    @property
    def up(self) -> Mat:
        """The camera's up (-y of cam) in world, unit."""
    @property
    def frustum(self) -> Optional[Frustum]:
        """glFrustum of the image at (near, far); None with skew or for an orthographic
        camera."""
    @property
    def perspective(self) -> Optional[Perspective]:
        """gluPerspective when the frustum is symmetric, else None (also for an orthographic
        camera)."""
    @property
    def report(self) -> Optional[FitReport]:
        """The fit's report; None for a camera not made by fit()."""
    @property
    def world_origin(self) -> Optional[Mat]:
        """(3,): GL exports' view matrix takes point_in_world - world_origin; None: no origin
        (fit(..., origin="auto" | [X, Y, Z]); docs/conventions.md, section 12)."""
    @property
    def ids(self) -> list[str]: ...
    @property
    def outlier_ids(self) -> list[str]:
        """Ids of the points left out of the fit (1-based numbers without ids)."""
    def gl_projection(self, near: Optional[float] = None, far: Optional[float] = None,
                      depth: str = "no", reversed_z: bool = False) -> Mat:
        """clip_from_gl_eye (4x4), the pinhole part (k1, k2 dropped); near/far default to the
        camera's; depth "no" | "zo"."""
    def gl_view(self) -> Mat:
        """gl_eye_from_world (4x4), the view matrix."""
    def project(self, points_in_world: ArrayLike) -> Mat:
        """(N, 3) -> (N, 2) pixels (OpenCV origin), distortion included; NaN rows for points
        not in front of the camera; ValueError naming a row that is not finite."""
    def summary(self) -> str:
        """The summary `camproj fit` prints, without the "note:" lines it prints after it
        (fitted cameras only; ValueError for another)."""
    def to_json(self, pixel_origin: Optional[str] = None) -> str:
        """The camera file (docs/camera-file.md); for a fitted camera the text `camproj fit -o`
        writes, in the fit's pixel origin unless given."""
    def write(self, path: PathLike, pixel_origin: Optional[str] = None) -> None:
        """to_json() written atomically to path."""
    def export(self, format: str, depth: str = "no", reversed_z: bool = False,
               row_major: bool = False, pixel_origin: str = "center",
               near: Optional[float] = None, far: Optional[float] = None) -> str:
        """`camproj export --to FORMAT`: one of EXPORT_FORMATS (docs/exports.md); near/far
        replace the camera's depth range (far=math.inf: infinite)."""

PathLike = Union[str, bytes, "os.PathLike[str]"]

def fit(points_in_world: ArrayLike, pixels: ArrayLike, image_size: ImageSize, *,
        ids: Optional[Sequence[Union[str, int]]] = None, model: str = "auto",
        criterion: str = "bic", free: Union[str, Sequence[str]] = ...,
        fix: Union[str, Sequence[str]] = ..., focal: Optional[float] = None,
        fovy_deg: Optional[float] = None, aspect: Optional[float] = None,
        principal_point: Optional[ArrayLike] = None, skew: Optional[float] = None,
        k1: Optional[float] = None, k2: Optional[float] = None,
        intrinsics: Union[PathLike, Intrinsics, None] = None, pixel_origin: str = "center",
        loss: str = "none", refiner: str = "lm", keep_all: bool = False,
        ransac_px: Optional[float] = None,
        sigma: Optional[float] = None, max_uncertainty: Optional[float] = None,
        object_points_in_world: Union[PathLike, ArrayLike, None] = None,
        near: Optional[float] = None, far: Optional[float] = None,
        bounds: Optional[Sequence[float]] = None,
        bounds_mesh: Union[PathLike, ArrayLike, None] = None,
        origin: Union[str, Sequence[float], None] = None,
        max_iterations: int = 100) -> Camera:
    """`camproj fit` on arrays: points_in_world (N, 3) seen at pixels (N, 2); every option is
    the command line's (`camproj fit --help`), with '-' as '_' (fovy -> fovy_deg, ransac ->
    ransac_px, intrinsics: a camera-file path or an Intrinsics in OpenCV's origin; bounds: the
    6 numbers of --bounds; bounds_mesh: an OBJ / PLY path or (M, 3) vertices, as
    --bounds-mesh; object_points_in_world: (M, 3) or a points file, as --object-points; origin:
    "auto" or [X, Y, Z], as --origin; free / fix: names, or one string split at commas; ids:
    strings or integers that a points file could hold). None is "not given". Every value is
    checked as the command line checks it: TypeError for the wrong type, ValueError for a wrong
    value (not finite, not positive, an unknown name), naming the option. Same camera, same
    report, same refusals (SceneError subclasses) as the command line. Releases the GIL while
    fitting (also in daemon threads at the interpreter's exit)."""

def fit_file(path: PathLike, image_size: ImageSize, **options: Any) -> Camera:
    """fit() on a points CSV (ids from its id column)."""

def read_camera(path: PathLike) -> Camera: ...
def camera_from_json(text: str, source: str = "<string>") -> Camera: ...
def read_points(path: PathLike) -> Tuple[Mat, Mat, list[str]]:
    """(points_in_world (N, 3), pixels (N, 2), ids) of a points CSV."""
def points_from_csv(text: str, source: str = "<string>") -> Tuple[Mat, Mat, list[str]]: ...
def points_to_csv(points_in_world: ArrayLike, pixels: ArrayLike,
                  ids: Optional[Sequence[Union[str, int]]] = None) -> str: ...
def write_points(path: PathLike, points_in_world: ArrayLike, pixels: ArrayLike,
                 ids: Optional[Sequence[Union[str, int]]] = None) -> None: ...

def write_file_atomically(path: PathLike, contents: str) -> None:
    """Writes text as `camproj fit -o` does: readers see the old file or the new one, never a
    partial one; flushed to disk before the rename (file_io.h)."""

def gl_projection_from_K(K: ArrayLike, image_size: ImageSize, near: float, far: float,
                         depth: str = "no", reversed_z: bool = False,
                         pixel_origin: str = "center") -> Mat:
    """clip_from_gl_eye of pinhole K (skew included) for the image (gl.h)."""
def K_from_gl_projection(clip_from_gl_eye: ArrayLike, image_size: ImageSize,
                         pixel_origin: str = "center") -> Mat: ...
def depth_range_from_gl_projection(clip_from_gl_eye: ArrayLike, depth: str = "no",
                                   reversed_z: bool = False) -> Tuple[float, float]: ...
def gl_projection_from_frustum(frustum: Frustum, depth: str = "no",
                               reversed_z: bool = False) -> Mat: ...
def gl_projection_from_perspective(perspective: Perspective, depth: str = "no",
                                   reversed_z: bool = False) -> Mat: ...
def frustum_from_gl_projection(clip_from_gl_eye: ArrayLike, depth: str = "no",
                               reversed_z: bool = False) -> Frustum: ...
def frustum_from_perspective(perspective: Perspective) -> Frustum: ...
def perspective_from_frustum(frustum: Frustum) -> Perspective:
    """ValueError for an off-axis frustum (no gluPerspective form)."""
def frustum_from_K(K: ArrayLike, image_size: ImageSize, near: float, far: float,
                   pixel_origin: str = "center") -> Frustum: ...
def K_from_frustum(frustum: Frustum, image_size: ImageSize, pixel_origin: str = "center") -> Mat: ...
def cam_from_world_from_look_at(eye: ArrayLike, target: ArrayLike,
                                up: ArrayLike) -> Tuple[Mat, Mat]:
    """(R, t) as gluLookAt builds them; ValueError for eye == target or up along the gaze."""
def look_at_from_cam_from_world(R: ArrayLike, t: ArrayLike,
                                target_distance: float = 1.0) -> Tuple[Mat, Mat, Mat]:
    """(eye, target, up)."""
def gl_view_from_cam_from_world(R: ArrayLike, t: ArrayLike) -> Mat: ...
def cam_from_world_from_gl_view(gl_eye_from_world: ArrayLike) -> Tuple[Mat, Mat]: ...
def pixel_origin_shift(from_origin: str, to_origin: str) -> float:
    """What to add to u, v (or cx, cy): +0.5 from "center" to "corner"."""

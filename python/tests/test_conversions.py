"""Conversions, files and exports of the Python module: round trips, cv2.projectPoints, the
command line's exports, and the lifetime of the arrays the module returns."""
import gc
import itertools
import math
import os

import numpy as np
import pytest

import camproj
from conftest import run_cli

cv2 = pytest.importorskip("cv2", reason="python3-opencv (scripts/install-deps.sh) is not installed")

# Exact algebra in double: a few roundings per entry, each <= 2^-53 relative to the magnitudes
# involved. 1e-12 relative to the largest entry leaves a factor ~100 over the ~10 operations.
EXACT = 1e-12

# A projector: off-axis principal point, skew, non-square pixels (OpenCV origin).
K = np.array([[2300.0, 3.5, 951.25], [0.0, 2310.0, 1079.5], [0.0, 0.0, 1.0]])
SIZE = (1920, 1080)


def close(a, b, relative=EXACT):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(np.max(np.abs(a)), np.max(np.abs(b)), 1e-300)
    return np.max(np.abs(a - b)) <= relative * scale


def pose():
    R, t = camproj.cam_from_world_from_look_at([0.4, 1.1, 3.2], [0.0, 0.9, 0.0], [0.0, 1.0, 0.0])
    return R, t


@pytest.mark.parametrize("depth,reversed_z,far,origin",
                         list(itertools.product(["no", "zo"], [False, True], [20.0, math.inf], ["center", "corner"])))
def test_K_gl_projection_round_trip(depth, reversed_z, far, origin):
    P = camproj.gl_projection_from_K(K, SIZE, 0.5, far, depth=depth, reversed_z=reversed_z, pixel_origin=origin)
    assert close(camproj.K_from_gl_projection(P, SIZE, pixel_origin=origin), K)
    near_back, far_back = camproj.depth_range_from_gl_projection(P, depth=depth, reversed_z=reversed_z)
    assert abs(near_back - 0.5) <= EXACT * 0.5
    assert far_back == far if math.isinf(far) else abs(far_back - far) <= 1e-10 * far
    # The pixel origin moves cx, cy by half a pixel, nothing else.
    if origin == "corner":
        centre = camproj.K_from_gl_projection(P, SIZE, pixel_origin="center")
        assert close(centre[:2, 2] + camproj.pixel_origin_shift("center", "corner"), K[:2, 2])


def test_gl_projection_maps_near_and_far_to_the_clip_range():
    # The purpose of the depth row (gl.h): ndc z is -1 at the near plane and +1 at the far plane.
    P = camproj.gl_projection_from_K(K, SIZE, 0.5, 20.0)
    for z_eye, expected in [(-0.5, -1.0), (-20.0, 1.0)]:
        clip = P @ np.array([0.0, 0.0, z_eye, 1.0])
        assert abs(clip[2] / clip[3] - expected) <= 1e-14
    P_zo_rev = camproj.gl_projection_from_K(K, SIZE, 0.5, 20.0, depth="zo", reversed_z=True)
    clip = P_zo_rev @ np.array([0.0, 0.0, -0.5, 1.0])
    assert abs(clip[2] / clip[3] - 1.0) <= 1e-14


def test_look_at_pose_round_trip():
    eye, target, up = np.array([0.4, 1.1, 3.2]), np.array([0.0, 0.9, 0.0]), np.array([0.1, 1.0, 0.0])
    R, t = camproj.cam_from_world_from_look_at(eye, target, up)
    assert close(R @ R.T, np.eye(3)) and np.linalg.det(R) > 0
    eye2, target2, up2 = camproj.look_at_from_cam_from_world(R, t, np.linalg.norm(target - eye))
    assert close(eye2, eye) and close(target2, target)
    R2, t2 = camproj.cam_from_world_from_look_at(eye2, target2, up2)
    assert close(R2, R) and close(t2, t)
    V = camproj.gl_view_from_cam_from_world(R, t)
    R3, t3 = camproj.cam_from_world_from_gl_view(V)
    assert close(R3, R) and close(t3, t)
    with pytest.raises(ValueError):
        camproj.cam_from_world_from_look_at(eye, eye, up)


def test_frustum_perspective_round_trip():
    p = camproj.Perspective(fovy_deg=40.0, aspect=16 / 9, near=0.1, far=math.inf)
    f = camproj.frustum_from_perspective(p)
    p2 = camproj.perspective_from_frustum(f)
    assert abs(p2.fovy_deg - 40.0) <= EXACT * 40 and abs(p2.aspect - 16 / 9) <= EXACT
    assert close(camproj.gl_projection_from_frustum(f), camproj.gl_projection_from_perspective(p))
    K0 = np.array([[2300.0, 0.0, 951.25], [0.0, 2310.0, 1079.5], [0.0, 0.0, 1.0]])
    frustum = camproj.frustum_from_K(K0, SIZE, 0.5, 20.0)
    assert close(camproj.K_from_frustum(frustum, SIZE), K0)
    f3 = camproj.frustum_from_gl_projection(camproj.gl_projection_from_frustum(frustum))
    assert close([f3.left, f3.right, f3.bottom, f3.top, f3.near],
                 [frustum.left, frustum.right, frustum.bottom, frustum.top, frustum.near])
    with pytest.raises(ValueError, match="off-axis and has no gluPerspective form"):
        camproj.perspective_from_frustum(frustum)  # off-axis: no gluPerspective form


def test_conversions_beyond_a_double_raise_instead_of_returning_inf():
    # Each argument passes its own check; the result does not fit in a double.
    with pytest.raises(ValueError, match="cannot be represented in a double"):
        camproj.gl_projection_from_frustum(camproj.Frustum(-1, 1, -1, 1, 1e308, math.inf))
    with pytest.raises(ValueError, match="cannot be represented in a double"):
        camproj.gl_projection_from_perspective(camproj.Perspective(fovy_deg=1e-320, aspect=1.0,
                                                                   near=1.0, far=10.0))
    with pytest.raises(ValueError, match="look-at target"):
        camproj.look_at_from_cam_from_world(np.eye(3), [0.0, 0.0, -1.5e308], 1e308)


def test_project_matches_cv2_project_points():
    R, t = pose()
    k1, k2 = -0.12, 0.031
    K0 = K.copy()
    K0[0, 1] = 0.0  # cv2.projectPoints ignores skew
    camera = camproj.Camera(SIZE, K0, R, t, k1=k1, k2=k2)
    rng = np.random.default_rng(5)
    points = rng.uniform(-0.5, 0.5, (200, 3)) + [0.0, 0.9, 0.0]
    ours = camera.project(points)
    rvec, _ = cv2.Rodrigues(R)
    theirs, _ = cv2.projectPoints(points, rvec, t, K0, np.array([k1, k2, 0.0, 0.0, 0.0]))
    # Same formula in double; the difference is cv2's Rodrigues round trip (~1e-16 rad) times
    # the focal length and the lever (|X| + |t|) / z ~ 2: ~1e-12 px. 1e-9 px leaves margin.
    assert np.max(np.abs(ours - theirs.reshape(-1, 2))) < 1e-9
    # A point behind the camera has no pixel.
    assert np.all(np.isnan(camera.project([camera.eye - 2 * (camera.target - camera.eye)])))


def test_gl_pipeline_lands_on_the_projected_pixel():
    # The central property (docs/conventions.md): GL's projection, view and viewport put a point
    # on the pixel K [R|t] gives it.
    R, t = pose()
    camera = camproj.Camera(SIZE, K, R, t, near=0.5, far=20.0)
    points = np.array([[0.1, 0.9, -0.2], [-0.3, 1.2, 0.4]])
    clip = (camera.gl_projection() @ camera.gl_view() @ np.c_[points, np.ones(2)].T).T
    ndc = clip[:, :2] / clip[:, 3:]
    window = (ndc + 1) / 2 * SIZE
    pixel = np.c_[window[:, 0] - 0.5, SIZE[1] - window[:, 1] - 0.5]
    # Rounding of ~10 operations on numbers up to ~2000 px: 1e-9 px is far above it.
    assert np.max(np.abs(pixel - camera.project(points))) < 1e-9


def test_camera_properties_are_those_of_the_camera_file(data_dir):
    camera = camproj.read_camera(os.path.join(data_dir, "projector/truth.json"))
    import json
    f = json.loads(camera.to_json())
    assert close(camera.R, f["cam_from_world"]["R"]) and close(camera.t, f["cam_from_world"]["t"])
    assert close(camera.K, [[f["intrinsics"]["fx"], f["intrinsics"]["skew"], f["intrinsics"]["cx"]],
                            [0, f["intrinsics"]["fy"], f["intrinsics"]["cy"]], [0, 0, 1]])
    assert close(camera.gl_projection().flatten(order="F"), f["gl"]["projection"])
    assert close(camera.gl_view().flatten(order="F"), f["gl"]["view"])
    assert close(camera.eye, f["look_at"]["eye"])
    assert camera.frustum.near == f["frustum"]["near"]
    assert camera.image_size == tuple(f["image_size"])
    assert camera.report is None


def test_camera_file_round_trip(tmp_path, data_dir):
    camera = camproj.fit_file(os.path.join(data_dir, "projector/points.csv"), SIZE)
    path = tmp_path / "camera.json"
    camera.write(str(path))
    back = camproj.read_camera(str(path))
    assert back.to_json() == camproj.camera_from_json(back.to_json()).to_json()
    assert np.array_equal(back.R, camera.R) and np.array_equal(back.t, camera.t)  # full precision
    assert np.array_equal(back.K, camera.K)


def test_world_origin_is_fitted_kept_and_exported(tmp_path, data_dir):
    # The projector scene at survey coordinates: origin="auto" is the camera file's world_origin
    # and the gl export's, as `camproj fit --origin auto` writes it; the pose stays absolute.
    points, pixels, ids = camproj.read_points(os.path.join(data_dir, "projector/points.csv"))
    shifted = np.array([412345.678, 5612345.678, 123.456]) + 20.0 * points
    plain = camproj.fit(shifted, pixels, SIZE, ids=ids)
    camera = camproj.fit(shifted, pixels, SIZE, ids=ids, origin="auto")
    assert plain.world_origin is None
    assert np.array_equal(camera.R, plain.R) and np.array_equal(camera.t, plain.t)
    path = tmp_path / "camera.json"
    camera.write(str(path))
    back = camproj.read_camera(str(path))
    assert np.array_equal(back.world_origin, camera.world_origin)
    o = camera.world_origin
    assert "# world origin (%.17g, %.17g, %.17g)" % tuple(o) in back.export("gl")
    fixed = camproj.fit(shifted, pixels, SIZE, ids=ids, origin=[412000.0, 5612000.0, 100.0])
    assert list(fixed.world_origin) == [412000.0, 5612000.0, 100.0]
    with pytest.raises(ValueError, match="origin"):
        camproj.fit(shifted, pixels, SIZE, origin="centre")


def test_points_file_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    points, pixels = rng.normal(size=(7, 3)) * 1e3, rng.normal(size=(7, 2)) * 1e-3
    ids = [f"corner {i}" for i in range(7)]
    path = tmp_path / "p.csv"
    camproj.write_points(str(path), points, pixels, ids)
    p2, q2, ids2 = camproj.read_points(str(path))
    assert np.array_equal(p2, points) and np.array_equal(q2, pixels) and ids2 == ids  # bit for bit
    p3, q3, ids3 = camproj.points_from_csv(camproj.points_to_csv(points, pixels))
    assert np.array_equal(p3, points) and ids3 == [str(i + 1) for i in range(7)]


@pytest.mark.parametrize("fmt,options,cli_options", [
    ("gl", {}, []), ("gl", {"depth": "zo", "reversed_z": True, "row_major": True}, ["--depth", "zo", "--reversed-z", "--row-major"]),
    ("glm", {}, []), ("opencv-yaml", {}, []), ("colmap", {}, []), ("three", {}, []),
    ("json", {"pixel_origin": "corner"}, ["--pixel-origin", "corner"]),
    ("gl", {"near": 0.01, "far": math.inf}, ["--near", "0.01", "--infinite-far"]),
])
def test_every_export_format_equals_the_cli(cli, data_dir, fmt, options, cli_options):
    path = os.path.join(data_dir, "projector/truth.json")
    done = run_cli(cli, "export", path, "--to", fmt, *cli_options)
    assert done.returncode == 0, done.stderr
    assert camproj.read_camera(path).export(fmt, **options) == done.stdout
    assert fmt in camproj.EXPORT_FORMATS


def test_arrays_outlive_the_camera(data_dir):
    camera = camproj.fit_file(os.path.join(data_dir, "projector/points.csv"), SIZE)
    R, t, K0, residuals = camera.R, camera.t, camera.K, camera.report.residuals_px
    expected = [R.copy(), t.copy(), K0.copy(), residuals.copy()]
    assert not R.flags.writeable and not R.flags.owndata  # a view into the camera, read-only
    report = camera.report
    del camera
    gc.collect()
    # Churn the allocator so that freed memory would be reused and overwritten.
    for _ in range(50):
        camproj.fit_file(os.path.join(data_dir, "synthetic/points.csv"), (1280, 800))
    gc.collect()
    for got, want in zip([R, t, K0, residuals], expected):
        assert np.array_equal(got, want)
    assert report.rms_px > 0  # the report keeps its fit alive too


def test_the_stub_declares_every_public_name_of_the_module():
    import ast
    stub = os.path.join(os.path.dirname(__file__), "..", "camproj.pyi")
    tree = ast.parse(open(stub).read())
    declared = {node.name for node in tree.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    declared |= {t.id for node in tree.body if isinstance(node, ast.AnnAssign) for t in [node.target]}
    public = {name for name in dir(camproj) if not name.startswith("_")}
    assert public - declared == set(), "in the module, not in camproj.pyi"
    assert {"fit", "Camera", "SceneError"} <= declared
    for cls in [camproj.Camera, camproj.FitReport, camproj.Intrinsics]:
        node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls.__name__)
        members = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        members |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        missing = {m for m in dir(cls) if not m.startswith("_")} - members
        assert missing == set(), f"{cls.__name__}: {missing} not in camproj.pyi"


# The value types compare field by field and pickle (to ship them to Dask workers); a pickle is
# checked on the way back in as the constructor checks its arguments.
def test_value_types_compare_and_pickle():
    import pickle
    k = camproj.Intrinsics(2300.0, 2310.0, 951.25, 1079.5, 3.5, k1=-0.12, k2=0.03, p1=1e-4, p2=-2e-4, k3=0.001)
    f = camproj.Frustum(-0.4, 0.35, -0.2, 0.25, 0.5, math.inf)
    p = camproj.Perspective(45.0, 16 / 9, 0.1, 100.0)
    for value in [k, f, p]:
        back = pickle.loads(pickle.dumps(value))
        assert back == value and repr(back) == repr(value)
        assert value != 3 and not (value == None)  # noqa: E711
    assert k != camproj.Intrinsics(2300.0, 2310.0, 951.25, 1079.5, 3.5)
    with pytest.raises(ValueError):
        camproj.Perspective.__new__(camproj.Perspective).__setstate__([45.0, 16 / 9, 1.0, 0.5])

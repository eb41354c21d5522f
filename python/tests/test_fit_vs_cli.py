"""camproj.fit against `camproj fit` on every bundled data file: the same camera file (to 1e-12
relative, fit time aside) or the same refusal, with the same message, as a SceneError subclass."""
import glob
import json
import os

import numpy as np
import pytest

import camproj
from conftest import assert_same_json, load_json, run_cli

DATA = os.environ.get("CAMPROJ_DATA_DIR", "/nonexistent")


def cli_refusal(error):
    """What `camproj fit` prints for the refusal `error`: why, then what to do on its own line;
    the two make up the message (str(error) == why + ". " + fix)."""
    assert str(error) == (f"{error.why}. {error.fix}" if error.fix else error.why)
    fix_line = f"camproj: to fix: {error.fix}\n" if error.fix else ""
    return f"camproj: cannot fit: {error.why}\n" + fix_line

# (file under data/, image size, CLI options, the same as fit() keywords)
CASES = [
    ("projector/points.csv", (1920, 1080), [], {}),
    ("projector/misclicked.csv", (1920, 1080), [], {}),
    ("projector/points.csv", (1920, 1080), ["--model", "focal+principal-point"], {"model": "focal+principal-point"}),
    ("projector/points.csv", (1920, 1080), ["--model", "focal+aspect+principal-point", "--loss", "huber:2"],
     {"model": "focal+aspect+principal-point", "loss": "huber:2"}),
    ("projector/points.csv", (1920, 1080), ["--fovy", "40", "--pixel-origin", "corner", "--near", "0.5", "--far", "20"],
     {"fovy_deg": 40, "pixel_origin": "corner", "near": 0.5, "far": 20}),
    ("synthetic/points.csv", (1280, 800), [], {}),
    ("synthetic/points.csv", (1280, 800), ["--ransac", "4", "--keep-all", "--max-uncertainty", "3"],
     {"ransac_px": 4, "keep_all": True, "max_uncertainty": 3}),
    ("projector/points.csv", (1920, 1080), ["--intrinsics", os.path.join(DATA, "projector/truth.json")],
     {"intrinsics": os.path.join(DATA, "projector/truth.json")}),
    ("projector/points.csv", (1920, 1080), ["--object-points", os.path.join(DATA, "synthetic/points.csv")],
     {"object_points_in_world": camproj.read_points(os.path.join(DATA, "synthetic/points.csv"))[0]}
     if os.path.isdir(DATA) else {}),
    # The model's mesh: near and far cover it, and the camera is judged at its vertices.
    ("projector/points.csv", (1920, 1080), ["--bounds-mesh", os.path.join(DATA, "projector/box.obj")],
     {"bounds_mesh": os.path.join(DATA, "projector/box.obj")}),
    ("projector/points.csv", (1920, 1080), ["--bounds", "-0.5,-0.3,-0.4,0.5,0.3,0.4", "--origin", "auto"],
     {"bounds": [-0.5, -0.3, -0.4, 0.5, 0.3, 0.4], "origin": "auto"}),
    ("synthetic/points.csv", (1280, 800), ["--criterion", "aic", "--sigma", "0.5"], {"criterion": "aic", "sigma": 0.5}),
    ("plane/points.csv", (1280, 720), ["--fix", "aspect,principal-point"], {"fix": ["aspect", "principal-point"]}),
    # Refused: a plane with every intrinsic free.
    ("plane/points.csv", (1280, 720), ["--model", "focal+aspect+principal-point+skew"],
     {"model": "focal+aspect+principal-point+skew"}),
] + [(os.path.relpath(p, os.environ.get("CAMPROJ_DATA_DIR", "")), (640, 427), [], {})
     for p in sorted(glob.glob(os.path.join(os.environ.get("CAMPROJ_DATA_DIR", "/nonexistent"), "real/balbianello/cam*.csv")))
     ] + [(os.path.relpath(p, os.environ.get("CAMPROJ_DATA_DIR", "")), (640, 480), [], {})
          for p in sorted(glob.glob(os.path.join(os.environ.get("CAMPROJ_DATA_DIR", "/nonexistent"), "real/opencv_chessboard/*.csv")))]


def test_every_bundled_data_file_is_a_case(data_dir):
    files = {case[0] for case in CASES}
    bundled = {os.path.relpath(p, data_dir) for p in glob.glob(os.path.join(data_dir, "**/*.csv"), recursive=True)}
    assert files == bundled


@pytest.mark.parametrize("name,size,cli_options,options", CASES,
                         ids=[f"{c[0]}{' ' + ' '.join(c[2]) if c[2] else ''}" for c in CASES])
def test_same_camera_or_refusal_as_the_cli(cli, data_dir, name, size, cli_options, options):
    path = os.path.join(data_dir, name)
    done = run_cli(cli, "fit", path, "--image-size", f"{size[0]}x{size[1]}", "--json", *cli_options)
    try:
        camera = camproj.fit_file(path, size, **options)
    except camproj.SceneError as error:
        assert done.returncode == 3, f"Python refused ({error}), the CLI exited {done.returncode}"
        assert type(error) is not camproj.SceneError  # a subclass naming the reason
        assert done.stderr == cli_refusal(error)
        return
    assert done.returncode == 0, f"the CLI exited {done.returncode}: {done.stderr}"
    assert_same_json(load_json(camera.to_json()), load_json(done.stdout))
    # The report's numbers are those of the file's `fit` record.
    record = load_json(done.stdout)["fit"]
    assert camera.report.model == record["model"]
    assert camera.report.outliers == record.get("outliers", [])
    assert abs(camera.report.rms_px - record["rms_px"]) <= 1e-12 * record["rms_px"]
    assert camera.summary().splitlines()[0] == camproj.fit_file(path, size, **options).summary().splitlines()[0]


def test_fit_on_arrays_equals_fit_file(data_dir):
    path = os.path.join(data_dir, "projector/points.csv")
    points, pixels, ids = camproj.read_points(path)
    a = camproj.fit(points, pixels, (1920, 1080), ids=ids)
    b = camproj.fit_file(path, (1920, 1080))
    assert_same_json(load_json(a.to_json()), load_json(b.to_json()))


def test_bounds_mesh_as_vertices_equals_the_mesh_file(data_dir):
    # The mesh's vertices as an array are the mesh file: the same camera file.
    path = os.path.join(data_dir, "projector/points.csv")
    mesh = os.path.join(data_dir, "projector/box.obj")
    vertices = np.array([[float(v) for v in line.split()[1:4]]
                         for line in open(mesh) if line.startswith("v ")])
    a = camproj.fit_file(path, (1920, 1080), bounds_mesh=mesh)
    b = camproj.fit_file(path, (1920, 1080), bounds_mesh=vertices)
    assert_same_json(load_json(a.to_json()), load_json(b.to_json()))
    with pytest.raises(ValueError, match="bounds_mesh: no vertices"):
        camproj.fit_file(path, (1920, 1080), bounds_mesh=np.zeros((0, 3)))


def test_outliers_by_index_and_id(cli, data_dir, tmp_path):
    # Two points of the synthetic scene moved 40 px: found, left out, named by id.
    points, pixels, ids = camproj.read_points(os.path.join(data_dir, "synthetic/points.csv"))
    pixels = pixels.copy()
    pixels[[4, 17], 0] += 40.0
    ids = [f"p{i}" for i in range(len(ids))]
    camera = camproj.fit(points, pixels, (1280, 800), ids=ids)
    assert sorted(camera.report.outliers) == [4, 17]
    assert sorted(camera.outlier_ids) == ["p17", "p4"]
    assert sorted(p.index for p in camera.report.left_out) == [4, 17]
    assert all(p.residual_px > 20 for p in camera.report.left_out)
    # The CLI on the same file says the same.
    csv = tmp_path / "moved.csv"
    csv.write_text(camproj.points_to_csv(points, pixels, ids))
    done = run_cli(cli, "fit", csv, "--image-size", "1280x800", "--json")
    assert done.returncode == 0, done.stderr
    assert_same_json(load_json(camera.to_json()), load_json(done.stdout))


def test_report_fields(data_dir):
    camera = camproj.fit_file(os.path.join(data_dir, "projector/points.csv"), (1920, 1080))
    report = camera.report
    assert report.model.startswith("pose+focal")
    assert report.criterion == "BIC"
    assert report.residuals_px.shape == (20, 2)
    # Every intrinsic the model selection left out comes with a reason.
    assert report.left_out_parameters and all(why for _, why in report.left_out_parameters)
    value, sigma, unit = report.sigmas["fx"]
    assert value == camera.intrinsics.fx and sigma > 0 and unit == "px"
    assert report.covariance.shape == (len(report.free_parameters),) * 2
    assert "consistent" in report.consistency
    # The least checked point, as the camera file says it.
    reliability = report.reliability
    assert 0 <= reliability["point"] < 20 and 0 <= reliability["redundancy"] <= 1
    assert abs(reliability["direction"][0] ** 2 + reliability["direction"][1] ** 2 - 1) < 1e-12
    assert reliability["summary"] == json.loads(camera.to_json())["fit"]["reliability"]
    # The linearity check, as the camera file has it (fit.h LinearityCheck).
    linearity = report.linearity
    fit_record = json.loads(camera.to_json())["fit"]["linearity"]
    assert linearity["linear"] == fit_record["linear"] == (linearity["worst_deviation"] <= linearity["bound"])
    assert linearity["worst_deviation"] == fit_record["worst_deviation"]
    assert linearity["level"] == 0.9999 and linearity["summary"]


@pytest.mark.parametrize("points,options,error", [
    # Three points cannot determine a camera.
    ([[0, 0, -2], [1, 0, -2], [0, 1, -2]], {}, camproj.TooFewPointsError),
    # Points on one line.
    ([[t, 2 * t, -2 - t] for t in range(8)], {}, camproj.CollinearPointsError),
])
def test_refusals_are_scene_error_subclasses_with_the_cli_message(cli, tmp_path, points, options, error):
    pixels = [[100.0 + 37 * i, 200.0 + 11 * i * i] for i in range(len(points))]
    with pytest.raises(error) as raised:
        camproj.fit(points, pixels, (640, 480), **options)
    csv = tmp_path / "p.csv"
    csv.write_text(camproj.points_to_csv(points, pixels))
    done = run_cli(cli, "fit", csv, "--image-size", "640x480")
    assert done.returncode == 3
    assert done.stderr == cli_refusal(raised.value)


def test_mirrored_world_is_refused(data_dir):
    points, pixels, _ = camproj.read_points(os.path.join(data_dir, "synthetic/points.csv"))
    points = points.copy()
    points[:, 0] *= -1  # a left-handed world
    with pytest.raises(camproj.SceneError) as raised:
        camproj.fit(points, pixels, (1280, 800))
    assert "mirror" in str(raised.value) or "left-handed" in str(raised.value)


@pytest.mark.parametrize("call,message", [
    (lambda: camproj.fit([[0, 0, 1, 4]], [[0, 0]], (640, 480)), "points_in_world: expected an (N, 3) array, got shape (1, 4)"),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0, 0]], (640, 480)), "pixels: expected an (N, 2) array"),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0]], (640, 480), modle="auto"), 'fit: unknown option "modle"'),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0]], (640, 480), model="focal+zoom"), '--model: unknown parameter "zoom"'),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0]], (640, 480), focal=-3), "focal: expected a positive number"),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0]], (0, 480)), "image size must be positive, got 0x480"),
    (lambda: camproj.fit([[0, 0, 1]], [[0, 0]], (640, 480), ids=["a", "b"]), "ids: expected one per point (1), got 2"),
    (lambda: camproj.gl_projection_from_K([[1000, 0, 320], [0, 1000, 240], [0, 0, 1]], (640, 480), 1, 10, depth="z"), '"z"'),
])
def test_bad_arguments_raise_value_error_naming_the_value(call, message):
    with pytest.raises(ValueError) as raised:
        call()
    assert message in str(raised.value)


def test_malformed_file_raises_input_error(tmp_path):
    csv = tmp_path / "bad.csv"
    csv.write_text("X,Y,Z,u,v\n1,2,3,4,abc\n")
    with pytest.raises(camproj.InputError) as raised:
        camproj.read_points(str(csv))
    assert str(raised.value) == f'{csv}: line 2, column 5 (v): expected a number, got "abc"'
    assert isinstance(raised.value, ValueError)

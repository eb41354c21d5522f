#include "camproj/camera_file.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "camproj/calibration_file.h"
#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

Camera RandomFileCamera(std::mt19937_64& rng) {
  const testing::RandomCamera random = testing::MakeRandomCamera(rng);
  Camera camera;
  camera.image_size = random.size;
  camera.intrinsics = random.intrinsics;
  camera.intrinsics.k1 = testing::Uniform(rng, -0.2, 0.2);
  camera.cam_from_world = random.cam_from_world;
  camera.z_near = testing::LogUniform(rng, 1e-3, 1);
  camera.z_far = camera.z_near * testing::LogUniform(rng, 2, 1e5);
  return camera;
}

std::string ExpectInputError(const std::string& text) {
  try {
    CameraFromJsonText(text, "cam.json");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for " << text;
  return "";
}

TEST(CameraFileTest, RoundTripsBitForBitInBothPixelOrigins) {
  std::mt19937_64 rng(testing::Seed(8));
  for (int i = 0; i < 200; ++i) {
    Camera camera = RandomFileCamera(rng);
    if (i % 3 == 0) {  // OpenCV's whole lens
      camera.intrinsics.k2 = testing::Uniform(rng, -0.1, 0.1);
      camera.intrinsics.p1 = testing::Uniform(rng, -0.01, 0.01);
      camera.intrinsics.p2 = testing::Uniform(rng, -0.01, 0.01);
      camera.intrinsics.k3 = testing::Uniform(rng, -0.1, 0.1);
    }
    CameraFileOptions options;
    options.pixel_origin = i % 2 ? PixelOrigin::kCorner : PixelOrigin::kCenter;
    const Camera back = CameraFromJsonText(CameraToJsonText(camera, options), "test");
    EXPECT_EQ(back.image_size.width, camera.image_size.width);
    EXPECT_EQ(back.intrinsics.fx, camera.intrinsics.fx);
    EXPECT_EQ(back.intrinsics.skew, camera.intrinsics.skew);
    EXPECT_EQ(back.intrinsics.k1, camera.intrinsics.k1);
    EXPECT_EQ(back.intrinsics.k2, camera.intrinsics.k2);
    EXPECT_EQ(back.intrinsics.p1, camera.intrinsics.p1);
    EXPECT_EQ(back.intrinsics.p2, camera.intrinsics.p2);
    EXPECT_EQ(back.intrinsics.k3, camera.intrinsics.k3);
    if (options.pixel_origin == PixelOrigin::kCenter) {
      EXPECT_EQ(back.intrinsics.cx, camera.intrinsics.cx);
      EXPECT_EQ(back.intrinsics.cy, camera.intrinsics.cy);
    } else {
      // +0.5 then -0.5 may round once.
      EXPECT_NEAR(back.intrinsics.cx, camera.intrinsics.cx, 1e-15 * (std::abs(camera.intrinsics.cx) + 1));
    }
    EXPECT_EQ(back.cam_from_world.rotation, camera.cam_from_world.rotation);
    EXPECT_EQ(back.cam_from_world.translation, camera.cam_from_world.translation);
    EXPECT_EQ(back.z_near, camera.z_near);
    EXPECT_EQ(back.z_far, camera.z_far);
  }
}

// An orthographic camera keeps its projection through the file; its glOrtho box is written, and
// no frustum or perspective (they do not exist for it).
TEST(CameraFileTest, OrthographicCameraRoundTrips) {
  std::mt19937_64 rng(testing::Seed(9));
  Camera camera = RandomFileCamera(rng);
  camera.projection = Projection::kOrthographic;
  camera.intrinsics.k1 = 0.0;
  camera.intrinsics.skew = 0.0;
  const std::string text = CameraToJsonText(camera);
  EXPECT_NE(text.find("\"orthographic\""), std::string::npos);
  EXPECT_NE(text.find("\"ortho\""), std::string::npos);
  EXPECT_EQ(text.find("\"perspective\": {"), std::string::npos);
  const Camera back = CameraFromJsonText(text, "test");
  EXPECT_EQ(back.projection, Projection::kOrthographic);
  EXPECT_EQ(back.intrinsics.fx, camera.intrinsics.fx);
  EXPECT_EQ(back.z_far, camera.z_far);
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480], "projection": "fisheye",
    "intrinsics": {"fx": 500, "fy": 500, "cx": 319.5, "cy": 239.5},
    "look_at": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]},
    "frustum": {"near": 0.1, "far": 10}})").find("projection"), std::string::npos);
}

TEST(CameraFileTest, InfiniteFarAndLookAtPoseAreRead) {
  const Camera camera = CameraFromJsonText(R"({
    "image_size": [640, 480],
    "intrinsics": {"fx": 500, "fy": 500, "cx": 319.5, "cy": 239.5},
    "look_at": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]},
    "frustum": {"near": 0.1, "far": "inf"}})", "t");
  EXPECT_EQ(camera.z_far, kInfinity);
  EXPECT_EQ(camera.cam_from_world.translation, Eigen::Vector3d(0, 0, 5));
  EXPECT_NE(CameraToJsonText(camera).find("\"perspective\""), std::string::npos);
}

// The fit record holds no non-finite number, which JSON would write as null: an unbounded
// linearity deviation (a point crosses behind the camera within the probed region) and a
// left-out point behind the camera (no pixel, no residual) are said in words. Found by the
// fit_scene fuzzer (issue #11): both were null.
TEST(CameraFileTest, FitRecordHoldsNoNonFiniteNumber) {
  std::mt19937_64 rng(testing::Seed(10));
  const Camera camera = RandomFileCamera(rng);
  FitRecord fit;
  fit.outliers = {3, 5};
  fit.outlier_method = "leave-one-out";
  fit.outlier_points = {{3, std::numeric_limits<double>::infinity(), 0.0}, {5, 120.5, 0.7}};
  fit.linearity.checked = true;
  fit.linearity.worst_deviation = std::numeric_limits<double>::infinity();
  fit.linearity.worst_direction = "fx";
  const std::string text = CameraToJsonText(camera, {}, &fit);
  EXPECT_EQ(text.find("null"), std::string::npos) << text;
  EXPECT_NE(text.find("\"behind_camera\": true"), std::string::npos) << text;
  EXPECT_NE(text.find("\"residual_px\": 120.5"), std::string::npos) << text;
  EXPECT_NE(text.find("\"unbounded\": true"), std::string::npos) << text;
  EXPECT_EQ(text.find("worst_deviation"), std::string::npos) << text;
  fit.linearity.worst_deviation = 0.25;
  const std::string bounded = CameraToJsonText(camera, {}, &fit);
  EXPECT_NE(bounded.find("\"worst_deviation\": 0.25"), std::string::npos) << bounded;
  EXPECT_NE(bounded.find("\"unbounded\": false"), std::string::npos) << bounded;
}

TEST(CameraFileTest, MalformedFilesNameTheKeyOrLine) {
  const std::string good_prefix =
      R"({"image_size": [640, 480], "intrinsics": {"fx": 500, "fy": 500, "cx": 1, "cy": 2},)";
  EXPECT_NE(ExpectInputError("{\n\"image_size\": [640,\n 480,,]}").find("line 3"), std::string::npos);
  EXPECT_NE(ExpectInputError("").find("cam.json"), std::string::npos);
  EXPECT_NE(ExpectInputError(R"({"image_size": [640]})").find("image_size"), std::string::npos);
  // A key twice in one object (the last was kept silently before session 37), at any depth.
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480], "image_size": [10, 10]})")
                .find("cam.json: key \"image_size\" appears twice in one object"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480], "intrinsics": {"fx": 1, "fx": 2}})")
                .find("key \"fx\" appears twice"),
            std::string::npos);
  // The same key in two objects is no duplicate.
  EXPECT_EQ(ExpectInputError(R"({"image_size": [640, 480], "a": {"fx": 1}, "b": {"fx": 2}})")
                .find("appears twice"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480]})").find("intrinsics: missing"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(good_prefix + R"("frustum": {"near": 1, "far": 2}})").find("look_at: missing"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(good_prefix + R"("look_at": {"eye": [0,0,0], "target": [0,0,0], "up": [0,1,0]},
            "frustum": {"near": 1, "far": 2}})").find("equals target"), std::string::npos);
  EXPECT_NE(ExpectInputError(good_prefix + R"("look_at": {"eye": [0,0,1], "target": [0,0,0], "up": [0,1,0]},
            "frustum": {"near": 0, "far": 2}})").find("near must be positive"), std::string::npos);
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480], "intrinsics": {"fx": "a", "fy": 1, "cx": 1, "cy": 2}})")
                .find("intrinsics.fx: expected a number"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(good_prefix + R"("cam_from_world": {"R": [[1,0,0],[0,1,0],[0,0,-1]], "t": [0,0,0]},
            "frustum": {"near": 1, "far": 2}})").find("left-handed"), std::string::npos);
}

// Values that pass their own checks but whose derived views overflow a double are refused under
// the key they come from: the pose (its look-at eye is -R^T t) or the intrinsics with near and far
// (whose frustum and projection matrix).
TEST(CameraFileTest, ViewsBeyondADoubleNameWhereTheyComeFrom) {
  const std::string intrinsics = R"({"image_size": [640, 480],
      "intrinsics": {"fx": 500, "fy": 500, "cx": 319.5, "cy": 239.5},)";
  const std::string rotated = R"("R": [[0.6,0,0.8],[0,1,0],[-0.8,0,0.6]])";
  const std::string overflowing_pose =
      ExpectInputError(intrinsics + R"("cam_from_world": {)" + rotated +
                       R"(, "t": [1.5e308, 0, 1.5e308]}, "frustum": {"near": 1, "far": 2}})");
  EXPECT_NE(overflowing_pose.find("cam.json: cam_from_world: the look-at eye"), std::string::npos)
      << overflowing_pose;
  const std::string overflowing_frustum = ExpectInputError(intrinsics + R"("cam_from_world": {)" +
                                                           rotated + R"(, "t": [0, 0, 0]},
      "frustum": {"near": 1e308, "far": "inf"}})");
  EXPECT_NE(overflowing_frustum.find("cam.json: intrinsics with frustum.near, frustum.far: "),
            std::string::npos)
      << overflowing_frustum;
}

// The message of the InputError that selecting `view` in `text` as "calib.json" throws.
std::string ExpectViewError(const std::string& text, const std::string& view) {
  try {
    CalibrationViewFromJsonText(text, "calib.json", view);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for view " << view;
  return "";
}

// A calibration file's view is selected by name, bit for bit the camera that was written; a
// calibration file is not taken for one camera, a camera file not for a calibration.
TEST(CameraFileTest, CalibrationViewsAreSelectedByName) {
  std::mt19937_64 rng(testing::Seed(31));
  Calibration calibration;
  calibration.image_size = {640, 480};
  for (const char* name : {"left01", "left03"}) {
    CalibratedView view;
    view.name = name;
    view.camera = RandomFileCamera(rng);
    view.camera.image_size = calibration.image_size;
    view.num_points = 54;
    calibration.views.push_back(view);
  }
  calibration.intrinsics = calibration.views[0].camera.intrinsics;
  calibration.refused_views.push_back({"left02", 54, 1.24, 0.25, 200.0, 40.0, ""});
  const std::string text = CalibrationToJsonText(calibration);
  for (const CalibratedView& view : calibration.views) {
    const Camera back = CalibrationViewFromJsonText(text, "calib.json", view.name);
    EXPECT_EQ(back.cam_from_world.rotation, view.camera.cam_from_world.rotation);
    EXPECT_EQ(back.cam_from_world.translation, view.camera.cam_from_world.translation);
    EXPECT_EQ(back.intrinsics.fx, view.camera.intrinsics.fx);
    EXPECT_EQ(back.intrinsics.cx, view.camera.intrinsics.cx);
    EXPECT_EQ(back.intrinsics.k1, view.camera.intrinsics.k1);
    EXPECT_EQ(back.z_near, view.camera.z_near);
    EXPECT_EQ(back.z_far, view.camera.z_far);
  }
  EXPECT_EQ(ExpectViewError(text, "left02"),
            "calib.json: view left02 was refused by the calibration (refused_views): it has no "
            "camera");
  EXPECT_EQ(ExpectViewError(text, "left9"),
            "calib.json: no view named left9; the views are left01, left03");
  EXPECT_EQ(ExpectInputError(text),
            "cam.json: a calibration file of 2 views, not one camera: select a view by its name "
            "(camproj export and project: --view NAME)");
  EXPECT_EQ(ExpectViewError(CameraToJsonText(calibration.views[0].camera), "left01"),
            "calib.json: not a calibration file (no views array): a view is selected only in the "
            "file camproj calibrate writes");
  EXPECT_EQ(ExpectViewError(R"({"views": [{"name": "a", "camera": {"image_size": [640, 480]}}]})",
                            "a"),
            "calib.json, view a: intrinsics: missing");
  EXPECT_EQ(ExpectViewError(R"({"views": [{"name": "a"}]})", "a"),
            "calib.json, view a: camera: missing");
}

// The convention a file states cx, cy in, for the commands that compare it with the user's
// pixels: the camera file's pixel_origin, a calibration view's, kCenter where absent; a bad value
// refused as the camera reader refuses it.
TEST(CameraFileTest, PixelOriginIsTheFilesStatedConvention) {
  std::mt19937_64 rng(testing::Seed(32));
  const Camera camera = RandomFileCamera(rng);
  for (const PixelOrigin origin : {PixelOrigin::kCenter, PixelOrigin::kCorner}) {
    CameraFileOptions options;
    options.pixel_origin = origin;
    EXPECT_EQ(CameraFilePixelOrigin(CameraToJsonText(camera, options), "cam.json"), origin);
    Calibration calibration;
    calibration.image_size = camera.image_size;
    CalibratedView view;
    view.name = "left01";
    view.camera = camera;
    view.num_points = 54;
    calibration.views.push_back(view);
    calibration.intrinsics = camera.intrinsics;
    const std::string text = CalibrationToJsonText(calibration, options);
    EXPECT_EQ(CameraFilePixelOrigin(text, "calib.json", "left01"), origin);
  }
  EXPECT_EQ(CameraFilePixelOrigin(R"({"image_size": [640, 480]})", "cam.json"),
            PixelOrigin::kCenter);
  EXPECT_THROW(CameraFilePixelOrigin(R"({"pixel_origin": "middle"})", "cam.json"), InputError);
  EXPECT_THROW(CameraFilePixelOrigin(R"({"views": []})", "calib.json", "left01"), InputError);
}

// Every reader of the JSON files goes through one parser, so a number beyond a double's range
// names its line in a calibration file's view and in an intrinsics file as in a camera file
// (fx 1e-400 read as 0 would be "fx must be positive, got 0", with no line).
TEST(CameraFileTest, CalibrationAndIntrinsicsReadersNameAnOutOfRangeNumbersLine) {
  const std::string calibration =
      "{\"views\": [{\"name\": \"a\", \"camera\": {\"image_size\": [640, 480],\n"
      "  \"intrinsics\": {\"fx\": 1e-400, \"fy\": 500, \"cx\": 1, \"cy\": 2}}}]}";
  EXPECT_EQ(ExpectViewError(calibration, "a"),
            "calib.json: line 2: the number 1e-400 is out of the range of a double (too small: "
            "it would read as 0)");
  const std::string intrinsics = "{\"image_size\": [640, 480],\n\"intrinsics\": {\"fx\": 500,\n"
                                 "\"fy\": 500, \"cx\": 1e400, \"cy\": 2}}";
  try {
    IntrinsicsFromJsonText(intrinsics, "k.json", nullptr);
    ADD_FAILURE() << "no InputError for " << intrinsics;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "k.json: line 3: the number 1e400 is out of the range of a double");
  }
}

// An orthographic camera's fx, fy are px per world unit: not intrinsics a pose fit can take
// (`camproj fit --intrinsics ortho.json` fitted a pinhole from them and refused the points as
// mismatched).
TEST(CameraFileTest, AnOrthographicCamerasIntrinsicsAreRefusedAsAPinholes) {
  const std::string intrinsics =
      R"({"image_size": [640, 480], "intrinsics": {"fx": 40, "fy": 40, "cx": 319.5, "cy": 239.5},
          "projection": )";
  for (const auto& [projection, message] :
       {std::pair<std::string, std::string>{
            "\"orthographic\"",
            "k.json: projection: an orthographic camera's intrinsics (px per world unit) are not "
            "a pinhole's: give a perspective camera or a calibration"},
        {"\"fisheye\"", "k.json: projection: expected \"perspective\" or \"orthographic\""},
        {"3", "k.json: projection: expected \"perspective\" or \"orthographic\""}}) {
    try {
      IntrinsicsFromJsonText(intrinsics + projection + "}", "k.json", nullptr);
      ADD_FAILURE() << "no InputError for projection " << projection;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
  EXPECT_EQ(IntrinsicsFromJsonText(intrinsics + "\"perspective\"}", "k.json", nullptr).fx, 40.0);
}

// world_origin (docs/camera-file.md) is optional: absent stays absent, present round-trips bit
// for bit (shortest round-trip printing), and gl.view_relative_to_origin is written with it.
TEST(CameraFileTest, WorldOriginRoundTripsAndIsOptional) {
  std::mt19937_64 rng(testing::Seed(10));
  for (int i = 0; i < 50; ++i) {
    Camera camera = RandomFileCamera(rng);
    const std::string without = CameraToJsonText(camera);
    EXPECT_EQ(without.find("world_origin"), std::string::npos);
    EXPECT_EQ(without.find("view_relative_to_origin"), std::string::npos);
    EXPECT_FALSE(CameraFromJsonText(without, "test").world_origin.has_value());
    const Eigen::Vector2d origin_xy =
        testing::DrawVector2([&] { return testing::Uniform(rng, -1e7, 1e7); });
    camera.world_origin = Eigen::Vector3d(origin_xy.x(), origin_xy.y(), 412350.0);
    const std::string with = CameraToJsonText(camera);
    EXPECT_NE(with.find("\"view_relative_to_origin\""), std::string::npos);
    const Camera back = CameraFromJsonText(with, "test");
    ASSERT_TRUE(back.world_origin.has_value());
    EXPECT_EQ(*back.world_origin, *camera.world_origin);
    EXPECT_EQ(back.cam_from_world.translation, camera.cam_from_world.translation);
  }
}

TEST(CameraFileTest, MalformedWorldOriginNamesTheKey) {
  const std::string prefix =
      R"({"image_size": [640, 480], "intrinsics": {"fx": 500, "fy": 500, "cx": 1, "cy": 2},
          "look_at": {"eye": [0,0,1], "target": [0,0,0], "up": [0,1,0]},
          "frustum": {"near": 1, "far": 2}, "world_origin": )";
  EXPECT_NE(ExpectInputError(prefix + "[1, 2]}").find("world_origin: expected an array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(prefix + R"([1, "a", 3]})").find("world_origin[1]: expected a number"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(prefix + "\"auto\"}").find("world_origin: expected an array"),
            std::string::npos);
  EXPECT_NE(ExpectInputError(prefix + "[1, 2, 1e400]}").find("cam.json: line 3: the number 1e400 is out of the range of a double"),
            std::string::npos);
  // One too small for a double read as 0 (fx 1e-400 was refused as "fx must be positive, got 0",
  // a world origin 1e-400 taken as 0); a subnormal one is a double and reads as itself.
  EXPECT_NE(ExpectInputError(prefix + "[1, 2,\n -1E-400]}")
                .find("cam.json: line 4: the number -1E-400 is out of the range of a double (too small: it would read as 0)"),
            std::string::npos);
  EXPECT_EQ(CameraFromJsonText(prefix + "[1e-310, 0e-500, -0.0]}", "cam.json").world_origin->x(), 1e-310);
  // Finite, but C - origin overflows a double: refused when read, naming the key (every number
  // the file derives must be finite).
  EXPECT_NE(ExpectInputError(R"({"image_size": [640, 480], "intrinsics": {"fx": 500, "fy": 500, "cx": 1, "cy": 2},
      "cam_from_world": {"R": [[1,0,0],[0,1,0],[0,0,1]], "t": [-1e308, 0, 0]},
      "frustum": {"near": 1, "far": 2}, "world_origin": [-1e308, 0, 0]})")
                .find("cam.json: world_origin: the view matrix relative to it is not finite"),
            std::string::npos);
}

TEST(CameraFileTest, AtomicWriteReplacesWholeFilesAndLeavesNoTemporary) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("camproj_atomic_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "camera.json").string();
  WriteFileAtomically(path, "first");
  WriteFileAtomically(path, "second, longer");
  EXPECT_EQ(ReadWholeFile(path), "second, longer");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
  // A folder that does not exist: an error naming the path, and nothing created.
  EXPECT_THROW(WriteFileAtomically((dir / "missing" / "c.json").string(), "x"), InputError);
  EXPECT_THROW(ReadWholeFile((dir / "nope.json").string()), InputError);
  EXPECT_THROW(ReadWholeFile(dir.string()), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace camproj

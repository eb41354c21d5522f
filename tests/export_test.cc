#include "camproj/export.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camproj/camera_file.h"
#include "camproj/world_origin.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

// Reprojection through a re-read export against PixelFromCam: both run in double on pixels of at
// most ~1e4 px; the rotation round trip (quaternion or Rodrigues vector) costs a few ulps
// (~1e-15 rad), which focal lengths up to ~2e5 px turn into ~1e-10 px.
constexpr double kReprojectionTolerancePx = 1e-9;
// A rotation rebuilt from a printed quaternion or Rodrigues vector: a few ulps per entry.
constexpr double kRotationRoundTrip = 1e-14;
// three's updateProjectionMatrix() goes through tan(atan(x)) in degrees; for the enlarged views
// of far off-centre cameras x reaches ~4e3, and tan's conditioning multiplies the ulp by that:
// ~1e-12 relative on pixels of ~1e4 px (observed: 2e-10 px).
constexpr double kThreeFovFormTolerancePx = 1e-8;
constexpr double kPi = 3.14159265358979323846;

const GlDepth kAllDepths[] = {{ClipDepth::kNegativeOneToOne, false},
                              {ClipDepth::kZeroToOne, false},
                              {ClipDepth::kNegativeOneToOne, true},
                              {ClipDepth::kZeroToOne, true}};

struct TestCamera {
  Camera camera;
  testing::RandomCamera random;  // the same camera, for MakeScene
};

// A random camera; `distorted` adds k1, k2 mild enough for a scene across the image.
TestCamera MakeTestCamera(std::mt19937_64& rng, bool skew, bool distorted, bool infinite_far) {
  testing::RandomCameraOptions options;
  if (!skew) options.max_skew_ratio = 0.0;
  if (distorted) {
    options.max_fov_deg = 90.0;
    options.max_principal_offset = 0.2;
  }
  TestCamera result;
  result.random = testing::MakeRandomCamera(rng, options);
  if (distorted) {
    result.random.intrinsics.k1 = testing::Uniform(rng, -0.05, 0.05);
    result.random.intrinsics.k2 = testing::Uniform(rng, -0.01, 0.01);
  }
  Camera& camera = result.camera;
  camera.image_size = result.random.size;
  camera.intrinsics = result.random.intrinsics;
  camera.cam_from_world = result.random.cam_from_world;
  camera.z_near = testing::LogUniform(rng, 1e-3, 1.0);
  camera.z_far = infinite_far ? kInfinity : camera.z_near * testing::LogUniform(rng, 2.0, 1e5);
  return result;
}

// Every number in `text` (separated by spaces, commas or newlines); fails on anything else.
std::vector<double> ParseNumbers(const std::string& text) {
  std::vector<double> numbers;
  std::string token;
  std::istringstream in(text);
  while (in >> token) {
    while (!token.empty() && token.back() == ',') token.pop_back();
    if (token.empty()) continue;
    char* end = nullptr;
    numbers.push_back(std::strtod(token.c_str(), &end));
    EXPECT_EQ(*end, '\0') << "not a number: " << token;
  }
  return numbers;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The 16 numbers after `name` on the line that starts with "name ".
Eigen::Matrix4d GlLineMatrix(const std::string& text, const std::string& name, bool row_major) {
  for (const std::string& line : Lines(text)) {
    if (line.rfind(name + " ", 0) != 0) continue;
    const std::vector<double> numbers = ParseNumbers(line.substr(name.size()));
    EXPECT_EQ(numbers.size(), 16u) << line;
    if (numbers.size() != 16) break;
    Eigen::Matrix4d m = Eigen::Map<const Eigen::Matrix4d>(numbers.data());
    return row_major ? Eigen::Matrix4d(m.transpose()) : m;
  }
  ADD_FAILURE() << "no line \"" << name << " ...\" in\n" << text;
  return Eigen::Matrix4d::Constant(std::nan(""));
}

// The literals of `const glm::dmat4 name(...);`, comments stripped.
std::vector<std::string> GlmLiterals(const std::string& text, const std::string& name) {
  const std::string opening = "const glm::dmat4 " + name + "(";
  const size_t begin = text.find(opening);
  const size_t end = text.find(");", begin);
  if (begin == std::string::npos || end == std::string::npos) {
    ADD_FAILURE() << "no " << opening << "...); in\n" << text;
    return {};
  }
  std::string body;
  for (const std::string& line :
       Lines(text.substr(begin + opening.size(), end - begin - opening.size()))) {
    body += line.substr(0, line.find("//")) + "\n";
  }
  std::vector<std::string> literals;
  std::istringstream in(body);
  for (std::string token; std::getline(in, token, ',');) {
    std::istringstream trim(token);
    std::string literal;
    trim >> literal;
    literals.push_back(literal);
  }
  return literals;
}

TEST(ExportFormatTest, NamesRoundTripAndBadNamesAreRefusedWithTheChoices) {
  for (const ExportFormat format :
       {ExportFormat::kGl, ExportFormat::kGlm, ExportFormat::kOpenCvYaml, ExportFormat::kColmap,
        ExportFormat::kThree, ExportFormat::kJson, ExportFormat::kGlsl,
        ExportFormat::kDistortionMesh}) {
    EXPECT_EQ(ExportFormatFromString(ToString(format)), format) << ToString(format);
  }
  EXPECT_EQ(ExportFormatFromString("distortion-mesh"), ExportFormat::kDistortionMesh);
  EXPECT_EQ(ExportFormatFromString("opencv-yaml"), ExportFormat::kOpenCvYaml);
  for (const std::string bad : {"", "GL", "yaml", "opencv_yaml", "json "}) {
    try {
      ExportFormatFromString(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("\"" + bad + "\""), std::string::npos) << message;
      EXPECT_NE(message.find("\"opencv-yaml\""), std::string::npos) << message;
      EXPECT_NE(message.find("\"three\""), std::string::npos) << message;
    }
  }
}

TEST(ExportGlTest, HandComputedMatrices) {
  // 2x2 image, fx = fy = 1, principal point on the image centre (0.5, 0.5), near 1, far 3:
  // P00 = 2fx/W = 1, P02 = 1 - 2(cx+0.5)/W = 0, A = -(f+n)/(f-n) = -2, B = -2fn/(f-n) = -3.
  Camera camera;
  camera.image_size = {2, 2};
  camera.intrinsics.cx = 0.5;
  camera.intrinsics.cy = 0.5;
  camera.cam_from_world.translation = Eigen::Vector3d(1, 2, 3);
  camera.z_near = 1.0;
  camera.z_far = 3.0;
  const std::string text = ExportCamera(camera, ExportFormat::kGl);
  EXPECT_NE(text.find("\nprojection 1 0 0 0 0 1 0 0 0 0 -2 -1 0 0 -3 0\n"), std::string::npos)
      << text;
  // view = diag(1,-1,-1,1) [I t]: column 3 is (1, -2, -3, 1).
  EXPECT_NE(text.find("\nview 1 0 0 0 0 -1 0 0 0 0 -1 0 1 -2 -3 1\n"), std::string::npos) << text;
}

TEST(ExportGlTest, NumbersReadBackBitForBitInBothOrders) {
  std::mt19937_64 rng(testing::Seed(1));
  for (int i = 0; i < 200; ++i) {
    const Camera camera = MakeTestCamera(rng, true, i % 3 == 0, i % 5 == 0).camera;
    ExportOptions options;
    options.depth = kAllDepths[i % 4];
    const Eigen::Matrix4d projection = ClipFromGlEye(camera.intrinsics.Pinhole(), camera.image_size,
                                                     camera.z_near, camera.z_far, options.depth);
    const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
    for (const bool row_major : {false, true}) {
      options.row_major = row_major;
      const std::string text = ExportCamera(camera, ExportFormat::kGl, options);
      EXPECT_EQ(GlLineMatrix(text, "projection", row_major), projection) << text;
      EXPECT_EQ(GlLineMatrix(text, "view", row_major), view) << text;
      EXPECT_EQ(text.find("k1 = ") != std::string::npos, camera.intrinsics.HasDistortion());
    }
  }
}

TEST(ExportGlmTest, SnippetHoldsTheExactMatricesInGlmsColumnOrder) {
  std::mt19937_64 rng(testing::Seed(2));
  for (int i = 0; i < 200; ++i) {
    const Camera camera = MakeTestCamera(rng, true, i % 3 == 0, i % 5 == 0).camera;
    ExportOptions options;
    options.depth = kAllDepths[i % 4];
    const std::string text = ExportCamera(camera, ExportFormat::kGlm, options);
    const Eigen::Matrix4d projection = ClipFromGlEye(camera.intrinsics.Pinhole(), camera.image_size,
                                                     camera.z_near, camera.z_far, options.depth);
    const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
    for (const auto& [name, expected] :
         {std::pair{"projection", projection}, std::pair{"view", view}}) {
      const std::vector<std::string> literals = GlmLiterals(text, name);
      ASSERT_EQ(literals.size(), 16u) << text;
      double v[16];
      for (int k = 0; k < 16; ++k) {
        // A double literal ("0.0", not the int "0"), which reads back bit for bit.
        EXPECT_NE(literals[k].find_first_of(".e"), std::string::npos) << literals[k];
        v[k] = ParseNumbers(literals[k]).at(0);
      }
      // glm's 16-scalar constructor fills column 0 first: m[col][row] == expected(row, col),
      // and value_ptr is the column-major array GL uploads, as Eigen's data().
      const glm::dmat4 m(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11],
                         v[12], v[13], v[14], v[15]);
      for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) EXPECT_EQ(m[col][row], expected(row, col)) << name;
      }
      EXPECT_EQ(std::memcmp(glm::value_ptr(m), expected.data(), sizeof(v)), 0) << name;
    }
    EXPECT_NE(text.find("GL_FALSE, glm::value_ptr("), std::string::npos);
    EXPECT_EQ(text.find("glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)") != std::string::npos,
              options.depth.clip_depth == ClipDepth::kZeroToOne);
    EXPECT_EQ(text.find("glDepthFunc(GL_GREATER)") != std::string::npos, options.depth.reversed_z);
    EXPECT_EQ(text.find("k1 = ") != std::string::npos, camera.intrinsics.HasDistortion());
  }
}

struct OpenCvCamera {
  int width = 0;
  int height = 0;
  cv::Mat camera_matrix, distortion, rvec, tvec, rotation;
};

OpenCvCamera ReadOpenCvYaml(const std::string& text) {
  cv::FileStorage storage(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  EXPECT_TRUE(storage.isOpened());
  OpenCvCamera result;
  storage["image_width"] >> result.width;
  storage["image_height"] >> result.height;
  storage["camera_matrix"] >> result.camera_matrix;
  storage["distortion_coefficients"] >> result.distortion;
  storage["rvec"] >> result.rvec;
  storage["tvec"] >> result.tvec;
  storage["R"] >> result.rotation;
  return result;
}

Eigen::Matrix3d EigenMatrix3(const cv::Mat& m) {
  Eigen::Matrix3d result;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result(r, c) = m.at<double>(r, c);
  }
  return result;
}

TEST(ExportOpenCvYamlTest, OpenCvReadsItBackAndProjectPointsGivesOurPixels) {
  std::mt19937_64 rng(testing::Seed(3));
  for (int i = 0; i < 200; ++i) {
    TestCamera test = MakeTestCamera(rng, false, i % 2 == 0, false);
    if (i % 4 == 0) {  // OpenCV's whole lens: p1, p2, k3 too
      test.random.intrinsics.p1 = testing::Uniform(rng, -0.002, 0.002);
      test.random.intrinsics.p2 = testing::Uniform(rng, -0.002, 0.002);
      test.random.intrinsics.k3 = testing::Uniform(rng, -0.01, 0.01);
      test.camera.intrinsics = test.random.intrinsics;
    }
    const Camera& camera = test.camera;
    const std::string text = ExportCamera(camera, ExportFormat::kOpenCvYaml);
    const OpenCvCamera cv_camera = ReadOpenCvYaml(text);
    // FileStorage prints doubles with 17 significant digits: everything but rvec is exact.
    EXPECT_EQ(cv_camera.width, camera.image_size.width);
    EXPECT_EQ(cv_camera.height, camera.image_size.height);
    ASSERT_EQ(cv_camera.camera_matrix.size(), cv::Size(3, 3)) << text;
    EXPECT_EQ(EigenMatrix3(cv_camera.camera_matrix), camera.intrinsics.K());
    ASSERT_EQ(cv_camera.distortion.size(), cv::Size(5, 1)) << text;
    EXPECT_EQ(cv_camera.distortion.at<double>(0), camera.intrinsics.k1);
    EXPECT_EQ(cv_camera.distortion.at<double>(1), camera.intrinsics.k2);
    EXPECT_EQ(cv_camera.distortion.at<double>(2), camera.intrinsics.p1);
    EXPECT_EQ(cv_camera.distortion.at<double>(3), camera.intrinsics.p2);
    EXPECT_EQ(cv_camera.distortion.at<double>(4), camera.intrinsics.k3);
    EXPECT_EQ(EigenMatrix3(cv_camera.rotation), camera.cam_from_world.rotation);
    ASSERT_EQ(cv_camera.tvec.size(), cv::Size(1, 3)) << text;
    ASSERT_EQ(cv_camera.rvec.size(), cv::Size(1, 3)) << text;
    for (int r = 0; r < 3; ++r) {
      EXPECT_EQ(cv_camera.tvec.at<double>(r), camera.cam_from_world.translation[r]);
    }
    cv::Mat rodrigues_rotation;
    cv::Rodrigues(cv_camera.rvec, rodrigues_rotation);
    EXPECT_LE(
        (EigenMatrix3(rodrigues_rotation) - camera.cam_from_world.rotation).cwiseAbs().maxCoeff(),
        kRotationRoundTrip);

    const testing::Scene scene = testing::MakeScene(rng, test.random, {});
    std::vector<cv::Point3d> object_points;
    for (const Eigen::Vector3d& p : scene.points_in_world)
      object_points.emplace_back(p.x(), p.y(), p.z());
    std::vector<cv::Point2d> image_points;
    cv::projectPoints(object_points, cv_camera.rvec, cv_camera.tvec, cv_camera.camera_matrix,
                      cv_camera.distortion, image_points);
    for (size_t k = 0; k < image_points.size(); ++k) {
      const Eigen::Vector2d expected =
          PixelFromCam(camera.intrinsics, camera.cam_from_world * scene.points_in_world[k]);
      EXPECT_NEAR(image_points[k].x, expected.x(), kReprojectionTolerancePx) << "camera " << i;
      EXPECT_NEAR(image_points[k].y, expected.y(), kReprojectionTolerancePx) << "camera " << i;
    }
  }
}

TEST(ExportOpenCvYamlTest, RodriguesVectorIsAccurateAtAnglesNearZeroAndPi) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.intrinsics = {500.0, 500.0, 319.5, 239.5};
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  for (const double angle : {0.0, 1e-12, 1e-6, 1e-3, kPi - 1e-3, kPi - 1e-6, kPi - 1e-12, kPi}) {
    camera.cam_from_world.rotation = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    const OpenCvCamera cv_camera = ReadOpenCvYaml(ExportCamera(camera, ExportFormat::kOpenCvYaml));
    cv::Mat rotation;
    cv::Rodrigues(cv_camera.rvec, rotation);
    EXPECT_LE((EigenMatrix3(rotation) - camera.cam_from_world.rotation).cwiseAbs().maxCoeff(),
              kRotationRoundTrip)
        << "angle " << angle;
  }
}

TEST(ExportOpenCvYamlTest, SkewIsRefusedBecauseOpenCvIgnoresIt) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.intrinsics = {500.0, 500.0, 319.5, 239.5, 3.0};
  try {
    ExportCamera(camera, ExportFormat::kOpenCvYaml);
    ADD_FAILURE() << "skew accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("skew = 3"), std::string::npos) << e.what();
  }
}

// The data lines of each "# ==> FILE <==" section, '#' comments dropped (as COLMAP reads them).
std::map<std::string, std::vector<std::string>> ColmapSections(const std::string& text) {
  std::map<std::string, std::vector<std::string>> sections;
  std::string file;
  for (const std::string& line : Lines(text)) {
    if (line.rfind("# ==> ", 0) == 0) {
      file = line.substr(6, line.find(" <==") - 6);
      sections[file];
    } else if (!file.empty() && line.rfind("#", 0) != 0) {
      sections[file].push_back(line);
    }
  }
  return sections;
}

// COLMAP's OPENCV / PINHOLE model (src/colmap/sensor/models.h), corner pixel origin.
Eigen::Vector2d ColmapPixel(const std::vector<double>& params,
                            const Eigen::Vector3d& point_in_cam) {
  const double x = point_in_cam.x() / point_in_cam.z();
  const double y = point_in_cam.y() / point_in_cam.z();
  double d = 1.0;
  if (params.size() == 8) {
    const double r2 = x * x + y * y;
    d = 1.0 + params[4] * r2 + params[5] * r2 * r2;
  }
  return {params[0] * d * x + params[2], params[1] * d * y + params[3]};
}

TEST(ExportColmapTest, ParsedModelReprojectsToOurPixelsInTheCornerOrigin) {
  std::mt19937_64 rng(testing::Seed(4));
  for (int i = 0; i < 200; ++i) {
    const TestCamera test = MakeTestCamera(rng, false, i % 2 == 0, false);
    const Camera& camera = test.camera;
    const std::string text = ExportCamera(camera, ExportFormat::kColmap);
    const auto sections = ColmapSections(text);
    ASSERT_EQ(sections.size(), 3u) << text;
    ASSERT_EQ(sections.at("cameras.txt").size(), 1u) << text;
    // One image = two lines: the pose and an empty POINTS2D line.
    ASSERT_EQ(sections.at("images.txt").size(), 2u) << text;
    EXPECT_EQ(sections.at("images.txt")[1], "");
    EXPECT_TRUE(sections.at("points3D.txt").empty());

    std::istringstream camera_line(sections.at("cameras.txt")[0]);
    int camera_id = 0;
    std::string model;
    int width = 0;
    int height = 0;
    camera_line >> camera_id >> model >> width >> height;
    std::string params_text;
    std::getline(camera_line, params_text);
    const std::vector<double> params = ParseNumbers(params_text);
    EXPECT_EQ(camera_id, 1);
    EXPECT_EQ(width, camera.image_size.width);
    EXPECT_EQ(height, camera.image_size.height);
    if (camera.intrinsics.HasDistortion()) {
      EXPECT_EQ(model, "OPENCV");
      ASSERT_EQ(params.size(), 8u);
      EXPECT_EQ(params[4], camera.intrinsics.k1);
      EXPECT_EQ(params[5], camera.intrinsics.k2);
      EXPECT_EQ(params[6], 0.0);
      EXPECT_EQ(params[7], 0.0);
    } else {
      EXPECT_EQ(model, "PINHOLE");
      ASSERT_EQ(params.size(), 4u);
    }
    EXPECT_EQ(params[0], camera.intrinsics.fx);
    EXPECT_EQ(params[1], camera.intrinsics.fy);

    std::istringstream image_line(sections.at("images.txt")[0]);
    int image_id = 0;
    double qw, qx, qy, qz;
    Eigen::Vector3d t;
    int image_camera_id = 0;
    std::string name;
    image_line >> image_id >> qw >> qx >> qy >> qz >> t.x() >> t.y() >> t.z() >> image_camera_id >>
        name;
    ASSERT_FALSE(image_line.fail()) << sections.at("images.txt")[0];
    EXPECT_EQ(image_id, 1);
    EXPECT_EQ(image_camera_id, 1);
    EXPECT_FALSE(name.empty());
    EXPECT_GE(qw, 0.0);
    Rigid3 cam_from_world;
    cam_from_world.rotation = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    cam_from_world.translation = t;
    EXPECT_LE((cam_from_world.rotation - camera.cam_from_world.rotation).cwiseAbs().maxCoeff(),
              kRotationRoundTrip);
    EXPECT_EQ(t, camera.cam_from_world.translation);

    const testing::Scene scene = testing::MakeScene(rng, test.random, {});
    for (const Eigen::Vector3d& point : scene.points_in_world) {
      // COLMAP's pixel is ours shifted by half a pixel (corner origin).
      const Eigen::Vector2d expected =
          PixelFromCam(camera.intrinsics, camera.cam_from_world * point) +
          Eigen::Vector2d(0.5, 0.5);
      const Eigen::Vector2d colmap = ColmapPixel(params, cam_from_world * point);
      EXPECT_NEAR(colmap.x(), expected.x(), kReprojectionTolerancePx) << "camera " << i;
      EXPECT_NEAR(colmap.y(), expected.y(), kReprojectionTolerancePx) << "camera " << i;
    }
  }
}

TEST(ExportColmapTest, HandComputedLinesAndSkewRefused) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.intrinsics = {500.0, 400.0, 319.5, 239.5};
  camera.cam_from_world.translation = Eigen::Vector3d(1, -2, 3);
  const std::string text = ExportCamera(camera, ExportFormat::kColmap);
  EXPECT_NE(text.find("\n1 PINHOLE 640 480 500 400 320 240\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n1 1 0 0 0 1 -2 3 1 image\n\n"), std::string::npos) << text;
  // OPENCV holds k1 k2 p1 p2; FULL_OPENCV adds k3 and the rational k4 k5 k6 (0).
  camera.intrinsics.k1 = -0.25;
  camera.intrinsics.p2 = 0.125;
  EXPECT_NE(ExportCamera(camera, ExportFormat::kColmap).find("\n1 OPENCV 640 480 500 400 320 240 -0.25 0 0 0.125\n"),
            std::string::npos);
  camera.intrinsics.k3 = 0.5;
  EXPECT_NE(ExportCamera(camera, ExportFormat::kColmap)
                .find("\n1 FULL_OPENCV 640 480 500 400 320 240 -0.25 0 0 0.125 0.5 0 0 0\n"),
            std::string::npos);
  camera.intrinsics.skew = -0.25;
  try {
    ExportCamera(camera, ExportFormat::kColmap);
    ADD_FAILURE() << "skew accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("skew = -0.25"), std::string::npos) << e.what();
  }
}

Eigen::Matrix4d JsonMatrix4(const nlohmann::json& numbers) {
  EXPECT_EQ(numbers.size(), 16u);
  Eigen::Matrix4d m = Eigen::Matrix4d::Constant(std::nan(""));
  for (int k = 0; k < 16 && k < static_cast<int>(numbers.size()); ++k) {
    m.data()[k] = numbers[static_cast<size_t>(k)].get<double>();  // column-major
  }
  return m;
}

// three.js r187 PerspectiveCamera.updateProjectionMatrix() and Matrix4.makePerspective
// (src/cameras/PerspectiveCamera.js, src/math/Matrix4.js): WebGLCoordinateSystem (NO),
// WebGPUCoordinateSystem (ZO) or reversedDepth (ZO reversed-Z).
Eigen::Matrix4d ThreeUpdateProjectionMatrix(const nlohmann::json& three, const GlDepth& depth) {
  const double near = three["near"].get<double>();
  const double far = three["far"].get<double>();
  const double aspect = three["aspect"].get<double>();
  double top =
      near * std::tan(kPi / 180.0 * 0.5 * three["fov"].get<double>()) / three["zoom"].get<double>();
  double height = 2.0 * top;
  double width = aspect * height;
  double left = -0.5 * width;
  if (three.contains("view") && three["view"]["enabled"].get<bool>()) {
    const nlohmann::json& view = three["view"];
    const double full_width = view["fullWidth"].get<double>();
    const double full_height = view["fullHeight"].get<double>();
    left += view["offsetX"].get<double>() * width / full_width;
    top -= view["offsetY"].get<double>() * height / full_height;
    width *= view["width"].get<double>() / full_width;
    height *= view["height"].get<double>() / full_height;
  }
  EXPECT_EQ(three["filmOffset"].get<double>(), 0.0);
  const double right = left + width;
  const double bottom = top - height;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * near / (right - left);
  m(1, 1) = 2 * near / (top - bottom);
  m(0, 2) = (right + left) / (right - left);
  m(1, 2) = (top + bottom) / (top - bottom);
  if (depth.reversed_z) {
    m(2, 2) = near / (far - near);
    m(2, 3) = far * near / (far - near);
  } else if (depth.clip_depth == ClipDepth::kZeroToOne) {
    m(2, 2) = -far / (far - near);
    m(2, 3) = -far * near / (far - near);
  } else {
    m(2, 2) = -(far + near) / (far - near);
    m(2, 3) = -2 * far * near / (far - near);
  }
  m(3, 2) = -1;
  return m;
}

TEST(ExportThreeTest, ProjectionAndMatrixWorldReprojectToOurPixels) {
  std::mt19937_64 rng(testing::Seed(5));
  for (int i = 0; i < 300; ++i) {
    const bool skew = i % 3 == 0;
    const bool infinite_far = i % 7 == 0;
    const TestCamera test = MakeTestCamera(rng, skew, false, infinite_far);
    const Camera& camera = test.camera;
    ExportOptions options;
    options.depth = kAllDepths[i % 4];
    const std::string text = ExportCamera(camera, ExportFormat::kThree, options);
    const nlohmann::json three = nlohmann::json::parse(text);
    const Eigen::Matrix4d projection = JsonMatrix4(three["projectionMatrix"]);
    const Eigen::Matrix4d matrix_world = JsonMatrix4(three["matrixWorld"]);
    EXPECT_EQ(projection, ClipFromGlEye(camera.intrinsics, camera.image_size, camera.z_near,
                                        camera.z_far, options.depth));
    // three computes matrixWorldInverse with a general 4x4 inverse; so do we.
    const Eigen::Matrix4d view = matrix_world.inverse();

    // position and quaternion (x, y, z, w) describe the same matrixWorld.
    const Eigen::Vector3d position(three["position"][0].get<double>(),
                                   three["position"][1].get<double>(),
                                   three["position"][2].get<double>());
    const Eigen::Quaterniond q(
        three["quaternion"][3].get<double>(), three["quaternion"][0].get<double>(),
        three["quaternion"][1].get<double>(), three["quaternion"][2].get<double>());
    EXPECT_EQ(position, Eigen::Vector3d(matrix_world.block<3, 1>(0, 3)));
    EXPECT_LE((q.toRotationMatrix() - matrix_world.block<3, 3>(0, 0)).cwiseAbs().maxCoeff(),
              kRotationRoundTrip);
    EXPECT_LE((position - CameraCenterInWorld(camera.cam_from_world)).norm(),
              testing::kExactRelative * (1.0 + position.norm()));

    // three builds no, zo and zo reversed-Z depth rows, none with an infinite far plane.
    const bool fov_form =
        !skew && !infinite_far &&
        !(options.depth.reversed_z && options.depth.clip_depth == ClipDepth::kNegativeOneToOne);
    EXPECT_EQ(three.contains("fov"), !skew) << text;
    EXPECT_EQ(three["far"].is_null(), infinite_far) << text;
    EXPECT_EQ(three["note"].get<std::string>().find("never let it run") == std::string::npos,
              fov_form)
        << text;
    const Eigen::Matrix4d rebuilt =
        fov_form ? ThreeUpdateProjectionMatrix(three, options.depth) : Eigen::Matrix4d::Zero();
    if (fov_form && three.contains("view")) {
      // setViewOffset sets aspect = fullWidth / fullHeight: the same aspect.
      EXPECT_NEAR(
          three["view"]["fullWidth"].get<double>() / three["view"]["fullHeight"].get<double>(),
          three["aspect"].get<double>(), testing::kExactRelative * three["aspect"].get<double>());
    }

    const testing::Scene scene = testing::MakeScene(rng, test.random, {});
    for (size_t k = 0; k < scene.points_in_world.size(); ++k) {
      const Eigen::Vector2d& expected = scene.true_pixels[k];
      const GlPixel pixel = GlPixelFromWorld(projection, view, scene.points_in_world[k],
                                             camera.image_size, options.depth.clip_depth);
      EXPECT_NEAR(pixel.pixel.x(), expected.x(), kReprojectionTolerancePx) << "camera " << i;
      EXPECT_NEAR(pixel.pixel.y(), expected.y(), kReprojectionTolerancePx) << "camera " << i;
      if (fov_form) {
        const GlPixel from_fov = GlPixelFromWorld(rebuilt, view, scene.points_in_world[k],
                                                  camera.image_size, options.depth.clip_depth);
        EXPECT_NEAR(from_fov.pixel.x(), expected.x(), kThreeFovFormTolerancePx) << text;
        EXPECT_NEAR(from_fov.pixel.y(), expected.y(), kThreeFovFormTolerancePx) << text;
      }
    }
  }
}

TEST(ExportThreeTest, CentredCameraHasPlainFovAndAspect) {
  Camera camera;
  camera.image_size = {1920, 1080};
  camera.intrinsics = {1500.0, 1400.0, 959.5, 539.5};
  const nlohmann::json three = nlohmann::json::parse(ExportCamera(camera, ExportFormat::kThree));
  EXPECT_FALSE(three.contains("view"));
  const double expected_fov = 2.0 * std::atan(540.0 / 1400.0) * 180.0 / kPi;
  EXPECT_NEAR(three["fov"].get<double>(), expected_fov, testing::kExactRelative * expected_fov);
  const double expected_aspect = (1920.0 / 1500.0) / (1080.0 / 1400.0);
  EXPECT_NEAR(three["aspect"].get<double>(), expected_aspect,
              testing::kExactRelative * expected_aspect);
  EXPECT_EQ(three["near"].get<double>(), camera.z_near);
  EXPECT_EQ(three["far"].get<double>(), camera.z_far);
  EXPECT_EQ(three["image_size"], nlohmann::json::array({1920, 1080}));

  // The principal point on the bottom row: the image is the top half of a view twice as high.
  camera.intrinsics.fy = 1500.0;
  camera.intrinsics.cy = 1079.5;
  const nlohmann::json off_axis = nlohmann::json::parse(ExportCamera(camera, ExportFormat::kThree));
  ASSERT_TRUE(off_axis.contains("view"));
  EXPECT_EQ(off_axis["view"]["fullWidth"].get<double>(), 1920.0);
  EXPECT_EQ(off_axis["view"]["fullHeight"].get<double>(), 2160.0);
  EXPECT_EQ(off_axis["view"]["offsetX"].get<double>(), 0.0);
  EXPECT_EQ(off_axis["view"]["offsetY"].get<double>(), 0.0);
  EXPECT_EQ(off_axis["view"]["height"].get<double>(), 1080.0);
  EXPECT_NE(off_axis["note"].get<std::string>().find("off-centre"), std::string::npos);
}

TEST(ExportJsonTest, CameraFileReadsBackBitForBit) {
  std::mt19937_64 rng(testing::Seed(6));
  for (int i = 0; i < 200; ++i) {
    const Camera camera = MakeTestCamera(rng, i % 2 == 0, i % 3 == 0, i % 5 == 0).camera;
    ExportOptions options;
    options.depth = kAllDepths[i % 4];
    const std::string text = ExportCamera(camera, ExportFormat::kJson, options);
    EXPECT_EQ(text, CameraToJsonText(camera, {PixelOrigin::kCenter, 1.0, options.depth}));
    const Camera back = CameraFromJsonText(text, "export");
    EXPECT_EQ(back.image_size.width, camera.image_size.width);
    EXPECT_EQ(back.image_size.height, camera.image_size.height);
    EXPECT_EQ(back.intrinsics.fx, camera.intrinsics.fx);
    EXPECT_EQ(back.intrinsics.fy, camera.intrinsics.fy);
    EXPECT_EQ(back.intrinsics.cx, camera.intrinsics.cx);
    EXPECT_EQ(back.intrinsics.cy, camera.intrinsics.cy);
    EXPECT_EQ(back.intrinsics.skew, camera.intrinsics.skew);
    EXPECT_EQ(back.intrinsics.k1, camera.intrinsics.k1);
    EXPECT_EQ(back.intrinsics.k2, camera.intrinsics.k2);
    EXPECT_EQ(back.cam_from_world.rotation, camera.cam_from_world.rotation);
    EXPECT_EQ(back.cam_from_world.translation, camera.cam_from_world.translation);
    EXPECT_EQ(back.z_near, camera.z_near);
    EXPECT_EQ(back.z_far, camera.z_far);

    // The corner origin writes cx + 0.5; reading subtracts it again (one rounding at most).
    options.pixel_origin = PixelOrigin::kCorner;
    const std::string corner_text = ExportCamera(camera, ExportFormat::kJson, options);
    EXPECT_NE(corner_text.find("\"corner\""), std::string::npos);
    const Camera corner_back = CameraFromJsonText(corner_text, "export");
    EXPECT_NEAR(corner_back.intrinsics.cx, camera.intrinsics.cx,
                1e-15 * (std::abs(camera.intrinsics.cx) + 1.0));
    EXPECT_NEAR(corner_back.intrinsics.cy, camera.intrinsics.cy,
                1e-15 * (std::abs(camera.intrinsics.cy) + 1.0));
  }
}

// OpenCV's and COLMAP's camera models are perspective: an orthographic camera is refused by
// name; the GL formats carry it (the matrix is tested in gl_test and render_test).
// A camera at survey coordinates with a world origin O: gl, glm and three export the view matrix
// for point_in_world - O (GlEyeFromOriginWorld, bit for bit) and say so in their header; the
// formats without a view matrix stay absolute; without an origin the header says "none".
TEST(ExportWorldOriginTest, GlFacingExportsAreRelativeToTheOriginAndSaySo) {
  std::mt19937_64 rng(testing::Seed(1303));
  for (int i = 0; i < 50; ++i) {
    TestCamera test = MakeTestCamera(rng, i % 2 == 0, false, false);
    Camera& camera = test.camera;
    const Eigen::Vector3d offset = testing::UniformVector3(rng, Eigen::Vector3d(1e5, 1e6, -100),
                                                           Eigen::Vector3d(9e5, 9e6, 1000));
    camera.cam_from_world = camera.cam_from_world * Rigid3{Eigen::Matrix3d::Identity(), -offset};
    const std::string plain = ExportCamera(camera, ExportFormat::kGl);
    EXPECT_NE(plain.find("\n# world origin: none: "), std::string::npos) << plain;
    EXPECT_EQ(GlLineMatrix(plain, "view", false), GlEyeFromWorld(camera.cam_from_world));
    EXPECT_EQ(nlohmann::json::parse(ExportCamera(camera, ExportFormat::kThree))["world_origin"],
              nullptr);

    camera.world_origin = RoundOrigin(offset, 100.0);
    const Eigen::Vector3d& o = *camera.world_origin;
    const Eigen::Matrix4d view = GlEyeFromOriginWorld(camera.cam_from_world, o);
    std::ostringstream origin_text;
    origin_text << std::setprecision(17) << "(" << o.x() << ", " << o.y() << ", " << o.z() << ")";
    const std::string gl = ExportCamera(camera, ExportFormat::kGl);
    EXPECT_NE(gl.find("view = gl_eye_from_origin_world\n"), std::string::npos) << gl;
    EXPECT_NE(gl.find("\n# world origin " + origin_text.str() +
                      ": the view matrix is gl_eye_from_origin_world: give vertices as "
                      "point_in_world - " + origin_text.str()),
              std::string::npos)
        << gl;
    EXPECT_EQ(GlLineMatrix(gl, "view", false), view);

    const std::string glm_text = ExportCamera(camera, ExportFormat::kGlm);
    EXPECT_NE(glm_text.find("// world origin " + origin_text.str()), std::string::npos);
    EXPECT_NE(glm_text.find("const glm::dvec3 world_origin("), std::string::npos);
    const std::vector<std::string> literals = GlmLiterals(glm_text, "view");
    ASSERT_EQ(literals.size(), 16u);
    for (int k = 0; k < 16; ++k) EXPECT_EQ(std::strtod(literals[k].c_str(), nullptr), view.data()[k]);

    const nlohmann::json three = nlohmann::json::parse(ExportCamera(camera, ExportFormat::kThree));
    EXPECT_EQ(three["world_origin"], nlohmann::json::array({o.x(), o.y(), o.z()}));
    EXPECT_NE(three["note"].get<std::string>().find("world origin " + origin_text.str()),
              std::string::npos);
    // three's camera sits at C - O; its view matrix is `view` up to the rigid inverse's rounding
    // (a few ulps of |C - O| <~ 1e3 here: 1e-9 covers it with room).
    const Eigen::Vector3d position(three["position"][0].get<double>(),
                                   three["position"][1].get<double>(),
                                   three["position"][2].get<double>());
    EXPECT_LE((position - (CameraCenterInWorld(camera.cam_from_world) - o)).norm(), 1e-9);
    EXPECT_LE((JsonMatrix4(three["matrixWorld"]).inverse() - view).cwiseAbs().maxCoeff(), 1e-9);

    // Absolute formats: opencv-yaml's tvec and colmap's T do not change with the origin.
    if (camera.intrinsics.skew == 0.0) {
      Camera no_origin = camera;
      no_origin.world_origin.reset();
      EXPECT_EQ(ExportCamera(camera, ExportFormat::kColmap),
                ExportCamera(no_origin, ExportFormat::kColmap));
      EXPECT_EQ(ExportCamera(camera, ExportFormat::kOpenCvYaml),
                ExportCamera(no_origin, ExportFormat::kOpenCvYaml));
    }
  }
}

TEST(ExportCameraTest, OrthographicCameraOnlyWhereTheFormatHasIt) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.projection = Projection::kOrthographic;
  camera.intrinsics.fx = camera.intrinsics.fy = 100.0;
  camera.intrinsics.cx = 319.5;
  camera.intrinsics.cy = 239.5;
  camera.cam_from_world.translation = Eigen::Vector3d(0, 0, 5);
  for (const ExportFormat format : {ExportFormat::kOpenCvYaml, ExportFormat::kColmap}) {
    try {
      ExportCamera(camera, format);
      ADD_FAILURE() << ToString(format) << " exported an orthographic camera";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("orthographic"), std::string::npos) << e.what();
    }
  }
  EXPECT_NE(ExportCamera(camera, ExportFormat::kThree).find("OrthographicCamera"), std::string::npos);
  EXPECT_NE(ExportCamera(camera, ExportFormat::kGl).find("orthographic"), std::string::npos);
}

TEST(ExportCameraTest, InvalidCameraIsRefusedByEveryFormat) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.intrinsics.fx = -1.0;
  for (const ExportFormat format :
       {ExportFormat::kGl, ExportFormat::kGlm, ExportFormat::kOpenCvYaml, ExportFormat::kColmap,
        ExportFormat::kThree, ExportFormat::kJson}) {
    EXPECT_THROW(ExportCamera(camera, format), std::invalid_argument) << ToString(format);
  }
}

// A valid camera far from the origin with a near plane of 1e-300: the automatic origin is the
// camera centre (the step 1e-300 cannot round 1e10), not "-inf"; a float32 error beyond a
// double is said in words.
TEST(ExportCameraTest, ExtremeNearPlanesAndErrorsBeyondADoubleAreWrittenInWords) {
  Camera camera;
  camera.image_size = {640, 480};
  camera.intrinsics.fx = camera.intrinsics.fy = 500.0;
  camera.intrinsics.cx = 319.5;
  camera.intrinsics.cy = 239.5;
  camera.cam_from_world.translation = Eigen::Vector3d(1e10, 0.0, 0.0);
  camera.z_near = 1e-300;
  camera.z_far = 10.0;
  for (const ExportFormat format : {ExportFormat::kGl, ExportFormat::kGlm, ExportFormat::kThree}) {
    const std::string text = ExportCamera(camera, format);
    EXPECT_THAT(text, ::testing::HasSubstr("px with camproj export --origin auto"))
        << ToString(format);
    EXPECT_THAT(text, ::testing::Not(::testing::HasSubstr("inf px"))) << ToString(format);
  }
  camera.intrinsics.fx = camera.intrinsics.fy = 1e300;
  camera.z_near = 1e-10;
  EXPECT_THAT(ExportCamera(camera, ExportFormat::kGl),
              ::testing::HasSubstr("float32 error at the near plane more than 1.8e+308 px"));
}

}  // namespace
}  // namespace camproj

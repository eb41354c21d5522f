// lens_gl.h without a GPU: the fold, the render target, the STMaps' convention and round trip,
// the tessellation rule and the mesh. The GL itself is in render_test.cc (Lens* suites).
#include "camproj/lens_gl.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <array>
#include <string>

#include "camproj/export.h"
#include "camproj/look_at.h"
#include "camproj/world_origin.h"
#include "seeds.h"

namespace camproj {
namespace {

using ::testing::HasSubstr;

// A map value is a float32 in [0, 1] (ulp <= 6e-8) times a size of ~200 px: ~1e-5 px; the
// round trip's double arithmetic adds nothing visible. 1e-4 px leaves 10x.
constexpr double kMapRoundTripPx = 1e-4;

Camera TestCamera(double k1, double k2, double skew = 0.0) {
  Camera camera;
  camera.image_size = {160, 120};
  camera.intrinsics.fx = 150.0;
  camera.intrinsics.fy = 145.0;
  camera.intrinsics.cx = 77.2;
  camera.intrinsics.cy = 62.9;
  camera.intrinsics.skew = skew;
  camera.intrinsics.k1 = k1;
  camera.intrinsics.k2 = k2;
  camera.cam_from_world = CamFromWorldFromLookAt(
      {Eigen::Vector3d(3.0, 2.0, 2.6), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()});
  camera.z_near = 0.5;
  camera.z_far = 40.0;
  return camera;
}

// The lens cases of render_test.cc's kind: both signs of k1 and k2, folds near the corners.
std::vector<Camera> Lenses() {
  return {TestCamera(-0.3, 0.0), TestCamera(-0.35, 0.05), TestCamera(0.25, 0.08),
          TestCamera(0.1, -0.3, 8.0)};
}

Eigen::Vector2d LensPixelOf(const Camera& camera, const Eigen::Vector2d& normalized) {
  return PixelFromCam(camera.intrinsics, Eigen::Vector3d(normalized.x(), normalized.y(), 1.0));
}

Eigen::Vector2d NormalizedOfTargetPixel(const LensRenderTarget& target, const Eigen::Vector2d& q) {
  return CamRayFromPixel(target.intrinsics, q).head<2>();
}

TEST(RadialFoldRadiusTest, HandComputed) {
  EXPECT_DOUBLE_EQ(RadialFoldRadius(-0.3, 0.0), 1.0 / std::sqrt(0.9));
  EXPECT_EQ(RadialFoldRadius(0.25, 0.08), std::numeric_limits<double>::infinity());
  EXPECT_EQ(RadialFoldRadius(0.0, 0.0), std::numeric_limits<double>::infinity());
  // 5 k2 s^2 + 3 k1 s + 1 = -1.5 s^2 + 0.3 s + 1: s = (0.3 + sqrt(0.09 + 6)) / 3.
  EXPECT_DOUBLE_EQ(RadialFoldRadius(0.1, -0.3), std::sqrt((0.3 + std::sqrt(6.09)) / 3.0));
  // k1 = -0.35, k2 = 0.04: 0.2 s^2 - 1.05 s + 1, smaller root (1.05 - 0.55) / 0.4 = 1.25.
  EXPECT_NEAR(RadialFoldRadius(-0.35, 0.04), std::sqrt(1.25), 1e-15);
  EXPECT_THROW(RadialFoldRadius(std::nan(""), 0.0), std::invalid_argument);
}

// Extreme coefficients: computed in units scaled by a power of two, so the discriminant does not
// overflow (k2 = 1e160, k3 = -1 searched for ever) and 3 k1 does not (k1 = -1e308 answered 0).
// Where the fold is k1's alone (k2, k3 negligible against it) it is 1 / sqrt(-3 k1) to a few
// ulps; where a double cannot place it, a refusal, not a hang or "no fold".
TEST(RadialFoldRadiusTest, ExtremeCoefficientsNeitherHangNorLoseTheFold) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(RadialFoldRadius(-1e308, 0.0, 0.0), 1.0 / (std::sqrt(3.0) * 1e154));
  EXPECT_DOUBLE_EQ(RadialFoldRadius(-1e308, 1e308, 1e308), 1.0 / (std::sqrt(3.0) * 1e154));
  EXPECT_DOUBLE_EQ(RadialFoldRadius(-1e160, 0.0, 1e160), 1.0 / std::sqrt(3e160));
  EXPECT_DOUBLE_EQ(RadialFoldRadius(-1e-300, 0.0, 0.0), 1.0 / std::sqrt(3e-300));
  // Scaling by powers of two is exact: a lens and the same lens in units 2^40 apart.
  EXPECT_EQ(RadialFoldRadius(-0.3 * 0x1p40, 0.04 * 0x1p80, -0.002 * 0x1p120),
            RadialFoldRadius(-0.3, 0.04, -0.002) * 0x1p-20);
  // A fold beyond r = 2^100 (k3 = -1e-320 against k1, k2 ~ 0.1): none that an image reaches.
  EXPECT_EQ(RadialFoldRadius(0.1, 0.01, -1e-320), inf);
  for (const auto& k : {std::array<double, 3>{0.0, 1e160, -1.0}, {1e160, 0.0, -1e160},
                        {0.0, 1e155, -1.0}}) {
    try {
      RadialFoldRadius(k[0], k[1], k[2]);
      ADD_FAILURE() << k[0] << " " << k[1] << " " << k[2] << " answered";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("too far apart in scale"), std::string::npos) << e.what();
    }
  }
}

TEST(LensGlTest, RefusesALensThatFoldsInsideTheImageAndOrthographicCameras) {
  // k1 = -0.5 folds at r = 0.816, distorted 0.544; the image corners are at ~0.66.
  const Camera folded = TestCamera(-0.5, 0.0);
  try {
    LensRenderTargetOf(folded);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("folds over at normalized radius 0.816"));
    EXPECT_THAT(e.what(), HasSubstr("image corner"));
  }
  EXPECT_THROW(LensGlslText(folded), std::invalid_argument);
  EXPECT_THROW(LensStMap(folded, LensMapDirection::kUndistort), std::invalid_argument);
  EXPECT_THROW(LensDistortionMeshJson(folded, 8), std::invalid_argument);
  Camera orthographic = TestCamera(0.0, 0.0);
  orthographic.projection = Projection::kOrthographic;
  EXPECT_THROW(LensRenderTargetOf(orthographic), std::invalid_argument);
  EXPECT_THROW(LensMaxEdgePx(TestCamera(-0.3, 0.0), 0.0), std::invalid_argument);
  EXPECT_THROW(LensDistortionMeshJson(TestCamera(-0.3, 0.0), -1), std::invalid_argument);
}

TEST(LensGlTest, RenderTargetWithoutDistortionIsTheImagePlusTheMargin) {
  // Footprint [-0.5, 159.5] x [-0.5, 119.5]: offset ceil(2 + 0.5) = 3, width
  // ceil(159.5 + 3 + 2) + 1 = 166, height ceil(119.5 + 3 + 2) + 1 = 126.
  const Camera camera = TestCamera(0.0, 0.0);
  const LensRenderTarget target = LensRenderTargetOf(camera);
  EXPECT_EQ(target.offset_x, 3);
  EXPECT_EQ(target.offset_y, 3);
  EXPECT_EQ(target.size.width, 166);
  EXPECT_EQ(target.size.height, 126);
  EXPECT_EQ(target.intrinsics.cx, camera.intrinsics.cx + 3);
  EXPECT_EQ(target.intrinsics.fx, camera.intrinsics.fx);
  EXPECT_EQ(LensSecondDerivativePx(camera), 0.0);
  EXPECT_EQ(LensMaxEdgePx(camera, 0.01), std::numeric_limits<double>::infinity());
  // Nuke's STMap: pixel (0, 0) samples target pixel (3, 3), window (3.5, 126 - 3.5).
  const StMap map = LensStMap(camera, LensMapDirection::kDistort);
  EXPECT_FLOAT_EQ(map.rgba[0], 3.5f / 166.0f);
  EXPECT_FLOAT_EQ(map.rgba[1], (126.0f - 3.5f) / 126.0f);
  EXPECT_EQ(map.rgba[2], 0.0f);
  EXPECT_EQ(map.rgba[3], 1.0f);
}

TEST(LensGlTest, RenderTargetHoldsEveryBilinearTapAndTheMapsRoundTrip) {
  for (const Camera& camera : Lenses()) {
    SCOPED_TRACE(::testing::Message()
                 << "k1 " << camera.intrinsics.k1 << ", k2 " << camera.intrinsics.k2);
    const LensRenderTarget target = LensRenderTargetOf(camera);
    const StMap map = LensStMap(camera, LensMapDirection::kDistort);
    ASSERT_EQ(map.width, camera.image_size.width);
    double worst = 0.0;
    for (int v = 0; v < map.height; ++v) {
      for (int u = 0; u < map.width; ++u) {
        const float* st = &map.rgba[(static_cast<size_t>(v) * map.width + u) * 4];
        const Eigen::Vector2d q(st[0] * target.size.width - 0.5,
                                (1.0 - st[1]) * target.size.height - 0.5);
        // Bilinear taps floor(q) and floor(q) + 1 inside the target.
        ASSERT_GE(q.minCoeff(), 0.0);
        ASSERT_LE(q.x(), target.size.width - 1.0);
        ASSERT_LE(q.y(), target.size.height - 1.0);
        worst = std::max(
            worst, (LensPixelOf(camera, NormalizedOfTargetPixel(target, q)) - Eigen::Vector2d(u, v))
                       .norm());
      }
    }
    EXPECT_LE(worst, kMapRoundTripPx);

    // The inverse map: where alpha is 1 its source is the lens's pixel of the target pixel's ray.
    const StMap inverse = LensStMap(camera, LensMapDirection::kUndistort);
    ASSERT_EQ(inverse.width, target.size.width);
    ASSERT_EQ(inverse.height, target.size.height);
    int on_plate = 0;
    worst = 0.0;
    const double r_fold = RadialFoldRadius(camera.intrinsics.k1, camera.intrinsics.k2);
    for (int v = 0; v < inverse.height; ++v) {
      for (int u = 0; u < inverse.width; ++u) {
        const float* st = &inverse.rgba[(static_cast<size_t>(v) * inverse.width + u) * 4];
        const Eigen::Vector2d n = NormalizedOfTargetPixel(target, Eigen::Vector2d(u, v));
        if (!(n.norm() < r_fold)) {
          EXPECT_EQ(st[0], -1.0f);
          EXPECT_EQ(st[3], 0.0f);
          continue;
        }
        const Eigen::Vector2d p(st[0] * camera.image_size.width - 0.5,
                                (1.0 - st[1]) * camera.image_size.height - 0.5);
        worst = std::max(worst, (LensPixelOf(camera, n) - p).norm());
        const bool inside = p.x() >= -0.5 && p.x() <= camera.image_size.width - 0.5 &&
                            p.y() >= -0.5 && p.y() <= camera.image_size.height - 0.5;
        if (std::abs(p.x() + 0.5) > 1e-3 &&
            std::abs(p.x() - camera.image_size.width + 0.5) > 1e-3 &&
            std::abs(p.y() + 0.5) > 1e-3 &&
            std::abs(p.y() - camera.image_size.height + 0.5) > 1e-3) {
          EXPECT_EQ(st[3], inside ? 1.0f : 0.0f) << "at " << u << ", " << v;
        }
        on_plate += st[3] == 1.0f;
      }
    }
    EXPECT_LE(worst, kMapRoundTripPx);
    EXPECT_GE(on_plate, camera.image_size.width * camera.image_size.height / 2);
  }
}

// The rule docs/exports.md gives: a triangle whose longest edge (pinhole px) is at most
// LensMaxEdgePx(camera, e) interpolates the lens within e. Checked on random triangles in the
// image's footprint against the lens evaluated in double at 21 points each; and the bound is not
// vacuous: some triangle comes within a factor 8 of it.
TEST(LensGlTest, TrianglesWithinTheMaxEdgeInterpolateTheLensWithinTheTarget) {
  std::mt19937_64 random(testing::Seed(13));
  for (const Camera& camera : Lenses()) {
    SCOPED_TRACE(::testing::Message()
                 << "k1 " << camera.intrinsics.k1 << ", k2 " << camera.intrinsics.k2);
    const LensRenderTarget target = LensRenderTargetOf(camera);
    const Intrinsics pinhole = camera.intrinsics.Pinhole();
    for (const double error_px : {0.1, 0.01}) {
      const double edge = LensMaxEdgePx(camera, error_px);
      std::uniform_real_distribution<double> u_in(0.0, camera.image_size.width - 1.0);
      std::uniform_real_distribution<double> v_in(0.0, camera.image_size.height - 1.0);
      std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
      double worst = 0.0;
      for (int trial = 0; trial < 2000; ++trial) {
        // A triangle around the undistorted position of a random image pixel, longest edge
        // exactly `edge` (pinhole px): two vertices `edge` apart, the third at an inner angle.
        const Eigen::Vector3d ray =
            CamRayFromPixel(camera.intrinsics, {u_in(random), v_in(random)});
        const Eigen::Vector2d center = PixelFromCam(pinhole, ray);
        const double a = angle(random);
        const Eigen::Vector2d dir(std::cos(a), std::sin(a));
        const Eigen::Vector2d normal(-dir.y(), dir.x());
        const std::array<Eigen::Vector2d, 3> corners = {
            center - 0.5 * edge * dir, center + 0.5 * edge * dir,
            center + (angle(random) / (4.0 * M_PI) - 0.25) * edge * dir + 0.5 * edge * normal};
        std::array<Eigen::Vector2d, 3> distorted;
        bool in_footprint = true;
        for (int i = 0; i < 3; ++i) {
          const Eigen::Vector3d corner_ray = CamRayFromPixel(pinhole, corners[i]);
          const Eigen::Vector2d p = PixelFromCam(camera.intrinsics, corner_ray);
          distorted[i] = p;
          in_footprint = in_footprint && p.x() >= -0.5 && p.y() >= -0.5 &&
                         p.x() <= camera.image_size.width - 0.5 &&
                         p.y() <= camera.image_size.height - 0.5;
        }
        if (!in_footprint) continue;
        for (int i = 0; i <= 5; ++i) {
          for (int j = 0; i + j <= 5; ++j) {
            const double l = (5 - i - j) / 5.0;
            const Eigen::Vector2d at = (i * corners[0] + j * corners[1]) / 5.0 + l * corners[2];
            const Eigen::Vector2d linear =
                (i * distorted[0] + j * distorted[1]) / 5.0 + l * distorted[2];
            const Eigen::Vector2d exact =
                PixelFromCam(camera.intrinsics, CamRayFromPixel(pinhole, at));
            worst = std::max(worst, (exact - linear).norm());
          }
        }
      }
      EXPECT_LE(worst, error_px) << "edge " << edge << " px";
      EXPECT_GE(worst, error_px / 8.0) << "edge " << edge << " px: the bound is far from tight";
      (void)target;
    }
  }
}

TEST(LensGlTest, GlslTextHasTheLensFunctionAndNoCharacterGlslLacks) {
  const Camera camera = TestCamera(-0.3, 0.0);
  const std::string text = LensGlslText(camera);
  EXPECT_THAT(text, HasSubstr("const float camproj_k1 = -0.29999999999999999;\n"));
  EXPECT_THAT(text, HasSubstr("const float camproj_k2 = 0.0;\n"));
  EXPECT_THAT(text, HasSubstr("vec4 camproj_lens(vec4 eye) {\n"));
  EXPECT_THAT(text, HasSubstr("return vec4(d * eye.xy, eye.zw);"));
  EXPECT_THAT(text, HasSubstr("const mat4 camproj_projection = mat4("));
  // GLSL before 4.20 has no '"', '\'', '`', '@', '$' or '\\' in its character set.
  EXPECT_EQ(text.find_first_of("\"'`@$\\"), std::string::npos);
  EXPECT_THAT(LensGlslText(TestCamera(0.0, 0.0)), HasSubstr("camproj_lens is the identity"));
  // r_limit = min(fold 1.054, 2 x the image corner's radius ~0.87).
  EXPECT_NEAR(LensRadiusLimit(camera), 1.0 / std::sqrt(0.9), 1e-15);
  EXPECT_NEAR(LensRadiusLimit(TestCamera(0.25, 0.08)),
              2.0 * LensImageRadius(TestCamera(0.25, 0.08)), 1e-15);
}

// The 16 numbers after `const mat4 NAME = mat4(` in `text`, column-major.
Eigen::Matrix4d GlslMatrix(const std::string& text, const std::string& name) {
  const std::string key = "const mat4 " + name + " = mat4(";
  const size_t start = text.find(key);
  EXPECT_NE(start, std::string::npos) << name;
  std::string numbers = text.substr(start + key.size(), text.find(')', start) - start - key.size());
  for (char& c : numbers) c = c == ',' ? ' ' : c;
  std::istringstream in(numbers);
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) in >> m.data()[i];
  return m;
}

TEST(LensGlTest, GlslHoldsTheGlExportsMatricesBitForBit) {
  for (const Camera& camera : Lenses()) {
    for (const GlDepth depth : {GlDepth{}, GlDepth{ClipDepth::kZeroToOne, true}}) {
      const std::string text = LensGlslText(camera, depth);
      EXPECT_EQ(GlslMatrix(text, "camproj_projection"),
                ClipFromGlEye(camera.intrinsics.Pinhole(), camera.image_size, camera.z_near,
                              camera.z_far, depth));
      EXPECT_EQ(GlslMatrix(text, "camproj_view"), GlEyeFromWorld(camera.cam_from_world));
      ExportOptions options;
      options.depth = depth;
      EXPECT_EQ(ExportCamera(camera, ExportFormat::kGlsl, options), text);
    }
  }
  // With a world origin the view matrix is the gl export's too, gl_eye_from_origin_world, and the
  // header says what to subtract (it held gl_eye_from_world and drew a UTM-scale point 14 px off
  // in float32, while the export's note gave the error with the origin).
  Camera survey = TestCamera(-0.1, 0.0);
  const Eigen::Vector3d center(412345.0, 5612345.0, 120.0);
  survey.cam_from_world = CamFromWorldFromLookAt(
      {center, center + Eigen::Vector3d(0.0, 5.0, -20.0), Eigen::Vector3d::UnitZ()});
  survey.world_origin = Eigen::Vector3d(412340.0, 5612340.0, 100.0);
  const std::string text = LensGlslText(survey);
  EXPECT_EQ(GlslMatrix(text, "camproj_view"),
            GlEyeFromOriginWorld(survey.cam_from_world, *survey.world_origin));
  EXPECT_THAT(text, HasSubstr("\n// world origin (412340, 5612340, 100): the view matrix is "
                              "gl_eye_from_origin_world: give vertices as point_in_world - "
                              "(412340, 5612340, 100), subtracted in double"));
  EXPECT_THAT(ExportCamera(survey, ExportFormat::kGl),
              HasSubstr("# world origin (412340, 5612340, 100): the view matrix is "
                        "gl_eye_from_origin_world"));
  // The pinhole-only exports name the ones that render the lens.
  const std::string gl = ExportCamera(TestCamera(-0.3, 0.0), ExportFormat::kGl);
  EXPECT_THAT(gl, HasSubstr("to render the lens: export glsl (per vertex), distortion-mesh or "
                            "stmap (post-process warp)"));
}

TEST(LensGlTest, MeshHasTheGridAndItsErrorMeetsTheStepRule) {
  const Camera camera = TestCamera(-0.3, 0.0);
  const nlohmann::json mesh = nlohmann::json::parse(LensDistortionMeshJson(camera, 8));
  const LensRenderTarget target = LensRenderTargetOf(camera);
  EXPECT_EQ(mesh["render_target"]["image_size"][0].get<int>(), target.size.width);
  // Grid lines x = 0, 8, ..., and the far edge, over the render target.
  const int columns = (target.size.width + 7) / 8 + 1;
  const int rows = (target.size.height + 7) / 8 + 1;
  EXPECT_EQ(mesh["vertex_count"].get<int>(), columns * rows);
  EXPECT_EQ(mesh["undistorted_uv"].size(), 2u * columns * rows);
  EXPECT_EQ(mesh["triangles"].size(), 3u * 2 * (columns - 1) * (rows - 1));
  EXPECT_EQ(mesh["undistorted_uv"][2].get<double>(), 8.0 / target.size.width);
  // Vertex 1's output: the lens's pixel of the source (8 - 0.5, Ht - 0.5) (window (8, 0)).
  const Eigen::Vector2d lens_pixel =
      LensPixelOf(camera, NormalizedOfTargetPixel(target, {7.5, target.size.height - 0.5}));
  EXPECT_NEAR(mesh["distorted_uv"][2].get<double>(), (lens_pixel.x() + 0.5) / 160.0, 1e-15);
  EXPECT_NEAR(mesh["distorted_uv"][3].get<double>(), (120.0 - lens_pixel.y() - 0.5) / 120.0, 1e-15);
  const int step = LensMeshStepPx(camera, kLensMeshErrorPx);
  const nlohmann::json automatic = nlohmann::json::parse(LensDistortionMeshJson(camera, 0));
  EXPECT_EQ(automatic["step_px"].get<int>(), step);
  EXPECT_LE(automatic["max_interpolation_error_px"].get<double>(), kLensMeshErrorPx);
  if (step < kLensMeshMaxStepPx) {
    const nlohmann::json coarser = nlohmann::json::parse(LensDistortionMeshJson(camera, 2 * step));
    EXPECT_GT(coarser["max_interpolation_error_px"].get<double>(), kLensMeshErrorPx);
  }
}

TEST(LensGlTest, MeshObjHoldsTheJsonMeshNumbers) {
  const Camera camera = TestCamera(0.1, -0.3, 8.0);
  const nlohmann::json mesh = nlohmann::json::parse(LensDistortionMeshJson(camera, 16));
  std::istringstream obj(LensDistortionMeshObj(camera, 16));
  std::vector<double> positions;
  std::vector<double> uvs;
  std::vector<int> faces;
  for (std::string line; std::getline(obj, line);) {
    std::istringstream in(line);
    std::string kind;
    in >> kind;
    if (kind == "v") {
      double x = 0.0, y = 0.0, z = 1.0;
      in >> x >> y >> z;
      EXPECT_EQ(z, 0.0);
      positions.insert(positions.end(), {x, y});
    } else if (kind == "vt") {
      double u = 0.0, v = 0.0;
      in >> u >> v;
      uvs.insert(uvs.end(), {u, v});
    } else if (kind == "f") {
      for (int i = 0; i < 3; ++i) {
        std::string corner;
        in >> corner;
        const int index = std::stoi(corner.substr(0, corner.find('/')));
        EXPECT_EQ(corner, std::to_string(index) + "/" + std::to_string(index));
        faces.push_back(index - 1);
      }
    } else {
      EXPECT_EQ(kind.substr(0, 1), "#") << line;
    }
  }
  ASSERT_EQ(positions.size(), mesh["distorted_uv"].size());
  for (size_t i = 0; i < positions.size(); ++i) {
    // Both are the same double, printed to round-trip: x * 2 - 1 of it, to rounding.
    EXPECT_NEAR(positions[i], mesh["distorted_uv"][i].get<double>() * 2.0 - 1.0, 1e-15);
  }
  EXPECT_EQ(uvs, mesh["undistorted_uv"].get<std::vector<double>>());
  EXPECT_EQ(faces, mesh["triangles"].get<std::vector<int>>());
}

TEST(LensGlTest, StMapFilesAreFloatRgbaInNukeChannelOrder) {
  StMap map;
  map.width = 3;
  map.height = 2;
  for (int i = 0; i < 6; ++i) map.rgba.insert(map.rgba.end(), {0.25f + i, 0.5f, 0.0f, 1.0f});
  for (const std::string extension : {".tif", ".exr"}) {
    const std::string bytes = EncodeStMap(map, extension);
    const cv::Mat image =
        cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(image.type(), CV_32FC4) << extension;
    // OpenCV reads R, G, B, A into channels 2, 1, 0, 3.
    EXPECT_EQ(image.at<cv::Vec4f>(1, 2)[2], 5.25f) << extension;
    EXPECT_EQ(image.at<cv::Vec4f>(1, 2)[1], 0.5f) << extension;
    EXPECT_EQ(image.at<cv::Vec4f>(1, 2)[3], 1.0f) << extension;
  }
  EXPECT_THROW(EncodeStMap(map, ".png"), std::invalid_argument);
  // A whole map reads back bit for bit (OpenCV's TIFF writer was seen to alter 3-channel floats;
  // 4 channels are stored as they are).
  const StMap full = LensStMap(TestCamera(-0.3, 0.0), LensMapDirection::kUndistort);
  for (const std::string extension : {".tiff", ".exr"}) {
    const std::string bytes = EncodeStMap(full, extension);
    const cv::Mat image =
        cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(image.rows, full.height);
    ASSERT_EQ(image.cols, full.width);
    int differ = 0;
    for (int y = 0; y < full.height; ++y) {
      for (int x = 0; x < full.width; ++x) {
        const cv::Vec4f texel = image.at<cv::Vec4f>(y, x);
        const float* want = &full.rgba[(static_cast<size_t>(y) * full.width + x) * 4];
        differ += texel[2] != want[0] || texel[1] != want[1] || texel[0] != want[2] ||
                  texel[3] != want[3];
      }
    }
    EXPECT_EQ(differ, 0) << extension;
  }
}

// Lenses whose numbers pass the camera's checks but that float32 GLSL or the lens polynomial
// cannot hold are refused, naming why, never written as inf, 0 px edges or null UVs.
TEST(LensGlTest, LensesBeyondFloatOrDoubleAreRefusedNotWrittenAsInfOrNull) {
  // k1 = 1e300 passes the camera's checks; a GLSL float literal above 3.4e38 is infinite.
  EXPECT_THAT([] { LensGlslText(TestCamera(1e300, 0.0)); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("k1 = 1e+300 is beyond float32's range")));
  EXPECT_NO_THROW(LensGlslText(TestCamera(1e38, 0.0)));
  Camera pinhole = TestCamera(0.0, 0.0);
  pinhole.intrinsics.fx = pinhole.intrinsics.fy = 1e300;  // 2 fx / W = 1.9e298
  EXPECT_THAT([&] { LensGlslText(pinhole); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("beyond float32's range")));
  // fx = 1e-300 px: the corners' normalized radius overflows the polynomial (null UVs before).
  for (const double k1 : {0.0, 0.1}) {
    Camera wide = TestCamera(k1, 0.0);
    wide.intrinsics.fx = wide.intrinsics.fy = 1e-300;
    EXPECT_THAT([&] { LensDistortionMeshJson(wide, 8); },
                ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("180 degrees")));
  }
}

}  // namespace
}  // namespace camproj

#include "camproj/gl.h"

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include <glm/ext/matrix_clip_space.hpp>
#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/look_at.h"
#include "glm_compare.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::kExactRelative;

// The CV path K [R|t] and the GL path P V X -> divide -> viewport -> pixel are different
// algebra on the same numbers, each erring by rounding of the magnitudes it handles
// (testing::PixelRoundingBound); the two differ by at most twice that. (A fixed 1e-9 px failed at
// 5 of 100 seed offsets: a principal point 2000 px off the image, orthographic scales of 1e4 px
// per unit.)
double PixelAgreement(const Intrinsics& k, const ImageSize& size, const Rigid3& cam_from_world,
                      const Eigen::Vector3d& point_in_world, const Eigen::Vector2d& pixel,
                      double sensitivity) {
  return 2.0 * testing::PixelRoundingBound(k, size, cam_from_world, point_in_world, pixel,
                                           sensitivity);
}

const GlDepth kAllDepths[] = {
    {ClipDepth::kNegativeOneToOne, false},
    {ClipDepth::kZeroToOne, false},
    {ClipDepth::kNegativeOneToOne, true},
    {ClipDepth::kZeroToOne, true},
};

Frustum RandomFrustum(std::mt19937_64& rng) {
  Frustum f;
  f.z_near = testing::LogUniform(rng, 1e-3, 10);
  f.z_far = f.z_near * testing::LogUniform(rng, 1.01, 1e4);
  f.left = testing::Uniform(rng, -2, 1) * f.z_near;
  f.right = f.left + testing::LogUniform(rng, 0.01, 3) * f.z_near;
  f.bottom = testing::Uniform(rng, -2, 1) * f.z_near;
  f.top = f.bottom + testing::LogUniform(rng, 0.01, 3) * f.z_near;
  return f;
}

TEST(GlTest, FrustumEqualsGlm) {
  std::mt19937_64 rng(testing::Seed(1));
  for (int i = 0; i < 1000; ++i) {
    const Frustum f = RandomFrustum(rng);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEye(f),
                  testing::FromGlm(glm::frustumRH_NO(f.left, f.right, f.bottom, f.top, f.z_near, f.z_far))),
              kExactRelative);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEye(f, {ClipDepth::kZeroToOne, false}),
                  testing::FromGlm(glm::frustumRH_ZO(f.left, f.right, f.bottom, f.top, f.z_near, f.z_far))),
              kExactRelative);
  }
}

TEST(GlTest, PerspectiveAndInfinitePerspectiveEqualGlm) {
  std::mt19937_64 rng(testing::Seed(2));
  for (int i = 0; i < 1000; ++i) {
    Perspective p;
    p.fovy_deg = testing::Uniform(rng, 0.1, 179);
    p.aspect = testing::LogUniform(rng, 0.2, 5);
    p.z_near = testing::LogUniform(rng, 1e-4, 10);
    p.z_far = p.z_near * testing::LogUniform(rng, 1.01, 1e6);
    const double fovy = p.fovy_deg * M_PI / 180.0;
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEye(p), testing::FromGlm(glm::perspectiveRH_NO(fovy, p.aspect, p.z_near, p.z_far))),
              kExactRelative);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEye(p, {ClipDepth::kZeroToOne, false}),
                  testing::FromGlm(glm::perspectiveRH_ZO(fovy, p.aspect, p.z_near, p.z_far))),
              kExactRelative);
    p.z_far = kInfinity;
    // glm 0.9.9 has only the NO infinite perspective; ZO's limit is checked in
    // DepthConventionsMapNearAndFarWhereStated.
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEye(p), testing::FromGlm(glm::infinitePerspectiveRH(fovy, p.aspect, p.z_near))),
              kExactRelative);
  }
}

TEST(GlTest, OrthoEqualsGlm) {
  std::mt19937_64 rng(testing::Seed(3));
  for (int i = 0; i < 1000; ++i) {
    const Ortho o{testing::Uniform(rng, -10, 0), testing::Uniform(rng, 0.1, 10),
                  testing::Uniform(rng, -10, 0), testing::Uniform(rng, 0.1, 10),
                  testing::Uniform(rng, -5, 1), testing::Uniform(rng, 2, 100)};
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEyeOrtho(o),
                  testing::FromGlm(glm::orthoRH_NO(o.left, o.right, o.bottom, o.top, o.z_near, o.z_far))),
              kExactRelative);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEyeOrtho(o, ClipDepth::kZeroToOne),
                  testing::FromGlm(glm::orthoRH_ZO(o.left, o.right, o.bottom, o.top, o.z_near, o.z_far))),
              kExactRelative);
  }
}

// An orthographic camera's matrix is glOrtho's (glm's orthoRH_NO / _ZO) of its box when skew is
// 0, and through GL's pipeline it puts every point on camera.h's pixel (fx x + skew y + cx,
// fy y + cy) with the window depth linear from near (0; 1 reversed) to far, for every depth
// convention and pixel origin. Double arithmetic on O(1e3) px: 1e-9 px as above.
TEST(GlTest, OrthographicCameraEqualsGlOrthoAndItsPixels) {
  std::mt19937_64 rng(testing::Seed(11));
  for (int i = 0; i < 500; ++i) {
    testing::RandomCamera camera = testing::MakeRandomCamera(rng);
    Intrinsics& k = camera.intrinsics;
    k.fx = testing::LogUniform(rng, 1e-2, 1e4);  // px per world unit
    k.fy = k.fx * testing::LogUniform(rng, 0.5, 2.0);
    const double z_near = testing::LogUniform(rng, 1e-3, 1.0);
    const double z_far = z_near + testing::LogUniform(rng, 1e-2, 1e4);
    Intrinsics unskewed = k;
    unskewed.skew = 0.0;
    const Ortho box = OrthoFromOrthographic(unskewed, camera.size, z_near, z_far);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEyeOrthographic(unskewed, camera.size, z_near, z_far),
                  testing::FromGlm(glm::orthoRH_NO(box.left, box.right, box.bottom, box.top,
                                                   box.z_near, box.z_far))),
              kExactRelative);
    EXPECT_LT(testing::RelativeDifference(
                  ClipFromGlEyeOrthographic(unskewed, camera.size, z_near, z_far,
                                            {ClipDepth::kZeroToOne, false}),
                  testing::FromGlm(glm::orthoRH_ZO(box.left, box.right, box.bottom, box.top,
                                                   box.z_near, box.z_far))),
              kExactRelative);
    Camera ortho;
    ortho.image_size = camera.size;
    ortho.projection = Projection::kOrthographic;
    ortho.intrinsics = k;
    ortho.cam_from_world = camera.cam_from_world;
    ortho.z_near = z_near;
    ortho.z_far = z_far;
    const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
    for (int j = 0; j < 4; ++j) {
      const Eigen::Vector2d pixel = testing::RandomPixelInImage(rng, camera.size);
      const double depth = testing::Uniform(rng, z_near, z_far);
      // The cam point at that pixel and depth: invert the affine map.
      const double y = (pixel.y() - k.cy) / k.fy;
      const double x = (pixel.x() - k.cx - k.skew * y) / k.fx;
      const Eigen::Vector3d point_in_world = Inverse(camera.cam_from_world) * Eigen::Vector3d(x, y, depth);
      const std::optional<Eigen::Vector2d> expected = PixelFromWorld(ortho, point_in_world);
      ASSERT_TRUE(expected.has_value());
      const double agreement =
          PixelAgreement(k, camera.size, camera.cam_from_world, point_in_world, *expected,
                         std::abs(k.fx) + std::abs(k.fy) + std::abs(k.skew));
      EXPECT_LT((*expected - pixel).norm(), agreement);
      for (const GlDepth& depth_convention : kAllDepths) {
        for (const PixelOrigin origin : {PixelOrigin::kCenter, PixelOrigin::kCorner}) {
          const Eigen::Matrix4d projection = ClipFromGlEyeOrthographic(
              ConvertPixelOrigin(k, PixelOrigin::kCenter, origin), camera.size, z_near, z_far,
              depth_convention, origin);
          const GlPixel gl = GlPixelFromWorld(projection, view, point_in_world, camera.size,
                                              depth_convention.clip_depth, origin);
          EXPECT_LT((gl.pixel - ConvertPixelOrigin(*expected, PixelOrigin::kCenter, origin)).norm(),
                    agreement)
              << "camera " << i;
          const double linear = (depth - z_near) / (z_far - z_near);
          // The world point's coordinates carry rounding of their size, which the depth row
          // divides by far - near (a 1e6-unit-wide view with a 0.01-deep range makes 1e-8):
          // making the point, R^T (p - t), errs by ~4 unit roundoffs of |p| + |t| per
          // coordinate, the view row's 4-term dot by ~4 of |X| + |t|, with |p|, |X| and |t| each
          // at most world_size: ~24 unit roundoffs of world_size in the eye depth; kWorldRoundings
          // = 32. Plus the window arithmetic's own on O(1) values. (9 unit roundoffs, 1e-15,
          // failed at 2 of 40 seed offsets, by up to 1.2x.)
          constexpr double kWorldRoundings = 32.0;
          const double world_size =
              std::max({std::abs(x), std::abs(y), depth, camera.cam_from_world.translation.norm()});
          EXPECT_NEAR(gl.window_depth, depth_convention.reversed_z ? 1.0 - linear : linear,
                      kWorldRoundings * 0x1p-53 * world_size / (z_far - z_near) + 1e-14)
              << "camera " << i;
        }
      }
    }
    // No orthographic limit of an infinite far plane; distortion is not orthographic.
    EXPECT_THROW(ClipFromGlEyeOrthographic(k, camera.size, z_near, kInfinity), std::invalid_argument);
    Intrinsics distorted = k;
    distorted.k1 = 0.1;
    EXPECT_THROW(ClipFromGlEyeOrthographic(distorted, camera.size, z_near, z_far),
                 std::invalid_argument);
  }
}

TEST(GlTest, DepthConventionsMapNearAndFarWhereStated) {
  const double n = 0.25;
  const double f = 40;
  for (const GlDepth& depth : kAllDepths) {
    const bool zo = depth.clip_depth == ClipDepth::kZeroToOne;
    const double near_ndc = depth.reversed_z ? 1.0 : (zo ? 0.0 : -1.0);
    const double far_ndc = depth.reversed_z ? (zo ? 0.0 : -1.0) : 1.0;
    for (const double far : {f, kInfinity}) {
      const Eigen::Matrix4d m = ClipFromGlEye(Frustum{-n, n, -n, n, n, far}, depth);
      auto ndc_z = [&](double z_eye) {
        const Eigen::Vector4d clip = m * Eigen::Vector4d(0, 0, z_eye, 1);
        return clip.z() / clip.w();
      };
      EXPECT_NEAR(ndc_z(-n), near_ndc, 1e-15);
      if (std::isfinite(far)) {
        EXPECT_NEAR(ndc_z(-far), far_ndc, 1e-14);
      } else {
        // The limit at infinity: approached as n/z.
        EXPECT_NEAR(ndc_z(-1e12), far_ndc, 1e-12);
      }
      const DepthRange range = DepthRangeFromClipFromGlEye(m, depth);
      EXPECT_NEAR(range.z_near, n, n * kExactRelative);
      if (std::isfinite(far)) {
        EXPECT_NEAR(range.z_far, far, far * kExactRelative);
      } else {
        EXPECT_EQ(range.z_far, kInfinity);
      }
    }
  }
}

// The central property: K [R|t] and the GL pipeline put every point on the same pixel.
TEST(GlTest, GlPipelineAgreesWithPinholeProjection) {
  std::mt19937_64 rng(testing::Seed(4));
  double worst = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const testing::RandomCamera camera = testing::MakeRandomCamera(rng);
    const double z_near = testing::LogUniform(rng, 1e-2, 1);
    const double z_far = z_near * testing::LogUniform(rng, 10, 1e4);
    const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
    for (int j = 0; j < 4; ++j) {
      const double depth = testing::LogUniform(rng, z_near, std::min(z_far, 1e3));
      const Eigen::Vector3d point_in_world = testing::WorldPointAtPixel(
          camera, testing::RandomPixelInImage(rng, camera.size), depth);
      const Eigen::Vector2d cv_pixel =
          PixelFromCam(camera.intrinsics, camera.cam_from_world * point_in_world);
      for (const GlDepth& depth_convention : kAllDepths) {
        for (const bool infinite : {false, true}) {
          for (const PixelOrigin origin : {PixelOrigin::kCenter, PixelOrigin::kCorner}) {
            const Intrinsics k = ConvertPixelOrigin(camera.intrinsics, PixelOrigin::kCenter, origin);
            const Eigen::Matrix4d projection = ClipFromGlEye(
                k, camera.size, z_near, infinite ? kInfinity : z_far, depth_convention, origin);
            const GlPixel gl = GlPixelFromWorld(projection, view, point_in_world, camera.size,
                                                depth_convention.clip_depth, origin);
            const Eigen::Vector2d expected =
                ConvertPixelOrigin(cv_pixel, PixelOrigin::kCenter, origin);
            const double error = (gl.pixel - expected).norm();
            const Intrinsics& t = camera.intrinsics;
            const double agreement = PixelAgreement(
                t, camera.size, camera.cam_from_world, point_in_world, cv_pixel,
                (t.fx + t.fy + std::abs(t.skew) + std::abs(cv_pixel.x() - t.cx) +
                 std::abs(cv_pixel.y() - t.cy)) / depth);
            worst = std::max(worst, error / agreement);
            ASSERT_LT(error, agreement)
                << "camera " << i << " fx " << k.fx << " cx " << k.cx << " skew " << k.skew;
            // Points between near and far land inside the depth range.
            EXPECT_GE(gl.window_depth, -1e-12);
            EXPECT_LE(gl.window_depth, 1.0 + 1e-12);
          }
        }
      }
    }
  }
  std::ostringstream worst_text;
  worst_text << worst;
  RecordProperty("worst_pixel_error_over_bound", worst_text.str());
}

TEST(GlTest, IntrinsicsRoundTripThroughTheProjectionMatrixAndTheFrustum) {
  std::mt19937_64 rng(testing::Seed(5));
  for (int i = 0; i < 1000; ++i) {
    const testing::RandomCamera camera = testing::MakeRandomCamera(rng);
    const Intrinsics& k = camera.intrinsics;
    const double w = camera.size.width;
    const double h = camera.size.height;
    for (const GlDepth& depth : kAllDepths) {
      for (const PixelOrigin origin : {PixelOrigin::kCenter, PixelOrigin::kCorner}) {
        const Eigen::Matrix4d m = ClipFromGlEye(k, camera.size, 0.5, 50, depth, origin);
        // Any positive overall scale describes the same projection.
        const Intrinsics back = IntrinsicsFromClipFromGlEye(3.0 * m, camera.size, origin);
        EXPECT_NEAR(back.fx, k.fx, kExactRelative * k.fx);
        EXPECT_NEAR(back.fy, k.fy, kExactRelative * k.fy);
        EXPECT_NEAR(back.cx, k.cx, kExactRelative * std::max(std::abs(k.cx), w));
        EXPECT_NEAR(back.cy, k.cy, kExactRelative * std::max(std::abs(k.cy), h));
        EXPECT_NEAR(back.skew, k.skew, kExactRelative * k.fx);
        Intrinsics no_skew = k;
        no_skew.skew = 0.0;
        const Eigen::Matrix4d unskewed = ClipFromGlEye(no_skew, camera.size, 0.5, 50, depth, origin);
        const Frustum frustum = FrustumFromClipFromGlEye(unskewed, depth);
        const Frustum expected = FrustumFromIntrinsics(no_skew, camera.size, 0.5, 50, origin);
        const double scale = std::max(expected.right - expected.left, expected.top - expected.bottom);
        EXPECT_NEAR(frustum.left, expected.left, kExactRelative * 10 * scale);
        EXPECT_NEAR(frustum.right, expected.right, kExactRelative * 10 * scale);
        EXPECT_NEAR(frustum.bottom, expected.bottom, kExactRelative * 10 * scale);
        EXPECT_NEAR(frustum.top, expected.top, kExactRelative * 10 * scale);
        EXPECT_NEAR(frustum.z_near, 0.5, 0.5 * kExactRelative);
        EXPECT_NEAR(frustum.z_far, 50, 50 * kExactRelative * 10);
      }
    }
  }
}

TEST(GlTest, ViewMatrixRoundTripsAndIsTheGlEyeFrame) {
  std::mt19937_64 rng(testing::Seed(6));
  for (int i = 0; i < 100; ++i) {
    const testing::RandomCamera camera = testing::MakeRandomCamera(rng);
    const Eigen::Matrix4d view = GlEyeFromWorld(camera.cam_from_world);
    const Rigid3 back = CamFromWorldFromGlEyeFromWorld(view);
    EXPECT_LT((back.rotation - camera.cam_from_world.rotation).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((back.translation - camera.cam_from_world.translation).norm(), 1e-14);
    // A point ahead of the CV camera is at negative z in GL eye space.
    const Eigen::Vector3d ahead = Inverse(camera.cam_from_world) * Eigen::Vector3d(0.1, 0.2, 3.0);
    const Eigen::Vector4d eye = view * ahead.homogeneous();
    EXPECT_NEAR(eye.z(), -3.0, 1e-12);
    EXPECT_NEAR(eye.y(), -0.2, 1e-12);
  }
}

TEST(GlTest, MalformedMatricesAreRefusedWithTheEntryNamed) {
  Intrinsics k;
  k.fx = k.fy = 500;
  k.cx = 320;
  k.cy = 240;
  const ImageSize size{640, 480};
  try {
    IntrinsicsFromClipFromGlEye(ClipFromGlEyeOrtho(Ortho{}), size);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 3, col 2"), std::string::npos) << e.what();
  }
  Eigen::Matrix4d m = ClipFromGlEye(k, size, 1, 10);
  m(1, 0) = 0.1;
  EXPECT_THROW(IntrinsicsFromClipFromGlEye(m, size), std::invalid_argument);
  m = ClipFromGlEye(k, size, 1, 10);
  m(2, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(IntrinsicsFromClipFromGlEye(m, size), std::invalid_argument);
  // Reading an NO matrix as reversed-Z gives no valid near/far: refused, not a wrong range.
  EXPECT_THROW(DepthRangeFromClipFromGlEye(ClipFromGlEye(k, size, 1, 10), {ClipDepth::kZeroToOne, true}),
               std::invalid_argument);
  Intrinsics distorted = k;
  distorted.k1 = -0.1;
  EXPECT_THROW(ClipFromGlEye(distorted, size, 1, 10), std::invalid_argument);
  EXPECT_NO_THROW(ClipFromGlEye(distorted.Pinhole(), size, 1, 10));
  k.skew = 5;
  EXPECT_THROW(FrustumFromClipFromGlEye(ClipFromGlEye(k, size, 1, 10)), std::invalid_argument);
  EXPECT_THROW(ClipFromGlEye(k, size, 0.0, 10), std::invalid_argument);
  EXPECT_THROW(ClipFromGlEye(k, size, 1, 0.5), std::invalid_argument);
}

// Every argument below passes its own check, yet the result is beyond a double (an entry
// overflows, or a scale underflows to 0): each conversion throws std::invalid_argument saying so,
// never returns inf, NaN or a matrix that maps every point to one pixel.
void ExpectBeyondADouble(const std::function<void()>& convert, const char* what) {
  try {
    convert();
    ADD_FAILURE() << what << ": no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be represented"), std::string::npos)
        << what << ": " << e.what();
  }
}

TEST(GlTest, ResultsBeyondADoubleAreRefused) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  ExpectBeyondADouble([] { ClipFromGlEye(Frustum{-1, 1, -1, 1, 1e308, kInfinity}); },
                      "frustum near 1e308, infinite far (B = -2 near)");
  ExpectBeyondADouble([] { ClipFromGlEye(Frustum{-1e-310, 1e-310, -1, 1, 1, 10}); },
                      "frustum width 2e-310");
  ExpectBeyondADouble([=] { ClipFromGlEye(Frustum{-1e300, 1e300, -1, 1, tiny, 1}); },
                      "frustum x scale underflows to 0");
  ExpectBeyondADouble([] { ClipFromGlEye(Perspective{1e-320, 1.0, 1.0, 10.0}); },
                      "perspective fovy 1e-320 deg");
  ExpectBeyondADouble([] { FrustumFromPerspective(Perspective{90.0, 1.7e308, 1.0, 10.0}); },
                      "perspective aspect 1.7e308 (right - left overflows)");
  Intrinsics k;
  k.fx = k.fy = 1e308;
  ExpectBeyondADouble([&] { ClipFromGlEye(k, ImageSize{1, 1}, 1.0, 10.0); },
                      "fx 1e308 on a 1x1 image");
  k.fx = k.fy = 1e-320;
  ExpectBeyondADouble([&] { ClipFromGlEye(k, ImageSize{1000000, 1000000}, 1.0, 10.0); },
                      "fx 1e-320 on 1e6 px (scale underflows)");
  k.fx = k.fy = 500.0;
  ExpectBeyondADouble([&] { ClipFromGlEyeOrthographic(k, ImageSize{640, 480}, 0.0, 1e-310); },
                      "orthographic near 0, far 1e-310");
  EXPECT_THROW(ClipFromGlEyeOrthographic(k, ImageSize{640, 480}, -1e308, 1e308),
               std::invalid_argument);  // far - near overflows
  k.fx = k.fy = 1e308;
  k.cx = 1e308;
  ExpectBeyondADouble([&] { OrthoFromOrthographic(k, ImageSize{2, 2}, 0.0, 1.0); },
                      "glOrtho box of fx 1e308, cx 1e308 (left == right)");
  Eigen::Matrix4d m = ClipFromGlEye(Frustum{});
  m(0, 0) = 1e308;
  ExpectBeyondADouble([&] { IntrinsicsFromClipFromGlEye(m, ImageSize{640, 480}); },
                      "intrinsics of m00 = 1e308");
  m(0, 0) = tiny;
  ExpectBeyondADouble([&] { FrustumFromClipFromGlEye(m); }, "frustum of m00 = 5e-324");
  ExpectBeyondADouble([=] { IntrinsicsFromFrustum(Frustum{-1e10, 1e10, -1, 1, 1e-320, 1},
                                                  ImageSize{640, 480}); },
                      "intrinsics of a frustum whose fx underflows to 0");
  Eigen::Matrix4d bad = ClipFromGlEye(Frustum{});
  bad(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(GlPixelFromWorld(bad, Eigen::Matrix4d::Identity(), Eigen::Vector3d(0, 0, -2),
                                ImageSize{640, 480}),
               std::invalid_argument);
  // The valid extremes nearest to these still convert, exactly as before.
  EXPECT_NO_THROW(ClipFromGlEye(Frustum{-1, 1, -1, 1, 1e307, kInfinity}));
  EXPECT_NO_THROW(ClipFromGlEye(Perspective{1e-3, 1.0, 1.0, 10.0}));
}

}  // namespace
}  // namespace camproj

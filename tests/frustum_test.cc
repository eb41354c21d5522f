#include "camproj/frustum.h"

#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "camproj/gl.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::kExactRelative;

// Hand-computed values (../shared/seeds: the glFrustum, pseudodepth, glOrtho and viewport
// derivations) agree to the last couple of bits.
constexpr double kHandTolerance = 1e-15;

TEST(FrustumTest, TextbookGlFrustum) {
  // glFrustum(-1, 1, -1, 1, 1, 4) = [[1,0,0,0],[0,1,0,0],[0,0,-5/3,-8/3],[0,0,-1,0]].
  const Eigen::Matrix4d m = ClipFromGlEye(Frustum{-1, 1, -1, 1, 1, 4});
  Eigen::Matrix4d expected;
  expected << 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -5.0 / 3.0, -8.0 / 3.0, 0, 0, -1, 0;
  EXPECT_LT((m - expected).cwiseAbs().maxCoeff(), kHandTolerance) << m;

  // The point (1, 0.5, -1.5) projects onto the near plane N = 1 at (x N/-z, y N/-z) = (2/3, 1/3):
  // in NDC of this frustum (near window [-1,1]^2) that is the same numbers.
  const Eigen::Vector4d clip = m * Eigen::Vector4d(1, 0.5, -1.5, 1);
  EXPECT_NEAR(clip.x() / clip.w(), 2.0 / 3.0, kHandTolerance);
  EXPECT_NEAR(clip.y() / clip.w(), 1.0 / 3.0, kHandTolerance);

  // Pseudodepth: z = -N maps to -1, z = -F to +1.
  const Eigen::Vector4d near_clip = m * Eigen::Vector4d(0, 0, -1, 1);
  const Eigen::Vector4d far_clip = m * Eigen::Vector4d(0, 0, -4, 1);
  EXPECT_NEAR(near_clip.z() / near_clip.w(), -1.0, kHandTolerance);
  EXPECT_NEAR(far_clip.z() / far_clip.w(), 1.0, kHandTolerance);
}

TEST(FrustumTest, FrustumCornersMapToNdcCorners) {
  const Frustum frustum{-0.3, 0.7, -0.2, 0.4, 0.5, 20};
  const double ratio = frustum.z_far / frustum.z_near;
  for (const GlDepth depth : {GlDepth{ClipDepth::kNegativeOneToOne, false},
                              GlDepth{ClipDepth::kZeroToOne, false},
                              GlDepth{ClipDepth::kNegativeOneToOne, true},
                              GlDepth{ClipDepth::kZeroToOne, true}}) {
    const Eigen::Matrix4d m = ClipFromGlEye(frustum, depth);
    const double near_ndc = depth.reversed_z ? 1.0 : (depth.clip_depth == ClipDepth::kZeroToOne ? 0.0 : -1.0);
    const double far_ndc = depth.reversed_z ? (depth.clip_depth == ClipDepth::kZeroToOne ? 0.0 : -1.0) : 1.0;
    for (int corner = 0; corner < 4; ++corner) {
      const double x = corner & 1 ? frustum.right : frustum.left;
      const double y = corner & 2 ? frustum.top : frustum.bottom;
      for (const bool at_far : {false, true}) {
        const double s = at_far ? ratio : 1.0;
        const Eigen::Vector4d clip = m * Eigen::Vector4d(s * x, s * y, -s * frustum.z_near, 1);
        const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
        EXPECT_NEAR(ndc.x(), corner & 1 ? 1.0 : -1.0, 1e-14);
        EXPECT_NEAR(ndc.y(), corner & 2 ? 1.0 : -1.0, 1e-14);
        EXPECT_NEAR(ndc.z(), at_far ? far_ndc : near_ndc, 1e-14);
      }
    }
  }
}

TEST(FrustumTest, TextbookGlOrtho) {
  // glOrtho(l=-2, r=6, b=-1, t=3, n=1, f=11): diag(2/8, 2/4, -2/10) and translation
  // (-(6-2)/8, -(3-1)/4, -(11+1)/10) = (-0.5, -0.5, -1.2).
  const Eigen::Matrix4d m = ClipFromGlEyeOrtho(Ortho{-2, 6, -1, 3, 1, 11});
  Eigen::Matrix4d expected;
  expected << 0.25, 0, 0, -0.5, 0, 0.5, 0, -0.5, 0, 0, -0.2, -1.2, 0, 0, 0, 1;
  EXPECT_LT((m - expected).cwiseAbs().maxCoeff(), kHandTolerance) << m;
  // Box corners map to the NDC cube: (l, b, -n) -> (-1, -1, -1), (r, t, -f) -> (1, 1, 1).
  EXPECT_LT((m * Eigen::Vector4d(-2, -1, -1, 1) - Eigen::Vector4d(-1, -1, -1, 1)).norm(), kHandTolerance);
  EXPECT_LT((m * Eigen::Vector4d(6, 3, -11, 1) - Eigen::Vector4d(1, 1, 1, 1)).norm(), kHandTolerance);
  // ZO: near -> 0, far -> 1.
  const Eigen::Matrix4d zo = ClipFromGlEyeOrtho(Ortho{-2, 6, -1, 3, 1, 11}, ClipDepth::kZeroToOne);
  EXPECT_NEAR((zo * Eigen::Vector4d(0, 0, -1, 1)).z(), 0.0, kHandTolerance);
  EXPECT_NEAR((zo * Eigen::Vector4d(0, 0, -11, 1)).z(), 1.0, kHandTolerance);
}

TEST(FrustumTest, ViewportFormula) {
  // glViewport(10, 20, 640, 480): NDC (-1,-1) -> (10, 20), (1,1) -> (650, 500), (0,0) -> (330, 260).
  const Viewport viewport{10, 20, 640, 480};
  EXPECT_EQ(WindowFromNdc({-1, -1, -1}, viewport), Eigen::Vector3d(10, 20, 0));
  EXPECT_EQ(WindowFromNdc({1, 1, 1}, viewport), Eigen::Vector3d(650, 500, 1));
  EXPECT_EQ(WindowFromNdc({0, 0, 0}, viewport), Eigen::Vector3d(330, 260, 0.5));
  EXPECT_EQ(WindowFromNdc({0, 0, 0.25}, viewport, ClipDepth::kZeroToOne).z(), 0.25);
}

TEST(FrustumTest, PerspectiveIsTheSymmetricFrustum) {
  // fovy 90 deg: top = near * tan(45 deg) = near.
  const Frustum frustum = FrustumFromPerspective(Perspective{90, 1.5, 2, 100});
  EXPECT_NEAR(frustum.top, 2.0, kHandTolerance * 2);
  EXPECT_NEAR(frustum.right, 3.0, kHandTolerance * 4);
  EXPECT_EQ(frustum.left, -frustum.right);
  const Perspective back = PerspectiveFromFrustum(frustum);
  EXPECT_NEAR(back.fovy_deg, 90.0, 90 * kExactRelative);
  EXPECT_NEAR(back.aspect, 1.5, kExactRelative);
}

TEST(FrustumTest, OffAxisFrustumHasNoPerspectiveForm) {
  try {
    PerspectiveFromFrustum(Frustum{-1, 1, -0.2, 1, 1, 10});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("off-axis"), std::string::npos) << e.what();
  }
  // A centred principal point gives a symmetric frustum and so a perspective.
  Intrinsics k;
  k.fx = k.fy = 1000;
  k.cx = 959.5;
  k.cy = 539.5;
  const Perspective perspective = PerspectiveFromIntrinsics(k, {1920, 1080}, 0.1, 100);
  EXPECT_NEAR(perspective.aspect, 1920.0 / 1080.0, kExactRelative);
  EXPECT_NEAR(perspective.fovy_deg, 2 * std::atan(540.0 / 1000) * 180 / M_PI, 1e-12);
}

TEST(FrustumTest, IntrinsicsFrustumRoundTrip) {
  std::mt19937_64 rng(testing::Seed(17));
  for (int i = 0; i < 1000; ++i) {
    testing::RandomCameraOptions options;
    options.max_skew_ratio = 0.0;
    const testing::RandomCamera camera = testing::MakeRandomCamera(rng, options);
    for (const PixelOrigin origin : {PixelOrigin::kCenter, PixelOrigin::kCorner}) {
      const Intrinsics& k = camera.intrinsics;
      const double z_near = testing::LogUniform(rng, 1e-3, 10);
      const Frustum frustum = FrustumFromIntrinsics(k, camera.size, z_near, z_near * 100, origin);
      const Intrinsics back = IntrinsicsFromFrustum(frustum, camera.size, origin);
      const double w = camera.size.width;
      const double h = camera.size.height;
      EXPECT_NEAR(back.fx, k.fx, kExactRelative * k.fx);
      EXPECT_NEAR(back.fy, k.fy, kExactRelative * k.fy);
      EXPECT_NEAR(back.cx, k.cx, kExactRelative * std::max(std::abs(k.cx), w));
      EXPECT_NEAR(back.cy, k.cy, kExactRelative * std::max(std::abs(k.cy), h));
      EXPECT_EQ(back.skew, 0.0);
    }
  }
}

TEST(FrustumTest, NearPlaneWindowIsTheImageOuterEdge) {
  // A 4x2 image with fx = fy = 2, cx = 1.5, cy = 0.5 (kCenter, the exact centre) and near = 1:
  // the outer pixel edges are at u = -0.5 and 3.5, i.e. x/z = -1 and +1; v = -0.5, 1.5 -> y/z = -0.5,
  // +0.5. GL's y is up, so top = 0.5.
  Intrinsics k;
  k.fx = k.fy = 2;
  k.cx = 1.5;
  k.cy = 0.5;
  const Frustum frustum = FrustumFromIntrinsics(k, {4, 2}, 1, 10);
  EXPECT_EQ(frustum.left, -1.0);
  EXPECT_EQ(frustum.right, 1.0);
  EXPECT_EQ(frustum.top, 0.5);
  EXPECT_EQ(frustum.bottom, -0.5);
  // Principal point at the bottom edge (a projector): the frustum lies above the axis.
  k.cy = 1.5;
  const Frustum projector = FrustumFromIntrinsics(k, {4, 2}, 1, 10);
  EXPECT_EQ(projector.bottom, 0.0);
  EXPECT_EQ(projector.top, 1.0);
}

TEST(FrustumTest, BadInputIsNamed) {
  auto expect_message = [](auto&& call, const std::string& words) {
    try {
      call();
      ADD_FAILURE() << "no exception, expected " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  Intrinsics k;
  k.fx = k.fy = 100;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_message([&] { FrustumFromIntrinsics(k, {640, 480}, 0.0, 10); }, "near must be positive");
  expect_message([&] { FrustumFromIntrinsics(k, {640, 480}, -1.0, 10); }, "near must be positive");
  expect_message([&] { FrustumFromIntrinsics(k, {640, 480}, 1.0, 1.0); }, "far must be greater");
  expect_message([&] { FrustumFromIntrinsics(k, {640, 480}, 1.0, nan); }, "far must not be NaN");
  expect_message([&] { FrustumFromIntrinsics(k, {0, 480}, 1.0, 10); }, "image size");
  expect_message([&] { ClipFromGlEye(Frustum{1, -1, -1, 1, 1, 10}); }, "left must be less");
  expect_message([&] { ClipFromGlEye(Perspective{180, 1, 1, 10}); }, "fovy_deg");
  expect_message([&] { ClipFromGlEye(Perspective{60, nan, 1, 10}); }, "aspect");
  expect_message([&] { ClipFromGlEyeOrtho(Ortho{0, 1, 0, 1, 2, 2}); }, "near must differ");
  Intrinsics skewed = k;
  skewed.skew = 3;
  expect_message([&] { FrustumFromIntrinsics(skewed, {640, 480}, 1, 10); }, "skew");
  Intrinsics distorted = k;
  distorted.k1 = 0.1;
  expect_message([&] { FrustumFromIntrinsics(distorted, {640, 480}, 1, 10); }, "distortion");
  expect_message([&] { WindowFromNdc({0, 0, 0}, Viewport{0, 0, 0, 10}); }, "viewport");
}

// Conversions whose results a double cannot hold throw instead of returning inf, 0 or a
// collapsed frustum (camproj convert printed them with exit 0 before session 37).
TEST(FrustumTest, OverflowingConversionsThrow) {
  const ImageSize size{100, 100};
  // r - l overflows: the matrix's scale would be 0.
  EXPECT_THROW(ClipFromGlEye(Frustum{-1e308, 1e308, -0.1, 0.1, 1e-308, 1.0}), std::invalid_argument);
  // Extents below what near can be divided by: fx = near W / (r - l) = inf.
  EXPECT_THROW(IntrinsicsFromFrustum(Frustum{-1e-310, 1e-310, -0.1, 0.1, 0.1, 1.0}, size),
               std::invalid_argument);
  // cx = 1e308: left and right round to the same plane.
  Intrinsics k;
  k.fx = k.fy = 100.0;
  k.cx = 1e308;
  k.cy = 50.0;
  EXPECT_THROW(FrustumFromIntrinsics(k, size, 0.1, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace camproj

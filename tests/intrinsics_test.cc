#include "camproj/intrinsics.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

using testing::kExactRelative;

// Newton's undistortion stops at a 1e-14 step in normalized units; times a focal length of
// ~1e3 px and a few roundings that is ~1e-10 px.
constexpr double kUndistortPixelTolerance = 1e-9;

TEST(IntrinsicsTest, HandComputedProjection) {
  Intrinsics k;
  k.fx = 800;
  k.fy = 600;
  k.cx = 320;
  k.cy = 240;
  k.skew = 10;
  // x = 0.5, y = 0.25: u = 800*0.5 + 10*0.25 + 320 = 722.5, v = 600*0.25 + 240 = 390.
  const Eigen::Vector2d pixel = PixelFromCam(k, Eigen::Vector3d(1.0, 0.5, 2.0));
  EXPECT_DOUBLE_EQ(pixel.x(), 722.5);
  EXPECT_DOUBLE_EQ(pixel.y(), 390.0);
  k.k1 = 0.1;
  k.k2 = 0.01;
  // r2 = 0.3125, d = 1 + 0.1*0.3125 + 0.01*0.3125^2 = 1.0322265625.
  const double d = 1.0322265625;
  const Eigen::Vector2d distorted = PixelFromCam(k, Eigen::Vector3d(1.0, 0.5, 2.0));
  EXPECT_DOUBLE_EQ(distorted.x(), 800 * d * 0.5 + 10 * d * 0.25 + 320);
  EXPECT_DOUBLE_EQ(distorted.y(), 600 * d * 0.25 + 240);
}

TEST(IntrinsicsTest, KRoundTripsAndPixelOriginShiftsThePrincipalPoint) {
  Intrinsics k;
  k.fx = 1000;
  k.fy = 990;
  k.cx = 959.5;
  k.cy = 539.5;
  k.skew = 1.5;
  const Intrinsics back = IntrinsicsFromK(2.0 * k.K());
  EXPECT_DOUBLE_EQ(back.fx, k.fx);
  EXPECT_DOUBLE_EQ(back.skew, k.skew);
  EXPECT_DOUBLE_EQ(back.cy, k.cy);
  const Intrinsics corner = ConvertPixelOrigin(k, PixelOrigin::kCenter, PixelOrigin::kCorner);
  EXPECT_EQ(corner.cx, 960.0);
  EXPECT_EQ(corner.cy, 540.0);
  EXPECT_EQ(corner.fx, k.fx);
}

TEST(IntrinsicsTest, RayFromPixelInvertsProjection) {
  std::mt19937_64 rng(testing::Seed(11));
  for (int i = 0; i < 1000; ++i) {
    Intrinsics k;
    k.fx = testing::LogUniform(rng, 100, 10000);
    k.fy = k.fx * testing::Uniform(rng, 0.8, 1.25);
    k.cx = testing::Uniform(rng, 0, 2000);
    k.cy = testing::Uniform(rng, 0, 2000);
    k.skew = testing::Uniform(rng, -0.1, 0.1) * k.fx;
    const bool distorted = i % 2 == 1;
    if (distorted) {
      k.k1 = testing::Uniform(rng, -0.3, 0.3);
      k.k2 = testing::Uniform(rng, -0.05, 0.05);
    }
    if (i % 4 == 3) {  // OpenCV's whole lens: the 2D Newton path
      k.p1 = testing::Uniform(rng, -0.01, 0.01);
      k.p2 = testing::Uniform(rng, -0.01, 0.01);
      k.k3 = testing::Uniform(rng, -0.05, 0.05);
    }
    // Normalized radius below 0.8 keeps d increasing for these k1, k2.
    const Eigen::Vector3d point =
        testing::DrawVector2([&] { return testing::Uniform(rng, -0.5, 0.5); }).homogeneous();
    const double depth = testing::LogUniform(rng, 0.01, 100);
    const Eigen::Vector2d pixel = PixelFromCam(k, depth * point);
    const Eigen::Vector3d ray = CamRayFromPixel(k, pixel);
    EXPECT_EQ(ray.z(), 1.0);
    const Eigen::Vector2d reprojected = PixelFromCam(k, ray);
    EXPECT_LT((reprojected - pixel).norm(), distorted ? kUndistortPixelTolerance
                                                      : kExactRelative * pixel.norm())
        << "case " << i;
  }
}

// cv::projectPoints' model by hand: x = 0.5, y = 0.25, r2 = 0.3125.
TEST(IntrinsicsTest, HandComputedTangentialAndK3) {
  Intrinsics k;
  k.fx = 800;
  k.fy = 600;
  k.cx = 320;
  k.cy = 240;
  k.k1 = 0.1;
  k.p1 = 0.01;
  k.p2 = -0.02;
  k.k3 = 0.5;
  const double r2 = 0.3125;
  const double d = 1.0 + 0.1 * r2 + 0.5 * r2 * r2 * r2;
  const double xd = d * 0.5 + 2 * 0.01 * 0.5 * 0.25 - 0.02 * (r2 + 2 * 0.25);
  const double yd = d * 0.25 + 0.01 * (r2 + 2 * 0.0625) + 2 * -0.02 * 0.5 * 0.25;
  const Eigen::Vector2d pixel = PixelFromCam(k, Eigen::Vector3d(1.0, 0.5, 2.0));
  EXPECT_NEAR(pixel.x(), 800 * xd + 320, kExactRelative * 1000);
  EXPECT_NEAR(pixel.y(), 600 * yd + 240, kExactRelative * 1000);
}

// The fold with k3: g'(r) = 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3 (s = r^2) vanishes at r_fold and is
// positive below it, for random k1, k2, k3 (grid of 1000 radii below the fold).
TEST(IntrinsicsTest, FoldRadiusWithK3IsTheFirstZeroOfTheSlope) {
  std::mt19937_64 rng(testing::Seed(12));
  int folds = 0;
  for (int i = 0; i < 1000; ++i) {
    const double k1 = testing::Uniform(rng, -0.5, 0.5);
    const double k2 = testing::Uniform(rng, -0.5, 0.5);
    const double k3 = testing::Uniform(rng, -0.5, 0.5);
    auto slope = [&](double r) {
      const double s = r * r;
      return 1.0 + s * (3.0 * k1 + s * (5.0 * k2 + s * 7.0 * k3));
    };
    const double r_fold = RadialFoldRadius(k1, k2, k3);
    if (k3 > 0.0 && !std::isfinite(r_fold)) {
      for (int j = 1; j <= 1000; ++j) ASSERT_GT(slope(0.01 * j), 0.0) << k1 << " " << k2 << " " << k3;
      continue;
    }
    ASSERT_TRUE(std::isfinite(r_fold)) << k1 << " " << k2 << " " << k3;  // k3 < 0: h -> -inf
    ++folds;
    // h(r_fold) is 0 to rounding: s is bisected to the adjacent double and r = sqrt(s) squared
    // back (together a few eps relative in s: |h'(s)| s times that), and h is evaluated as a sum
    // of terms up to 7 |k3| s^3 (a few eps of their magnitude). With a small |k3| the root s is
    // large and the terms with it (1e3 and more), so the bound scales with both, 8 eps each.
    const double s = r_fold * r_fold;
    const double terms = 1.0 + std::abs(3.0 * k1 * s) + std::abs(5.0 * k2 * s * s) +
                         std::abs(7.0 * k3 * s * s * s);
    const double derivative_s = std::abs(s * (3.0 * k1 + s * (10.0 * k2 + s * 21.0 * k3)));
    const double eps = std::numeric_limits<double>::epsilon();
    EXPECT_NEAR(slope(r_fold), 0.0, 8.0 * eps * (terms + derivative_s))
        << k1 << " " << k2 << " " << k3 << ", s = " << s;
    for (int j = 0; j < 1000; ++j) {
      ASSERT_GT(slope(r_fold * j / 1000.0), 0.0) << k1 << " " << k2 << " " << k3;
    }
  }
  EXPECT_GT(folds, 500);  // every k3 < 0 folds: about half, plus some with k3 > 0
}

TEST(IntrinsicsTest, UndistortionRefusesWhereTheRadialMapFolds) {
  Intrinsics k;
  k.fx = k.fy = 500;
  k.cx = k.cy = 250;
  k.k1 = -0.5;  // d r / d r_u = 1 - 1.5 r^2 vanishes at r = 0.816: rd peaks at 0.544.
  EXPECT_THROW(CamRayFromPixel(k, Eigen::Vector2d(250 + 500 * 0.6, 250)), std::domain_error);
  EXPECT_NO_THROW(CamRayFromPixel(k, Eigen::Vector2d(250 + 500 * 0.5, 250)));
  // k1 = -1, k2 = 0.4: g(r) = r - r^3 + 0.4 r^5 rises to 0.424 at r = 0.707, dips, then rises
  // again. Only radii below the first fold are invertible, whatever Newton's start would find.
  k.k1 = -1.0;
  k.k2 = 0.4;
  EXPECT_THROW(CamRayFromPixel(k, Eigen::Vector2d(250 + 500 * 1.2, 250)), std::domain_error);
  EXPECT_THROW(CamRayFromPixel(k, Eigen::Vector2d(250 + 500 * 0.849, 250)), std::domain_error);
  const Eigen::Vector3d ray = CamRayFromPixel(k, Eigen::Vector2d(250 + 500 * 0.4, 250));
  EXPECT_NEAR(PixelFromCam(k, ray).x(), 250 + 500 * 0.4, kUndistortPixelTolerance);
  EXPECT_LT(ray.x(), std::sqrt(0.5));
}

TEST(IntrinsicsTest, BadValuesAreNamed) {
  Intrinsics k;
  k.fx = -1;
  try {
    k.Check();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
  k.fx = 1;
  k.cy = std::numeric_limits<double>::infinity();
  EXPECT_THROW(k.Check(), std::invalid_argument);
  EXPECT_THROW(PixelFromCam(Intrinsics{}, Eigen::Vector3d(0, 0, -1)), std::invalid_argument);
  EXPECT_THROW(PixelFromCam(Intrinsics{}, Eigen::Vector3d(0, 0, 0)), std::invalid_argument);
  Intrinsics negative;
  negative.fx = -1;
  EXPECT_THROW(PixelFromCam(negative, Eigen::Vector3d(0, 0, 1)), std::invalid_argument);
  EXPECT_THROW(PixelFromCam(Intrinsics{}, Eigen::Vector3d(std::nan(""), 0, 1)),
               std::invalid_argument);
}

TEST(IntrinsicsTest, ARayBeyondADoubleIsRefusedNotInfinite) {
  // Both finite, the pixel's offset from the principal point is not: the ray would be inf.
  Intrinsics k;
  k.fx = k.fy = 1.0;
  k.cx = -1e308;
  try {
    CamRayFromPixel(k, Eigen::Vector2d(1e308, 0.0));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be represented"), std::string::npos) << e.what();
  }
  k.k1 = 0.1;  // the distorted path too
  EXPECT_THROW(CamRayFromPixel(k, Eigen::Vector2d(1e308, 0.0)), std::invalid_argument);
  EXPECT_EQ(CamRayFromPixel(k, Eigen::Vector2d(-1e308, 0.0)), Eigen::Vector3d(0, 0, 1));
}

}  // namespace
}  // namespace camproj

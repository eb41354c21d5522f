// The closed forms (lib/src/fit/closed_form.h): the DLT's smallest eigenvector; the start a
// plane gets (fit/start.h).
#include "fit/closed_form.h"

#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/fit.h"
#include "fit/scene.h"
#include "fit/start.h"
#include "seeds.h"

namespace camproj {
namespace {

using Matrix12 = Eigen::Matrix<double, 12, 12>;
using Vector12 = Eigen::Matrix<double, 12, 1>;

// The distance between two unit vectors up to sign: 2 sin(angle / 2), the angle to within its
// cube (from a cosine it would lose half the digits: 1 - cos rounds to 1e-16 at 1e-8).
double ChordBetween(const Vector12& a, const Vector12& b) {
  return std::min((a - b).norm(), (a + b).norm());
}

// The DLT's normal matrix for `n` random points seen by a random camera with pixel noise
// `noise` (normalized units), built as A^T A from the rows [x^T, 0, -u x^T], [0, x^T, -v x^T].
Matrix12 DltNormal(std::mt19937_64& rng, int n, double noise) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Matrix<double, 3, 4> p = Eigen::Matrix<double, 3, 4>::Random() +
                                        (Eigen::Matrix<double, 3, 4>() << 1, 0, 0, 0,  //
                                         0, 1, 0, 0,                                  //
                                         0, 0, 0, 4)
                                            .finished();
  Matrix12 normal = Matrix12::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4d x(gauss(rng), gauss(rng), gauss(rng), 1.0);
    const Eigen::Vector3d y = p * x;
    const Eigen::Vector2d u = y.head<2>() / y.z() + noise * Eigen::Vector2d(gauss(rng), gauss(rng));
    Eigen::Matrix<double, 2, 12> a = Eigen::Matrix<double, 2, 12>::Zero();
    a.block<1, 4>(0, 0) = x.transpose();
    a.block<1, 4>(0, 8) = -u.x() * x.transpose();
    a.block<1, 4>(1, 4) = x.transpose();
    a.block<1, 4>(1, 8) = -u.y() * x.transpose();
    normal += a.transpose() * a;
  }
  return normal;
}

// Where the smallest eigenvalue is separated (noisy points in general position, 6 to 100), the
// inverse iteration and Eigen's tridiagonal QR find the same vector. Each is backward stable:
// the vector of a matrix within ~12 u |M| of M, which Davis-Kahan moves by at most that over the
// gap lambda_2 - lambda_1; the bound allows 100 u |M| / gap.
TEST(ClosedFormTest, SmallestEigenvectorIsTheEigenSolvers) {
  std::mt19937_64 rng(testing::Seed(12));
  constexpr double kUnitRoundoff = 0x1p-53;
  int compared = 0;
  int iterated = 0;  // not Eigen's vector bit for bit: the inverse iteration's
  for (const int n : {6, 7, 10, 30, 100}) {
    for (const double noise : {1e-4, 1e-3, 1e-2}) {
      for (int draw = 0; draw < 20; ++draw) {
        const Matrix12 m = DltNormal(rng, n, noise);
        const Eigen::SelfAdjointEigenSolver<Matrix12> eigen(m);
        const double gap = eigen.eigenvalues()(1) - eigen.eigenvalues()(0);
        const Vector12 v = internal::SmallestEigenvector(m);
        EXPECT_NEAR(v.norm(), 1.0, 1e-14);
        EXPECT_LE(ChordBetween(v, eigen.eigenvectors().col(0)),
                  100.0 * kUnitRoundoff * eigen.eigenvalues()(11) / gap)
            << "n " << n << ", noise " << noise << ", gap " << gap;
        ++compared;
        iterated += v != eigen.eigenvectors().col(0) && v != -eigen.eigenvectors().col(0);
      }
    }
  }
  EXPECT_EQ(compared, 300);
  EXPECT_GT(iterated, 250) << "the inverse iteration was rarely used";
}

// A matrix singular to rounding has no separated smallest eigenvalue to iterate towards: with a
// null space of two dimensions (as six coplanar points give the DLT) every vector in it is a
// minimum, and the one returned is Eigen's, bit for bit (the fitters were tuned with it).
TEST(ClosedFormTest, SingularMatricesGetTheEigenSolversVector) {
  std::mt19937_64 rng(testing::Seed(13));
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int draw = 0; draw < 50; ++draw) {
    Eigen::Matrix<double, 12, 10> b;
    for (int i = 0; i < b.size(); ++i) b(i) = gauss(rng);
    const Matrix12 m = b * b.transpose();  // rank 10
    const Eigen::SelfAdjointEigenSolver<Matrix12> eigen(m);
    const Vector12 expected = eigen.eigenvectors().col(0);
    EXPECT_EQ(internal::SmallestEigenvector(m), expected) << "draw " << draw;
  }
}

// A plane tilted about the image's x axis does not determine the aspect (the homography's two
// equations in 1 / fx^2, 1 / fy^2 become one: r1 . r2 = 0 holds for any pair), so with the
// focal length and aspect free its closed form has no pair of focal lengths. The start is then
// the homography's one focal length at the aspect's start value (1), not the focal sweep's 48
// SQPnP poses: noise-free, the true focal length, to the homography's rounding (a normalized
// 8-parameter fit of 20 exact points: 1e-8 relative leaves four orders over its ~1e-12).
TEST(PlaneStartTest, APlaneTiltedAboutTheImageXAxisStartsFromItsHomography) {
  constexpr double kFocalPx = 1500.0;
  constexpr double kCx = 959.5;
  constexpr double kCy = 1079.5;  // a projector's lens shift
  constexpr double kRelativeTolerance = 1e-8;
  const ImageSize size{1920, 1080};
  for (const double tilt_deg : {20.0, 35.0, 50.0, 65.0}) {
    // The plane z = 0, turned about the camera's x axis by the tilt, 4 units ahead.
    const Eigen::Matrix3d cam_from_world =
        Eigen::AngleAxisd(tilt_deg * 3.14159265358979323846 / 180.0, Eigen::Vector3d::UnitX())
            .toRotationMatrix();
    const Eigen::Vector3d translation(0.0, 0.0, 4.0);
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (int i = 0; i < 5; ++i) {
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector3d x(-1.0 + 0.5 * i, -0.6 + 0.4 * j, 0.0);
        const Eigen::Vector3d p = cam_from_world * x + translation;
        points.push_back(x);
        pixels.emplace_back(kFocalPx * p.x() / p.z() + kCx, kFocalPx * p.y() / p.z() + kCy);
      }
    }
    FitOptions options;
    options.pixel_origin = PixelOrigin::kCenter;
    options.aspect = ParameterMode::Free();
    options.principal_point = ParameterMode::Fixed(kCx, kCy);
    const internal::Scene scene = internal::ValidateScene(points, pixels, size, options);
    const internal::Start start =
        internal::ClosedFormStart(scene, options, std::chrono::steady_clock::now());
    EXPECT_EQ(start.method, "homography") << "tilt " << tilt_deg << " deg";
    EXPECT_NEAR(start.camera.intrinsics.fx / kFocalPx, 1.0, kRelativeTolerance)
        << "tilt " << tilt_deg << " deg";
    EXPECT_NEAR(start.camera.intrinsics.fy / kFocalPx, 1.0, kRelativeTolerance)
        << "tilt " << tilt_deg << " deg";
  }
}

}  // namespace
}  // namespace camproj

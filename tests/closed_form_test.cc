// The closed forms (lib/src/fit/closed_form.h): the DLT's smallest eigenvector; the start a
// plane gets (fit/start.h).
#include "fit/closed_form.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
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

// A plane z = 0 seen by a camera turned by `tilt_deg` about the axis in the image plane at
// `axis_deg` from the image's x axis, 4 units ahead, through a principal point at the bottom
// edge (a projector's lens shift): `n` random points in [-1, 1]^2 and their pixels (kCenter) with
// Gaussian noise `sigma_px` per axis.
struct PlaneScene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
};
constexpr double kPlaneFocalPx = 1500.0;
constexpr double kPlaneCx = 959.5;
constexpr double kPlaneCy = 1079.5;
PlaneScene TiltedPlane(std::mt19937_64& rng, int n, double tilt_deg, double axis_deg,
                       double sigma_px) {
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, sigma_px);
  const Eigen::Vector3d axis(std::cos(axis_deg * kDeg), std::sin(axis_deg * kDeg), 0.0);
  const Eigen::Matrix3d cam_from_world = Eigen::AngleAxisd(tilt_deg * kDeg, axis).toRotationMatrix();
  PlaneScene scene;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x(uniform(rng), uniform(rng), 0.0);
    const Eigen::Vector3d p = cam_from_world * x + Eigen::Vector3d(0.0, 0.0, 4.0);
    scene.points.push_back(x);
    scene.pixels.emplace_back(kPlaneFocalPx * p.x() / p.z() + kPlaneCx + gauss(rng),
                              kPlaneFocalPx * p.y() / p.z() + kPlaneCy + gauss(rng));
  }
  return scene;
}

// The sum of squared pixel distances of the plane's points (z = 0) mapped by h.
double HomographySumSquares(const Eigen::Matrix3d& h, const PlaneScene& scene) {
  double sum = 0.0;
  for (size_t i = 0; i < scene.points.size(); ++i) {
    const Eigen::Vector3d p = h * Eigen::Vector3d(scene.points[i].x(), scene.points[i].y(), 1.0);
    sum += (p.head<2>() / p.z() - scene.pixels[i]).squaredNorm();
  }
  return sum;
}

std::vector<Eigen::Vector2d> InPlane(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector2d> plane;
  for (const Eigen::Vector3d& x : points) plane.push_back(x.head<2>());
  return plane;
}

// The least-squares homography is the minimum of the pixels' sum of squares: noise-free, the
// true map (its pixels to 1e-9 px: a normalized 8-parameter solve of exact data is ~1e-12
// relative, 1e-9 px at 1e3 px); with noise, no step can lower it: the Gauss-Newton step from it
// (pseudo-inverse of the 2N x 9 Jacobian in H's entries, the scale's null direction left out)
// predicts a decrease within 1e-9 of the cost (the LM stops at steps of 1e-12 of |H|, whose
// remaining decrease is their square), and it is never above the DLT's.
TEST(LeastSquaresHomographyTest, IsTheMinimumOfThePixelsSumOfSquares) {
  std::mt19937_64 rng(testing::Seed(14));
  std::uniform_real_distribution<double> angle(0.0, 180.0);
  std::uniform_real_distribution<double> tilt(5.0, 70.0);
  int fitted = 0;
  for (const int n : {5, 10, 50}) {
    for (int draw = 0; draw < 60; ++draw) {
      const double sigma = draw % 3 == 0 ? 0.0 : 1.0;
      const PlaneScene scene = TiltedPlane(rng, n, tilt(rng), angle(rng), sigma);
      const std::vector<Eigen::Vector2d> plane = InPlane(scene.points);
      const std::optional<Eigen::Matrix3d> h =
          internal::LeastSquaresHomography(plane, scene.pixels);
      ASSERT_TRUE(h.has_value()) << "n " << n << ", draw " << draw;
      ++fitted;
      const double cost = HomographySumSquares(*h, scene);
      if (sigma == 0.0) {
        EXPECT_LE(std::sqrt(cost / n), 1e-9) << "n " << n << ", draw " << draw;
        continue;
      }
      EXPECT_LE(cost, HomographySumSquares(internal::NormalizedHomography(plane, scene.pixels),
                                           scene) * (1.0 + 1e-12))
          << "n " << n << ", draw " << draw;
      Eigen::MatrixXd j(2 * n, 9);
      Eigen::VectorXd r(2 * n);
      const Eigen::Matrix3d hn = *h / h->norm();
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d x(plane[i].x(), plane[i].y(), 1.0);
        const Eigen::Vector3d p = hn * x;
        const Eigen::Vector2d u = p.head<2>() / p.z();
        r.segment<2>(2 * i) = u - scene.pixels[i];
        j.row(2 * i) << x.transpose() / p.z(), Eigen::RowVector3d::Zero(), -u.x() * x.transpose() / p.z();
        j.row(2 * i + 1) << Eigen::RowVector3d::Zero(), x.transpose() / p.z(), -u.y() * x.transpose() / p.z();
      }
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j, Eigen::ComputeThinU);
      // The 8 directions that move the pixels (the 9th, H's scale, does not).
      const Eigen::VectorXd along = svd.matrixU().leftCols(8).transpose() * r;
      EXPECT_LE(along.squaredNorm(), 1e-9 * cost) << "n " << n << ", draw " << draw;
    }
  }
  EXPECT_EQ(fitted, 180);
}

// Pose + focal + aspect on a plane with the principal point given is the homography's model
// (fit/start.h, PlaneAspectStart): where the least-squares homography has a camera, the fit is
// that camera -- its sum of squares the homography's to 1e-9 relative (both minima of the same
// cost, each to ~1e-12), reached in at most one iteration of LM (it starts at the minimum); where
// it has none, a refusal that names the aspect (before: LM crawled up to 321 iterations after
// ever larger focal lengths, then refused as not converged). A plane tilted about an axis 45 deg
// from the image's axes determines the aspect: every scene answered, fx and fy within 5 % of
// the truth (at 1 px noise over 30 points their sigma is under 1 %). Tilted about the image x
// axis, the aspect is not determined: with noise the homography's camera exists or not as it
// falls, and both outcomes occur.
TEST(PlaneStartTest, PoseFocalAspectOnAPlaneIsItsHomographysCameraOrRefused) {
  std::mt19937_64 rng(testing::Seed(15));
  const ImageSize size{1920, 1080};
  FitOptions options;
  options.pixel_origin = PixelOrigin::kCenter;
  options.aspect = ParameterMode::Free();
  options.principal_point = ParameterMode::Fixed(kPlaneCx, kPlaneCy);
  for (const double axis_deg : {45.0, 0.0}) {
    int answered = 0;
    int refused = 0;
    for (int draw = 0; draw < 100; ++draw) {
      const PlaneScene scene = TiltedPlane(rng, 30, 40.0, axis_deg, 1.0);
      const std::optional<Eigen::Matrix3d> h =
          internal::LeastSquaresHomography(InPlane(scene.points), scene.pixels);
      ASSERT_TRUE(h.has_value());
      const std::string label = "axis " + std::to_string(axis_deg) + ", draw " + std::to_string(draw);
      try {
        const FitResult fit = FitCamera(scene.points, scene.pixels, size, options);
        ++answered;
        const double sum_squares = fit.rms_px * fit.rms_px * 30.0;
        EXPECT_NEAR(sum_squares / HomographySumSquares(*h, scene), 1.0, 1e-9) << label;
        // Started at the minimum: the polish settles there, or where the minimum is nearly flat
        // (the tilt about the image x axis) LM's first step changes the cost by less than its
        // function tolerance and stops it.
        EXPECT_LE(fit.iterations, 1) << label;
        EXPECT_EQ(fit.start_method, "homography") << label;
        if (axis_deg == 45.0) {
          EXPECT_NEAR(fit.camera.intrinsics.fx / kPlaneFocalPx, 1.0, 0.05) << label;
          EXPECT_NEAR(fit.camera.intrinsics.fy / kPlaneFocalPx, 1.0, 0.05) << label;
        }
      } catch (const SceneError& error) {
        ++refused;
        EXPECT_EQ(error.reason(), SceneError::Reason::kDegenerate) << label;
        const std::string message = error.what();
        // Refused for the aspect where the homography has no camera; a camera found may still
        // be refused by the assessment as not determined.
        internal::StartCamera camera;
        const bool has_camera = internal::StartFromHomography(
            *h, Eigen::Matrix3d::Identity(), Intrinsics{1.0, 1.0, kPlaneCx, kPlaneCy}, true, true,
            &camera);
        EXPECT_EQ(message.find("does not determine the aspect") != std::string::npos, !has_camera)
            << label << ": " << message;
      }
    }
    std::printf("[ INFO     ] tilted about an axis %.0f deg from the image x axis: %d answered, "
                "%d refused\n", axis_deg, answered, refused);
    if (axis_deg == 45.0) {
      EXPECT_EQ(answered, 100);
    } else {
      EXPECT_GT(answered, 0);
      EXPECT_GT(refused, 0);
    }
  }
}

}  // namespace
}  // namespace camproj

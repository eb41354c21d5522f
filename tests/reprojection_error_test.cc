// White-box test of the fitter's analytic Jacobian (lib/src/fit/reprojection_error.h) against
// Ceres' automatic differentiation of the templated functor the library's model is written in.
#include "fit/reprojection_error.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "fit/normal_equations.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

// Both are exact derivatives of the same double expressions: they differ by rounding only,
// ~1e-15 relative to the Jacobian's entries (px per unit of parameter).
constexpr double kJacobianRelative = 1e-10;

TEST(ReprojectionErrorTest, AnalyticJacobianMatchesAutomaticDifferentiation) {
  std::mt19937_64 rng(testing::Seed(21));
  for (int i = 0; i < 500; ++i) {
    const Eigen::Quaterniond q(testing::RandomRotation(rng));
    const Eigen::Vector3d center = testing::UniformVector3(rng, -2, 2);
    // Every slot non-zero, p1, p2 and k3 (OpenCV's lens) included.
    double intrinsics[internal::kFitIntrinsicsSize] = {
        testing::Uniform(rng, 300, 3000),  testing::Uniform(rng, 0.8, 1.2),
        testing::Uniform(rng, 0, 2000),    testing::Uniform(rng, 0, 2000),
        testing::Uniform(rng, -50, 50),    testing::Uniform(rng, -0.3, 0.3),
        testing::Uniform(rng, -0.1, 0.1),  testing::Uniform(rng, -0.01, 0.01),
        testing::Uniform(rng, -0.01, 0.01), testing::Uniform(rng, -0.05, 0.05)};
    const Eigen::Vector3d point_in_cam =
        testing::UniformVector3(rng, Eigen::Vector3d(-1, -1, 1), Eigen::Vector3d(1, 1, 5));
    const Eigen::Vector3d point = q.inverse() * point_in_cam + center;
    const Eigen::Vector2d observed = testing::DrawVector2([&] { return testing::Uniform(rng, 0, 2000); });

    std::unique_ptr<ceres::CostFunction> automatic(internal::ReprojectionError::Create(point, observed));
    const internal::PointReprojectionCost analytic(point, observed);
    const double* parameters[3] = {q.coeffs().data(), center.data(), intrinsics};
    double residual_a[2], residual_b[2];
    double jq_a[8], jc_a[6], jk_a[2 * internal::kFitIntrinsicsSize], jq_b[8], jc_b[6],
        jk_b[2 * internal::kFitIntrinsicsSize];
    double* jacobians_a[3] = {jq_a, jc_a, jk_a};
    double* jacobians_b[3] = {jq_b, jc_b, jk_b};
    ASSERT_TRUE(automatic->Evaluate(parameters, residual_a, jacobians_a));
    ASSERT_TRUE(analytic.Evaluate(parameters, residual_b, jacobians_b));
    EXPECT_NEAR(residual_a[0], residual_b[0], 1e-9);
    EXPECT_NEAR(residual_a[1], residual_b[1], 1e-9);
    auto expect_close = [&](const double* a, const double* b, int size, const char* name) {
      double scale = 0.0;
      for (int j = 0; j < size; ++j) scale = std::max(scale, std::abs(a[j]));
      for (int j = 0; j < size; ++j) {
        EXPECT_NEAR(a[j], b[j], kJacobianRelative * scale) << name << " entry " << j << " case " << i;
      }
    };
    expect_close(jq_a, jq_b, 8, "rotation");
    expect_close(jc_a, jc_b, 6, "center");
    expect_close(jk_a, jk_b, 2 * internal::kFitIntrinsicsSize, "intrinsics");
  }
}

// The radial-only path (p1 = p2 = k3 = 0, what single-view fits run) is the general one with
// those terms at zero, in the same order of operations: equal to the bit (a fit must not depend
// on which ran: a knife-edge scene of fit_auto_test changed its answer at 1e-16), and it writes no
// column for p1, p2, k3.
TEST(ReprojectionErrorTest, RadialOnlyPathEqualsTheGeneralOneWithoutTangentialTerms) {
  std::mt19937_64 rng(testing::Seed(22));
  constexpr int kSize = internal::kFitIntrinsicsSize;
  for (int i = 0; i < 500; ++i) {
    double intrinsics[kSize] = {
        testing::Uniform(rng, 300, 3000), testing::Uniform(rng, 0.8, 1.2),
        testing::Uniform(rng, 0, 2000),   testing::Uniform(rng, 0, 2000),
        testing::Uniform(rng, -50, 50),   testing::Uniform(rng, -0.3, 0.3),
        testing::Uniform(rng, -0.1, 0.1), 0.0, 0.0, 0.0};
    ASSERT_TRUE(internal::RadialOnly(intrinsics));
    const Eigen::Vector3d p =
        testing::UniformVector3(rng, Eigen::Vector3d(-1, -1, 1), Eigen::Vector3d(1, 1, 5));
    const Eigen::Vector2d observed = testing::DrawVector2([&] { return testing::Uniform(rng, 0, 2000); });
    double r_general[2], r_radial[2], jk_general[2 * kSize], jp_general[6], jp_radial[6];
    double jk_radial[2 * kSize];
    std::fill(jk_radial, jk_radial + 2 * kSize, -7.0);  // the unwritten columns keep this
    internal::ResidualOfCamPoint(intrinsics, p, observed, r_general, jk_general, jp_general);
    internal::ResidualOfCamPoint<true>(intrinsics, p, observed, r_radial, jk_radial, jp_radial);
    auto expect_equal = [&](const double* a, const double* b, int size, const char* name) {
      for (int j = 0; j < size; ++j) {
        EXPECT_EQ(a[j], b[j]) << name << " entry " << j << " case " << i;
      }
    };
    expect_equal(r_general, r_radial, 2, "residual");
    expect_equal(jp_general, jp_radial, 6, "d residual / d point");
    for (int row = 0; row < 2; ++row) {
      expect_equal(jk_general + row * kSize, jk_radial + row * kSize, 7, "d residual / d k");
      for (int slot = 7; slot < kSize; ++slot) EXPECT_EQ(jk_radial[row * kSize + slot], -7.0);
    }
  }
}

TEST(ReprojectionErrorTest, PointBehindTheCameraIsAnInvalidEvaluation) {
  const internal::PointReprojectionCost cost(Eigen::Vector3d(0, 0, -1), Eigen::Vector2d(0, 0));
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const double center[3] = {0, 0, 0};
  const double intrinsics[internal::kFitIntrinsicsSize] = {500, 1, 320, 240};
  const double* parameters[3] = {q.coeffs().data(), center, intrinsics};
  double residual[2];
  EXPECT_FALSE(cost.Evaluate(parameters, residual, nullptr));
}

// ToChart (fit/normal_equations.h) is the change of variables J -> J T, T = diag(A, R, I): the
// normal equations T^T J^T J T and T^T J^T r, here formed densely, for 6-13 parameters. Both are
// sums of at most 6 products of entries of size 1: they agree to rounding (1e-13 of the largest
// entry).
TEST(ReprojectionErrorTest, ToChartIsTheChangeOfVariables) {
  constexpr double kRounding = 1e-13;
  std::mt19937_64 rng(testing::Seed(23));
  for (int i = 0; i < 200; ++i) {
    const int p = 6 + i % (internal::kFitIntrinsicsSize + 1);
    Eigen::MatrixXd j(2 * p, p);
    for (int r = 0; r < j.rows(); ++r) {
      for (int c = 0; c < p; ++c) j(r, c) = testing::Uniform(rng, -1, 1);
    }
    Eigen::VectorXd residual(2 * p);
    for (int r = 0; r < residual.size(); ++r) residual(r) = testing::Uniform(rng, -1, 1);
    Eigen::Matrix3d a;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) a(r, c) = (r == c) + testing::Uniform(rng, -0.3, 0.3);
    }
    const Eigen::Matrix3d rotation = testing::RandomRotation(rng);
    internal::NormalEquations normal;
    normal.jtj = j.transpose() * j;
    normal.jtr = j.transpose() * residual;
    Eigen::MatrixXd t = Eigen::MatrixXd::Identity(p, p);
    t.topLeftCorner<3, 3>() = a;
    t.block<3, 3>(3, 3) = rotation;
    const Eigen::MatrixXd expected_jtj = t.transpose() * normal.jtj * t;
    const Eigen::VectorXd expected_jtr = t.transpose() * normal.jtr;
    internal::ToChart(a, rotation, &normal);
    const double scale = expected_jtj.cwiseAbs().maxCoeff();
    for (int r = 0; r < p; ++r) {
      for (int c = 0; c < p; ++c) {
        EXPECT_NEAR(normal.jtj(r, c), expected_jtj(r, c), kRounding * scale)
            << "(" << r << ", " << c << ") case " << i;
      }
      EXPECT_NEAR(normal.jtr(r), expected_jtr(r), kRounding * expected_jtr.cwiseAbs().maxCoeff())
          << r << " case " << i;
    }
  }
}

}  // namespace
}  // namespace camproj

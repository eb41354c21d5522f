// White-box test of the fitter's analytic Jacobian (lib/src/fit/reprojection_error.h) against
// Ceres' automatic differentiation of the templated functor the library's model is written in.
#include "fit/reprojection_error.h"

#include <random>

#include <gtest/gtest.h>

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
    const Eigen::Vector3d center(testing::Uniform(rng, -2, 2), testing::Uniform(rng, -2, 2),
                                 testing::Uniform(rng, -2, 2));
    // Every slot non-zero, p1, p2 and k3 (OpenCV's lens) included.
    double intrinsics[internal::kFitIntrinsicsSize] = {
        testing::Uniform(rng, 300, 3000),  testing::Uniform(rng, 0.8, 1.2),
        testing::Uniform(rng, 0, 2000),    testing::Uniform(rng, 0, 2000),
        testing::Uniform(rng, -50, 50),    testing::Uniform(rng, -0.3, 0.3),
        testing::Uniform(rng, -0.1, 0.1),  testing::Uniform(rng, -0.01, 0.01),
        testing::Uniform(rng, -0.01, 0.01), testing::Uniform(rng, -0.05, 0.05)};
    const Eigen::Vector3d point_in_cam(testing::Uniform(rng, -1, 1), testing::Uniform(rng, -1, 1),
                                       testing::Uniform(rng, 1, 5));
    const Eigen::Vector3d point = q.inverse() * point_in_cam + center;
    const Eigen::Vector2d observed(testing::Uniform(rng, 0, 2000), testing::Uniform(rng, 0, 2000));

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

TEST(ReprojectionErrorTest, PointBehindTheCameraIsAnInvalidEvaluation) {
  const internal::PointReprojectionCost cost(Eigen::Vector3d(0, 0, -1), Eigen::Vector2d(0, 0));
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const double center[3] = {0, 0, 0};
  const double intrinsics[internal::kFitIntrinsicsSize] = {500, 1, 320, 240};
  const double* parameters[3] = {q.coeffs().data(), center, intrinsics};
  double residual[2];
  EXPECT_FALSE(cost.Evaluate(parameters, residual, nullptr));
}

}  // namespace
}  // namespace camproj

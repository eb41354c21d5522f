// The condition number of the fitter's scaled Jacobian at a true camera, computed independently
// of the fitter's code: what decides whether a noise-free scene must be fitted (below the
// fitter's limit) or refused as undetermined (above it).
#ifndef CAMPROJ_TESTS_TRUTH_CONDITION_H_
#define CAMPROJ_TESTS_TRUTH_CONDITION_H_

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "camproj/fit.h"
#include "camproj/intrinsics.h"

namespace camproj {
namespace testing {

// fit.h: a fit whose scaled Jacobian has a condition number above this is refused as
// undetermined (SceneError kDegenerate; assess.cc: reciprocal condition of the Jacobi-scaled
// normal equations below 1e-12).
inline constexpr double kFitterConditionLimit = 1e6;

// The condition number of the scaled Jacobian at the true camera (rotation of cam_from_world,
// centre in world, intrinsics) in the fitter's parameterization (fit.h, src/fit/): pose in the
// world centred on the points and scaled to unit RMS distance, rotation R = exp(omega) R_true,
// then the free slots of `options` -- focal, aspect (fy / fx), cx, cy, skew, k1, k2; columns
// scaled to unit norm. Central differences in long double (step 1e-6 relative: truncation
// ~1e-12, rounding ~1e-19 / 1e-6 = 1e-13 relative). Infinite where a column vanishes.
inline double ConditionAtTruth(const std::vector<Eigen::Vector3d>& points,
                               const Eigen::Matrix3d& true_rotation,
                               const Eigen::Vector3d& true_center, const Intrinsics& k,
                               const FitOptions& options) {
  using Vector = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
  using Matrix = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector3l = Eigen::Matrix<long double, 3, 1>;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const bool known = options.known_intrinsics.has_value();
  const bool free[7] = {!known && options.focal.IsFree(),  !known && options.aspect.IsFree(),
                        !known && options.principal_point.IsFree(),
                        !known && options.principal_point.IsFree(),
                        !known && options.skew.IsFree(),   !known && options.k1.IsFree(),
                        !known && options.k2.IsFree()};
  const int n = static_cast<int>(points.size());
  Vector3l centroid = Vector3l::Zero();
  for (const auto& x : points) centroid += x.cast<long double>();
  centroid /= n;
  long double scale = 0.0L;
  for (const auto& x : points) scale += (x.cast<long double>() - centroid).squaredNorm();
  scale = std::sqrt(scale / n);
  const long double slot_values[7] = {k.fx, k.fy / static_cast<long double>(k.fx), k.cx, k.cy,
                                      k.skew, k.k1, k.k2};
  std::vector<int> slots;
  for (int slot = 0; slot < 7; ++slot) {
    if (free[slot]) slots.push_back(slot);
  }
  const int p = 6 + static_cast<int>(slots.size());
  Vector u0 = Vector::Zero(p);
  u0.segment<3>(3) = (true_center.cast<long double>() - centroid) / scale;
  for (size_t j = 0; j < slots.size(); ++j) u0(6 + j) = slot_values[slots[j]];
  auto residuals = [&](const Vector& u) {
    const Vector3l omega = u.head<3>();
    const long double angle = omega.norm();
    Eigen::Matrix<long double, 3, 3> rotation = true_rotation.cast<long double>();
    if (angle > 0.0L) rotation = Eigen::AngleAxis<long double>(angle, omega / angle) * rotation;
    long double v[7];
    std::copy(slot_values, slot_values + 7, v);
    for (size_t j = 0; j < slots.size(); ++j) v[slots[j]] = u(6 + j);
    Vector r(2 * n);
    for (int i = 0; i < n; ++i) {
      const Vector3l q =
          rotation * ((points[i].cast<long double>() - centroid) / scale - u.segment<3>(3));
      const long double x = q.x() / q.z();
      const long double y = q.y() / q.z();
      const long double r2 = x * x + y * y;
      const long double d = 1.0L + v[5] * r2 + v[6] * r2 * r2;
      r(2 * i) = v[0] * x * d + v[4] * y * d + v[2];
      r(2 * i + 1) = v[1] * v[0] * y * d + v[3];
    }
    return r;
  };
  Matrix jacobian(2 * n, p);
  for (int j = 0; j < p; ++j) {
    const long double h = 1e-6L * std::max(1.0L, std::abs(u0(j)));
    Vector plus = u0;
    Vector minus = u0;
    plus(j) += h;
    minus(j) -= h;
    jacobian.col(j) = (residuals(plus) - residuals(minus)) / (2.0L * h);
    const long double norm = jacobian.col(j).norm();
    if (!(norm > 0.0L)) return kInfinity;
    jacobian.col(j) /= norm;
  }
  const Vector singular = Eigen::JacobiSVD<Matrix>(jacobian).singularValues();
  if (!(singular(p - 1) > 0.0L)) return kInfinity;
  return static_cast<double>(singular(0) / singular(p - 1));
}

}  // namespace testing
}  // namespace camproj

#endif  // CAMPROJ_TESTS_TRUTH_CONDITION_H_

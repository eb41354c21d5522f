// What a true camera says about a noise-free fit, computed independently of the fitter's code:
// the condition number of the fitter's scaled Jacobian there, which decides whether the scene
// must be fitted (below the fitter's limit) or refused as undetermined (above it); and the
// first-order bound on the fit's error. The fit's error in parameter j is
// e_j = -[(J^T J)^-1 J^T r]_j, so |e_j| <= sigma_j(1 px) |r|_2 (Cauchy-Schwarz), sigma_j(1 px)
// the fit's own sigma at a pixel sigma of 1 and r what perturbs the data: the pixels'
// inconsistency with the true camera (in long double) plus a bound on the fitter's own rounding
// when it evaluates residuals. This is "condition number x rounding" made per parameter.
#ifndef CAMPROJ_TESTS_TRUTH_CONDITION_H_
#define CAMPROJ_TESTS_TRUTH_CONDITION_H_

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "camproj/pose.h"
#include "camproj/intrinsics.h"

namespace camproj {
namespace testing {

// fit.h: a fit whose scaled Jacobian has a condition number above this is refused as
// undetermined (SceneError kDegenerate; assess.cc: reciprocal condition of the Jacobi-scaled
// normal equations below 1e-12).
inline constexpr double kFitterConditionLimit = 1e6;

// Unit roundoff of float64: every correctly rounded operation errs by at most this relative.
inline constexpr double kUnitRoundoff = 0x1p-53;
// |e_j| <= kFirstOrderMargin sigma_j(1 px) |r|_2: the bound is exact to first order; the factor
// 2 covers the second-order terms (the Jacobian at the fit rather than at the truth differs by
// O(e), i.e. ~1e-10 relative) and a Gauss-Newton polish that stops within its own rounding
// floor, not at the exact fixed point.
inline constexpr double kFirstOrderMargin = 2.0;
// The fitter's rounding when it evaluates one residual, in unit roundoffs per term: centring and
// scaling the world (2), X - C and the quaternion rotation (about 12 operations deep), the
// perspective division (1), the distortion (3), then fx x + skew y + cx (3); each step errs by
// at most one unit roundoff of the magnitude it handles. About 21 in all; 32 leaves a margin of
// 1.5.
inline constexpr double kEvalRoundings = 32.0;
// Rounding of the returned camera itself, in unit roundoffs of each value: the eye is
// centroid + scale * centre and goes through t = -R C and back (C = -R^T t: ~8 roundings), the
// rotation through a quaternion and back (~8); 16 is twice that.
inline constexpr double kOutputRoundings = 16.0;

// |r|_2 of what perturbs a noise-free fit of `pixels`: their inconsistency with the true camera
// (in long double) plus the bound on the fitter's own evaluation rounding (kEvalRoundings): per
// term, the magnitudes it handles, (fx + fy + |skew|) (1 + |x| + |y|) d'(r) (|X - c| + |C - c|) / z
// + |u| + |v| + |cx| + |cy| with c the points' centroid and d'(r) = 1 + 3 |k1| r^2 + 5 |k2| r^4
// the radial map's slope bound.
inline double PerturbationNorm(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector2d>& pixels,
                               const Eigen::Matrix3d& true_rotation,
                               const Eigen::Vector3d& true_center, const Intrinsics& k) {
  using Vector3l = Eigen::Matrix<long double, 3, 1>;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& x : points) centroid += x;
  centroid /= static_cast<double>(points.size());
  const long double slots[kIntrinsicsArraySize] = {k.fx,   k.fy, k.cx, k.cy, k.skew,
                                                   k.k1,   k.k2, k.p1, k.p2, k.k3};
  long double data = 0.0L;
  double eval = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vector3l p = true_rotation.cast<long double>() *
                       (points[i].cast<long double>() - true_center.cast<long double>());
    long double pixel[2];
    PixelFromNormalized<long double>(slots, p.x() / p.z(), p.y() / p.z(), pixel);
    data += (pixels[i].cast<long double>() - Eigen::Matrix<long double, 2, 1>(pixel[0], pixel[1]))
                .squaredNorm();
    const double z = static_cast<double>(p.z());
    const double x = static_cast<double>(p.x()) / z;
    const double y = static_cast<double>(p.y()) / z;
    const double r2 = x * x + y * y;
    const double slope = 1.0 + 3.0 * std::abs(k.k1) * r2 + 5.0 * std::abs(k.k2) * r2 * r2;
    const double per_term =
        (k.fx + k.fy + std::abs(k.skew)) * (1.0 + std::abs(x) + std::abs(y)) * slope *
            ((points[i] - centroid).norm() + (true_center - centroid).norm()) / std::abs(z) +
        std::abs(static_cast<double>(pixel[0])) + std::abs(static_cast<double>(pixel[1])) +
        std::abs(k.cx) + std::abs(k.cy);
    const double bound = kEvalRoundings * kUnitRoundoff * per_term;
    eval += 2.0 * bound * bound;  // u and v
  }
  return static_cast<double>(std::sqrt(data)) + std::sqrt(eval);
}

// Rounding of the returned value of the fit's parameter j (fit.h's order: rotation in degrees,
// eye in world units, then the free intrinsics), kOutputRoundings unit roundoffs of it.
inline double OutputRounding(const FitResult& fit, const Eigen::Vector3d& true_center,
                             const std::vector<Eigen::Vector3d>& points, int j) {
  constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
  if (j < 3) return kOutputRoundings * kUnitRoundoff * kDegPerRad;
  if (j < 6) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& x : points) centroid += x;
    centroid /= static_cast<double>(points.size());
    return kOutputRoundings * kUnitRoundoff *
           (true_center.cwiseAbs().maxCoeff() + centroid.cwiseAbs().maxCoeff());
  }
  return kOutputRoundings * kUnitRoundoff * std::abs(fit.sigmas[j].value);
}

// The fit's error in its own parameterization (fit.h: rotation as omega with
// R = exp(omega) R_fit, degrees; eye in world units; free intrinsics in px), in the order of
// fit.free_parameters.
inline Eigen::VectorXd EstimationError(const FitResult& fit, const Eigen::Matrix3d& true_rotation,
                                       const Eigen::Vector3d& true_center, const Intrinsics& t) {
  constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
  const int p = static_cast<int>(fit.free_parameters.size());
  Eigen::VectorXd error(p);
  const Eigen::AngleAxisd omega_true(true_rotation *
                                     fit.camera.cam_from_world.rotation.transpose());
  error.head<3>() = -omega_true.angle() * omega_true.axis() * kDegPerRad;
  error.segment<3>(3) = CameraCenterInWorld(fit.camera.cam_from_world) - true_center;
  const Intrinsics& k = fit.camera.intrinsics;
  for (int j = 6; j < p; ++j) {
    const std::string& name = fit.free_parameters[j];
    if (name == "fx") error(j) = k.fx - t.fx;
    if (name == "fy") error(j) = k.fy - t.fy;
    if (name == "cx") error(j) = k.cx - t.cx;
    if (name == "cy") error(j) = k.cy - t.cy;
    if (name == "skew") error(j) = k.skew - t.skew;
    if (name == "k1") error(j) = k.k1 - t.k1;
    if (name == "k2") error(j) = k.k2 - t.k2;
  }
  return error;
}

// A noise-free fit of `points` / `pixels` (fitted with pixel_sigma = 1, so that its covariance
// is (J^T J)^-1) against the true camera: every free parameter within
// kFirstOrderMargin sigma_j(1 px) |r|_2 plus its output rounding, every intrinsic the fit did not
// estimate at the truth's value (as given) to kOutputRoundings unit roundoffs. EXPECTs each;
// returns the worst |e_j| / bound.
inline double ExpectWithinFirstOrderBound(const FitResult& fit,
                                          const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<Eigen::Vector2d>& pixels,
                                          const Eigen::Matrix3d& true_rotation,
                                          const Eigen::Vector3d& true_center,
                                          const Intrinsics& t, const std::string& label) {
  EXPECT_TRUE(fit.covariance_available) << label;
  if (!fit.covariance_available) return std::numeric_limits<double>::infinity();
  const Eigen::VectorXd e = EstimationError(fit, true_rotation, true_center, t);
  const double r = PerturbationNorm(points, pixels, true_rotation, true_center, t);
  double worst = 0.0;
  for (int j = 0; j < static_cast<int>(e.size()); ++j) {
    const double bound = kFirstOrderMargin * std::sqrt(fit.covariance(j, j)) * r +
                         OutputRounding(fit, true_center, points, j);
    EXPECT_LE(std::abs(e(j)), bound)
        << label << ": " << fit.free_parameters[j] << " (|r|_2 = " << r << ")";
    worst = std::max(worst, std::abs(e(j)) / bound);
  }
  // With the aspect not free, fy = aspect fx follows fx: check the aspect instead.
  const Intrinsics& k = fit.camera.intrinsics;
  auto is_free = [&](const char* name) {
    return std::find(fit.free_parameters.begin(), fit.free_parameters.end(), name) !=
           fit.free_parameters.end();
  };
  const double given = kOutputRoundings * kUnitRoundoff;
  if (!is_free("fx")) {
    EXPECT_NEAR(k.fx, t.fx, given * t.fx) << label << ": fx (not free)";
  }
  if (!is_free("fy")) {
    EXPECT_NEAR(k.fy / k.fx, t.fy / t.fx, given * t.fy / t.fx) << label << ": aspect (not free)";
  }
  if (!is_free("cx")) {
    EXPECT_NEAR(k.cx, t.cx, given * (std::abs(t.cx) + t.fx)) << label << ": cx (not free)";
  }
  if (!is_free("cy")) {
    EXPECT_NEAR(k.cy, t.cy, given * (std::abs(t.cy) + t.fy)) << label << ": cy (not free)";
  }
  if (!is_free("skew")) {
    EXPECT_NEAR(k.skew, t.skew, given * t.fx) << label << ": skew (not free)";
  }
  if (!is_free("k1")) {
    EXPECT_NEAR(k.k1, t.k1, given) << label << ": k1 (not free)";
  }
  if (!is_free("k2")) {
    EXPECT_NEAR(k.k2, t.k2, given) << label << ": k2 (not free)";
  }
  return worst;
}

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

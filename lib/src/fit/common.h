// Pieces both fitters (fit.cc with its stages in fit/, and fit/orthographic_fit.cc) and the
// model selection share (private).
#ifndef CAMPROJ_SRC_FIT_COMMON_H_
#define CAMPROJ_SRC_FIT_COMMON_H_

#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "fit/small_solve.h"

namespace camproj {
namespace internal {

// The fix of every refusal that finds the world frame left-handed (SceneError::fix).
inline constexpr char kFlipAnAxis[] =
    "Flip one world axis (e.g. negate Z of every point, and again in anything you render) and "
    "refit";

// The fix of a refusal for a numerical failure (SceneError::Reason::kNumerical).
inline constexpr char kReportNumericalFailure[] =
    "Please report it with the points file; meanwhile, extreme coordinates (subtract an offset, "
    "change units) or fixing intrinsics may avoid it";

// The perspective fitter's clock: FitResult::time_ms and the trace's elapsed times count from
// FitCamera's start.
using Clock = std::chrono::steady_clock;

inline double MicrosecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

// The mean of `points` (not empty): the normalized world's origin.
inline Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : points) centroid += x;
  return centroid / static_cast<double>(points.size());
}

// The midpoints of the image's four edges (left, right, top, bottom) moved outward by `beyond`
// image sizes, in kCenter px: the principal points the refinement restarts from where the closed
// form's says little (fit/refine.cc, fit/other_minima.cc).
inline std::vector<Eigen::Vector2d> EdgeMidpoints(const ImageSize& size, double beyond) {
  const double w = size.width;
  const double h = size.height;
  const double cx = 0.5 * (w - 1.0);  // the image centre
  const double cy = 0.5 * (h - 1.0);
  return {{-beyond * w - 0.5, cy}, {(1.0 + beyond) * w - 0.5, cy},
          {cx, -beyond * h - 0.5}, {cx, (1.0 + beyond) * h - 0.5}};
}

// The points with the world's z negated: the same scene seen through a mirror.
inline std::vector<Eigen::Vector3d> MirroredZ(std::vector<Eigen::Vector3d> points) {
  for (Eigen::Vector3d& x : points) x.z() = -x.z();
  return points;
}

// The RMS length of the rows of `centred` (points minus their centroid): the normalized world's
// scale. The squares are summed on the coordinates times a power of two (exact), so that they
// neither overflow above ~1e154 nor underflow below ~1e-154; elsewhere the result is bit for bit
// sqrt(squaredNorm / rows). 0 when every row is 0; not finite when a coordinate is not.
inline double RmsRowLength(const Eigen::MatrixXd& centred) {
  const double largest = centred.cwiseAbs().maxCoeff();
  if (!(largest > 0.0 && std::isfinite(largest))) return largest;
  const double unit = std::ldexp(1.0, -std::ilogb(largest));  // largest * unit in [1, 2)
  return std::sqrt((unit * centred).squaredNorm() / static_cast<double>(centred.rows())) / unit;
}

struct SceneGeometry;       // fit/scene.h
struct ChartLinearization;  // fit/normal_equations.h

// What a fit may leave out when the model selection only scores it (fit/candidate.h). The
// default leaves out nothing: every FitCamera call.
struct FitEffort {
  // Skip the refinement's restarts (from the image centre after a DLT start at few points;
  // from beyond the image's edges with radial distortion and the principal point free;
  // refine.cc) when the best fit's sum of squares is within the chi-square quantile at this
  // pixel sigma.
  std::optional<double> skip_restarts_when_consistent_at_px;
  // Check the covariance's linearization (FitResult::linearity; assess.cc).
  bool check_linearity = true;
  // Describe the camera: FitResult::views and, with options.compute_uncertainty, the covariance
  // and sigmas (assess.cc). A candidate's score reads its residuals and camera only.
  bool describe = true;
  // Start at this camera (fit/start.h, WarmStart) instead of the closed form, if not null.
  const Camera* warm_start = nullptr;
  // The correspondences already prepared (fit/scene.h, PrepareScene): the scene is made from
  // them instead of again from the points.
  const SceneGeometry* geometry = nullptr;
  // If not null, receives the answer's normal equations (AssessFit; perspective fits only).
  ChartLinearization* linearization = nullptr;
};

// J^T J with its columns scaled to a unit diagonal (Jacobi): its smallest over largest
// eigenvalue is the reciprocal condition the fitters refuse on (kDegenerate), and its inverse
// gives the covariance. `Matrix` is Eigen::MatrixXd or a fixed-capacity type. With
// Eigen::EigenvaluesOnly the eigenvectors (and Inverse) are not available; the eigenvalues, and
// so rcond, are the same bit for bit (Eigen's tridiagonal QR steps update the vectors alongside,
// never reading them), at about half the instructions.
template <typename Matrix>
struct JacobiScaledNormal {
  using Vector = Eigen::Matrix<double, Matrix::RowsAtCompileTime, 1, 0, Matrix::MaxRowsAtCompileTime, 1>;

  explicit JacobiScaledNormal(const Matrix& jtj, int eigen_options = Eigen::ComputeEigenvectors)
      : column_scale(jtj.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse()),
        eigen(Matrix(column_scale.asDiagonal() * jtj * column_scale.asDiagonal()), eigen_options),
        rcond(eigen.eigenvalues()(0) / eigen.eigenvalues()(jtj.rows() - 1)) {}

  // sqrt(largest / smallest eigenvalue): the scaled Jacobian's condition number.
  double JacobianCondition() const { return std::sqrt(1.0 / rcond); }

  // (J^T J)^-1, undoing the scaling.
  Matrix Inverse() const {
    return column_scale.asDiagonal() *
           Matrix(eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                  eigen.eigenvectors().transpose()) *
           column_scale.asDiagonal();
  }

  Vector column_scale;
  Eigen::SelfAdjointEigenSolver<Matrix> eigen;
  double rcond;
};

// X = L^-1 for the Jacobi-scaled S = D J^T J D = L L^T (D = diag(J^T J)^-1/2, so S has a unit
// diagonal): S^-1 = X^T X, and (J^T J)^-1 = W W^T with W = D X^T. Lower triangular, column by
// column (L x = e_j), by plain loops on the fixed-capacity storage (as fit/small_solve.h, whose
// Cholesky factors S). Nothing where a column has no effect (a zero diagonal) or S is not
// positive definite to rounding.
template <typename Matrix>
std::optional<Matrix> InverseCholeskyOfScaled(const Matrix& jtj) {
  const int p = static_cast<int>(jtj.rows());
  for (int j = 0; j < p; ++j) {
    if (!(jtj(j, j) > 0.0 && std::isfinite(jtj(j, j)))) return std::nullopt;
  }
  Matrix scaled(p, p);  // its lower triangle
  for (int j = 0; j < p; ++j) {
    scaled(j, j) = 1.0;
    for (int i = j + 1; i < p; ++i) scaled(i, j) = jtj(i, j) / std::sqrt(jtj(i, i) * jtj(j, j));
  }
  Matrix l;
  if (!FactorCholesky(scaled, &l)) return std::nullopt;
  Matrix x = Matrix::Zero(p, p);
  for (int j = 0; j < p; ++j) {
    for (int i = j; i < p; ++i) {
      double sum = i == j ? 1.0 : 0.0;
      for (int k = j; k < i; ++k) sum -= l(i, k) * x(k, j);
      x(i, j) = sum / l(i, i);
    }
  }
  return x;
}

// A lower bound on JacobiScaledNormal's rcond from InverseCholeskyOfScaled's X, without the
// eigenvalues: S's largest eigenvalue is at most trace S = p and its smallest at least
// 1 / trace(S^-1) = 1 / |X|_F^2, so rcond >= 1 / (p |X|_F^2), at most p^2 below it.
template <typename Matrix>
double ReciprocalConditionLowerBoundOf(const Matrix& inverse_cholesky) {
  const int p = static_cast<int>(inverse_cholesky.rows());
  double trace_of_inverse = 0.0;
  for (int j = 0; j < p; ++j) {
    for (int i = j; i < p; ++i) trace_of_inverse += inverse_cholesky(i, j) * inverse_cholesky(i, j);
  }
  if (!(trace_of_inverse > 0.0 && std::isfinite(trace_of_inverse))) return 0.0;
  return 1.0 / (static_cast<double>(p) * trace_of_inverse);
}

// The same from J^T J; 0 where S is not positive definite to rounding. About a tenth of the
// eigenvalues' instructions at 9 parameters.
template <typename Matrix>
double ReciprocalConditionLowerBound(const Matrix& jtj) {
  const std::optional<Matrix> x = InverseCholeskyOfScaled(jtj);
  return x ? ReciprocalConditionLowerBoundOf(*x) : 0.0;
}

// The pixel noise the covariance is scaled by: given, or sqrt(sum_squares / dof) (none when
// dof <= 0). Sets result->pixel_sigma and pixel_sigma_estimated; returns whether there is one.
inline bool SetPixelSigma(const FitOptions& options, double sum_squares, int dof,
                          FitResult* result) {
  if (options.pixel_sigma) {
    result->pixel_sigma = *options.pixel_sigma;
    result->pixel_sigma_estimated = false;
    return true;
  }
  if (dof <= 0) return false;
  result->pixel_sigma = std::sqrt(sum_squares / dof);
  return true;
}

// Every pair (a < b) whose |correlation| is at least `threshold`, named by `names` (the
// covariance's order).
inline std::vector<Correlation> StrongCorrelations(const Eigen::MatrixXd& covariance,
                                                   const std::vector<std::string>& names,
                                                   double threshold) {
  std::vector<Correlation> strong;
  for (int a = 0; a < covariance.rows(); ++a) {
    for (int b = a + 1; b < covariance.rows(); ++b) {
      const double rho = covariance(a, b) / std::sqrt(covariance(a, a) * covariance(b, b));
      if (std::abs(rho) >= threshold) strong.push_back({names[a], names[b], rho});
    }
  }
  return strong;
}

// Predicted - observed pixel (observed in `origin`, the result in kCenter px) of every point
// against `camera`; infinite for a point behind it. For reporting RANSAC's outliers too.
inline std::vector<Eigen::Vector2d> ResidualsAgainst(const Camera& camera,
                                                     const std::vector<Eigen::Vector3d>& points,
                                                     const std::vector<Eigen::Vector2d>& observed,
                                                     PixelOrigin origin) {
  const double shift = PixelOriginShift(origin, PixelOrigin::kCenter);
  std::vector<Eigen::Vector2d> residuals(points.size(), Eigen::Vector2d::Constant(
                                                            std::numeric_limits<double>::infinity()));
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Eigen::Vector2d> predicted = PixelFromWorld(camera, points[i]);
    if (predicted) residuals[i] = *predicted - (observed[i] + Eigen::Vector2d(shift, shift));
  }
  return residuals;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_COMMON_H_

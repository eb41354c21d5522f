#include "fit/pixel_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>

#include "camproj/intrinsics.h"
#include "camproj/pose.h"
#include "check.h"
#include "fit/common.h"
#include "fit/reprojection_error.h"

namespace camproj {
namespace internal {

namespace {

// Reciprocal condition of the Jacobi-scaled J^T J below which a direction is taken as not
// determined (the fitter refuses at 1e-12; this only guards the inverse).
constexpr double kSingularRcond = 1e-14;

using Parameter = PixelParameter;

// The parameters `model` frees at `camera`. An orthographic camera is the limit of perspective
// cameras whose distance grows with their focal length; it answers for the scene only if the
// points show that limit is reached, so its uncertainty has the perspective strength free too:
// pixel = c + (u_ortho - c) / (1 + e z_cam), judged at e = 0. Where the points do not determine
// e (too little depth spread against the distance for their noise), no orthographic camera is
// determined either.
std::vector<Parameter> ParametersOf(const Camera& camera, const FitOptions& model) {
  std::vector<Parameter> params;
  for (int a = 0; a < 3; ++a) params.push_back({Parameter::kRotation, a});
  // An orthographic image does not change when the eye moves along the gaze.
  const bool orthographic = camera.projection == Projection::kOrthographic;
  for (int a = 0; a < (orthographic ? 2 : 3); ++a) params.push_back({Parameter::kEye, a});
  if (orthographic) params.push_back({Parameter::kPerspective});
  if (model.known_intrinsics) return params;
  if (model.focal.IsFree()) params.push_back({Parameter::kFocal});
  if (model.aspect.IsFree()) params.push_back({Parameter::kAspect});
  if (model.principal_point.IsFree()) {
    params.push_back({Parameter::kCx});
    params.push_back({Parameter::kCy});
  }
  if (model.skew.IsFree()) params.push_back({Parameter::kSkew});
  if (model.k1.IsFree()) params.push_back({Parameter::kK1});
  if (model.k2.IsFree()) params.push_back({Parameter::kK2});
  return params;
}

// d pixel / d parameter (2 x params) at every point, analytic; rows 2i, 2i+1 for point i.
// Returns the index of the first point not in front of the camera, if any; the Jacobian is then
// incomplete. A kPerspective column (orthographic) is -(pixel - principal point) * z_cam /
// length_scale: the derivative at e = 0 of pixel = c + (u_ortho - c) / (1 + e z_cam) per unit of
// e * length_scale.
// `Matrix`: Eigen::MatrixXd, or a 2 x params matrix for one point.
template <typename Matrix>
std::optional<size_t> PixelJacobian(const PixelLinearization& at, const Eigen::Vector3d* points,
                                    size_t count, Matrix* jacobian) {
  const Intrinsics& k = at.camera.intrinsics;
  const bool orthographic = at.camera.projection == Projection::kOrthographic;
  jacobian->resize(2 * count, at.params.size());
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d p = at.camera.cam_from_world * points[i];
    if (!(p.z() > 0.0)) return i;
    // d pixel / d point_in_cam, and the pixel's parts the intrinsics scale.
    Eigen::Matrix<double, 2, 3> by_point;
    Eigen::Vector2d scaled;  // (fx xd, fy yd): what fx and fy multiply
    Eigen::Vector2d sheared;  // (yd, 0): what skew multiplies
    Eigen::Vector2d by_k1 = Eigen::Vector2d::Zero();
    Eigen::Vector2d by_k2 = Eigen::Vector2d::Zero();
    if (orthographic) {
      by_point << k.fx, k.skew, 0.0, 0.0, k.fy, 0.0;
      scaled << k.fx * p.x(), k.fy * p.y();
      sheared << p.y(), 0.0;
    } else {
      // pixel = (fx xd + skew yd + cx, fy yd + cy), (xd, yd) = d (x, y), d = 1 + k1 r2 + k2 r2^2.
      const double x = p.x() / p.z();
      const double y = p.y() / p.z();
      const double r2 = x * x + y * y;
      const double d = 1.0 + r2 * (k.k1 + r2 * k.k2);
      const double g = 2.0 * (k.k1 + 2.0 * k.k2 * r2);  // d d / d r2, times 2
      Eigen::Matrix2d distorted_by_normalized;  // d (xd, yd) / d (x, y)
      distorted_by_normalized << d + g * x * x, g * x * y, g * x * y, d + g * y * y;
      Eigen::Matrix2d pixel_by_distorted;
      pixel_by_distorted << k.fx, k.skew, 0.0, k.fy;
      Eigen::Matrix<double, 2, 3> normalized_by_point;
      normalized_by_point << 1.0, 0.0, -x, 0.0, 1.0, -y;
      by_point = pixel_by_distorted * distorted_by_normalized * normalized_by_point / p.z();
      scaled << k.fx * d * x, k.fy * d * y;
      sheared << d * y, 0.0;
      by_k1 = pixel_by_distorted * Eigen::Vector2d(x, y) * r2;
      by_k2 = by_k1 * r2;
    }
    // The pose's columns (ParametersOf puts them first): by_point times e_a x p, a turn about
    // camera axis a, and times -length_scale e_a, a step of the eye along it.
    auto set = [&](int j, const Eigen::Vector2d& column) {
      (*jacobian)(2 * i, j) = column.x();
      (*jacobian)(2 * i + 1, j) = column.y();
    };
    const Eigen::Vector2d b0 = by_point.col(0);
    const Eigen::Vector2d b1 = by_point.col(1);
    const Eigen::Vector2d b2 = by_point.col(2);
    set(0, b1 * -p.z() + b2 * p.y());
    set(1, b2 * -p.x() + b0 * p.z());
    set(2, b0 * -p.y() + b1 * p.x());
    const double step = -at.length_scale;
    set(3, b0 * step);
    set(4, b1 * step);
    if (!orthographic) set(5, b2 * step);
    for (size_t j = at.pose_columns; j < at.params.size(); ++j) {
      Eigen::Vector2d column = Eigen::Vector2d::Zero();  // every kind sets it below
      switch (at.params[j].kind) {
        case Parameter::kRotation:
        case Parameter::kEye: break;  // above
        case Parameter::kFocal: column = scaled; break;
        case Parameter::kAspect: column << 0.0, scaled.y(); break;
        case Parameter::kCx: column << k.fx, 0.0; break;
        case Parameter::kCy: column << 0.0, k.fx; break;
        case Parameter::kSkew: column = k.fx * sheared; break;
        case Parameter::kK1: column = by_k1; break;
        case Parameter::kK2: column = by_k2; break;
        case Parameter::kPerspective: {
          const Eigen::Vector2d pixel(k.fx * p.x() + k.skew * p.y() + k.cx, k.fy * p.y() + k.cy);
          column = -(pixel - Eigen::Vector2d(k.cx, k.cy)) * (p.z() / at.length_scale);
          break;
        }
      }
      set(static_cast<int>(j), column);
    }
  }
  return std::nullopt;
}

// Up to this many fitted points PixelUncertainty keeps J (2 x 16 doubles per point at most:
// 1 MB here), and a fitted point's rows are read, not recomputed: the determination check asks
// for every fitted point's rows once per model it judges (its sigma there, its hat block), and
// at 100 points recomputing them was 5 % of the default path (bench --stage-cost).
constexpr size_t kKeptJacobianPoints = 4096;

// lower += J^T J's lower triangle, row by row. At the determination check's sizes (2N rows of at
// most 16 columns, N from 6) Eigen's symmetric rank update goes through its blocked product, a
// twelfth of the determination check at 12 points (bench --stage-cost: the default path 0.3 /
// 0.8 / 1.0 % fewer instructions at 6 / 8 / 12 points with these loops; at 20 points and more
// the fitted models' own normal equations serve instead).
void AddLowerProducts(const Eigen::MatrixXd& jacobian, Eigen::MatrixXd* lower) {
  const int p = static_cast<int>(jacobian.cols());
  for (int a = 0; a < p; ++a) {
    for (int b = 0; b <= a; ++b) {
      (*lower)(a, b) += jacobian.col(a).dot(jacobian.col(b));
    }
  }
}

}  // namespace

PixelUncertainty::PixelUncertainty(const Camera& camera, const FitOptions& model,
                                   const std::vector<Eigen::Vector3d>& fitted_points,
                                   double sigma_px, bool mirrored_z)
    : sigma_px_(sigma_px), fitted_(&fitted_points), mirrored_z_(mirrored_z) {
  Require(!fitted_points.empty(), "no fitted points");
  const std::vector<Parameter> params = ParametersOf(camera, model);
  Require(params.size() <= static_cast<size_t>(kMaxParameters), "too many parameters: ",
          params.size());
  // The eye's step scale: the median distance from the eye to the fitted points.
  const Eigen::Vector3d eye = CameraCenterInWorld(camera.cam_from_world);
  std::vector<double> distances;
  distances.reserve(fitted_points.size());
  for (size_t i = 0; i < fitted_points.size(); ++i) distances.push_back((Fitted(i) - eye).norm());
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double length_scale = std::max(distances[distances.size() / 2], 1e-300);
  at_.camera = camera;
  at_.length_scale = length_scale;
  at_.params = params;
  at_.pose_columns = camera.projection == Projection::kOrthographic ? 5 : 6;

  constexpr size_t kBlock = 256;  // points per block of J: large enough for a blocked product
  const size_t count = fitted_points.size();
  if (count <= kKeptJacobianPoints) jacobian_.resize(2 * count, params.size());
  // J^T J's lower triangle (a symmetric rank update per block: half the products).
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(params.size(), params.size());
  std::vector<Eigen::Vector3d> block;
  Eigen::MatrixXd block_jacobian;
  for (size_t begin = 0; begin < count; begin += kBlock) {
    block.clear();
    for (size_t i = begin; i < std::min(begin + kBlock, count); ++i) block.push_back(Fitted(i));
    const std::optional<size_t> behind =
        PixelJacobian(at_, block.data(), block.size(), &block_jacobian);
    Require(!behind, "point ", begin + behind.value_or(0), " is not in front of the camera");
    AddLowerProducts(block_jacobian, &lower);
    if (jacobian_.size() > 0) {
      jacobian_.middleRows(2 * begin, block_jacobian.rows()) = block_jacobian;
    }
  }
  SetWhitening(lower.selfadjointView<Eigen::Lower>());
}

PixelUncertainty::PixelUncertainty(const ChartLinearization& chart, const Eigen::Vector3d& origin,
                                   double unit, const std::vector<Eigen::Vector3d>& fitted_points,
                                   double sigma_px)
    : sigma_px_(sigma_px), fitted_(&fitted_points), chart_(&chart), origin_(origin), unit_(unit),
      radial_only_(RadialOnly(chart.model.value.data()) && !chart.model.free[7] &&
                   !chart.model.free[8] && !chart.model.free[9]) {
  Require(!fitted_points.empty(), "no fitted points");
  for (size_t i = 0; i < fitted_points.size(); ++i) {
    Require(InChart(fitted_points[i]).z() > 0.0, "point ", i, " is not in front of the camera");
  }
  SetWhitening(Eigen::MatrixXd(chart.jtj));
}

double PixelUncertainty::SigmaAt(const Eigen::Vector3d& x) const {
  const double infinity = std::numeric_limits<double>::infinity();
  if (singular_) return infinity;
  if (chart_ != nullptr) {
    const std::optional<PointRows> rows = ChartRows(x);
    return rows ? SigmaOf(*rows) : infinity;
  }
  PointRows jacobian;
  try {
    if (PixelJacobian(at_, &x, 1, &jacobian)) return infinity;
  } catch (const std::invalid_argument&) {
    return infinity;
  }
  return SigmaOf(jacobian);
}

Eigen::Matrix2d PixelUncertainty::HatAt(size_t i) const {
  if (singular_) return Eigen::Matrix2d::Identity();
  const PointRows rows = Whitened(FittedRows(i));
  return rows * rows.transpose();
}

double PixelUncertainty::HatQuadratic(const std::vector<Eigen::Vector2d>& residuals) const {
  if (singular_) return 0.0;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxParameters, 1> gradient =
      Eigen::VectorXd::Zero(whitening_.rows());
  for (size_t i = 0; i < residuals.size(); ++i) {
    gradient.noalias() += FittedRows(i).transpose() * residuals[i];
  }
  return whitening_.transpose().lazyProduct(gradient).squaredNorm();
}

// SigmaAt of fitted point i (J's rows 2i, 2i+1; in front of the camera, as the constructor
// checked).
double PixelUncertainty::SigmaAtFitted(size_t i) const {
  if (singular_) return std::numeric_limits<double>::infinity();
  return SigmaOf(FittedRows(i));
}

double PixelUncertainty::SigmaAndHatAtFitted(size_t i, Eigen::Matrix2d* hat) const {
  if (singular_) {
    *hat = Eigen::Matrix2d::Identity();
    return std::numeric_limits<double>::infinity();
  }
  const PointRows whitened = Whitened(FittedRows(i));
  *hat = whitened * whitened.transpose();
  return sigma_px_ * std::sqrt(whitened.squaredNorm());
}

// The private helpers below are inline: the queries above call them once per point, and with
// the external linkage of out-of-line members GCC stopped inlining them (0.7 % more instructions
// for the default path at 100 points, bench --stage-cost).
inline Eigen::Vector3d PixelUncertainty::Fitted(size_t i) const {
  Eigen::Vector3d x = (*fitted_)[i];
  if (mirrored_z_) x.z() = -x.z();
  return x;
}

// Rows 2i, 2i + 1 of J: kept, or recomputed (the same numbers).
inline PixelUncertainty::PointRows PixelUncertainty::FittedRows(size_t i) const {
  if (chart_ != nullptr) return *ChartRows((*fitted_)[i]);  // in front: the constructor checked
  if (jacobian_.size() > 0) return jacobian_.middleRows<2>(2 * i);
  const Eigen::Vector3d x = Fitted(i);
  PointRows jacobian;
  PixelJacobian(at_, &x, 1, &jacobian);
  return jacobian;
}

// W from J^T J: Jacobi scaling (the parameters' units differ by orders of magnitude), then the
// inverse through the Cholesky factor where its bound clears kSingularRcond by kBoundMargin
// (fit/common.h, InverseCholeskyOfScaled: W = D X^T), else through the eigen-decomposition,
// refusing near-singular directions.
void PixelUncertainty::SetWhitening(const Eigen::MatrixXd& normal) {
  constexpr double kBoundMargin = 1e3;
  const Eigen::VectorXd d_inverse = normal.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse();
  const std::optional<ParameterMatrix> inverse_cholesky =
      InverseCholeskyOfScaled(ParameterMatrix(normal));
  if (inverse_cholesky && ReciprocalConditionLowerBoundOf(*inverse_cholesky) >
                              kBoundMargin * kSingularRcond) {
    whitening_ = d_inverse.asDiagonal() * inverse_cholesky->transpose();
    upper_triangular_ = true;
    return;
  }
  const Eigen::MatrixXd scaled = d_inverse.asDiagonal() * normal * d_inverse.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  const Eigen::VectorXd values = eigen.eigenvalues();
  singular_ = !(values(0) > kSingularRcond * values(values.size() - 1));
  if (singular_) return;
  // (J^T J)^-1 = W W^T with W = D^-1 V L^-1/2 (scaled = V L V^T): a point's variance is the
  // squared norm of J_x W.
  whitening_ = d_inverse.asDiagonal() * eigen.eigenvectors() *
               values.cwiseSqrt().cwiseInverse().asDiagonal();
}

// The Jacobian's rows at `x` (unit world) in the chart of chart_ (ComputeNormalEquations'
// columns: p x a for the turns, -a R for the centre, then the free slots' columns, with a the
// residual's derivative by the camera point p); nothing where x is not in front of the camera.
inline std::optional<PixelUncertainty::PointRows> PixelUncertainty::ChartRows(
    const Eigen::Vector3d& x) const {
  const ChartLinearization& at = *chart_;
  const Eigen::Vector3d p = InChart(x);
  if (!(p.z() > 0.0)) return std::nullopt;
  double residual[2];
  double jk[2 * kFitIntrinsicsSize];
  double jp[6];
  if (radial_only_) {
    ResidualOfCamPoint<true>(at.model.value.data(), p, Eigen::Vector2d::Zero(), residual, jk,
                             jp);
  } else {
    ResidualOfCamPoint<false>(at.model.value.data(), p, Eigen::Vector2d::Zero(), residual, jk,
                              jp);
  }
  PointRows rows(2, 6 + at.model.NumFree());
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d a(jp[3 * k], jp[3 * k + 1], jp[3 * k + 2]);
    rows.block<1, 3>(k, 0) = p.cross(a).transpose();
    rows.block<1, 3>(k, 3) = -(at.rotation.transpose() * a).transpose();
    int column = 6;
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (at.model.free[slot]) rows(k, column++) = jk[k * kFitIntrinsicsSize + slot];
    }
  }
  return rows;
}

// `x` (unit world) as chart_'s camera sees it.
inline Eigen::Vector3d PixelUncertainty::InChart(const Eigen::Vector3d& x) const {
  const ChartLinearization& at = *chart_;
  return at.rotation * ((origin_ + unit_ * x - at.centroid) / at.scale - at.center);
}

// A point's rows times W: where W is upper triangular (the Cholesky path), without the
// products with its zeros (p (p + 1) of the 2 p^2 multiply-adds).
inline PixelUncertainty::PointRows PixelUncertainty::Whitened(const PointRows& rows) const {
  if (!upper_triangular_) return rows.lazyProduct(whitening_);
  const int p = static_cast<int>(whitening_.cols());
  PointRows whitened(2, p);
  for (int j = 0; j < p; ++j) {
    double first = 0.0;
    double second = 0.0;
    for (int k = 0; k <= j; ++k) {
      first += rows(0, k) * whitening_(k, j);
      second += rows(1, k) * whitening_(k, j);
    }
    whitened(0, j) = first;
    whitened(1, j) = second;
  }
  return whitened;
}

// The 1-sigma length of a point's reprojection error from its Jacobian (2 x params).
inline double PixelUncertainty::SigmaOf(const PointRows& jacobian) const {
  return sigma_px_ * std::sqrt(Whitened(jacobian).squaredNorm());
}

}  // namespace internal
}  // namespace camproj

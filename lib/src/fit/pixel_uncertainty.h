// The uncertainty of a fitted camera's pixels (private; the determination check's measure,
// fit/determination.h): the linearized 1-sigma length of a point's reprojection error,
// sigma_px sqrt(trace(J_x (J^T J)^-1 J_x^T)), J the Jacobian of the fitted points' pixels and J_x
// the point's, with respect to the parameters the model frees; and the hat matrix's blocks at the
// fitted points (how much a point's own pixel moves its prediction). Prepared once per camera:
// a query then costs one point's Jacobian.
#ifndef CAMPROJ_SRC_FIT_PIXEL_UNCERTAINTY_H_
#define CAMPROJ_SRC_FIT_PIXEL_UNCERTAINTY_H_

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "fit/normal_equations.h"

namespace camproj {
namespace internal {

// One parameter a model frees, as the uncertainty linearizes it (pixel_uncertainty.cc,
// ParametersOf). kPerspective: an orthographic camera's perspective strength.
struct PixelParameter {
  enum Kind { kRotation, kEye, kFocal, kAspect, kCx, kCy, kSkew, kK1, kK2, kPerspective };
  Kind kind;
  int axis = 0;  // kRotation, kEye: the camera axis
};

// A camera linearized along `params`: the rotation turns about the camera's own axes
// (R -> exp([a e]x) R), the eye moves along them in units of length_scale, the focal length and
// aspect scale (fx, fy by 1 + a; fy by 1 + a), the principal point and skew move by a * fx, k1
// and k2 by a.
struct PixelLinearization {
  Camera camera;
  double length_scale = 1.0;
  std::vector<PixelParameter> params;
  // The pose's parameters, first in params: 3 turns, then 3 eye steps (2 for an orthographic
  // camera, which does not see a step along its gaze).
  size_t pose_columns = 6;
};

// Beyond a few thousand fitted points (kKeptJacobianPoints, pixel_uncertainty.cc) J is not held
// whole: J^T J is summed over blocks of points, and a fitted point's rows are recomputed where
// they are asked for, so the memory does not grow with the points (at a million points J alone
// would be ~100 MB).
class PixelUncertainty {
 public:
  // At `camera` with the parameters `model` frees (an orthographic camera's perspective strength
  // too: it answers for the scene only if the points show the perspective is gone).
  // `fitted_points` (with z negated if mirrored_z) must outlive this object. Throws
  // std::invalid_argument if a fitted point is not in front of the camera.
  PixelUncertainty(const Camera& camera, const FitOptions& model,
                   const std::vector<Eigen::Vector3d>& fitted_points, double sigma_px,
                   bool mirrored_z = false);

  // From a fit's own normal equations at its answer (the selection's rivals: `chart`, which must
  // outlive this object) instead of a pass over the points: the same sigmas, to the step between
  // those normal equations and the answer (a point's sigma does not depend on the
  // parameterization). `origin` and `unit` map the unit world of `fitted_points` and of the points
  // asked about to the world (origin + unit * y). Throws std::invalid_argument if a fitted point
  // is not in front of the camera.
  PixelUncertainty(const ChartLinearization& chart, const Eigen::Vector3d& origin, double unit,
                   const std::vector<Eigen::Vector3d>& fitted_points, double sigma_px);

  // The 1-sigma length of the reprojection error of `x`; +inf where J^T J is singular or `x` is
  // at the camera's plane (no pixel to be sure of).
  double SigmaAt(const Eigen::Vector3d& x) const;

  // The 2x2 block of the hat matrix J (J^T J)^-1 J^T at fitted point i: how much its own pixel
  // moves its prediction (identity where J^T J is singular).
  Eigen::Matrix2d HatAt(size_t i) const;

  // r^T H r with H = J (J^T J)^-1 J^T, r the fitted points' residuals (pixel minus observed, in
  // the order of fitted_points): by how much a Gauss-Newton step with every parameter free
  // lowers their sum of squares. 0 where J^T J is singular.
  double HatQuadratic(const std::vector<Eigen::Vector2d>& residuals) const;

  // SigmaAt of fitted point i.
  double SigmaAtFitted(size_t i) const;

  // SigmaAtFitted(i) and HatAt(i) from one evaluation of its rows (the same numbers).
  double SigmaAndHatAtFitted(size_t i, Eigen::Matrix2d* hat) const;

  // At least every parameter either constructor frees: the pose's 6 and a fit's 10 intrinsic
  // slots (from its normal equations); the pose's 5 or 6, the perspective strength and 7
  // intrinsics (from a camera and a model).
  static constexpr int kMaxParameters = 16;

 private:
  // One point's rows of the Jacobian (2 x params), on the stack.
  using PointRows = Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxParameters>;
  using ParameterMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxParameters, kMaxParameters>;

  // Inline (defined in the .cc, called only there): once per point.
  inline Eigen::Vector3d Fitted(size_t i) const;
  inline PointRows FittedRows(size_t i) const;
  void SetWhitening(const Eigen::MatrixXd& normal);
  inline std::optional<PointRows> ChartRows(const Eigen::Vector3d& x) const;
  inline Eigen::Vector3d InChart(const Eigen::Vector3d& x) const;
  inline PointRows Whitened(const PointRows& rows) const;
  inline double SigmaOf(const PointRows& jacobian) const;

  double sigma_px_;
  const std::vector<Eigen::Vector3d>* fitted_;
  bool mirrored_z_ = false;
  PixelLinearization at_;
  Eigen::MatrixXd jacobian_;   // J (2 rows per fitted point), empty beyond kKeptJacobianPoints
  // Set by the constructor from a fit's normal equations (at_ and jacobian_ then unused).
  const ChartLinearization* chart_ = nullptr;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // the unit world's, in the world
  double unit_ = 1.0;
  // chart_'s model has no tangential distortion or k3 and frees none (ResidualOfCamPoint<true>,
  // which writes no column for them).
  bool radial_only_ = false;
  ParameterMatrix whitening_;  // W: (J^T J)^-1 = W W^T
  bool upper_triangular_ = false;  // W = D X^T (the Cholesky path), else dense
  bool singular_ = false;
};

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_PIXEL_UNCERTAINTY_H_

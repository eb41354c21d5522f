#include "fit/determination.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "camproj/conventions.h"
#include "camproj/pose.h"
#include "check.h"
#include "fit/common.h"
#include "fit/gate.h"

namespace camproj {
namespace internal {

namespace {

// Reciprocal condition of the Jacobi-scaled J^T J below which a direction is taken as not
// determined (the fitter refuses at 1e-12; this only guards the inverse).
constexpr double kSingularRcond = 1e-14;
// Central-difference steps, relative to each parameter's natural scale: the truncation error is
// O(step^2), far below what an uncertainty needs.
constexpr double kStep = 1e-6;
// A rival's shift of a test point counts beyond this many of its own sigmas there.
constexpr double kRivalSigmas = 3.0;

enum Kind { kRotation, kEye, kFocal, kAspect, kCx, kCy, kSkew, kK1, kK2 };

struct Parameter {
  Kind kind;
  int axis = 0;  // kRotation, kEye: the camera axis
};

std::vector<Parameter> ParametersOf(const Camera& camera, const FitOptions& model) {
  std::vector<Parameter> params;
  for (int a = 0; a < 3; ++a) params.push_back({kRotation, a});
  // An orthographic image does not change when the eye moves along the gaze.
  const int eye_axes = camera.projection == Projection::kOrthographic ? 2 : 3;
  for (int a = 0; a < eye_axes; ++a) params.push_back({kEye, a});
  if (model.known_intrinsics) return params;
  if (model.focal.IsFree()) params.push_back({kFocal});
  if (model.aspect.IsFree()) params.push_back({kAspect});
  if (model.principal_point.IsFree()) {
    params.push_back({kCx});
    params.push_back({kCy});
  }
  if (model.skew.IsFree()) params.push_back({kSkew});
  if (model.k1.IsFree()) params.push_back({kK1});
  if (model.k2.IsFree()) params.push_back({kK2});
  return params;
}

// `camera` moved by `amount` (in the parameter's step units) along one parameter; the eye and the
// rotation move about and along the camera's own axes.
Camera Moved(const Camera& camera, const Parameter& p, double amount, double length_scale) {
  Camera moved = camera;
  const Eigen::Matrix3d& r = camera.cam_from_world.rotation;
  const Eigen::Vector3d eye = CameraCenterInWorld(camera.cam_from_world);
  Intrinsics& k = moved.intrinsics;
  const double f = camera.intrinsics.fx;
  switch (p.kind) {
    case kRotation: {
      const Eigen::Matrix3d turn =
          Eigen::AngleAxisd(amount, Eigen::Vector3d::Unit(p.axis)).toRotationMatrix();
      moved.cam_from_world = CamFromWorldFromCenter(turn * r, eye);
      break;
    }
    case kEye:
      moved.cam_from_world = CamFromWorldFromCenter(
          r, eye + r.transpose() * (amount * length_scale * Eigen::Vector3d::Unit(p.axis)));
      break;
    case kFocal:
      k.fx *= 1.0 + amount;
      k.fy *= 1.0 + amount;
      break;
    case kAspect: k.fy *= 1.0 + amount; break;
    case kCx: k.cx += amount * f; break;
    case kCy: k.cy += amount * f; break;
    case kSkew: k.skew += amount * f; break;
    case kK1: k.k1 += amount; break;
    case kK2: k.k2 += amount; break;
  }
  return moved;
}

// d pixel / d parameter (2 x params) at every point, by central differences; rows 2i, 2i+1 for
// point i. Throws if a point is not in front of a moved camera.
Eigen::MatrixXd PixelJacobian(const Camera& camera, const std::vector<Parameter>& params,
                              const std::vector<Eigen::Vector3d>& points, double length_scale) {
  Eigen::MatrixXd jacobian(2 * points.size(), params.size());
  for (size_t j = 0; j < params.size(); ++j) {
    const Camera plus = Moved(camera, params[j], kStep, length_scale);
    const Camera minus = Moved(camera, params[j], -kStep, length_scale);
    for (size_t i = 0; i < points.size(); ++i) {
      const std::optional<Eigen::Vector2d> a = PixelFromWorld(plus, points[i]);
      const std::optional<Eigen::Vector2d> b = PixelFromWorld(minus, points[i]);
      Require(a && b, "point ", i, " is not in front of the camera");
      jacobian.block<2, 1>(2 * i, j) = (*a - *b) / (2.0 * kStep);
    }
  }
  return jacobian;
}

// `camera` for the world point_in_world = origin + unit * y: the same pixel for y as `camera`
// gives for the point. (Perspective: the cam-frame point scales by unit, which a pinhole does not
// see; orthographic: fx, fy and skew are px per world unit.)
Camera InUnitWorld(const Camera& camera, const Eigen::Vector3d& origin, double unit) {
  Camera moved = camera;
  moved.cam_from_world.translation = (camera.cam_from_world * origin) / unit;
  moved.z_near /= unit;
  moved.z_far /= unit;
  if (camera.projection == Projection::kOrthographic) {
    moved.intrinsics.fx *= unit;
    moved.intrinsics.fy *= unit;
    moved.intrinsics.skew *= unit;
  }
  return moved;
}

}  // namespace

std::vector<Eigen::Vector3d> SceneTestPoints(const Camera& camera,
                                             const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> candidates = points;
  if (!points.empty()) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : points) mean += x;
    mean /= static_cast<double>(points.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& x : points) scatter += (x - mean) * (x - mean).transpose();
    const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3d& x : points) {
      const Eigen::Vector3d c = axes.transpose() * (x - mean);
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    const Eigen::Vector3d mid = 0.5 * (lo + hi);
    for (int bits = 0; bits < 8; ++bits) {  // corners
      const Eigen::Vector3d c((bits & 1) ? hi.x() : lo.x(), (bits & 2) ? hi.y() : lo.y(),
                              (bits & 4) ? hi.z() : lo.z());
      candidates.push_back(mean + axes * c);
    }
    for (int axis = 0; axis < 3; ++axis) {  // face centres
      for (const double side : {lo(axis), hi(axis)}) {
        Eigen::Vector3d c = mid;
        c(axis) = side;
        candidates.push_back(mean + axes * c);
      }
    }
  }
  std::vector<Eigen::Vector3d> inside;
  for (const Eigen::Vector3d& x : candidates) {
    const std::optional<Eigen::Vector2d> u = PixelFromWorld(camera, x);
    if (u && u->x() >= -0.5 && u->x() <= camera.image_size.width - 0.5 && u->y() >= -0.5 &&
        u->y() <= camera.image_size.height - 0.5) {
      inside.push_back(x);
    }
  }
  return inside;
}

std::vector<double> ReprojectionSigmaPx(const Camera& camera, const FitOptions& model,
                                        const std::vector<Eigen::Vector3d>& fitted_points,
                                        double sigma_px,
                                        const std::vector<Eigen::Vector3d>& test_points) {
  Require(!fitted_points.empty(), "no fitted points");
  const std::vector<Parameter> params = ParametersOf(camera, model);
  // The eye's step scale: the median distance from the eye to the fitted points.
  const Eigen::Vector3d eye = CameraCenterInWorld(camera.cam_from_world);
  std::vector<double> distances;
  for (const Eigen::Vector3d& x : fitted_points) distances.push_back((x - eye).norm());
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const double length_scale = std::max(distances[distances.size() / 2], 1e-300);

  const Eigen::MatrixXd jacobian = PixelJacobian(camera, params, fitted_points, length_scale);
  const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
  // Jacobi scaling (the parameters' units differ by orders of magnitude), then the inverse
  // through the eigen-decomposition, refusing near-singular directions.
  const Eigen::VectorXd d = normal.diagonal().cwiseSqrt().cwiseMax(1e-300);
  const Eigen::MatrixXd scaled = d.cwiseInverse().asDiagonal() * normal * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  const Eigen::VectorXd values = eigen.eigenvalues();
  const double infinity = std::numeric_limits<double>::infinity();
  if (!(values(0) > kSingularRcond * values(values.size() - 1))) {
    return std::vector<double>(test_points.size(), infinity);
  }
  const Eigen::MatrixXd scaled_inverse =
      eigen.eigenvectors() * values.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();

  std::vector<double> sigmas;
  sigmas.reserve(test_points.size());
  for (const Eigen::Vector3d& x : test_points) {
    Eigen::MatrixXd jx;
    try {
      jx = PixelJacobian(camera, params, {x}, length_scale) * d.cwiseInverse().asDiagonal();
    } catch (const std::invalid_argument&) {
      sigmas.push_back(infinity);  // at the camera's plane: no pixel to be sure of
      continue;
    }
    const double variance = (jx * scaled_inverse * jx.transpose()).trace();
    sigmas.push_back(sigma_px * std::sqrt(std::max(0.0, variance)));
  }
  return sigmas;
}

DeterminationCheck CheckDetermination(const Selection& selection,
                                      const std::vector<Eigen::Vector3d>& kept_points,
                                      const AutoFitOptions& options) {
  DeterminationCheck check;
  check.checked = true;
  check.bound_px = options.max_uncertainty_px;
  // Everything below in the points' centred, unit-RMS world (as the fitter's): in world units
  // the squared lengths overflow or underflow beyond ~1e+-154, and at an offset of 1e10 scene
  // sizes the finite-difference steps (1e-6 of the scene) fall below the coordinates' rounding.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : kept_points) origin += x;
  origin /= static_cast<double>(kept_points.size());
  Eigen::MatrixXd centred(kept_points.size(), 3);
  for (size_t i = 0; i < kept_points.size(); ++i) {
    centred.row(i) = (kept_points[i] - origin).transpose();
  }
  const double unit = RmsRowLength(centred);
  std::vector<Eigen::Vector3d> points(kept_points.size());
  for (size_t i = 0; i < kept_points.size(); ++i) points[i] = centred.row(i).transpose() / unit;
  const Camera camera = InUnitWorld(selection.fit.camera, origin, unit);
  std::vector<Eigen::Vector3d> test = SceneTestPoints(camera, points);
  if (test.empty()) test = points;  // none in the image: judge the points themselves
  const double sigma = selection.options.pixel_sigma.value_or(selection.sigma_px);
  const std::vector<double> sigmas =
      ReprojectionSigmaPx(camera, selection.options, points, sigma, test);
  for (size_t i = 0; i < test.size(); ++i) {
    if (!(sigmas[i] <= check.max_sigma_px)) {
      check.max_sigma_px = sigmas[i];
      check.worst_pixel = *PixelFromWorld(camera, test[i]);
    }
  }
  for (const Rival& rival : selection.rivals) {
    if (!(std::abs(rival.criterion - selection.criterion) <= kEqualFitCriterion)) continue;
    // A richer rival scatters by its own uncertainty: only a shift beyond kRivalSigmas of it
    // is a different reading of the data rather than the rival's noise.
    const Camera rival_camera = InUnitWorld(rival.camera, origin, unit);
    std::vector<double> rival_sigmas;
    try {
      rival_sigmas = ReprojectionSigmaPx(rival_camera, rival.options, points, sigma, test);
    } catch (const std::invalid_argument&) {
      continue;  // a kept point behind the rival: not a reading of these points
    }
    double shift = 0.0;
    for (size_t i = 0; i < test.size(); ++i) {
      const std::optional<Eigen::Vector2d> ours = PixelFromWorld(camera, test[i]);
      const std::optional<Eigen::Vector2d> theirs = PixelFromWorld(rival_camera, test[i]);
      const double d = theirs ? (*theirs - *ours).norm() : std::numeric_limits<double>::infinity();
      if (d > kRivalSigmas * rival_sigmas[i]) shift = std::max(shift, d);
    }
    if (!(shift <= check.rival_shift_px)) {
      check.rival_shift_px = shift;
      check.rival = rival.model;
    }
  }
  check.passed = check.max_sigma_px <= check.bound_px && check.rival_shift_px <= check.bound_px;
  const Eigen::Vector2d where =
      ConvertPixelOrigin(check.worst_pixel, PixelOrigin::kCenter, options.fit.pixel_origin);
  check.summary = "uncertain by up to " + Px(check.max_sigma_px) +
                  " (1 sigma) over the box the points span, most near pixel (" +
                  std::to_string(static_cast<long>(std::lround(where.x()))) + ", " +
                  std::to_string(static_cast<long>(std::lround(where.y()))) + "); bound " +
                  Px(check.bound_px);
  if (!check.rival.empty()) {
    check.summary += "; " + check.rival + " fits about as well and moves a point by " +
                     Px(check.rival_shift_px);
  }
  return check;
}

}  // namespace internal
}  // namespace camproj

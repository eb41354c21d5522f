// The fitter's reprojection residual (private): templated for Ceres' Jets, and analytic.
#ifndef CAMPROJ_SRC_FIT_REPROJECTION_ERROR_H_
#define CAMPROJ_SRC_FIT_REPROJECTION_ERROR_H_

#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "camproj/intrinsics.h"

namespace camproj {
namespace internal {

// Fit intrinsics block layout: [f, aspect, cx, cy, skew, k1, k2, p1, p2, k3] with fx = f,
// fy = aspect * f (pixels, kCenter). Aspect as a ratio lets "square pixels" be a constant, not a
// penalty. The single-view fitter frees at most the first 7 (p1, p2, k3 hold given values);
// Calibrate frees any.
inline constexpr int kFitIntrinsicsSize = 10;
static_assert(kFitIntrinsicsSize == kIntrinsicsArraySize);

template <typename T>
void PixelFromFitIntrinsics(const T* fit, const T& x, const T& y, T* pixel) {
  const T k[kIntrinsicsArraySize] = {fit[0], fit[1] * fit[0], fit[2], fit[3], fit[4],
                                     fit[5], fit[6],          fit[7], fit[8], fit[9]};
  PixelFromNormalized(k, x, y, pixel);
}

// Residual = predicted - observed pixel, for one point in the normalized world frame, by
// automatic differentiation: the reference the analytic PointReprojectionCost below is tested
// against (tests/reprojection_error_test.cc). Parameter blocks: rotation, cam_from_world as an Eigen quaternion (x, y, z, w; on
// ceres::EigenQuaternionManifold); center, the camera centre (3); intrinsics (layout above).
struct ReprojectionError {
  ReprojectionError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed)
      : point_(point), observed_(observed) {}

  template <typename T>
  bool operator()(const T* rotation, const T* center, const T* intrinsics, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> cam_from_world(rotation);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> c(center);
    const Eigen::Matrix<T, 3, 1> p = cam_from_world * (point_.cast<T>() - c);
    // A point reaching the camera plane makes the step invalid rather than infinite.
    if (!(p.z() > T(0.0))) return false;
    T pixel[2];
    PixelFromFitIntrinsics(intrinsics, p.x() / p.z(), p.y() / p.z(), pixel);
    residual[0] = pixel[0] - T(observed_.x());
    residual[1] = pixel[1] - T(observed_.y());
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point,
                                     const Eigen::Vector2d& observed) {
    return new ceres::AutoDiffCostFunction<ReprojectionError, 2, 4, 3, kFitIntrinsicsSize>(
        new ReprojectionError(point, observed));
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
};

// The residual (predicted - observed pixel) of a point already in the camera frame, which the
// caller has checked is in front (z > 0), with analytic derivatives: d residual / d intrinsics
// (2 x kFitIntrinsicsSize, row-major, layout above) and d residual / d point_in_cam (2 x 3, row-major), each
// only if its pointer is given. The part of the model after the rotation, shared by
// ProjectPointWithJacobian and the fitter's normal equations (which rotate with a matrix).
// kRadialOnly: the caller knows p1 = p2 = k3 = 0 (RadialOnly) and reads no derivative by them:
// their terms are left out, and jacobian_k's columns for them are not written (the single-view
// fits hold them at 0 unless given). Every value written is the general path's to the bit.
template <bool kRadialOnly = false>
inline void ResidualOfCamPoint(const double* k, const Eigen::Vector3d& point_in_cam,
                               const Eigen::Vector2d& observed, double* residual,
                               double* jacobian_k, double* jacobian_p) {
  const Eigen::Vector3d& p = point_in_cam;
  const double inv_z = 1.0 / p.z();
  const double x = p.x() * inv_z;
  const double y = p.y() * inv_z;
  const double f = k[0], a = k[1], s = k[4], k1 = k[5], k2 = k[6];
  if constexpr (kRadialOnly) {
    const double r2 = x * x + y * y;
    const double d = 1.0 + r2 * (k1 + r2 * k2);
    const double xd = d * x, yd = d * y;
    residual[0] = f * xd + s * yd + k[2] - observed.x();
    residual[1] = a * f * yd + k[3] - observed.y();
    if (jacobian_k != nullptr) {
      const double pu = f * x + s * y, pv = a * f * y, r4 = r2 * r2;
      double* u = jacobian_k;
      double* v = jacobian_k + kFitIntrinsicsSize;
      u[0] = xd, u[1] = 0.0, u[2] = 1.0, u[3] = 0.0, u[4] = yd, u[5] = pu * r2, u[6] = pu * r4;
      v[0] = a * yd, v[1] = f * yd, v[2] = 0.0, v[3] = 1.0, v[4] = 0.0, v[5] = pv * r2,
      v[6] = pv * r4;
    }
    if (jacobian_p == nullptr) return;
    const double dd = 2.0 * (k1 + 2.0 * k2 * r2);
    const double off = x * y * dd;
    const double dxd_dx = d + x * x * dd, dyd_dy = d + y * y * dd;
    const double u_x = f * dxd_dx + s * off, u_y = f * off + s * dyd_dy;
    const double v_x = a * f * off, v_y = a * f * dyd_dy;
    // In the general path's order of operations (its 2 x 2 by 2 x 3 product), so that both
    // round alike: a fit's result does not depend on which path ran.
    const double x_z = -x * inv_z, y_z = -y * inv_z;
    jacobian_p[0] = u_x * inv_z, jacobian_p[1] = u_y * inv_z;
    jacobian_p[2] = u_x * x_z + u_y * y_z;
    jacobian_p[3] = v_x * inv_z, jacobian_p[4] = v_y * inv_z;
    jacobian_p[5] = v_x * x_z + v_y * y_z;
    return;
  }
  const double p1 = k[7], p2 = k[8], k3 = k[9];
  const double xx = x * x, yy = y * y, xy = x * y;
  const double r2 = xx + yy;
  const double d = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = d * x + 2.0 * p1 * xy + p2 * (r2 + 2.0 * xx);
  const double yd = d * y + p1 * (r2 + 2.0 * yy) + 2.0 * p2 * xy;
  residual[0] = f * xd + s * yd + k[2] - observed.x();
  residual[1] = a * f * yd + k[3] - observed.y();
  if (jacobian_k != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, kFitIntrinsicsSize, Eigen::RowMajor>> jk(jacobian_k);
    const double pu = f * x + s * y;  // d u / d d: u = d (f x + s y) + (tangential) + cx
    const double pv = a * f * y;      // d v / d d
    const double r4 = r2 * r2;
    // d (xd, yd) / d p1 = (2 x y, r2 + 2 y^2), / d p2 = (r2 + 2 x^2, 2 x y).
    const double xd_p1 = 2.0 * xy, yd_p1 = r2 + 2.0 * yy, xd_p2 = r2 + 2.0 * xx, yd_p2 = 2.0 * xy;
    jk << xd, 0.0, 1.0, 0.0, yd, pu * r2, pu * r4, f * xd_p1 + s * yd_p1, f * xd_p2 + s * yd_p2,
        pu * r4 * r2,  //
        a * yd, f * yd, 0.0, 1.0, 0.0, pv * r2, pv * r4, a * f * yd_p1, a * f * yd_p2,
        pv * r4 * r2;
  }
  if (jacobian_p == nullptr) return;
  // d pixel / d (x, y), then / d p. d' = 2 (k1 + 2 k2 r2 + 3 k3 r2^2): d d / d x = d' x.
  const double dd = 2.0 * (k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2));
  const double off = xy * dd + 2.0 * p1 * x + 2.0 * p2 * y;
  const double dxd_dx = d + xx * dd + 2.0 * p1 * y + 6.0 * p2 * x, dxd_dy = off;
  const double dyd_dx = off, dyd_dy = d + yy * dd + 6.0 * p1 * y + 2.0 * p2 * x;
  Eigen::Matrix2d d_pixel_d_xy;
  d_pixel_d_xy << f * dxd_dx + s * dyd_dx, f * dxd_dy + s * dyd_dy,  //
      a * f * dyd_dx, a * f * dyd_dy;
  Eigen::Matrix<double, 2, 3> d_xy_d_p;
  d_xy_d_p << inv_z, 0.0, -x * inv_z, 0.0, inv_z, -y * inv_z;
  Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jacobian_p);
  jp = d_pixel_d_xy * d_xy_d_p;
}

// Whether `k` (fit layout) has no tangential distortion and no k3: ResidualOfCamPoint<true>.
inline bool RadialOnly(const double* k) { return k[7] == 0.0 && k[8] == 0.0 && k[9] == 0.0; }

// The same residual with analytic derivatives, for one point; the blocks are as above. Any
// Jacobian pointer may be null. Returns false where the point is not in front (z <= 0).
//   p = q * (X - C), Eigen's rotation of v by q: t = 2 u x v, p = v + w t + u x t (u = q.vec());
//   dp/dw = t, dp/du = -2w [v]x - [t]x - 2 [u]x [v]x, dp/dC = -R.
// jacobian_p, if given, receives d pixel / d p (2 x 3, row-major) for the caller's own chain rule.
inline bool ProjectPointWithJacobian(const double* q, const double* c, const double* k,
                                     const Eigen::Vector3d& point, const Eigen::Vector2d& observed,
                                     double* residual, double* jacobian_q, double* jacobian_c,
                                     double* jacobian_k, double* jacobian_p = nullptr) {
  const Eigen::Vector3d u(q[0], q[1], q[2]);
  const double w = q[3];
  const Eigen::Vector3d v = point - Eigen::Vector3d(c[0], c[1], c[2]);
  const Eigen::Vector3d t = 2.0 * u.cross(v);
  const Eigen::Vector3d p = v + w * t + u.cross(t);
  if (!(p.z() > 0.0)) return false;
  const bool pose_jacobian = jacobian_q != nullptr || jacobian_c != nullptr;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> d_pixel_d_p;
  ResidualOfCamPoint(k, p, observed, residual, jacobian_k,
                     pose_jacobian || jacobian_p != nullptr ? d_pixel_d_p.data() : nullptr);
  if (jacobian_p != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jacobian_p);
    jp = d_pixel_d_p;
  }
  if (!pose_jacobian) return true;
  auto skew = [](const Eigen::Vector3d& e) {
    Eigen::Matrix3d m;
    m << 0.0, -e.z(), e.y(), e.z(), 0.0, -e.x(), -e.y(), e.x(), 0.0;
    return m;
  };
  const Eigen::Matrix3d skew_u = skew(u);
  const Eigen::Matrix3d skew_v = skew(v);
  if (jacobian_q != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 4, Eigen::RowMajor>> jq(jacobian_q);
    const Eigen::Matrix3d dp_du = -2.0 * w * skew_v - skew(t) - 2.0 * skew_u * skew_v;
    jq.leftCols<3>() = d_pixel_d_p * dp_du;
    jq.col(3) = d_pixel_d_p * t;
  }
  if (jacobian_c != nullptr) {
    // dp/dv is the rotation (for the unit quaternion); dv/dC = -I.
    const Eigen::Matrix3d dp_dv = Eigen::Matrix3d::Identity() + 2.0 * w * skew_u + 2.0 * skew_u * skew_u;
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jc(jacobian_c);
    jc = -d_pixel_d_p * dp_dv;
  }
  return true;
}

// One point, analytic: for per-point blocks (robust losses apply per point).
class PointReprojectionCost : public ceres::SizedCostFunction<2, 4, 3, kFitIntrinsicsSize> {
 public:
  PointReprojectionCost(const Eigen::Vector3d& point, const Eigen::Vector2d& observed)
      : point_(point), observed_(observed) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return ProjectPointWithJacobian(parameters[0], parameters[1], parameters[2], point_, observed_,
                                    residuals, jacobians ? jacobians[0] : nullptr,
                                    jacobians ? jacobians[1] : nullptr,
                                    jacobians ? jacobians[2] : nullptr);
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
};

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_REPROJECTION_ERROR_H_

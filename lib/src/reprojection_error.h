// The fitter's Ceres functor (private).
#ifndef CAMPROJ_SRC_REPROJECTION_ERROR_H_
#define CAMPROJ_SRC_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "camproj/intrinsics.h"

namespace camproj {
namespace internal {

// Fit intrinsics block layout: [f, aspect, cx, cy, skew, k1, k2] with fx = f, fy = aspect * f
// (pixels, kCenter). Aspect as a ratio lets "square pixels" be a constant, not a penalty.
inline constexpr int kFitIntrinsicsSize = 7;

template <typename T>
void PixelFromFitIntrinsics(const T* fit, const T& x, const T& y, T* pixel) {
  const T k[7] = {fit[0], fit[1] * fit[0], fit[2], fit[3], fit[4], fit[5], fit[6]};
  PixelFromNormalized(k, x, y, pixel);
}

// Residual = predicted - observed pixel, for one point in the normalized world frame.
// Parameter blocks: rotation, cam_from_world as an Eigen quaternion (x, y, z, w; on
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

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_REPROJECTION_ERROR_H_

// The orthographic camera fit (private; FitCamera dispatches to it for
// FitOptions::projection == kOrthographic).
#ifndef CAMPROJ_SRC_FIT_ORTHOGRAPHIC_FIT_H_
#define CAMPROJ_SRC_FIT_ORTHOGRAPHIC_FIT_H_

#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"

namespace camproj {
namespace internal {

// Affine start (linear least squares of pixel = A X + b, then A = K2 R2 with K2 upper
// triangular), Ceres refinement of rotation, image offset and the free intrinsics among scale
// (focal), aspect and skew; principal point fixed (it trades exactly with the position). Points
// and pixels as FitCamera takes them; options already checked.
FitResult FitOrthographic(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& observed_pixels,
                          const ImageSize& image_size, const FitOptions& options);

// The least sum of squares (px^2) of any affine camera, pixel = A X + b, in closed form: a lower
// bound on every orthographic camera's (each is an affine camera; with aspect and skew free
// the bound is reached). It costs what FitOrthographic's start costs, without its refinement
// and the two Ceres problems of 2N residuals. Throws SceneError as FitOrthographic does (too
// few points, collinear or coplanar points, coordinates too large, no affine camera).
double AffineSumSquaresPx2(const std::vector<Eigen::Vector3d>& points_in_world,
                           const std::vector<Eigen::Vector2d>& observed_pixels,
                           const FitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_ORTHOGRAPHIC_FIT_H_

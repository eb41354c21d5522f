// The mirrored reading of a fitted camera (private), for the default path's mirror test: the
// same model fitted to the points with the world's z negated, started from the fitted camera's
// depth reversal (the Necker reading). Where the perspective is weak the two readings explain
// the image about equally well and either may win the closed form by noise; where it is strong
// the reversal fits far worse and no other start could make a mirrored camera fit better.
#ifndef CAMPROJ_SRC_FIT_MIRROR_H_
#define CAMPROJ_SRC_FIT_MIRROR_H_

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/fit.h"

namespace camproj {
namespace internal {

// `camera` (perspective) with its depths reversed about the depth of the points' centroid and
// the world's z negated: point_in_cam = D * cam_from_world(x) + (0, 0, 2 z_c) for the mirrored
// point M x (D = M = diag(1, 1, -1)), a proper rotation D R M. Under an affine camera the two
// give the same pixels; under perspective they differ at second order in depth / distance.
Camera NeckerReversal(const Camera& camera, const std::vector<Eigen::Vector3d>& points_in_world);

// The RMS (px) of `model` fitted by least squares (at most 20 LM iterations) to the points with
// z negated, from NeckerReversal(camera, points): the RMS of a proper camera of the mirrored
// world, at or above the best one near the reversal. Nothing when that refinement ends with a
// point behind the camera or a non-positive focal length or aspect.
std::optional<double> MirroredReadingRmsPx(const Camera& camera, const FitOptions& model,
                                           const std::vector<Eigen::Vector3d>& points_in_world,
                                           const std::vector<Eigen::Vector2d>& observed_pixels);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_MIRROR_H_

// The assessment, the fitter's last stage (private): the FitResult of the refined camera on the
// scene. It maps the camera back to the user's world, and reports the residuals (kCenter px),
// the depth range and GL views, the model's free and fixed parameters, and the uncertainty: the
// covariance in user units (rotation in degrees about the camera axes, eye in world units,
// intrinsics in px), sigmas, fields of view and strong correlations. It refuses points behind
// the camera and parameters the points do not determine (singular normal equations).
#ifndef CAMPROJ_SRC_FIT_ASSESS_H_
#define CAMPROJ_SRC_FIT_ASSESS_H_

#include <string>

#include "camproj/fit.h"
#include "fit/refine.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// Everything FitResult holds for a fit without RANSAC but time_ms, which the caller sets.
// start_method: FitResult::start_method. Throws SceneError kPointsBehindCamera (a point behind
// the camera), kDegenerate (reciprocal condition of the Jacobi-scaled normal equations at most
// 1e-12, naming the parameters along the undetermined direction and the intrinsic to fix), and
// DepthRange's refusal. FitResult::linearity is checked where there is a covariance and
// `effort` asks for it.
FitResult AssessFit(const Scene& scene, const std::string& start_method, RefinedCamera refined,
                    const FitOptions& options, const FitEffort& effort);

// ViewsOfCamera of a fitted camera (valid: Camera::Check passes), refusing (TooLargeForDouble)
// one whose GL matrices or frustum overflow a double (a world scaled by 1e307).
CameraViews ViewsOfFittedCamera(const Camera& camera, double target_distance);

struct DepthRange {
  double z_near;
  double z_far;
};
// The depth range of a fitted camera whose points lie at depths min_depth..max_depth: a given
// FitOptions::z_near / z_far as given, an unset one tight around the points (widened by
// depth_margin). Throws SceneError kPointsBehindCamera where a given plane has every point on
// its far side and the other plane is unset (the frustum would clip every point).
DepthRange DepthRangeOfPoints(const FitOptions& options, double min_depth, double max_depth);

// Sets the given FitOptions::z_near / z_far (if any) on a fitted camera, the other plane tight
// around the depths of the points it kept (those not in fit->outliers), and its views again
// (DepthRangeOfPoints; throws as it does). The automatic selection judges its candidates with
// tight planes and sets the given ones on its answer here: a plane is the answer's, and in each
// candidate's assessment it refused candidates whose depths it did not hold.
void SetGivenDepthRange(const FitOptions& options,
                        const std::vector<Eigen::Vector3d>& kept_points_in_world, FitResult* fit);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_ASSESS_H_

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
// std::invalid_argument when the given near / far leave no depth range. FitResult::linearity
// is checked where there is a covariance and `effort` asks for it.
FitResult AssessFit(const Scene& scene, const std::string& start_method, RefinedCamera refined,
                    const FitOptions& options, const FitEffort& effort);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_ASSESS_H_

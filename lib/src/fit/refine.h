// The refinement, the fitter's third stage (private): from the closed-form start, the camera that
// best reprojects the scene's points. Without a loss, least squares (least_squares.h), with a
// second start from the image centre for a DLT on few points; with a robust loss (Huber,
// Cauchy), Ceres with one residual block per point; with options.refine false, the start itself.
// Takes the scene and the start; returns the camera with its normal equations for the
// assessment, or refuses a camera short of the minimum, mirrored, or with points behind it.
#ifndef CAMPROJ_SRC_FIT_REFINE_H_
#define CAMPROJ_SRC_FIT_REFINE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/normal_equations.h"
#include "fit/scene.h"
#include "fit/start.h"

namespace camproj {
namespace internal {

struct RefinedCamera {
  // point_in_cam = rotation * (point - center), in the scene's normalized world.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Model model;
  // ComputeNormalEquations at the camera (least squares: possibly one settling step before it);
  // empty when a point is behind the camera, which the assessment refuses.
  NormalEquations normal;
  bool normal_predicted_step_back = false;  // LeastSquaresOutcome's
  int iterations = 0;
  std::string refiner;      // FitResult::refiner
  std::string termination;  // FitResult::termination
  std::vector<TraceEntry> trace;
};


// Throws SceneError kMirroredWorld (least squares found only a negative aspect),
// kPointsBehindCamera (least squares put points behind the camera or made the focal length
// negative), kDegenerate (the refinement failed, or did not reach the minimum). The trace's times
// count from start_time.
RefinedCamera RefineCamera(const Scene& scene, const Start& start, const FitOptions& options,
                           const FitEffort& effort, Clock::time_point start_time);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_REFINE_H_

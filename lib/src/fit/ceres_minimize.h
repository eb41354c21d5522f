// Ceres as the least-squares engine (private; FitOptions::refiner = kCeres, and every robust
// loss): a ceres::Problem with one analytic block per point (PointReprojectionCost, the residuals
// the own LM minimizes), the rotation on EigenQuaternionManifold, fixed intrinsics held by a
// SubsetManifold, DENSE_NORMAL_CHOLESKY (p <= 13 unknowns).
#ifndef CAMPROJ_SRC_FIT_CERES_MINIMIZE_H_
#define CAMPROJ_SRC_FIT_CERES_MINIMIZE_H_

#include <memory>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "camproj/fit.h"
#include "fit/common.h"
#include "fit/model.h"

namespace camproj {
namespace internal {

struct CeresSummary {
  ceres::TerminationType termination_type = ceres::FAILURE;
  int iterations = 0;
  std::string termination;  // "CONVERGENCE: ..." in Ceres' words
};

// The robust loss `options` asks for (options.loss not kNone): ceres::HuberLoss or CauchyLoss
// at options.loss_scale_px, applied to a point's squared residual (px^2).
std::unique_ptr<ceres::LossFunction> LossOf(const FitOptions& options);

// Minimizes sum over points of loss(|pixel(point) - observed|^2) (loss nullptr: plain least
// squares) from *rotation, *center, *model (the normalized world, kCenter pixels) with options'
// max_iterations and tolerances, and leaves the answer there. Appends (iteration, time, plain
// RMS) after each accepted step to *trace, times from start_time. Does not take `loss`.
CeresSummary MinimizeWithCeres(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector2d>& pixels,
                               ceres::LossFunction* loss, const FitOptions& options,
                               Clock::time_point start_time, Eigen::Matrix3d* rotation,
                               Eigen::Vector3d* center, Model* model,
                               std::vector<TraceEntry>* trace);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_CERES_MINIMIZE_H_

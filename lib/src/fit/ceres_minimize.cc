#include "fit/ceres_minimize.h"

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "fit/reprojection_error.h"

namespace camproj {
namespace internal {

namespace {

// Records (iteration, elapsed, RMS) after every accepted Ceres iteration.
class TraceCallback : public ceres::IterationCallback {
 public:
  TraceCallback(const std::vector<Eigen::Vector3d>& points,
                const std::vector<Eigen::Vector2d>& pixels, const double* rotation,
                const double* center, const double* intrinsics, Clock::time_point start,
                std::vector<TraceEntry>* trace)
      : points_(points), pixels_(pixels), rotation_(rotation), center_(center),
        intrinsics_(intrinsics), start_(start), trace_(trace),
        first_iteration_(trace->empty() ? 0 : trace->back().iteration + 1) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0 && !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    const double n = static_cast<double>(points_.size());
    // With a robust loss the cost is robustified: recompute the plain RMS.
    const Eigen::Map<const Eigen::Quaterniond> q(rotation_);
    const Eigen::Map<const Eigen::Vector3d> c(center_);
    double sum = 0.0;
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p = q * (points_[i] - c);
      double pixel[2];
      PixelFromFitIntrinsics(intrinsics_, p.x() / p.z(), p.y() / p.z(), pixel);
      sum += (Eigen::Vector2d(pixel[0], pixel[1]) - pixels_[i]).squaredNorm();
    }
    trace_->push_back({first_iteration_ + summary.iteration, MicrosecondsSince(start_),
                       std::sqrt(sum / n)});
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  const double* rotation_;
  const double* center_;
  const double* intrinsics_;
  Clock::time_point start_;
  std::vector<TraceEntry>* trace_;
  int first_iteration_;  // after the trace's last entry: rounds continue its numbering
};

}  // namespace

std::unique_ptr<ceres::LossFunction> LossOf(const FitOptions& options) {
  if (options.loss == LossType::kHuber) {
    return std::make_unique<ceres::HuberLoss>(options.loss_scale_px);
  }
  return std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
}

CeresSummary MinimizeWithCeres(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector2d>& pixels,
                               ceres::LossFunction* loss, const FitOptions& options,
                               Clock::time_point start_time, Eigen::Matrix3d* rotation,
                               Eigen::Vector3d* center, Model* model,
                               std::vector<TraceEntry>* trace) {
  Eigen::Quaterniond quaternion(*rotation);
  quaternion.normalize();
  std::array<double, kFitIntrinsicsSize> intrinsics = model->value;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  // A robust loss weighs each point's squared distance, so each point has its own block.
  for (size_t i = 0; i < points.size(); ++i) {
    problem.AddResidualBlock(new PointReprojectionCost(points[i], pixels[i]), loss,
                             quaternion.coeffs().data(), center->data(), intrinsics.data());
  }
  problem.SetManifold(quaternion.coeffs().data(), new ceres::EigenQuaternionManifold);
  std::vector<int> constant_slots;
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (!model->free[slot]) constant_slots.push_back(slot);
  }
  if (constant_slots.size() == kFitIntrinsicsSize) {
    problem.SetParameterBlockConstant(intrinsics.data());
  } else if (!constant_slots.empty()) {
    problem.SetManifold(intrinsics.data(),
                        new ceres::SubsetManifold(kFitIntrinsicsSize, constant_slots));
  }
  ceres::Solver::Options solver_options;
  // p <= 13 unknowns: the normal equations (O(N p^2)) beat QR of the 2N x p Jacobian.
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.logging_type = ceres::SILENT;
  solver_options.num_threads = 1;
  solver_options.update_state_every_iteration = true;
  TraceCallback trace_callback(points, pixels, quaternion.coeffs().data(), center->data(),
                               intrinsics.data(), start_time, trace);
  solver_options.callbacks.push_back(&trace_callback);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  quaternion.normalize();
  *rotation = quaternion.toRotationMatrix();
  model->value = intrinsics;
  CeresSummary result;
  result.termination_type = summary.termination_type;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.termination = std::string(ceres::TerminationTypeToString(summary.termination_type)) +
                       ": " + summary.message;
  return result;
}

}  // namespace internal
}  // namespace camproj

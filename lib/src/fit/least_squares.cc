#include "fit/least_squares.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fit/ceres_minimize.h"
#include "fit/small_solve.h"

namespace camproj {
namespace internal {

namespace {

// The least-squares problem Levenberg-Marquardt solves, on the chart u = [omega (3), center (3),
// free intrinsic slots] with R = exp(omega) R_start, fixed for the whole solve. At omega != 0,
// dtheta = J_l(omega) domega, J_l the left Jacobian of SO(3).
class ChartProblem {
 public:
  ChartProblem(const std::vector<Eigen::Vector3d>& points,
               const std::vector<Eigen::Vector2d>& pixels, const Eigen::Matrix3d& start_rotation,
               const Model& model)
      : points_(points), pixels_(pixels), start_rotation_(start_rotation), model_(model),
        columns_(model) {}

  int NumPoints() const { return static_cast<int>(points_.size()); }

  ParamVector Pack(const Eigen::Vector3d& center) const {
    ParamVector u(6 + model_.NumFree());
    u.head<3>().setZero();
    u.segment<3>(3) = center;
    int next = 6;
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (model_.free[slot]) u(next++) = model_.value[slot];
    }
    return u;
  }

  void Unpack(const ParamVector& u, Eigen::Matrix3d* rotation, Eigen::Vector3d* center,
              Model* model) const {
    *model = model_;
    Unpack(u, rotation, center, &model->value);
  }

  // The camera (rotation, center, every slot's value) on this chart: rotation = exp(omega)
  // start_rotation with |omega| <= pi.
  ParamVector PackCamera(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                         const IntrinsicValues& intrinsics) const {
    ParamVector u(6 + model_.NumFree());
    const Eigen::AngleAxisd turn(rotation * start_rotation_.transpose());
    u.head<3>() = turn.angle() * turn.axis();
    u.segment<3>(3) = center;
    int next = 6;
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (model_.free[slot]) u(next++) = intrinsics[slot];
    }
    return u;
  }

  // The normal equations at u on the chart; `local` receives them before the change of variables
  // (what ComputeNormalEquations would rebuild at the same camera, for the polish).
  bool Linearize(const ParamVector& u, NormalEquations* chart, NormalEquations* local) const {
    Eigen::Matrix3d rotation;
    Eigen::Vector3d center;
    IntrinsicValues intrinsics;
    Unpack(u, &rotation, &center, &intrinsics);
    if (!LocalNormalEquations(points_, pixels_, rotation, center, intrinsics, columns_, local)) {
      return false;
    }
    *chart = *local;
    ToChart(LeftJacobian(u), rotation, chart);
    return true;
  }

  // J(u)^T r''(u; v), r'' the second directional derivative of the residuals along v, by the
  // finite difference (2 / h) ((r(u + h v) - r(u)) / h - J v) (Transtrum and Sethna 2012,
  // "Improvements to the Levenberg-Marquardt algorithm for nonlinear least-squares
  // minimization", eq. 15). False if a point is behind the camera at u or u + h v.
  bool JacobianTransposeSecondDerivative(const ParamVector& u, const ParamVector& v, double h,
                                         ParamVector* out) const {
    Eigen::Matrix3d rotation, moved_rotation;
    Eigen::Vector3d center, moved_center;
    IntrinsicValues intrinsics, moved_intrinsics;
    Unpack(u, &rotation, &center, &intrinsics);
    Unpack(u + h * v, &moved_rotation, &moved_center, &moved_intrinsics);
    // v in the local frame of LocalNormalEquations: dtheta = J_l(omega) domega, dc = R dC.
    const int p = static_cast<int>(u.size());
    ParamVector v_local = v;
    v_local.head<3>() = LeftJacobian(u) * v.head<3>();
    v_local.segment<3>(3) = rotation * v.segment<3>(3);
    ParamVector sum = ParamVector::Zero(p);
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d q = rotation * (points_[i] - center);
      const Eigen::Vector3d moved_q = moved_rotation * (points_[i] - moved_center);
      if (!(q.z() > 0.0) || !(moved_q.z() > 0.0)) return false;
      double r[2], moved_r[2], jk[2 * kFitIntrinsicsSize], jp[6];
      ResidualOfCamPoint(intrinsics.data(), q, pixels_[i], r, jk, jp);
      ResidualOfCamPoint(moved_intrinsics.data(), moved_q, pixels_[i], moved_r, nullptr, nullptr);
      Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxParams> j(2, p);
      for (int row = 0; row < 2; ++row) {
        const Eigen::Vector3d a(jp[3 * row], jp[3 * row + 1], jp[3 * row + 2]);
        j.block<1, 3>(row, 0) = q.cross(a).transpose();
        j.block<1, 3>(row, 3) = -a.transpose();
        int next = 6;
        for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
          if (model_.free[slot]) j(row, next++) = jk[kFitIntrinsicsSize * row + slot];
        }
      }
      const Eigen::Vector2d second =
          (2.0 / h) * ((Eigen::Vector2d(moved_r[0], moved_r[1]) - Eigen::Vector2d(r[0], r[1])) / h -
                       j * v_local);
      sum += j.transpose() * second;
    }
    // Back to the chart: J_chart = J_local T, T = diag(J_l(omega), R, I).
    *out = sum;
    out->head<3>() = LeftJacobian(u).transpose() * sum.head<3>();
    out->segment<3>(3) = rotation.transpose() * sum.segment<3>(3);
    return true;
  }

 private:
  // Unpack without copying the model's descriptions (strings): for every pass over the points.
  void Unpack(const ParamVector& u, Eigen::Matrix3d* rotation, Eigen::Vector3d* center,
              IntrinsicValues* intrinsics) const {
    *rotation = Rotation(u) * start_rotation_;
    *center = u.segment<3>(3);
    *intrinsics = model_.value;
    int next = 6;
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (model_.free[slot]) (*intrinsics)[slot] = u(next++);
    }
  }

  static Eigen::Matrix3d Rotation(const ParamVector& omega) {
    const Eigen::Vector3d w = omega.head<3>();
    const double angle = w.norm();
    return angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                       : Eigen::Matrix3d::Identity();
  }

  static Eigen::Matrix3d Skew(const Eigen::Vector3d& e) {
    Eigen::Matrix3d m;
    m << 0.0, -e.z(), e.y(), e.z(), 0.0, -e.x(), -e.y(), e.x(), 0.0;
    return m;
  }

  // J_l(w) = I + (1 - cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2, t = |w| (series near 0).
  static Eigen::Matrix3d LeftJacobian(const ParamVector& omega) {
    const Eigen::Vector3d w = omega.head<3>();
    const double t2 = w.squaredNorm();
    const Eigen::Matrix3d k = Skew(w);
    double a, b;
    if (t2 < 1e-8) {
      a = 0.5 - t2 / 24.0;
      b = 1.0 / 6.0 - t2 / 120.0;
    } else {
      const double t = std::sqrt(t2);
      a = (1.0 - std::cos(t)) / t2;
      b = (t - std::sin(t)) / (t2 * t);
    }
    return Eigen::Matrix3d::Identity() + a * k + b * k * k;
  }

  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  Eigen::Matrix3d start_rotation_;
  Model model_;
  JacobianColumns columns_;
};

// Why Levenberg-Marquardt stopped; the texts are Ceres' (TinySolver's statuses).
enum class LmStatus {
  kGradientTooSmall,
  kRelativeStepTooSmall,
  kCostTooSmall,
  kMaxIterations,
  kCostChangeTooSmall,
  kTargetOutOfReach,
  kAtKnownMinimum,
};

std::string LmStatusText(LmStatus status) {
  switch (status) {
    case LmStatus::kGradientTooSmall: return "CONVERGENCE: gradient below tolerance";
    case LmStatus::kRelativeStepTooSmall: return "CONVERGENCE: relative step below tolerance";
    case LmStatus::kCostTooSmall: return "CONVERGENCE: cost below threshold";
    case LmStatus::kCostChangeTooSmall: return "CONVERGENCE: cost change below tolerance";
    case LmStatus::kTargetOutOfReach:
      return "NO_CONVERGENCE: the linear model's minimum is far above the cost asked for";
    case LmStatus::kAtKnownMinimum:
      return "CONVERGENCE: in the quadratic neighbourhood of the minimum already found";
    case LmStatus::kMaxIterations: break;
  }
  return "NO_CONVERGENCE: maximum number of iterations reached";
}

struct LmSummary {
  int iterations = 0;
  LmStatus status = LmStatus::kMaxIterations;
  // The local normal equations at the returned u (the polish's first), if they were formed there.
  bool local_at_solution = false;
  NormalEquations local;
};

// A KnownMinimum on a ChartProblem's chart: its parameters there, its cost and the squared radius
// of its neighbourhood (px^2).
struct KnownOnChart {
  ParamVector u;
  double cost = 0.0;
  double radius_px2 = 0.0;
};

KnownOnChart OnChart(const KnownMinimum& known, const ChartProblem& problem) {
  KnownOnChart on;
  on.u = problem.PackCamera(known.rotation, known.center, known.intrinsics);
  on.cost = known.cost;
  const double dof =
      std::max(1.0, 2.0 * problem.NumPoints() - static_cast<double>(on.u.size()));
  on.radius_px2 = KnownMinimum::kSameBasinFraction * KnownMinimum::kSameBasinFraction *
                  known.cost / dof;
  return on;
}

// TinySolver's trust region, as the damping of J^T J's diagonal (Ceres 2.1, tiny_solver.h).
class Damping {
 public:
  // jtj with its diagonal raised by the damping (each entry clamped first, as TinySolver does).
  ParamMatrix Regularized(const ParamMatrix& jtj) const {
    constexpr double kMinDiagonal = 1e-6;
    constexpr double kMaxDiagonal = 1e32;
    ParamMatrix regularized = jtj;
    for (int i = 0; i < regularized.rows(); ++i) {
      const double lm_diagonal =
          std::sqrt(damping_ * std::min(std::max(jtj(i, i), kMinDiagonal), kMaxDiagonal));
      regularized(i, i) += lm_diagonal * lm_diagonal;
    }
    return regularized;
  }
  // After a rejected step: the trust region shrinks, faster each time in a row.
  void Reject() {
    damping_ *= factor_;
    factor_ *= 2.0;
  }
  // After an accepted step whose actual reduction was `rho` times the predicted one.
  void Accept(double rho) {
    const double t = 2.0 * rho - 1.0;
    damping_ *= std::max(1.0 / 3.0, 1.0 - t * t * t);
    factor_ = 2.0;
  }

 private:
  static constexpr double kInitialTrustRegionRadius = 1e4;
  double damping_ = 1.0 / kInitialTrustRegionRadius;
  double factor_ = 2.0;
};

// Transtrum and Sethna's geodesic acceleration (2012, cited at
// JacobianTransposeSecondDerivative) of the Jacobi-scaled LM step `*lm_step` at u (`*step` =
// scaling * lm_step on the chart; `solver` factors the damped scaled J^T J): a = -(J^T J +
// damping)^-1 J^T r''(v), taken as lm_step + a / 2 (both updated) when |a| <= kGeodesicAlpha
// |lm_step| / 2. False where a is larger or not finite: the step is then to be rejected. Where
// r'' cannot be formed (a point behind the camera along v), the step stays as it is.
bool AddGeodesicAcceleration(const ChartProblem& problem, const ParamVector& u,
                             const SymmetricSolver& solver, const ParamVector& scaling,
                             ParamVector* lm_step, ParamVector* step) {
  // Transtrum and Sethna's defaults: the finite-difference step along v and the largest
  // acceptable |a| / |v| (times 2).
  constexpr double kGeodesicStep = 0.1;
  constexpr double kGeodesicAlpha = 0.75;
  ParamVector second;
  if (!problem.JacobianTransposeSecondDerivative(u, *step, kGeodesicStep, &second)) return true;
  const ParamVector acceleration = -solver.Solve(scaling.asDiagonal() * second);
  if (!acceleration.allFinite() || 2.0 * acceleration.norm() > kGeodesicAlpha * lm_step->norm()) {
    return false;
  }
  *lm_step += 0.5 * acceleration;
  *step = scaling.asDiagonal() * *lm_step;
  return true;
}

// An accepted iterate of LM in TinySolver's Jacobi-scaled variables: J_s = J D with
// D = diag(1 / (1 + |column of J|)) at the start, jtj = J_s^T J_s, gradient = -J_s^T r;
// cost = r^T r / 2.
struct ScaledIterate {
  ParamVector scaling;  // D's diagonal; empty until the first iterate sets it
  ParamMatrix jtj;
  ParamVector gradient;
  double cost = 0.0;

  // The iterate whose normal equations on the chart are `chart`.
  void Set(const NormalEquations& chart) {
    if (scaling.size() == 0) {
      scaling = (1.0 + chart.jtj.diagonal().array().sqrt()).inverse().matrix();
    }
    jtj = scaling.asDiagonal() * chart.jtj * scaling.asDiagonal();
    gradient = -(scaling.asDiagonal() * chart.jtr);
    cost = chart.cost / 2.0;
  }

  // The Gauss-Newton model's minimum here, a sum of squares (twice cost - g^T (J^T J)^-1 g / 2);
  // NaN where the solve is singular: J^T J is positive semi-definite, so a negative or
  // non-finite decrease tells nothing.
  double GaussNewtonMinimumPx2() const {
    const double decrease = 0.5 * gradient.dot(SymmetricSolver(jtj).Solve(gradient));
    return decrease >= 0.0 && std::isfinite(decrease)
               ? 2.0 * (cost - decrease)
               : std::numeric_limits<double>::quiet_NaN();
  }
};

// The stopping rules LM reads at every accepted iterate (`u`, `iterate`; `at`: its unscaled
// normal equations), in TinySolver's order, then the caller's two (MinimizeLevenbergMarquardt):
// even the Gauss-Newton model's minimum out of reach, or the iterate in the known minimum's
// neighbourhood with no lower minimum in its Gauss-Newton model's reach.
std::optional<LmStatus> StopAt(const ScaledIterate& iterate, const NormalEquations& at,
                               const ParamVector& u, const FitOptions& options,
                               double out_of_reach_px2, const KnownOnChart* known) {
  // TinySolver's default where FitOptions has no say.
  const double cost_threshold = std::numeric_limits<double>::epsilon();
  if (iterate.gradient.cwiseAbs().maxCoeff() < options.gradient_tolerance) {
    return LmStatus::kGradientTooSmall;
  }
  if (iterate.cost < cost_threshold) return LmStatus::kCostTooSmall;
  if (std::isfinite(out_of_reach_px2) && iterate.GaussNewtonMinimumPx2() > out_of_reach_px2) {
    return LmStatus::kTargetOutOfReach;
  }
  if (known != nullptr) {
    const ParamVector d = u - known->u;
    if (d.dot(at.jtj * d) <= known->radius_px2 &&
        iterate.GaussNewtonMinimumPx2() >= known->cost * (1.0 - kLowerByRounding)) {
      return LmStatus::kAtKnownMinimum;
    }
  }
  return std::nullopt;
}

// Levenberg-Marquardt exactly as ceres::TinySolver (Ceres 2.1) runs it -- Jacobi scaling fixed at
// the start, the same damping and trust-region updates, stopping rules and defaults -- but on
// normal equations accumulated point by point: TinySolver forms the 2N x p Jacobian and multiplies
// it out (J^T J by GEMM), which cost more than the residuals themselves. Two further differences:
// a candidate step is evaluated with its normal equations, not its cost alone, because nearly
// every candidate is accepted and then needs them (TinySolver evaluates it twice); and a candidate
// that puts a point behind the camera is rejected and the damping raised (TinySolver ignores the
// failed evaluation and compares stale residuals). Each accepted iterate is recorded in the trace.
//
// With `geodesic`, each step also gets Transtrum and Sethna's geodesic acceleration
// (AddGeodesicAcceleration; a step whose acceleration is too large is rejected). It follows a
// curved valley to second order where plain LM steps leave it after a tiny fraction of its
// length (the cost rises across it).
//
// With a finite `out_of_reach_px2`, LM also stops (kTargetOutOfReach) at an iterate where the
// Gauss-Newton model's minimum, twice (cost - g^T (J^T J)^-1 g / 2), is above it.
//
// With `known` (KnownMinimum in least_squares.h, on this problem's chart), LM also stops
// (kAtKnownMinimum) at an iterate within its radius of the known minimum whose Gauss-Newton
// model's minimum is not below the known cost.
LmSummary MinimizeLevenbergMarquardt(const ChartProblem& problem, const FitOptions& options,
                                     Clock::time_point start_time, bool geodesic,
                                     double out_of_reach_px2, const KnownOnChart* known,
                                     ParamVector* u, std::vector<TraceEntry>* trace) {
  const int max_iterations = std::max(1, options.max_iterations + 1);

  LmSummary summary;
  ScaledIterate iterate;
  // The local normal equations of the trial and of the last accepted iterate, by pointer: an
  // accepted trial's become the accepted ones without a copy (summary.local is set once, at the
  // end).
  NormalEquations locals[2];
  NormalEquations* accepted_local = nullptr;
  NormalEquations* trial_local = &locals[0];
  // Makes `at` the current iterate: `chart` its normal equations in the chart, *trial_local its
  // local ones.
  auto accept = [&](const ParamVector& at, const NormalEquations& chart) {
    *u = at;
    iterate.Set(chart);
    accepted_local = trial_local;
    trial_local = accepted_local == &locals[0] ? &locals[1] : &locals[0];
    summary.local_at_solution = true;
    trace->push_back({static_cast<int>(trace->size()), MicrosecondsSince(start_time),
                      std::sqrt(chart.cost / problem.NumPoints())});
  };

  NormalEquations chart;
  // The summary with the last accepted local normal equations (every return below).
  auto finish = [&]() -> LmSummary {
    if (accepted_local != nullptr) summary.local = std::move(*accepted_local);
    return summary;
  };
  summary.iterations = 0;
  // A point behind the start: nothing to minimize (the polish refuses it too).
  if (!problem.Linearize(*u, &chart, trial_local)) return summary;
  // TinySolver's function tolerance is absolute (on twice the cost): scale it by the start's.
  const double function_tolerance = options.function_tolerance * std::max(chart.cost, 1e-300);
  accept(*u, chart);
  if (const std::optional<LmStatus> stop =
          StopAt(iterate, chart, *u, options, out_of_reach_px2, known)) {
    summary.status = *stop;
    return finish();
  }
  Damping damping;
  for (summary.iterations = 1; summary.iterations < max_iterations; ++summary.iterations) {
    const SymmetricSolver solver(damping.Regularized(iterate.jtj));
    ParamVector lm_step = solver.Solve(iterate.gradient);
    ParamVector step = iterate.scaling.asDiagonal() * lm_step;
    // Adding parameter_tolerance to |u| keeps the test meaningful near u = 0.
    if (step.norm() < options.parameter_tolerance * (u->norm() + options.parameter_tolerance)) {
      summary.status = LmStatus::kRelativeStepTooSmall;
      break;
    }
    const ParamVector velocity = lm_step;
    if (geodesic &&
        !AddGeodesicAcceleration(problem, *u, solver, iterate.scaling, &lm_step, &step)) {
      damping.Reject();
      continue;
    }
    const ParamVector candidate = *u + step;
    if (!problem.Linearize(candidate, &chart, trial_local)) {
      // A point behind the camera: no cost to compare. Shrink the trust region as for a
      // rejected step.
      damping.Reject();
      continue;
    }
    const double cost_change = 2.0 * iterate.cost - chart.cost;
    // With the acceleration, the reduction the linear model predicts for the velocity (the
    // acceleration's own is second order, which the linear model does not see).
    const double model_cost_change =
        velocity.dot(2.0 * iterate.gradient - iterate.jtj * velocity);
    // rho: the actual reduction over the reduction the linear model predicts.
    const double rho = cost_change / model_cost_change;
    if (rho > 0.0) {
      accept(candidate, chart);
      if (std::abs(cost_change) < function_tolerance) {
        summary.status = LmStatus::kCostChangeTooSmall;
        break;
      }
      if (const std::optional<LmStatus> stop =
              StopAt(iterate, chart, *u, options, out_of_reach_px2, known)) {
        summary.status = *stop;
        break;
      }
      damping.Accept(rho);
    } else {
      if (std::abs(cost_change) < function_tolerance) {
        summary.status = LmStatus::kCostChangeTooSmall;
        break;
      }
      damping.Reject();
    }
  }
  return finish();
}

// The polish's tests on its steps' joint sizes |J delta| (px: the change a step makes to the
// residual vector), against the residuals' own sigma sqrt(cost / dof).
struct PolishSteps {
  // Converged when the last Gauss-Newton step, taken or not, changes the residual vector by at
  // most kConvergedFraction of the residuals' own sigma (|J delta| in px against
  // sqrt(cost / (2N - p))), or by rounding alone (kRoundingStepPx): the parameters are then
  // within 1e-3 of their standard deviation of the minimum in the joint (Mahalanobis) sense.
  // Where LM stops short on a curved valley, most of the residual is still removable and the
  // step is about sqrt(2N - p) sigmas.
  static constexpr double kConvergedFraction = 1e-3;
  static constexpr double kRoundingStepPx = 1e-8;
  // A step taken on a prediction (NextPredictedWithinTest) is at most this fraction of the
  // residuals' sigma: the normal equations returned are then those one such step back
  // (LeastSquaresOutcome::normal_predicted_step_back), where a sigma read from them moves by up
  // to 2.4e-3 of itself (k1 free at 20 points, seed offsets 0-99000 of
  // tests/determination_test.cc), so a rival's uncertainty is then read by a pass over the points
  // (fit/determination.cc); one step back within the convergence test moves it by under 1e-3.
  static constexpr double kPredictedStepFraction = 1e-2;

  double dof;  // 2N - p, at least 1
  double last_px = std::numeric_limits<double>::infinity();      // the latest step's
  // The step before it, with a pass over the points after it (none yet: infinite).
  double previous_px = std::numeric_limits<double>::infinity();

  bool Converged(double cost) const {
    const double noise_px = std::sqrt(cost / dof);
    return last_px <= std::max(kConvergedFraction * noise_px, kRoundingStepPx);
  }

  // Whether the next step, predicted from the latest one and the one before, is within the
  // convergence test: Gauss-Newton contracts linearly where the residuals are not small (rate q:
  // next = q * this = this^2 / before) and quadratically near a small-residual minimum (next ~
  // c this^2, below this^2 / before once the steps shrink), so this^2 / before bounds it while
  // the steps contract (by half at least). Measured on the stage-cost scenes at 100 points: 15
  // polish passes per default fit, most of them the pass after a step of ~1e-2 sigma that only
  // finds the next of ~1e-5.
  bool NextPredictedWithinTest(double cost) const {
    const double noise_px = std::sqrt(cost / dof);
    return std::isfinite(previous_px) && last_px <= 0.5 * previous_px &&
           last_px <= kPredictedStepFraction * noise_px &&
           last_px * last_px <= previous_px * std::max(kConvergedFraction * noise_px,
                                                       kRoundingStepPx);
  }
};

// The camera `fraction` of the step `delta` (rotation on the chart, centre, free intrinsics in
// order) away from rotation, center and model's values.
struct SteppedCamera {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d center;
  IntrinsicValues intrinsics;
};
SteppedCamera Stepped(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                      const Model& model, const ParamVector& delta, double fraction) {
  SteppedCamera stepped{rotation, center + fraction * delta.segment<3>(3), model.value};
  const double angle = fraction * delta.head<3>().norm();
  if (angle > 0.0) {
    stepped.rotation =
        Eigen::AngleAxisd(angle, delta.head<3>().normalized()).toRotationMatrix() * rotation;
  }
  int next = 6;
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (model.free[slot]) stepped.intrinsics[slot] += fraction * delta(next++);
  }
  return stepped;
}

// Gauss-Newton steps from LM's answer (least squares without a loss only). LM's stopping rules
// (relative cost change, relative step under damping) can leave it ~1e-8 from the optimum in
// flat directions; undamped steps with the exact Jacobian take it to rounding level. `normal`
// holds the normal equations (ComputeNormalEquations) at the start on entry; on return, those
// at the final parameters, or one settling step (under kSettledStepPx) before them. Returns
// whether it converged: a step under kSettledStepPx (then also *settled, if given), or a last
// step within the convergence test below (steps that stopped shrinking at the rounding floor, or
// that raised the cost by rounding). It does not converge where LM stopped short of the minimum
// on a curved valley: there Gauss-Newton steps overshoot and raise the cost.
// With stop_when_converged (a camera only scored), a step within the convergence test is taken
// without the pass that would confirm it, and so is one whose successor the steps so far predict
// within it (below: the pass after it would only find that successor); *predicted, if given,
// says the last was taken on that prediction. With `halve`, a step that raises the cost is
// shortened instead (below) before the polish gives up.
bool PolishGaussNewton(const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector2d>& pixels,
                       Eigen::Matrix3d* rotation, Eigen::Vector3d* center, Model* model,
                       NormalEquations* normal, bool* settled = nullptr,
                       bool stop_when_converged = false, bool* predicted = nullptr,
                       bool halve = false) {
  if (settled != nullptr) *settled = false;
  if (predicted != nullptr) *predicted = false;
  // Where the residuals are not small against the curvature they neglect, Gauss-Newton contracts
  // only linearly (rate q = |next step| / |step|): seen q = 0.37 at 6 points with focal, aspect
  // and principal point free (2 residual degrees of freedom, rms 0.68 px), where 6 steps left fy
  // 1.8e-6 px from the minimum (1.4e-9 of fx; the own LM's and Ceres' answers then differed by
  // more than issue #12's 1e-9: FitTest.CeresRefinerFindsTheSameOptimum at seed offset 12345).
  // From LM's answer (|J delta| ~1e-4 px) to kSettledStepPx at q = 0.37 takes 12 steps; steps
  // that stop shrinking (q > 1/2) end it earlier (below). Cost: +1.4 / -1.6 / 0 % instructions
  // for one fit at 6 / 20 / 100 points, +0.3 / 0 % for the default path at 6 / 100 (bench
  // --stage-cost, --one-fit): most polishes settle within a few steps.
  constexpr int kMaxSteps = 20;
  // Settled when a step moves the residuals by under this (parameters then move by under 1e-9 of
  // their pixel-noise sigma per px of noise).
  constexpr double kSettledStepPx = 1e-9;
  PolishSteps steps{std::max(1.0, 2.0 * points.size() - normal->jtj.rows())};
  auto converged = [&] { return steps.Converged(normal->cost); };
  // The cost's rounding: each residual (a projection less a pixel) is rounded to about
  // kResidualUlps units of the pixel's magnitude, so the cost sum_i |r_i|^2 is rounded to
  // 2 sum_i |r_i| kResidualUlps u |pixel_i| <= 2 kResidualUlps u sqrt(cost) sqrt(sum |pixel_i|^2).
  // Near a small-residual minimum that is ~1e-11 of the cost (6 points at 0.05 px: 3e-12
  // measured), above a fixed relative allowance: the step would be refused for its rounding.
  constexpr double kResidualUlps = 16.0;
  double pixel_norm2 = 0.0;
  for (const Eigen::Vector2d& u : pixels) pixel_norm2 += u.squaredNorm();
  const double cost_rounding_per_root = 2.0 * kResidualUlps *
                                        std::numeric_limits<double>::epsilon() *
                                        std::sqrt(pixel_norm2);
  const JacobianColumns columns(*model);
  double previous_step_px = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxSteps; ++step) {
    const ParamVector scale = normal->jtj.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse();
    const ParamVector delta =
        -(scale.asDiagonal() *
          SymmetricSolver(ParamMatrix(scale.asDiagonal() * normal->jtj * scale.asDiagonal()))
              .Solve(scale.asDiagonal() * normal->jtr));
    if (!delta.allFinite()) return false;
    SteppedCamera stepped = Stepped(*rotation, *center, *model, delta, 1.0);
    Eigen::Matrix3d& new_rotation = stepped.rotation;
    Eigen::Vector3d& new_center = stepped.center;
    IntrinsicValues& new_intrinsics = stepped.intrinsics;
    // In Jacobi-scaled units a step's size is the change it makes to the residuals, in px.
    const double step_px = (delta.cwiseQuotient(scale)).cwiseAbs().maxCoeff();
    // The step's joint size: |J delta|, the change it makes to the residual vector, in px.
    steps.last_px = std::sqrt(std::max(0.0, delta.dot(normal->jtj * delta)));
    // With stop_when_converged, a step within the convergence test is the last as well, and so
    // is one whose successor is predicted within it.
    if (step_px <= kSettledStepPx ||
        (stop_when_converged &&
         (converged() || steps.NextPredictedWithinTest(normal->cost)))) {
      // The last step: take it without another pass over the points. The normal equations stay
      // those one step back, where J^T J differs by ~1e-12 relative after a settling step (the
      // step's size against the parameters' scales), and by what a step of at most
      // PolishSteps::kPredictedStepFraction of the noise changes after a predicted one.
      *rotation = new_rotation;
      *center = new_center;
      model->value = new_intrinsics;
      if (settled != nullptr) *settled = step_px <= kSettledStepPx;
      if (predicted != nullptr) *predicted = !(step_px <= kSettledStepPx) && !converged();
      return true;
    }
    NormalEquations new_normal;
    if (!ComputeNormalEquations(points, pixels, new_rotation, new_center, new_intrinsics, columns,
                                &new_normal)) {
      return false;  // a point behind the camera
    }
    // Near the optimum the cost is flat to rounding (a 1e-8 relative parameter change moves it by
    // ~1e-16), so accept rounding-level increases and stop on the step's size instead.
    auto accepted = [&](const NormalEquations& at) {
      return at.cost <= normal->cost * (1.0 + 1e-12) +
                            cost_rounding_per_root * std::sqrt(normal->cost) + 1e-300;
    };
    // With `halve` (a fit FitCamera returns): where the full step overshoots -- a curved valley,
    // or residuals whose own curvature Gauss-Newton neglects -- a shorter step along it still
    // descends (J^T J is positive definite) and the steps after it go on towards the minimum:
    // halved up to kMaxHalvings times. Without it a noise-free near-planar scene (thickness
    // 1e-4, focal, aspect and principal point free, condition ~5e5) was refused as "did not
    // reach the minimum": each overshooting step ended the polish unconverged and LM, restarted,
    // stopped at once on its relative step tolerance, 20 rounds over (StabilityTest
    // NearPlanar1em4FullModel at seed offset 65536).
    constexpr int kMaxHalvings = 4;
    double fraction = 1.0;
    for (int halving = 0; !accepted(new_normal) && halve && halving < kMaxHalvings &&
                          !(step_px <= kSettledStepPx);
         ++halving) {
      fraction *= 0.5;
      stepped = Stepped(*rotation, *center, *model, delta, fraction);
      if (!ComputeNormalEquations(points, pixels, new_rotation, new_center, new_intrinsics,
                                  columns, &new_normal)) {
        return false;
      }
    }
    if (!accepted(new_normal)) return converged();
    *rotation = new_rotation;
    *center = new_center;
    model->value = new_intrinsics;
    *normal = std::move(new_normal);
    if (fraction < 1.0) {
      // A shortened step: the next full one is no measure of the rounding floor.
      previous_step_px = std::numeric_limits<double>::infinity();
      steps.previous_px = std::numeric_limits<double>::infinity();
      continue;
    }
    // A step that stops shrinking has reached the rounding floor.
    if (step_px > 0.5 * previous_step_px) return converged();
    previous_step_px = step_px;
    steps.previous_px = steps.last_px;
  }
  return converged();
}

}  // namespace

LeastSquaresOutcome RefineLeastSquares(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector2d>& pixels,
                                       const Eigen::Matrix3d& start_rotation,
                                       const Eigen::Vector3d& start_center, const Model& model,
                                       const FitOptions& options, Clock::time_point start_time,
                                       int max_rounds, PolishFirst polish_first,
                                       PolishUntil until, double out_of_reach_px2,
                                       const KnownMinimum* known) {
  const bool scored = until == PolishUntil::kConverged;
  LeastSquaresOutcome outcome;
  outcome.rotation = start_rotation;
  outcome.center = start_center;
  outcome.model = model;
  bool have_normal = false;
  if (polish_first != PolishFirst::kNo && options.refiner != Refiner::kCeres &&
      ComputeNormalEquations(points, pixels, outcome.rotation, outcome.center, outcome.model,
                             &outcome.normal)) {
    // From a start at a nested model's minimum, or a closed form on many points, the minimum
    // is usually a few Gauss-Newton steps away; where the polish does not end there (it never
    // raises the cost), LM goes on from where it stopped.
    outcome.trace.push_back({0, MicrosecondsSince(start_time),
                             std::sqrt(outcome.normal.cost / static_cast<double>(points.size()))});
    bool settled = false;
    const bool polished =
        PolishGaussNewton(points, pixels, &outcome.rotation, &outcome.center, &outcome.model,
                          &outcome.normal, &settled, scored, &outcome.normal_predicted_step_back,
                          until == PolishUntil::kSettledHalving);
    outcome.converged =
        polish_first == PolishFirst::kFromClosedForm && !scored ? settled : polished;
    have_normal = true;
    if (outcome.converged) {
      outcome.termination = polish_first == PolishFirst::kFromClosedForm
                                ? "CONVERGENCE: Gauss-Newton from the closed form"
                                : "CONVERGENCE: Gauss-Newton from a nested minimum";
    }
  }
  for (int round = 0; round < max_rounds && !outcome.converged; ++round) {
    have_normal = false;
    outcome.normal_predicted_step_back = false;  // LM's own normal equations are at its answer
    if (options.refiner == Refiner::kCeres) {
      // The same residuals in a ceres::Problem; each round resumes from the last.
      const CeresSummary summary =
          MinimizeWithCeres(points, pixels, nullptr, options, start_time, &outcome.rotation,
                            &outcome.center, &outcome.model, &outcome.trace);
      outcome.iterations += summary.iterations;
      outcome.termination = "ceres " + summary.termination;
    } else {
      const ChartProblem problem(points, pixels, outcome.rotation, outcome.model);
      ParamVector u = problem.Pack(outcome.center);
      std::optional<KnownOnChart> known_on_chart;
      if (known != nullptr) known_on_chart = OnChart(*known, problem);
      // The first round is TinySolver's LM; where its answer is short of the minimum (a curved
      // valley), the next rounds add geodesic acceleration.
      const LmSummary summary = MinimizeLevenbergMarquardt(
          problem, options, start_time, round > 0, out_of_reach_px2,
          known_on_chart ? &*known_on_chart : nullptr, &u, &outcome.trace);
      problem.Unpack(u, &outcome.rotation, &outcome.center, &outcome.model);
      outcome.iterations += summary.iterations;
      outcome.termination = LmStatusText(summary.status);
      // LM's last normal equations, when they are at its answer, are the polish's first (the
      // local ones at the same camera: only the change of variables differs).
      have_normal = summary.local_at_solution;
      if (have_normal) {
        outcome.normal = summary.local;
        ToChart(Eigen::Matrix3d::Identity(), outcome.rotation, &outcome.normal);
      }
      // Not a minimum, and no polish can take it to the cost asked for: the caller reads only
      // that it is above it.
      if (have_normal && summary.status == LmStatus::kTargetOutOfReach) break;
      // Only the known minimum again: the caller keeps that one.
      if (summary.status == LmStatus::kAtKnownMinimum) {
        outcome.at_known_minimum = true;
        break;
      }
    }
    if (!have_normal) {
      have_normal = ComputeNormalEquations(points, pixels, outcome.rotation, outcome.center,
                                           outcome.model, &outcome.normal);
    }
    if (!have_normal) break;
    outcome.converged =
        PolishGaussNewton(points, pixels, &outcome.rotation, &outcome.center, &outcome.model,
                          &outcome.normal, nullptr, scored, &outcome.normal_predicted_step_back,
                          until == PolishUntil::kSettledHalving);
  }
  if (!have_normal) outcome.normal = NormalEquations();
  // A negative aspect is a mirror image (y flipped) and a negative focal length a camera turned
  // half a turn: neither is an answer (the caller refuses).
  outcome.ok = !outcome.at_known_minimum && outcome.normal.jtj.size() > 0 &&
               std::isfinite(outcome.normal.cost) && outcome.model.value[0] > 0.0 &&
               outcome.model.value[1] > 0.0;
  // The polish's result closes the trace, so it ends at the reported RMS.
  outcome.trace.push_back({static_cast<int>(outcome.trace.size()), MicrosecondsSince(start_time),
                           std::sqrt(outcome.normal.cost / static_cast<double>(points.size()))});
  return outcome;
}

}  // namespace internal
}  // namespace camproj

// Least squares on a fixed set of points (private): Levenberg-Marquardt on normal equations
// accumulated point by point (ceres::TinySolver's algorithm, normal_equations.h), then undamped
// Gauss-Newton steps to the minimum, from a start camera and Model in the scene's normalized
// world. Takes the points, their pixels (kCenter), the start and the stopping rules; returns the
// camera with its normal equations and whether it reached the minimum, leaving the refusal to the
// caller. The refinement stage (refine.h) runs it, and so does the start (start.h) to decide a
// DLT that reads the world as mirrored.
#ifndef CAMPROJ_SRC_FIT_LEAST_SQUARES_H_
#define CAMPROJ_SRC_FIT_LEAST_SQUARES_H_

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/normal_equations.h"

namespace camproj {
namespace internal {

// One least-squares refinement: Levenberg-Marquardt, then the Gauss-Newton polish, with its trace.
// LM's stopping rules can fire while it crawls along a curved, nearly flat valley (a nearly
// planar scene with the full model: 100 iterations left it 6 sigma from the optimum; at
// thickness 1e-4 it needs 700). The polish then does not converge, and LM resumes from where it
// stopped; after this many rounds the caller refuses rather than return a camera short of the
// minimum.
inline constexpr int kMaxLeastSquaresRounds = 20;

struct LeastSquaresOutcome {
  bool ok = false;
  bool converged = false;  // the polish settled (see PolishGaussNewton in least_squares.cc)
  Eigen::Matrix3d rotation;
  Eigen::Vector3d center;
  Model model;
  NormalEquations normal;
  // `normal` is one step back, a step the polish took on its prediction of the next (up to 1e-2
  // of the residuals' sigma; least_squares.cc, PolishSteps), not within its convergence test.
  bool normal_predicted_step_back = false;
  // LM stopped at the known minimum's neighbourhood (KnownMinimum): not a minimum of its own.
  bool at_known_minimum = false;
  int iterations = 0;
  std::string termination;
  std::vector<TraceEntry> trace;
};

// Refines the camera point_in_cam = start_rotation * (point - start_center) with `model`'s free
// slots over `points` (normalized world) and `pixels` (kCenter), under options' stopping rules
// (max_iterations, function, gradient and parameter tolerances). Where the polish does not
// settle, LM resumes from where it stopped, up to max_rounds rounds. `ok` is false when a point
// ends behind the camera or the focal length or aspect is not positive (normal is then empty if
// the normal equations could not be formed); `normal` holds ComputeNormalEquations at (or one
// settling step before) the answer. The trace's times count from start_time; it ends at the answer's RMS.
// With a finite `out_of_reach_px2` (a sum of squares in px^2 below which alone the caller reads
// the answer), the own LM stops where even its Gauss-Newton model's minimum is above it (not
// with Refiner::kCeres, which runs to its own end), and neither polish nor further round
// follows: the outcome is then a camera with a cost above out_of_reach_px2 (not a minimum;
// converged false). A linear model's minimum is no bound on the nonlinear one; the caller's
// margin over it is measured where it is used (fit/mirror.cc).
// Where the Gauss-Newton polish may run before LM (not with Refiner::kCeres): LM then runs only
// if the polish does not end at the minimum, and the termination says where it started
// ("Gauss-Newton from a nested minimum" / "... from the closed form") when it does.
enum class PolishFirst {
  kNo,
  // A start at a nested model's minimum (fit/start.h WarmStart): the new minimum is usually a
  // step or two away; the polish's own convergence test decides.
  kFromNestedMinimum,
  // A closed form on many points (the DLT's start is then close): for a camera returned
  // (PolishUntil::kSettled) the polish must settle (a step under 1e-9 px), not only converge to
  // the test's 1e-3 sigma, so that the answer is the one LM would reach to rounding; else LM
  // goes on from where it stopped.
  kFromClosedForm,
};

// How far the polish goes. A camera only scored (its cost, or a rival's camera: a model
// selection's candidate, fit/candidate.h) needs it only to the polish's
// convergence test, the last step under 1e-3 of the residuals' sigma (|J delta|), or the next
// step predicted under it by the last two (least_squares.cc): the step is taken without a pass
// after it, so the sum of squares then exceeds the minimum's by about |J delta|^2 of the step
// after it, under 1e-6 sigma^2, far below any criterion difference read. A camera returned goes
// on until a step settles under 1e-9 px, saving no pass over the points. kSettledHalving (a fit
// returned by FitCamera, refine.cc) also halves a step that overshoots, up to 4 times, where
// kSettled ends the polish there (the readings of other minima and mirrored worlds keep it: on
// the click benchmark halving there changed 1 status and 2 reasons in 2200 scenes).
enum class PolishUntil { kSettled, kConverged, kSettledHalving };

// A refinement's cost lower than another's by at most this fraction is the same (rounding): the
// refinement stage keeps the first of two such (fit/refine.cc).
inline constexpr double kLowerByRounding = 1e-9;

// A minimum already found from another start (its camera, and the sum of squares there in px^2),
// for a refinement that matters only where it ends lower than that minimum (a restart of the
// refinement stage, fit/refine.cc, whose caller keeps the lower cost). The own LM stops where its
// iterate is within kSameBasinFraction of the known minimum's residual sigma of it, in the joint
// sense (|J delta| over the points, J the iterate's Jacobian: sqrt(delta^T J^T J delta) <=
// kSameBasinFraction sqrt(cost / max(1, 2N - p))), and its Gauss-Newton model's minimum is not
// below the known cost (by more than the caller's 1e-9 relative): there the cost is quadratic to
// a part in ~1e4 of the noise's square (the linearity check's curvature shows only at sigmas), so
// LM would converge to the known minimum itself. The outcome is then not ok, and neither polish
// nor further round follows. Not with Refiner::kCeres. (Where the known minimum settled a part in
// 1e8 above the bottom of a valley flat to its rounding, the restart would have settled lower by
// more than kLowerByRounding at the same minimum, within 1e-4 px of it, and replaced it: 4 of
// 46 727 restarts stopped, tests/known_minimum_test.cc. The known one is kept there.)
struct KnownMinimum {
  static constexpr double kSameBasinFraction = 0.1;
  Eigen::Matrix3d rotation;  // point_in_cam = rotation * (point - center)
  Eigen::Vector3d center;
  IntrinsicValues intrinsics;  // every slot's value (Model::value)
  double cost = 0.0;           // sum of squared residuals, px^2
};

LeastSquaresOutcome RefineLeastSquares(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<Eigen::Vector2d>& pixels,
                                       const Eigen::Matrix3d& start_rotation,
                                       const Eigen::Vector3d& start_center, const Model& model,
                                       const FitOptions& options, Clock::time_point start_time,
                                       int max_rounds = kMaxLeastSquaresRounds,
                                       PolishFirst polish_first = PolishFirst::kNo,
                                       PolishUntil until = PolishUntil::kSettled,
                                       double out_of_reach_px2 =
                                           std::numeric_limits<double>::infinity(),
                                       const KnownMinimum* known = nullptr);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_LEAST_SQUARES_H_

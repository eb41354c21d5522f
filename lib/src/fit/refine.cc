#include "fit/refine.h"

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "check.h"
#include "fit/ceres_minimize.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/least_squares.h"
#include "fit/reprojection_error.h"
#include "fit/statistics.h"

namespace camproj {
namespace internal {

namespace {

// Below this many points a DLT start with the principal point free gets a second start from
// the image centre (the DLT's principal point is poorly determined there).
constexpr int kSecondStartBelowPoints = 20;

// `other` replaces `*best` if it is a camera at a lower cost (by more than rounding).
void KeepTheLower(LeastSquaresOutcome other, LeastSquaresOutcome* best) {
  if (other.ok &&
      (!best->ok || other.normal.cost < best->normal.cost * (1.0 - kLowerByRounding))) {
    *best = std::move(other);
  }
}

// `best` as the minimum a restart need not reach again (least_squares.h, KnownMinimum): a
// restart that comes back to it stops in its neighbourhood instead of converging to it again
// (at 6 points, one fit's second start from the image centre ends at the DLT start's minimum in
// 40 of 40 stage-cost scenes). Null where best is no minimum.
std::optional<KnownMinimum> KnownOf(const LeastSquaresOutcome& best) {
  if (!best.ok || !best.converged) return std::nullopt;
  return KnownMinimum{best.rotation, best.center, best.model.value, best.normal.cost};
}

// Refines from `model` (its free values the start) with an SQPnP pose for its pinhole part,
// and makes it `*best` if it ends at a lower cost. The pose is SQPnP's first minimum
// (SqPnpSearch::kFirstMinimum): the intrinsics here are a guess the points need not fit, where
// OpenCV's search goes on through every eigenvector (at 6 points 11 % of one fit); a worse start
// only ends higher and is dropped. Measured on 12000 one fits at 6-10 points: the same minima
// (docs/model-selection.md, session 29).
void RefineAlsoFrom(const Scene& scene, const Model& model, const FitOptions& options,
                    Clock::time_point start_time, PolishUntil until, LeastSquaresOutcome* best) {
  StartCamera start;
  if (!PnpStart(scene.points, scene.pixels, model.ToIntrinsics(), &start,
                SqPnpSearch::kFirstMinimum)) {
    return;
  }
  const std::optional<KnownMinimum> known = KnownOf(*best);
  KeepTheLower(RefineLeastSquares(scene.points, scene.pixels, start.rotation, start.center, model,
                                  options, start_time, kMaxLeastSquaresRounds, PolishFirst::kNo,
                                  until, std::numeric_limits<double>::infinity(),
                                  known ? &*known : nullptr),
               best);
}

// Whether a fitted model has an intrinsic no lens has: pixels more than kMaxAspect times as tall
// as wide (or wide as tall), or the principal point more than an image width or height from the
// image's centre. (Far beyond a projector's lens shift, which puts it at an edge.)
bool UnlikeAnyLens(const Model& model, const ImageSize& size) {
  constexpr double kMaxAspect = 1.5;
  const double aspect = model.value[1];
  if (model.free[1] && !(aspect >= 1.0 / kMaxAspect && aspect <= kMaxAspect)) return true;
  return model.free[2] && !(std::abs(model.value[2] - 0.5 * (size.width - 1)) <= size.width &&
                            std::abs(model.value[3] - 0.5 * (size.height - 1)) <= size.height);
}

// Where the refinement starts with Gauss-Newton steps: from a nested model's minimum (a warm
// start), and from a DLT on at least kSecondStartBelowPoints points, which starts close enough
// that LM's first iterations only repeat what Gauss-Newton does in fewer passes over the points
// (15 % fewer instructions for one fit at 20-100 points; bench --stage-cost --one-fit). Below
// that the DLT's start can be far off (the second start from the image centre is for that), and
// LM's damping keeps the first steps in its basin.
PolishFirst FirstSteps(const Start& start, const Scene& scene) {
  if (start.method == "warm") return PolishFirst::kFromNestedMinimum;
  if (start.at_minimum) return PolishFirst::kFromClosedForm;
  if (start.method == "dlt" && scene.NumPoints() >= kSecondStartBelowPoints) {
    return PolishFirst::kFromClosedForm;
  }
  return PolishFirst::kNo;
}

// True unless `effort` may skip the restarts and `outcome` fits as well as its pixel sigma
// says it can: the sum of squares within the chi-square quantile kConsistentQuantile of its
// residual degrees of freedom.
bool MayBeAboveTheMinimum(const LeastSquaresOutcome& outcome, const Scene& scene,
                          const FitEffort& effort) {
  // Refitting a fit this consistent cannot find one whose criterion the noise could tell apart.
  constexpr double kConsistentQuantile = 0.999;
  if (!outcome.ok || !effort.skip_restarts_when_consistent_at_px) return true;
  const double dof = 2.0 * scene.NumPoints() - 6 - outcome.model.NumFree();
  if (dof < 1.0) return true;
  const double sigma = *effort.skip_restarts_when_consistent_at_px;
  const double chi_square = outcome.normal.cost / (sigma * sigma);
  // The quantile is above the mean dof: most consistent fits need no quantile (a bisection).
  return chi_square > dof && chi_square > ChiSquareQuantile(dof, kConsistentQuantile);
}

// Least squares from the start and, for a DLT on fewer than kSecondStartBelowPoints points with
// the principal point free, also from the image centre; from a focal sweep, also from its other
// valleys; with radial distortion and the principal point free, also from beyond each edge of
// the image: the lowest cost.
LeastSquaresOutcome RefineFromStarts(const Scene& scene, const Start& start,
                                     const FitOptions& options, const FitEffort& effort,
                                     Clock::time_point start_time) {
  // A fit not described (a model selection's candidate) is only scored.
  const PolishUntil until =
      effort.describe ? PolishUntil::kSettledHalving : PolishUntil::kConverged;
  LeastSquaresOutcome best = RefineLeastSquares(
      scene.points, scene.pixels, start.camera.rotation, start.camera.center, start.model, options,
      start_time, kMaxLeastSquaresRounds, FirstSteps(start, scene), until);
  if (start.method == "dlt" && scene.NumPoints() < kSecondStartBelowPoints &&
      scene.model.free[2] && MayBeAboveTheMinimum(best, scene, effort)) {
    // With few points the DLT's principal point can be far off and LM stop in a local minimum
    // (seen at 6 points: cy 96 px for 540). Refine also from the image centre (SQPnP pose for
    // the DLT's focal length there) and keep the lower cost. A candidate of the model selection
    // whose first fit is already consistent with the noise skips it (FitEffort): on the click
    // benchmark the same silent failures and answers but one in 4400 scenes, at 11 / 21 / 24 %
    // fewer instructions for the default path at N = 6 / 8 / 12 (docs/bench/stage_cost.md).
    Model centred = start.model;
    centred.value[2] = scene.model.value[2];
    centred.value[3] = scene.model.value[3];
    RefineAlsoFrom(scene, centred, options, start_time, until, &best);
  }
  // With few points the sweep's RMS over the focal length can have several valleys (seen: 4
  // noise-free points fitted at fx 3292 px, RMS 0.19 px, for a true 1220 px; tests/fit_test.cc
  // NoiseFreeTest GluPerspective): refine also from each other valley's start.
  auto refine_from_sweep_valleys = [&](const std::vector<StartCamera>& valleys) {
    for (const StartCamera& other : valleys) {
      const std::optional<KnownMinimum> known = KnownOf(best);
      KeepTheLower(RefineLeastSquares(scene.points, scene.pixels, other.rotation, other.center,
                                      ProjectOntoModel(start.model, other.intrinsics), options,
                                      start_time, kMaxLeastSquaresRounds, PolishFirst::kNo, until,
                                      std::numeric_limits<double>::infinity(),
                                      known ? &*known : nullptr),
                   &best);
    }
  };
  refine_from_sweep_valleys(start.other_sweep_minima);
  // Refine also from every valley of the focal sweep (square pixels, the image centre), the start
  // at 4-5 points off a plane, where another closed form may have started LM in a local minimum:
  // - a homography for points only nearly coplanar (thinner than kPlanarStartRatio, not
  //   kPlanarRatio: at 4-5 points always), which are not on its plane (seen: 4 noise-free points
  //   fitted at RMS 0.35 px, fx 361 px off, rotated 172 deg; NoiseFreeTest GluPerspective at
  //   seed offset 123);
  // - a DLT on few noisy points whose fit (and second start) ended with an intrinsic no lens has
  //   (seen at 6 points, 2-5 px noise, focal + aspect + principal point free: aspect 0.56-2.3,
  //   a principal point 1.9-4.5 image sizes off centre, rms 7.5 px where the truth's is 3.0; 4 of
  //   8000 scenes fitted worse than the truth, FitTest.NoisySixPointScenesAreNotCalledMirrored).
  // Not for a candidate of the model selection already consistent with the noise, as the
  // restarts above (for the DLT's: 10 % more instructions for the default path at 6 points).
  const bool nearly_planar = start.method == "homography" && !scene.planar;
  const bool unlike_any_lens =
      start.method == "dlt" && best.ok && UnlikeAnyLens(best.model, scene.image_size);
  if ((nearly_planar || unlike_any_lens) && scene.model.free[0] &&
      scene.NumPoints() < kSecondStartBelowPoints && MayBeAboveTheMinimum(best, scene, effort)) {
    StartCamera sweep;
    std::vector<StartCamera> valleys;
    if (FocalSweepStart(scene.points, scene.pixels, scene.model.ToIntrinsics(),
                        scene.model.value[1], scene.image_size.width, &sweep, &valleys)) {
      valleys.insert(valleys.begin(), sweep);
      refine_from_sweep_valleys(valleys);
    }
  }
  const bool distortion_free = scene.model.free[5] || scene.model.free[6];
  if (distortion_free && scene.model.free[2] && MayBeAboveTheMinimum(best, scene, effort)) {
    // A principal point far off centre (a projector's lens shift, a cropped image) makes the
    // radial distortion one-sided across the image, and LM from a principal point on the other
    // side can stop in a minimum where k2 bends to make up for it (seen noise-free: cx 260 px
    // left of a 3041 x 373 image fitted at 1462 px with k2 -0.32, RMS 8 px; tests/fit_test.cc
    // NoiseFreeTest, 7 of 1230 distorted cameras). Refine also from a principal point a quarter
    // of the image beyond each edge's midpoint, without distortion: one of them is on the
    // right side.
    constexpr double kBeyondEdge = 0.25;
    const Model from = best.ok ? best.model : start.model;
    for (const Eigen::Vector2d& principal_point : EdgeMidpoints(scene.image_size, kBeyondEdge)) {
      Model model = from;
      model.value[2] = principal_point.x();
      model.value[3] = principal_point.y();
      if (model.free[5]) model.value[5] = 0.0;
      if (model.free[6]) model.value[6] = 0.0;
      RefineAlsoFrom(scene, model, options, start_time, until, &best);
    }
  }
  return best;
}

// Without a loss: Levenberg-Marquardt on normal equations accumulated point by point
// (MinimizeLevenbergMarquardt: TinySolver's algorithm) on the chart R = exp(omega) R_start, then
// the Gauss-Newton polish; refused unless it reached the minimum.
RefinedCamera RefineWithoutLoss(const Scene& scene, const Start& start, const FitOptions& options,
                                const FitEffort& effort, Clock::time_point start_time) {
  LeastSquaresOutcome best = RefineFromStarts(scene, start, options, effort, start_time);
  if (!best.ok) {
    if (best.normal.jtj.size() > 0 && best.model.value[1] <= 0.0) {
      throw SceneError(SceneError::Reason::kMirroredWorld,
                       "the best camera has a negative aspect (fy < 0): the points are seen as "
                       "through a mirror, i.e. the world frame is left-handed",
                       kFlipAnAxis);
    }
    throw SceneError(SceneError::Reason::kPointsBehindCamera,
                     "the refined camera has points behind it (or a negative focal length): "
                     "the correspondences are inconsistent (mismatched or mis-clicked points)",
                     "Check the correspondences or use --ransac");
  }
  if (!best.converged) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     Concat("the refinement did not reach the minimum in ", best.iterations,
                            " iterations: the points barely determine the model (a nearly flat, "
                            "curved valley of cameras that fit about equally well; ",
                            best.termination, ")"),
                     "Fix intrinsics (e.g. --model focal), or add points spread further in depth");
  }
  RefinedCamera refined;
  refined.rotation = best.rotation;
  refined.center = best.center;
  refined.model = std::move(best.model);
  refined.normal = std::move(best.normal);
  refined.normal_predicted_step_back = best.normal_predicted_step_back;
  refined.iterations = best.iterations;
  refined.refiner = options.refiner == Refiner::kCeres ? "ceres" : "levenberg-marquardt";
  refined.termination = std::move(best.termination);
  refined.trace = std::move(best.trace);
  return refined;
}

// With a robust loss: Ceres (MinimizeWithCeres), which the own LM does not replace there
// (a robust loss reweights each point's residual).
RefinedCamera RefineRobust(const Scene& scene, const Start& start, const FitOptions& options,
                           Clock::time_point start_time) {
  RefinedCamera refined;
  refined.rotation = start.camera.rotation;
  refined.center = start.camera.center;
  refined.model = start.model;
  const std::unique_ptr<ceres::LossFunction> loss = LossOf(options);
  const CeresSummary summary =
      MinimizeWithCeres(scene.points, scene.pixels, loss.get(), options, start_time,
                        &refined.rotation, &refined.center, &refined.model, &refined.trace);
  if (summary.termination_type == ceres::FAILURE) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the refinement failed: " + summary.termination, "Check the correspondences");
  }
  if (summary.termination_type == ceres::NO_CONVERGENCE) {
    // As for least squares: never a camera short of the minimum.
    throw SceneError(SceneError::Reason::kDegenerate,
                     Concat("the robust refinement did not converge in ", options.max_iterations,
                            " iterations (", summary.termination, "): the points barely determine "
                            "the model"),
                     "Fix intrinsics, add points, or raise --max-iterations");
  }
  refined.iterations = summary.iterations;
  refined.refiner = Concat("ceres, ", options.loss == LossType::kHuber ? "huber" : "cauchy",
                           " loss ", options.loss_scale_px, " px");
  refined.termination = summary.termination;
  return refined;
}

}  // namespace

RefinedCamera RefineCamera(const Scene& scene, const Start& start, const FitOptions& options,
                           const FitEffort& effort, Clock::time_point start_time) {
  if (options.refine && options.loss == LossType::kNone) {
    return RefineWithoutLoss(scene, start, options, effort, start_time);
  }
  RefinedCamera refined;
  if (options.refine) {
    refined = RefineRobust(scene, start, options, start_time);
  } else {
    refined.rotation = start.camera.rotation;
    refined.center = start.camera.center;
    refined.model = start.model;
    refined.refiner = "none";
    refined.termination = "not refined (closed-form start only)";
  }
  // A point behind the camera leaves them empty: the assessment refuses it.
  ComputeNormalEquations(scene.points, scene.pixels, refined.rotation, refined.center,
                         refined.model, &refined.normal);
  return refined;
}

}  // namespace internal
}  // namespace camproj

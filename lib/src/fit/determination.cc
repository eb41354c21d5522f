#include "fit/determination.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "camproj/conventions.h"
#include "camproj/intrinsics.h"
#include "camproj/pose.h"
#include "fit/common.h"
#include "fit/gate.h"
#include "fit/pixel_uncertainty.h"
#include "fit/statistics.h"

namespace camproj {
namespace internal {

namespace {

// A rival's shift of a test point counts beyond this many of its own sigmas there.
constexpr double kRivalSigmas = 3.0;
// The rivals are compared over the points' box widened so that no side is shorter than this
// fraction of its longest. Clicked corners often lie on one or two faces of an object that
// extends behind them; a model that fits them as well as the chosen one but has the wrong lens
// shows it there. Measured on the click benchmark (bench --clicks, 2200 scenes): 0.25 removes 3
// of 15 silent failures for 4 of 1554 answers; 0.5 costs 9 answers more for none further; the
// same widening for the uncertainty bound as well costs 16 answers more and removes none.
constexpr double kRivalBoxThickness = 0.25;

// The model-averaged camera (DeterminationCheck::averaged_sigma_px) counts the unmirrored rivals
// up to this far above the returned model's BIC: weight exp(-13.8 / 2) = 1e-3 of its.
constexpr double kAveragedCriterion = 13.8;

// The chosen model refitted from another start (fit/other_minima.h) that lands within this of
// the returned camera at every test point has found the same minimum again, not another: LM's
// runs into one minimum agree to ~1e-12 px (seen: 2.5e-12 px, then named as the rival that
// "moves a point by 2.5e-12 px") near the origin; far from it both cameras are rounded in world
// coordinates, by up to the 1e-5 px that CheckOffset (fit/scene.h) accepts at the fitted points
// (seen: 1.4e-6 px at 1.1e6 scene sizes, where a bound of 1e-6 px named the same minimum as
// another), and by more at test points beyond them (seen: 1.2e-4 px at 2.5e7 scene sizes, six
// noise-free points, where a bound of kMinNoisePx = 1e-4 px named the same minimum as another
// and refused the scene as ambiguous while the unmoved one was answered;
// FitAutoStress.TwoThousandAdversarialScenesKeepTheContract at seed offset 123456). The bound
// is ten times the smallest pixel noise the selection believes: a hundred times the rounding at
// the fitted points, and far below any reading of clicked pixels.
constexpr double kSameMinimumPx = 10.0 * kMinNoisePx;

// A point whose leverage is within this of 1 in some direction is one the others cannot predict
// there (their fit moves with it): its leave-one-out error counts as at this leverage, so that
// PRESS stays finite and one such point does not decide it alone.
constexpr double kMinFreeLeverage = 1e-3;

// Up to this many kept points (AutoFitOptions::exhaustive_max_points' default: a handful of
// clicks, where the prior rather than the data sets the noise and BIC's choice is weak evidence),
// the rival that cross-validates better than the chosen model loses its 3-sigma exemption.
// Measured on the click benchmark: docs/model-selection.md, "Rules tried".
constexpr size_t kCrossValidationMaxPoints = 12;

// The same handful of points cannot tell a projector's lens shift from a longer focal length and
// a tilt: pose + focal with the principal point at the image centre explains 7 clicks of a
// projector whose principal point is 250 px below it within their noise, and is 12-35 px off at
// the object's corners beyond them. So an answer that leaves the principal point at the centre
// must agree with the model that frees it (when that fits about as well) within the bound,
// without the 3-sigma exemption, over the rivals' box scaled by this about its centre: an
// object extends beyond its clicked corners. Measured on the click benchmark
// (docs/model-selection.md, "The lens-shift rival"): silent failures 4 -> 2 (development), 16 ->
// 9 (held out), 5 -> 4 (scenes 300-499, run once after the rule was fixed), for 4, 7 and 6 right
// answers (2.6-9.8 px off, none of them with the principal point free).
constexpr double kLensShiftBoxScale = 2.0;

// Beyond kCrossValidationMaxPoints, an exempt rival whose model nests the chosen one is not
// judged point by point where its fit lowers the sum of squares by at most this many noise
// variances (NestedRivalWithinItsNoise: then, linearized, it moves no point by more than
// kNestedRivalBound of its own sigmas there, a third of kRivalSigmas). Measured over 9252
// nested rivals (bench --stage-cost at N = 6-1000, bench --clicks): among those the rule skips
// at more than 12 points, the largest shift in the rival's sigmas was 1.15 (at 7-12 points,
// where the rule is not used, 1.67).
constexpr double kNestedRivalBound = 1.0;

// `camera` for the world point_in_world = origin + unit * y: the same pixel for y as `camera`
// gives for the point. (Perspective: the cam-frame point scales by unit, which a pinhole does not
// see; orthographic: fx, fy and skew are px per world unit.)
Camera InUnitWorld(const Camera& camera, const Eigen::Vector3d& origin, double unit) {
  Camera moved = camera;
  moved.cam_from_world.translation = (camera.cam_from_world * origin) / unit;
  moved.z_near /= unit;
  moved.z_far /= unit;
  if (camera.projection == Projection::kOrthographic) {
    moved.intrinsics.fx *= unit;
    moved.intrinsics.fy *= unit;
    moved.intrinsics.skew *= unit;
  }
  return moved;
}

// The kept points in their centred, unit-RMS world (the fitter's: in world units squared
// lengths overflow or underflow beyond ~1e+-154), and `camera` there.
struct UnitWorld {
  Eigen::Vector3d origin;  // the points' centroid, world
  double unit = 1.0;       // their RMS distance from it, world units
  std::vector<Eigen::Vector3d> points;
  Camera camera;
};

UnitWorld ToUnitWorld(const Camera& camera, const std::vector<Eigen::Vector3d>& kept_points) {
  UnitWorld world;
  world.origin = Centroid(kept_points);
  Eigen::MatrixXd centred(kept_points.size(), 3);
  for (size_t i = 0; i < kept_points.size(); ++i) {
    centred.row(i) = (kept_points[i] - world.origin).transpose();
  }
  world.unit = RmsRowLength(centred);
  world.points.resize(kept_points.size());
  for (size_t i = 0; i < kept_points.size(); ++i) {
    world.points[i] = centred.row(i).transpose() / world.unit;
  }
  world.camera = InUnitWorld(camera, world.origin, world.unit);
  return world;
}

// A symmetric 2 x 2 matrix's larger eigenvalue, in closed form: mean + radius (EigenOf's).
double LargerEigenvalueOf(const Eigen::Matrix2d& h) {
  return 0.5 * (h(0, 0) + h(1, 1)) + std::hypot(0.5 * (h(0, 0) - h(1, 1)), h(0, 1));
}

// A symmetric 2 x 2 matrix's eigenvalues and the larger one's unit eigenvector, in closed form:
// mean +- radius, and (h01, larger - h00) or, where that vanishes (a diagonal matrix with
// h00 >= h11), (larger - h11, h01) = (2 radius, 0), the longer of the two.
struct SymmetricEigen2 {
  double larger = 0.0;
  double smaller = 0.0;
  Eigen::Vector2d larger_vector = Eigen::Vector2d(1.0, 0.0);
};
SymmetricEigen2 EigenOf(const Eigen::Matrix2d& h) {
  const double mean = 0.5 * (h(0, 0) + h(1, 1));
  const double half_difference = 0.5 * (h(0, 0) - h(1, 1));
  const double radius = std::hypot(half_difference, h(0, 1));
  SymmetricEigen2 eigen;
  eigen.larger = mean + radius;
  eigen.smaller = mean - radius;
  const Eigen::Vector2d a(h(0, 1), radius - half_difference);
  const Eigen::Vector2d b(radius + half_difference, h(0, 1));
  const Eigen::Vector2d v = a.squaredNorm() > b.squaredNorm() ? a : b;
  if (v.norm() > 0.0) eigen.larger_vector = v.normalized();
  return eigen;
}

// The fitted point whose own pixel the fit follows most: the largest eigenvalue of its hat block
// over the points, with its eigenvector (PointReliability; `point` its index among the fitted
// points). `hats`: the blocks already computed (SigmasAt), one slot per fitted point.
PointReliability LeastChecked(const PixelUncertainty& uncertainty,
                              const std::vector<std::optional<Eigen::Matrix2d>>& hats) {
  PointReliability least;
  least.checked = true;
  for (size_t i = 0; i < hats.size(); ++i) {
    const Eigen::Matrix2d h = hats[i] ? *hats[i] : uncertainty.HatAt(i);
    // The larger eigenvalue alone first: the eigenvector only for a new least checked point.
    const double redundancy = std::max(0.0, 1.0 - LargerEigenvalueOf(h));
    if (least.point >= 0 && !(redundancy < least.redundancy)) continue;
    least.point = static_cast<int>(i);
    least.redundancy = redundancy;
    least.direction = EigenOf(h).larger_vector;
  }
  return least;
}

// SceneTestPoints with, for each, the index of the fitted point it is (-1: a corner or face
// centre of the box), whose Jacobian the uncertainty already has.
struct TestPoints {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> fitted;
};

// Whether the image shows `point_in_world` at `pixel` (its pixel under `camera`): beyond the first
// fold of the radial distortion (intrinsics.h) the model folds the image over, and a point there
// lands on a pixel whose ray is another (seen: a box corner 20 degrees outside a 60 degree view
// with k1 = -0.2 judged inside the image, at 20 times the uncertainty of any point seen).
bool BeforeTheFold(const Camera& camera, const Eigen::Vector3d& point_in_world,
                   const Eigen::Vector2d& pixel) {
  const Intrinsics& k = camera.intrinsics;
  if (k.k1 == 0.0 && k.k2 == 0.0) return true;
  // The ray's inversion converges to ~1e-15 in normalized units; the other branch is far.
  constexpr double kSameRay = 1e-9;
  const Eigen::Vector3d in_cam = camera.cam_from_world * point_in_world;
  const Eigen::Vector2d normalized = in_cam.head<2>() / in_cam.z();
  try {
    const Eigen::Vector3d ray = CamRayFromPixel(k, pixel);  // kCenter, as PixelFromWorld's
    return (ray.head<2>() - normalized).norm() <= kSameRay * (1.0 + normalized.norm());
  } catch (const std::domain_error&) {
    return false;  // at or beyond the fold's distorted radius
  }
}

TestPoints TestPointsOf(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                        double min_thickness,
                        const std::vector<Eigen::Vector3d>& object_points = {},
                        double box_scale = 1.0) {
  std::vector<Eigen::Vector3d> box;  // corners, then face centres
  if (!points.empty()) {
    const Eigen::Vector3d mean = Centroid(points);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& x : points) scatter += (x - mean) * (x - mean).transpose();
    const Eigen::Matrix3d axes =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3d& x : points) {
      const Eigen::Vector3d c = axes.transpose() * (x - mean);
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    const Eigen::Vector3d mid = 0.5 * (lo + hi);
    const double min_half_side = 0.5 * min_thickness * (hi - lo).maxCoeff();
    lo = lo.cwiseMin(mid - Eigen::Vector3d::Constant(min_half_side));
    hi = hi.cwiseMax(mid + Eigen::Vector3d::Constant(min_half_side));
    lo = mid + box_scale * (lo - mid);
    hi = mid + box_scale * (hi - mid);
    for (int bits = 0; bits < 8; ++bits) {  // corners
      const Eigen::Vector3d c((bits & 1) ? hi.x() : lo.x(), (bits & 2) ? hi.y() : lo.y(),
                              (bits & 4) ? hi.z() : lo.z());
      box.push_back(mean + axes * c);
    }
    for (int axis = 0; axis < 3; ++axis) {  // face centres
      for (const double side : {lo(axis), hi(axis)}) {
        Eigen::Vector3d c = mid;
        c(axis) = side;
        box.push_back(mean + axes * c);
      }
    }
  }
  // The fitted points, the box, the object points, in that order, where the image shows them
  // (reserved once: the fitted points can be millions).
  TestPoints inside;
  const size_t total = points.size() + box.size() + object_points.size();
  inside.points.reserve(total);
  inside.fitted.reserve(total);
  auto consider = [&](const Eigen::Vector3d& x, int fitted) {
    const std::optional<Eigen::Vector2d> u = PixelFromWorld(camera, x);
    if (u && PixelInImage(*u, camera.image_size) && BeforeTheFold(camera, x, *u)) {
      inside.points.push_back(x);
      inside.fitted.push_back(fitted);
    }
  };
  for (size_t k = 0; k < points.size(); ++k) consider(points[k], static_cast<int>(k));
  for (const Eigen::Vector3d& x : box) consider(x, -1);
  for (const Eigen::Vector3d& x : object_points) consider(x, -1);
  return inside;
}

// TestPointsOf, or the fitted points themselves when none of the box is in the image.
TestPoints TestPointsOrFitted(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                              double min_thickness,
                              const std::vector<Eigen::Vector3d>& object_points) {
  TestPoints test = TestPointsOf(camera, points, min_thickness, object_points);
  if (test.points.empty()) {
    test.points = points;
    test.fitted.resize(points.size());
    std::iota(test.fitted.begin(), test.fitted.end(), 0);
  }
  return test;
}

// The sigmas at the test points; with `fitted_hats` not null, also the hat block of every
// fitted point among them, at its index (the others left as they are).
std::vector<double> SigmasAt(const PixelUncertainty& uncertainty, const TestPoints& test,
                             std::vector<std::optional<Eigen::Matrix2d>>* fitted_hats = nullptr) {
  std::vector<double> sigmas;
  sigmas.reserve(test.points.size());
  for (size_t i = 0; i < test.points.size(); ++i) {
    const int fitted = test.fitted[i];
    if (fitted >= 0 && fitted_hats != nullptr) {
      Eigen::Matrix2d hat;
      sigmas.push_back(uncertainty.SigmaAndHatAtFitted(fitted, &hat));
      (*fitted_hats)[fitted] = hat;
    } else {
      sigmas.push_back(fitted >= 0 ? uncertainty.SigmaAtFitted(fitted)
                                   : uncertainty.SigmaAt(test.points[i]));
    }
  }
  return sigmas;
}

// PRESS, the sum over the fitted points of the squared error with which the camera fitted to the
// others predicts each (Allen 1974), from the hat matrix: for least squares, linearized, that
// error is (I - H_ii)^-1 r_i (Cook & Weisberg, Residuals and Influence in Regression, 2.2). r_i:
// `camera`'s pixel of point i minus `observed` i. +inf where a point has no pixel.
double PredictionSumOfSquares(const PixelUncertainty& uncertainty, const Camera& camera,
                              const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector2d>& observed) {
  double press = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Eigen::Vector2d> pixel = PixelFromWorld(camera, points[i]);
    if (!pixel) return std::numeric_limits<double>::infinity();
    // The residual along each eigenvector of I - H_ii (the other is the larger's turned by 90
    // degrees), over its eigenvalue.
    const SymmetricEigen2 free = EigenOf(Eigen::Matrix2d::Identity() - uncertainty.HatAt(i));
    const Eigen::Vector2d r = *pixel - observed[i];
    const Eigen::Vector2d& v = free.larger_vector;
    const double along_larger = v.dot(r) / std::max(free.larger, kMinFreeLeverage);
    const double along_smaller =
        (v.x() * r.y() - v.y() * r.x()) / std::max(free.smaller, kMinFreeLeverage);
    press += along_larger * along_larger + along_smaller * along_smaller;
  }
  return press;
}

// A rival of the returned camera with its uncertainty at the kept points, in the unit world.
struct FittedRival {
  const Rival* rival;
  Camera camera;
  PixelUncertainty uncertainty;
  bool about_as_well;  // within kEqualFitCriterion: the rival check's
  double weight;       // in the model average, relative to the returned model's 1 (0: not in it)
};

// The rival that frees the principal point where the selection left it at the image centre (a
// perspective answer; not one whose principal point the caller fixed, which no rival frees): the
// lowest criterion among the unmirrored `counted` rivals with it free, or null.
const FittedRival* LensShiftRival(const Selection& selection,
                                  const std::vector<const FittedRival*>& counted) {
  if (selection.fit.camera.projection != Projection::kPerspective ||
      selection.options.principal_point.IsFree()) {
    return nullptr;
  }
  const FittedRival* best = nullptr;
  for (const FittedRival* c : counted) {
    const Rival& rival = *c->rival;
    if (rival.mirrored_world || rival.same_model || !rival.options.principal_point.IsFree()) {
      continue;
    }
    if (!best || rival.criterion < best->rival->criterion) best = c;
  }
  return best;
}

// At a handful of points, the unmirrored rival that predicts each kept point from the others
// better than the chosen model and every other such rival (PRESS), or null: as good a reading
// of the data, so its shift counts even within its own 3 sigma.
const FittedRival* RivalPredictingBetter(const Selection& selection, const Camera& camera,
                                         const PixelUncertainty& uncertainty,
                                         const std::vector<Eigen::Vector3d>& points,
                                         const std::vector<const FittedRival*>& counted) {
  if (points.size() > kCrossValidationMaxPoints ||
      selection.fit.residuals_px.size() != points.size()) {
    return nullptr;
  }
  std::vector<Eigen::Vector2d> observed(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    observed[i] = *PixelFromWorld(camera, points[i]) - selection.fit.residuals_px[i];
  }
  const FittedRival* predicts_better = nullptr;
  double best = PredictionSumOfSquares(uncertainty, camera, points, observed);
  for (const FittedRival* c : counted) {
    if (c->rival->mirrored_world) continue;
    const double press = PredictionSumOfSquares(c->uncertainty, c->camera, points, observed);
    if (press < best) {
      best = press;
      predicts_better = c;
    }
  }
  return predicts_better;
}

// `around` with the corners and face centres of the box the rivals are judged over
// (kRivalBoxThickness) scaled by `scale` about its centre, where the image shows them.
TestPoints WithScaledBox(TestPoints around, const Camera& camera,
                         const std::vector<Eigen::Vector3d>& points, double scale) {
  const TestPoints scaled = TestPointsOf(camera, points, kRivalBoxThickness, {}, scale);
  for (size_t i = 0; i < scaled.points.size(); ++i) {
    if (scaled.fitted[i] >= 0) continue;  // the fitted points are in `around` already
    around.points.push_back(scaled.points[i]);
    around.fitted.push_back(-1);
  }
  return around;
}

// The largest distance between where `camera` and a rival put a test point (infinite where the
// rival has it behind), and where; within the rival's kRivalSigmas only if not `exempt`.
struct RivalShift {
  double px = 0.0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // the returned camera's
  std::vector<double> rival_sigmas;  // the rival's sigma at each test point
};
RivalShift ShiftOf(const Camera& camera, const FittedRival& rival, const Eigen::Vector3d& flip,
                   const TestPoints& test, bool exempt) {
  TestPoints their_test = test;  // as the rival sees them (a mirrored reading: z negated)
  for (Eigen::Vector3d& x : their_test.points) x = flip.asDiagonal() * x;
  RivalShift shift;
  shift.rival_sigmas = SigmasAt(rival.uncertainty, their_test);
  const std::vector<double>& rival_sigmas = shift.rival_sigmas;
  for (size_t i = 0; i < test.points.size(); ++i) {
    const std::optional<Eigen::Vector2d> ours = PixelFromWorld(camera, test.points[i]);
    const std::optional<Eigen::Vector2d> theirs = PixelFromWorld(rival.camera, their_test.points[i]);
    const double d = theirs ? (*theirs - *ours).norm() : std::numeric_limits<double>::infinity();
    if ((!exempt || d > kRivalSigmas * rival_sigmas[i]) && d > shift.px) {
      shift.px = d;
      shift.pixel = *ours;
    }
  }
  return shift;
}

// Whether `outer` frees every parameter `inner` frees and fixes the others as `inner` does: the
// chosen model is then a point of the rival's parameter space.
bool Nests(const FitOptions& outer, const FitOptions& inner) {
  if (outer.projection != inner.projection || outer.known_intrinsics || inner.known_intrinsics) {
    return false;
  }
  auto contains = [](const ParameterMode& o, const ParameterMode& i) {
    return o.IsFree() || (o.kind == i.kind && o.value == i.value && o.value2 == i.value2);
  };
  return contains(outer.focal, inner.focal) && contains(outer.aspect, inner.aspect) &&
         contains(outer.principal_point, inner.principal_point) &&
         contains(outer.skew, inner.skew) && contains(outer.k1, inner.k1) &&
         contains(outer.k2, inner.k2);
}

// Whether a rival whose model nests the chosen one (Nests) is, linearized, within its own noise
// everywhere. With J^T J the rival's normal matrix at its optimum and delta the step from it to
// the chosen camera (a point of its space), a point x moves by |J_x delta| <= |J_x (J^T J)^-1/2|
// |(J^T J)^1/2 delta| = (sigma_x / sigma) sqrt(delta^T J^T J delta) (Cauchy-Schwarz; sigma_x its
// ReprojectionSigmaPx there), and delta^T J^T J delta is the drop in the sum of squares from the
// chosen fit to the rival's. So a drop of at most (kNestedRivalBound sigma)^2 moves no point by
// more than kNestedRivalBound sigma_x. `chosen_sum_squares`: the chosen fit's (px^2).
bool NestedRivalWithinItsNoise(const FitOptions& chosen, double chosen_sum_squares,
                               const Rival& rival, double sigma) {
  if (rival.mirrored_world || rival.same_model || rival.sum_squares_px2 < 0.0 ||
      !Nests(rival.options, chosen)) {
    return false;
  }
  const double drop = chosen_sum_squares - rival.sum_squares_px2;
  // A rival above the chosen fit is at another minimum: not the linearized picture.
  return drop >= 0.0 && drop <= kNestedRivalBound * kNestedRivalBound * sigma * sigma;
}

// True if `other` puts every point of `test` within kSameMinimumPx of where `camera` does.
bool SameMinimum(const Camera& camera, const Camera& other, const std::vector<Eigen::Vector3d>& test) {
  for (const Eigen::Vector3d& x : test) {
    const std::optional<Eigen::Vector2d> ours = PixelFromWorld(camera, x);
    const std::optional<Eigen::Vector2d> theirs = PixelFromWorld(other, x);
    if (!ours || !theirs || !((*theirs - *ours).norm() <= kSameMinimumPx)) return false;
  }
  return true;
}

// The rivals that fit about as well (the rival check's) or are unmirrored within
// kAveragedCriterion (the model average's), each with its uncertainty at the kept points (a
// mirrored reading sees them with z negated); one with a kept point behind it is no reading of
// them, nor a refit into the returned minimum (the same at every point of `test`). In
// `unit_world`, which must outlive them (their uncertainties read its points).
std::vector<FittedRival> FittedRivals(const Selection& selection, const UnitWorld& unit_world,
                                      double sigma, const std::vector<Eigen::Vector3d>& test) {
  std::vector<FittedRival> fitted;
  fitted.reserve(selection.rivals.size());  // moved in once, never copied
  for (const Rival& rival : selection.rivals) {
    const double excess = rival.criterion - selection.criterion;
    const bool about_as_well = rival.mirrored_world || rival.same_model
                                   ? excess <= kEqualFitCriterion
                                   : std::abs(excess) <= kEqualFitCriterion;
    const bool averaged = !rival.mirrored_world && excess >= -kEqualFitCriterion &&
                          excess <= kAveragedCriterion;
    if (!about_as_well && !averaged) continue;
    // A mirrored reading sees every point, test points included, with z negated: in the unit
    // world about the centroid, whose mirror image is the mirrored points' centroid.
    const Eigen::Vector3d flip(1.0, 1.0, rival.mirrored_world ? -1.0 : 1.0);
    const Camera rival_camera =
        InUnitWorld(rival.camera, flip.asDiagonal() * unit_world.origin, unit_world.unit);
    if (rival.same_model && SameMinimum(unit_world.camera, rival_camera, test)) continue;
    // A fitted rival's uncertainty from its fit's own normal equations: no pass over the points
    // (but where they are a predicted step back: least_squares.cc, kPredictedStepFraction).
    const bool from_its_fit = rival.linearization != nullptr &&
                              !rival.linearization->predicted_step_back &&
                              !rival.mirrored_world &&
                              rival.camera.projection == Projection::kPerspective;
    try {
      fitted.push_back(
          {&rival, rival_camera,
           from_its_fit ? PixelUncertainty(*rival.linearization, unit_world.origin,
                                           unit_world.unit, unit_world.points, sigma)
                        : PixelUncertainty(rival_camera, rival.options, unit_world.points, sigma,
                                           rival.mirrored_world),
           about_as_well, averaged ? std::exp(-0.5 * excess) : 0.0});
    } catch (const std::invalid_argument&) {
    }
  }
  return fitted;
}

// The model average (DeterminationCheck::averaged_sigma_px): at each point of `around` that is
// not a fitted one, the mixture of `camera` (weight 1) and every rival with a weight, each with
// its own sigma there. Not at the fitted points: every model in the average is pinned there by
// the point itself, within a few sigmas of its noise (a rival 5 px from the returned camera at one
// adds about 25 / sigma^2 to its sum of squares, beyond kAveragedCriterion at the 1 px prior), and
// N of them would cost N sigmas per model (the click benchmark's answers are the same without
// them). A rival that puts a point behind it makes the spread infinite there.
// `known`: sigmas already computed at the first points of `around` (the same numbers SigmasAt
// gives): known[0] the returned camera's, known[1 + m] rival m's; a shorter or empty vector
// where fewer or none are known.
void AverageOverModels(const Camera& camera, const PixelUncertainty& uncertainty,
                       const std::vector<FittedRival>& rivals, const TestPoints& around,
                       const std::vector<std::vector<double>>& known,
                       DeterminationCheck* check) {
  double total_weight = 1.0;
  for (const FittedRival& r : rivals) total_weight += r.weight;
  if (total_weight == 1.0) return;
  TestPoints beyond;
  std::vector<size_t> index;  // of each point of `beyond` in `around`
  for (size_t i = 0; i < around.points.size(); ++i) {
    if (around.fitted[i] >= 0) continue;
    beyond.points.push_back(around.points[i]);
    beyond.fitted.push_back(-1);
    index.push_back(i);
  }
  // One model's sigmas at `beyond`: read where known, else computed.
  auto sigmas_of = [&](const PixelUncertainty& model, size_t slot) {
    // `index` increases: its last entry decides.
    const bool all_known =
        slot < known.size() && (index.empty() || index.back() < known[slot].size());
    if (!all_known) return SigmasAt(model, beyond);
    std::vector<double> read(index.size());
    for (size_t j = 0; j < index.size(); ++j) read[j] = known[slot][index[j]];
    return read;
  };
  const std::vector<double> own_sigmas = sigmas_of(uncertainty, 0);
  std::vector<std::vector<double>> their_sigmas(rivals.size());
  for (size_t m = 0; m < rivals.size(); ++m) {
    if (rivals[m].weight > 0.0) their_sigmas[m] = sigmas_of(rivals[m].uncertainty, 1 + m);
  }
  std::vector<Eigen::Vector2d> pixels(rivals.size());
  for (size_t i = 0; i < beyond.points.size(); ++i) {
    const Eigen::Vector3d& x = beyond.points[i];
    const Eigen::Vector2d ours = *PixelFromWorld(camera, x);  // a test point is in its image
    Eigen::Vector2d mean = ours / total_weight;
    const FittedRival* behind = nullptr;
    for (size_t m = 0; m < rivals.size() && !behind; ++m) {
      if (rivals[m].weight == 0.0) continue;
      const std::optional<Eigen::Vector2d> theirs = PixelFromWorld(rivals[m].camera, x);
      if (!theirs) {
        behind = &rivals[m];
      } else {
        pixels[m] = *theirs;
        mean += rivals[m].weight / total_weight * *theirs;
      }
    }
    double variance = std::numeric_limits<double>::infinity();
    const FittedRival* most = behind;
    if (!behind) {
      variance = (own_sigmas[i] * own_sigmas[i] + (ours - mean).squaredNorm()) / total_weight;
      double largest = 0.0;
      for (size_t m = 0; m < rivals.size(); ++m) {
        if (rivals[m].weight == 0.0) continue;
        const double term =
            rivals[m].weight / total_weight *
            (their_sigmas[m][i] * their_sigmas[m][i] + (pixels[m] - mean).squaredNorm());
        variance += term;
        if (term > largest) {
          largest = term;
          most = &rivals[m];
        }
      }
    }
    if (!(std::sqrt(variance) <= check->averaged_sigma_px)) {
      check->averaged_sigma_px = std::sqrt(variance);
      check->averaged_worst_pixel = ours;
      check->averaged_rival = most ? most->rival->model : "";
    }
  }
}

// DeterminationCheck::summary of a check whose numbers are set; pixels in `origin_convention`.
std::string SummaryOf(const DeterminationCheck& check, bool with_object_points,
                      PixelOrigin origin_convention) {
  std::string summary = "uncertain by up to " + Px(check.max_sigma_px) +
                        " (1 sigma) over the box the points span" +
                        (with_object_points ? " and the object points" : "") +
                        ", most near pixel " + PixelText(check.worst_pixel, origin_convention) +
                        "; bound " + Px(check.bound_px);
  if (check.averaged_sigma_px > 0.0) {
    summary += "; averaged over the models fitted (BIC weights), " +
               (std::isfinite(check.averaged_sigma_px)
                    ? Px(check.averaged_sigma_px)
                    : std::string("a point behind one of their cameras")) +
               " near pixel " + PixelText(check.averaged_worst_pixel, origin_convention) +
               (check.averaged_rival.empty() ? "" : ", most from " + check.averaged_rival);
  }
  if (!check.rival.empty()) {
    summary += "; " + check.rival + " fits about as well" +
               (check.rival_predicts_better ? ", predicts each point from the others better,"
                                            : "") +
               " and moves a point by " + Px(check.rival_shift_px);
  }
  return summary;
}

}  // namespace

std::vector<Eigen::Vector3d> SceneTestPoints(const Camera& camera,
                                             const std::vector<Eigen::Vector3d>& points,
                                             double min_thickness) {
  return TestPointsOf(camera, points, min_thickness).points;
}

std::vector<double> ReprojectionSigmaPx(const Camera& camera, const FitOptions& model,
                                        const std::vector<Eigen::Vector3d>& fitted_points,
                                        double sigma_px,
                                        const std::vector<Eigen::Vector3d>& test_points) {
  const PixelUncertainty uncertainty(camera, model, fitted_points, sigma_px);
  std::vector<double> sigmas;
  sigmas.reserve(test_points.size());
  for (const Eigen::Vector3d& x : test_points) sigmas.push_back(uncertainty.SigmaAt(x));
  return sigmas;
}

std::vector<double> ReprojectionSigmaFromFitPx(const ChartLinearization& fit,
                                               const std::vector<Eigen::Vector3d>& fitted_points,
                                               double sigma_px,
                                               const std::vector<Eigen::Vector3d>& test_points) {
  const PixelUncertainty uncertainty(fit, Eigen::Vector3d::Zero(), 1.0, fitted_points, sigma_px);
  std::vector<double> sigmas;
  sigmas.reserve(test_points.size());
  for (const Eigen::Vector3d& x : test_points) sigmas.push_back(uncertainty.SigmaAt(x));
  return sigmas;
}

PerspectiveTest TestPerspectiveStrength(const Selection& selection,
                                        const std::vector<Eigen::Vector3d>& kept_points,
                                        const AutoFitOptions& options) {
  PerspectiveTest test;
  const std::vector<Eigen::Vector2d>& residuals = selection.fit.residuals_px;
  if (selection.fit.camera.projection != Projection::kOrthographic ||
      residuals.size() != kept_points.size() || kept_points.empty()) {
    return test;
  }
  test.checked = true;
  // In the points' centred, unit-RMS world, as CheckDetermination's.
  const UnitWorld unit_world = ToUnitWorld(selection.fit.camera, kept_points);
  const std::vector<Eigen::Vector3d>& points = unit_world.points;
  const Camera& camera = unit_world.camera;
  for (const Eigen::Vector2d& r : residuals) test.sum_squares_px2 += r.squaredNorm();
  try {
    test.removed_px2 = std::min(test.sum_squares_px2,
                                PixelUncertainty(camera, selection.options, points, 1.0)
                                    .HatQuadratic(residuals));
  } catch (const std::invalid_argument&) {
    return test;  // a point behind the camera: the determination check says so
  }
  const double dof = 2.0 * static_cast<double>(kept_points.size()) -
                     static_cast<double>(selection.fit.free_parameters.size()) - 1.0;
  test.sigma_px = options.fit.pixel_sigma
                      ? *options.fit.pixel_sigma
                      : CombinedNoise(options, test.sum_squares_px2 - test.removed_px2, dof);
  test.statistic = test.removed_px2 / (test.sigma_px * test.sigma_px);
  test.bound = ChiSquareQuantile(1.0, 1.0 - options.significance);
  test.observable = test.statistic > test.bound;
  return test;
}

DeterminationCheck CheckDetermination(const Selection& selection,
                                      const std::vector<Eigen::Vector3d>& kept_points,
                                      const AutoFitOptions& options,
                                      PointReliability* reliability) {
  DeterminationCheck check;
  check.checked = true;
  check.bound_px = options.max_uncertainty_px;
  // Everything below in the points' centred, unit-RMS world (as the fitter's): in world units
  // the squared lengths overflow or underflow beyond ~1e+-154, and at an offset of 1e10 scene
  // sizes the finite-difference steps (1e-6 of the scene) fall below the coordinates' rounding.
  const UnitWorld unit_world = ToUnitWorld(selection.fit.camera, kept_points);
  const Eigen::Vector3d& origin = unit_world.origin;
  const double unit = unit_world.unit;
  const std::vector<Eigen::Vector3d>& points = unit_world.points;
  const Camera& camera = unit_world.camera;
  std::vector<Eigen::Vector3d> object_points(options.object_points_in_world.size());
  for (size_t i = 0; i < object_points.size(); ++i) {
    object_points[i] = (options.object_points_in_world[i] - origin) / unit;
  }
  const TestPoints test_points = TestPointsOrFitted(camera, points, 0.0, object_points);
  const std::vector<Eigen::Vector3d>& test = test_points.points;
  const double sigma = selection.options.pixel_sigma.value_or(selection.sigma_px);
  // From the chosen fit's own normal equations where it kept them (as a rival's, FittedRivals).
  const PixelUncertainty uncertainty =
      selection.linearization != nullptr && camera.projection == Projection::kPerspective
          ? PixelUncertainty(*selection.linearization, origin, unit, points, sigma)
          : PixelUncertainty(camera, selection.options, points, sigma);
  std::vector<std::optional<Eigen::Matrix2d>> hats(reliability != nullptr ? points.size() : 0);
  const std::vector<double> sigmas =
      SigmasAt(uncertainty, test_points, reliability != nullptr ? &hats : nullptr);
  if (reliability != nullptr) *reliability = LeastChecked(uncertainty, hats);
  for (size_t i = 0; i < test.size(); ++i) {
    if (!(sigmas[i] <= check.max_sigma_px)) {
      check.max_sigma_px = sigmas[i];
      if (const std::optional<Eigen::Vector2d> pixel = PixelFromWorld(camera, test[i])) {
        check.worst_pixel = *pixel;
      }
    }
  }
  const std::vector<FittedRival> fitted = FittedRivals(selection, unit_world, sigma, test);
  std::vector<const FittedRival*> counted;
  for (const FittedRival& c : fitted) {
    if (c.about_as_well) counted.push_back(&c);
  }
  const FittedRival* predicts_better =
      RivalPredictingBetter(selection, camera, uncertainty, points, counted);
  // The unmirrored rivals are judged over the box widened to kRivalBoxThickness.
  std::optional<TestPoints> rival_test;
  if (std::any_of(fitted.begin(), fitted.end(),
                  [](const FittedRival& c) { return !c.rival->mirrored_world; })) {
    rival_test = TestPointsOrFitted(camera, points, kRivalBoxThickness, object_points);
  }
  // At a handful of points, an answer with the principal point at the image centre is judged
  // against the model that frees it (kLensShiftBoxScale). Not for coplanar points: one plane
  // determines no principal point (its homography has 8 degrees of freedom; pose, focal and
  // principal point are 9), and every camera that fits it agrees on it.
  const FittedRival* lens_shift =
      points.size() <= kCrossValidationMaxPoints && !selection.fit.planar
          ? LensShiftRival(selection, counted)
          : nullptr;
  std::optional<TestPoints> lens_shift_test;
  if (lens_shift) lens_shift_test = WithScaledBox(*rival_test, camera, points, kLensShiftBoxScale);
  // The sigmas known at the first points of *rival_test, for the model average: the returned
  // camera's where the rivals' box is its own (a scene thicker than kRivalBoxThickness), each
  // rival's where its shift was judged over rival_test (or the lens-shift test, which begins
  // with it).
  std::vector<std::vector<double>> known(1 + fitted.size());
  if (rival_test && rival_test->points == test) known[0] = sigmas;
  // Beyond kCrossValidationMaxPoints, the chosen fit's sum of squares for the nested rivals.
  std::optional<double> chosen_sum_squares;
  if (points.size() > kCrossValidationMaxPoints &&
      selection.fit.residuals_px.size() == points.size()) {
    chosen_sum_squares = 0.0;
    for (const Eigen::Vector2d& r : selection.fit.residuals_px) {
      *chosen_sum_squares += r.squaredNorm();
    }
  }
  for (const FittedRival* counted_rival : counted) {
    const FittedRival& c = *counted_rival;
    const Rival& rival = *c.rival;
    const Eigen::Vector3d flip(1.0, 1.0, rival.mirrored_world ? -1.0 : 1.0);
    // The mirrored reading is judged over the points' own box: off a plane (or a nearly flat
    // scene) the two readings always part, and no data on it can tell them apart.
    const TestPoints& our_test = rival.mirrored_world ? test_points
                                 : &c == lens_shift    ? *lens_shift_test
                                                       : *rival_test;
    // A richer rival scatters by its own uncertainty: only a shift beyond kRivalSigmas of it
    // is a different reading of the data rather than the rival's noise -- except for the rival
    // that predicts the points better and the lens-shift rival (above).
    const bool exempt = &c != predicts_better && &c != lens_shift;
    if (exempt && chosen_sum_squares &&
        NestedRivalWithinItsNoise(selection.options, *chosen_sum_squares, rival, sigma)) {
      continue;
    }
    RivalShift shift = ShiftOf(camera, c, flip, our_test, exempt);
    if (!(shift.px <= check.rival_shift_px)) {
      check.rival_shift_px = shift.px;
      check.rival_worst_pixel = shift.pixel;
      check.rival = rival.model;
      check.rival_predicts_better = &c == predicts_better;
      check.rival_frees_lens_shift = &c == lens_shift;
    }
    if (!rival.mirrored_world) {
      known[1 + static_cast<size_t>(&c - fitted.data())] = std::move(shift.rival_sigmas);
    }
  }
  // The model average over the rivals' test points; for coplanar points over their own (in their
  // plane, and the object points): a plane determines no model with a free intrinsic off itself,
  // and the bundled plane was refused at 30 px off it (docs/model-selection.md).
  if (rival_test) {
    AverageOverModels(camera, uncertainty, fitted,
                      selection.fit.planar ? test_points : *rival_test,
                      selection.fit.planar ? std::vector<std::vector<double>>() : known, &check);
  }
  check.passed = check.max_sigma_px <= check.bound_px && check.rival_shift_px <= check.bound_px &&
                 check.averaged_sigma_px <= check.bound_px;
  check.summary = SummaryOf(check, !object_points.empty(), options.fit.pixel_origin);
  return check;
}

}  // namespace internal
}  // namespace camproj

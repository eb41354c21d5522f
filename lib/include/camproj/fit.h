// Fitting a camera or projector to 2D-3D correspondences: the only fitting entry point.
//
// FitCamera starts from a closed form (Hartley-normalized DLT for >= 6 non-coplanar points, a
// homography with constrained intrinsics for planar scenes, SQPnP when the intrinsics are known or
// only the focal length is free with few points), then refines -- least squares by the
// project's own Levenberg-Marquardt on normal equations accumulated point by point (or, with
// FitOptions::refiner = kCeres, ceres::Solver on the same residuals), then a Gauss-Newton
// polish; Ceres (ceres::Problem) always for a robust loss -- where residuals are
// predicted - observed pixels; rotation on a quaternion manifold, translation in a world frame
// centred and scaled to the points (so units and offsets do not matter); fixed intrinsics are
// constants, not penalties. Conventions: docs/conventions.md.
//
// Below 20 points a fit that may sit in a local minimum is refined from more starts, keeping the
// lowest cost: a DLT start with the principal point free also from the image centre; a focal
// sweep start from each other valley of its RMS; and from every valley of the focal sweep (SQPnP
// over fields of view 0.5-175 deg) a homography start for points only nearly coplanar and a DLT
// start whose best fit has an intrinsic no lens has (pixels 1.5 times as tall as wide or more,
// the principal point more than an image size from the centre). A restart that comes back to the
// lowest minimum found so far stops in its quadratic neighbourhood instead of converging to it
// again (fit/least_squares.h, KnownMinimum). Details: fit/refine.cc.
//
// On a plane, focal and aspect free with the principal point given and neither skew nor
// distortion is the homography's model: the fit starts at the camera of the least-squares
// homography, which is its minimum, and is refused (kDegenerate, "does not determine the
// aspect") where that homography has no such camera: the model then has no minimum at finite
// focal lengths. Details: fit/start.h, PlaneAspectStart.
#ifndef CAMPROJ_FIT_H_
#define CAMPROJ_FIT_H_

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/conventions.h"
#include "camproj/intrinsics.h"

namespace camproj {

// How one intrinsic parameter is treated.
struct ParameterMode {
  enum class Kind {
    kDefault,  // fixed at its default: focal has none (must be free or given), aspect 1,
               // principal point at the image centre ((W-1)/2, (H-1)/2 in kCenter), skew 0, k = 0
    kFree,     // estimated
    kFixed,    // fixed at `value` (px for focal, principal point, skew; fy/fx for aspect)
  };
  Kind kind = Kind::kDefault;
  double value = 0.0;       // for kFixed; for the principal point `value` is cx and `value2` cy
  double value2 = 0.0;

  static ParameterMode Default() { return {}; }
  static ParameterMode Free() { return {Kind::kFree, 0.0, 0.0}; }
  static ParameterMode Fixed(double v, double v2 = 0.0) { return {Kind::kFixed, v, v2}; }
  bool IsFree() const { return kind == Kind::kFree; }
};

enum class LossType { kNone, kHuber, kCauchy };

// The least-squares engine without a robust loss (with one, Ceres always runs):
// kLevenbergMarquardt, the project's own (ceres::TinySolver's algorithm on normal equations
// accumulated point by point, least_squares.cc), or kCeres, ceres::Solver on a ceres::Problem of
// the same residuals (one analytic block per point, the rotation on a quaternion manifold,
// DENSE_NORMAL_CHOLESKY). Either is followed by the same Gauss-Newton polish and the same test
// that the answer is at the minimum, so both return the same optimum (FitTest.CeresRefinerFinds
// TheSameOptimum: 1e-9 relative); the own LM is the faster (bench: docs/bench/README.md). From a
// DLT on 20 points or more the own path takes the Gauss-Newton steps first, and LM only where
// they do not settle (a step under 1e-9 px): that start is close enough.
enum class Refiner { kLevenbergMarquardt, kCeres };

struct FitOptions {
  // The intrinsic model. focal: fx (fy = aspect * fx). Defaults: focal, aspect and principal
  // point free (an off-axis pinhole: 10 parameters with the pose), skew 0, no distortion.
  ParameterMode focal = ParameterMode::Free();
  ParameterMode aspect = ParameterMode::Free();
  ParameterMode principal_point = ParameterMode::Free();
  ParameterMode skew = ParameterMode::Default();
  ParameterMode k1 = ParameterMode::Default();
  ParameterMode k2 = ParameterMode::Default();

  // kOrthographic fits a parallel projection (camera.h): focal is the scale (px per world unit),
  // aspect and skew as above; the principal point stays at the image centre or its given value
  // (it trades exactly with the position); no distortion, RANSAC or known intrinsics. Needs
  // points off a plane (a plane seen orthographically has two mirror-image poses). The depth
  // order, which an orthographic image does not show, is the one a right-handed world implies.
  Projection projection = Projection::kPerspective;

  // When set, the intrinsics are known (in `pixel_origin`) and only the pose is fitted; the
  // modes above are ignored.
  std::optional<Intrinsics> known_intrinsics;

  // Convention of the observed pixels, of fixed principal-point values and of known_intrinsics;
  // the result is always in kCenter (Camera's convention) with residuals in pixels.
  PixelOrigin pixel_origin = PixelOrigin::kCenter;

  // Outliers (mis-clicked points): RANSAC on minimal closed-form samples (6-point DLT; 4 points
  // for known intrinsics (SQPnP) or a plane (homography)), with local optimization, then the
  // fit on the consensus. Points farther than ransac_threshold_px from the result are listed in
  // FitResult::outliers; the residual statistics are over the consensus.
  bool ransac = false;
  double ransac_threshold_px = 4.0;
  double ransac_confidence = 0.9999;
  long ransac_max_iterations = 20000;
  uint64_t ransac_seed = 1;

  LossType loss = LossType::kNone;
  double loss_scale_px = 1.0;  // Huber / Cauchy scale, px, > 0
  Refiner refiner = Refiner::kLevenbergMarquardt;  // without a loss (see Refiner)

  // Expected pixel noise (standard deviation per axis, px). Unset: estimated from the residuals
  // as sqrt(sum of squared residuals / (2N - p)); with a robust loss (perspective), from their
  // median as a 2D Gaussian's (FitResult::pixel_sigma).
  std::optional<double> pixel_sigma;

  // false: return the closed-form start (DLT / homography / PnP, projected onto the model)
  // without refinement; the residuals, views and uncertainty are those of the start. (A
  // six-point DLT that reads the world as mirrored still refines both readings to decide.)
  bool refine = true;
  // false: skip the covariance (sigmas, correlations); saves its cost in batch use.
  bool compute_uncertainty = true;

  // Levenberg-Marquardt's stopping rules (ceres::TinySolver's; Ceres' own solver with a robust
  // loss). LM only needs to get close: undamped Gauss-Newton steps with the exact Jacobian follow
  // it (without a robust loss) and settle when a step moves the residuals by under 1e-9 px. The
  // answer must be at the minimum -- the last Gauss-Newton step changes the residual vector by at
  // most 1e-3 of the residuals' sigma -- else LM resumes from there, up to 20 rounds of
  // max_iterations, and then the fit is refused (kDegenerate) rather than returned short of it.
  int max_iterations = 100;
  double function_tolerance = 1e-10;   // relative cost change
  double gradient_tolerance = 1e-16;
  double parameter_tolerance = 1e-10;  // relative step

  // Depth range of the result's GL matrices. Unset: tight around the points' depths, near =
  // min depth / (1 + depth_margin), far = max depth * (1 + depth_margin). One given beyond every
  // point (near) or before every point (far), the other unset: refused (kPointsBehindCamera).
  std::optional<double> z_near;
  std::optional<double> z_far;
  double depth_margin = 0.1;

  // |correlation| at or above which a pair of parameters is reported as strongly correlated.
  double strong_correlation = 0.9;

  // Throws std::invalid_argument naming the field.
  void Check() const;
};

// A refusal: the data cannot determine the requested camera. what() says why and what to do:
// why() is what the points show, fix() what to do about it (the imperative advice that stands
// alone: it names the points, pixels and options it refers to), and what() is "why. fix". The
// command line prints the fix on a line of its own. A refusal whose advice is part of its
// reason (the one-string constructor) has an empty fix() and why() == what().
class SceneError : public std::runtime_error {
 public:
  enum class Reason {
    kTooFewPoints,
    kCollinearPoints,
    kPlanarUnderdetermined,  // a plane determines at most 2 intrinsics (besides distortion)
    kNonFiniteInput,
    kPointsBehindCamera,     // or every point past a given near / far plane (the other unset)
    kMirroredWorld,          // left-handed world frame
    kDegenerate,             // no unique solution (e.g. a plane seen head-on with free focal)
    // FitCameraAuto (model_select.h) only, but kAmbiguous:
    kContaminated,  // some points disagree with the rest and the rest cannot say which
    kInconsistent,  // the best camera's residuals are larger than the pixel noise allows
    // Two different cameras explain the points about equally well: FitCameraAuto's
    // determination check (a rival model, or the world read mirrored, puts the scene
    // elsewhere), and FitCamera's start (a mirrored reading fits somewhat better than any
    // proper camera, by too little to call the world left-handed).
    kAmbiguous,
    kNumerical,     // a numerical failure on these values (a bug: please report it)
  };
  SceneError(Reason reason, const std::string& message)
      : std::runtime_error(message), reason_(reason), why_length_(message.size()) {}
  // `why` and `fix` as above; `fix` must not be empty.
  SceneError(Reason reason, const std::string& why, const std::string& fix)
      : std::runtime_error(why + ". " + fix), reason_(reason), why_length_(why.size()) {}
  Reason reason() const { return reason_; }
  std::string why() const { return std::string(what(), why_length_); }
  std::string fix() const {
    const std::string message = what();
    return why_length_ + 2 <= message.size() ? message.substr(why_length_ + 2) : std::string();
  }

 private:
  Reason reason_;
  // what()'s first why_length_ characters are the why; a fix follows after ". ". (An offset
  // rather than two more strings: copying the exception cannot throw.)
  size_t why_length_;
};

// One accepted LM iterate (entry 0 is the closed-form start; without a robust loss the last entry
// is the Gauss-Newton polish): elapsed wall time since FitCamera started, and the RMS
// reprojection error there.
struct TraceEntry {
  int iteration = 0;
  double elapsed_us = 0.0;
  double rms_px = 0.0;
};

// A reported parameter with its standard deviation in user units.
struct ParameterSigma {
  std::string name;  // "fx", "cx", "fovy_deg", "eye_x", "rotation_x_deg", ...
  double value = 0.0;
  double sigma = 0.0;
  std::string unit;  // "px", "deg", "world", ""
};

// An intrinsic the fit did not estimate: its value (cx, cy in FitResult::pixel_origin) and why:
// "given" (fixed by the caller), "default: ..." (left at its default), "given: pose only" (known
// intrinsics).
struct FixedParameter {
  std::string name;   // "aspect", "principal point", "skew", "k1", ...
  std::string value;
  std::string why;
};

struct Correlation {
  std::string first;
  std::string second;
  double correlation = 0.0;
};

// One model FitCameraAuto (model_select.h) tried.
struct ModelCandidate {
  std::string name;          // as FitResult::model
  int num_params = 0;        // pose 6 + free intrinsics
  bool fitted = false;       // false: refused or not determined (see verdict)
  double sum_squares_px2 = 0.0;
  double rms_px = 0.0;
  double criterion = 0.0;    // AIC or BIC with the selection's noise
  std::string verdict;       // "chosen", "kept", "not supported ...", "not determined ...", ...
};

// A point FitCameraAuto's outlier stage left out of the fit, measured against the returned
// camera.
struct LeftOutPoint {
  int index = 0;               // into the caller's points, 0-based
  double residual_px = 0.0;    // |predicted - observed| against the returned camera
  double rms_with_px = 0.0;    // RMS of the same model refitted, from the returned camera, with
                               // this point put back (0: not computed, beyond 10 left out;
                               // inf: no camera fits with it)
};

// FitCameraAuto's final consistency gate (docs/model-selection.md): the returned camera's
// residuals are consistent with the pixel noise. A result is only returned when `passed`.
struct ConsistencyCheck {
  bool checked = false;        // false: FitCamera alone, no gate ran
  bool passed = false;
  double noise_px = 0.0;       // the noise the residuals are tested against (per axis)
  std::string noise_source;    // "given", "default prior", ...
  double rms_px = 0.0;         // of the points kept
  double noise_estimate_px = 0.0;  // sqrt(J / (2N - p)) over the points kept
  double noise_bound_px = 0.0;     // the largest noise estimate the chi-square test accepts
  double robust_noise_px = 0.0;    // from the median residual (Rayleigh), over the points kept
  double max_residual_px = 0.0;    // largest residual among the points kept
  double max_residual_bound_px = 0.0;  // outlier bound: sqrt(2 ln(N / alpha)) * noise
  double significance = 0.0;   // alpha of both tests
  int observations = 0;        // N: the points kept, each repeated correspondence counted once
  std::string summary;         // one line in words
};

// How well the other kept points check each one (FitCameraAuto only; the redundancy numbers of
// Baarda's internal reliability): the fit follows a point's own pixel by its leverage, the 2 x 2
// block H_ii of the hat matrix J (J^T J)^-1 J^T, so a mis-click d of that point moves its own
// residual by (I - H_ii) d, to first order (and the sum of squares by d^T (I - H_ii) d). Reported
// for the least checked kept point, along its direction of largest leverage. At 6 clicks with
// the principal point free (9 parameters, 12 equations) a point's residual can keep 1e-5 of a
// mis-click: no test of the residuals can show one there, however large.
struct PointReliability {
  bool checked = false;
  int point = -1;  // input index of the least checked kept point
  // 1 - the largest eigenvalue of its H_ii: the fraction of a mis-click along `direction` that its
  // residual keeps (0: the fit follows it entirely; the sum over all points and both directions
  // is 2N - p).
  double redundancy = 1.0;
  Eigen::Vector2d direction = Eigen::Vector2d::Zero();  // unit, image axes (u right, v down)
  std::string summary;  // one line in words
};

// FitCameraAuto's check that the points determine the returned camera where it is used
// (docs/model-selection.md): the linearized 1-sigma reprojection uncertainty of the test points
// -- the corners and face centres of the box the kept points span along their principal axes,
// and the points, where they are in the image -- at the selection's noise, and whether a model
// that fits about as well (BIC within kEqualFitCriterion) puts them elsewhere. A result is only
// returned when `passed`.
struct DeterminationCheck {
  bool checked = false;
  bool passed = false;
  double max_sigma_px = 0.0;  // the largest 1-sigma uncertainty over the test points
  Eigen::Vector2d worst_pixel = Eigen::Vector2d::Zero();  // where (kCenter)
  double bound_px = 0.0;      // AutoFitOptions::max_uncertainty_px
  std::string rival;          // the model that fits about as well and moves a test point most
  double rival_shift_px = 0.0;  // by how much (0: no such model)
  Eigen::Vector2d rival_worst_pixel = Eigen::Vector2d::Zero();  // where it moves it (kCenter)
  // The rival predicts each kept point from the others better than the returned model
  // (leave-one-out, at up to 12 points): its shift counts even within its own 3 sigma.
  bool rival_predicts_better = false;
  // The returned camera has its principal point at the image centre and the rival frees it (at
  // up to 12 points): the clicks cannot tell a lens shift from a longer focal length, so its
  // shift counts even within its own 3 sigma, over the box the points span doubled
  // (fit/determination.cc, kLensShiftBoxScale).
  bool rival_frees_lens_shift = false;
  // The camera averaged over the models fitted (the returned one and every unmirrored rival,
  // each weighted by exp(-(its BIC - the returned model's) / 2), as posterior model
  // probabilities: Raftery 1995): its largest 1-sigma spread sqrt(sum_m w_m (sigma_m^2 +
  // |u_m - u_mean|^2)) over the rivals' test points, and where. Above the bound the points cannot
  // tell which model is right well enough (kAmbiguous); a model that puts a test point behind
  // it makes this infinite. 0 when no rival is in the average (e.g. a forced model). Asked at the
  // test points that are not fitted points (fit/determination.cc, AverageOverModels).
  double averaged_sigma_px = 0.0;
  Eigen::Vector2d averaged_worst_pixel = Eigen::Vector2d::Zero();  // kCenter
  std::string averaged_rival;  // the rival that adds most to the spread there ("": none)
  std::string summary;        // one line in words
};

// Whether the covariance's linearization holds where it is read (docs/stability.md). Along each
// principal direction of the covariance, both ways, at the edge of the kLinearityLevel confidence
// region (radius c sigmas, c^2 = chi^2_p(level)), where the quadratic model puts the sum of
// squares up by P = c^2 sigma^2: the straight line's rise L and, where L departs from P, the
// profile's F (the sum re-minimized across the line). A curved valley of near-equivalent cameras
// (narrow fields of view, near-planar scenes, large noise, few points) has its floor
// (L - F) / sigma^2 off the straight line there, and the region's true edge at c sqrt(P / F):
// the linearized NEES of an error on that edge is (P + L - F) / F times its true chi-square.
struct LinearityCheck {
  bool checked = false;  // false: no covariance, or a candidate of FitCameraAuto's selection
  double level = 0.0;    // of the confidence region probed (kLinearityLevel)
  // The largest (P + L - F) / F - 1 over directions and signs: 0 for a linear model, negative
  // where the walls are steeper than the quadratic model's (the sigmas overstate the error),
  // infinite where a point crosses behind the camera within the region.
  double worst_deviation = 0.0;
  std::string worst_direction;  // the parameter that moves most (in its sigmas) along that direction
  double bound = 0.0;           // kMaxLinearityDeviation
  bool linear = false;          // worst_deviation <= bound
};

// The confidence level whose region the linearity check probes, and the largest deviation that
// still counts as linear: the sigmas then hold to a factor sqrt(2) out to the 99.99 % region.
// A local check: it sees the valley within the region around the estimate, not beyond it
// (docs/stability.md says where that misses).
inline constexpr double kLinearityLevel = 0.9999;
inline constexpr double kMaxLinearityDeviation = 1.0;

struct FitResult {
  Camera camera;      // intrinsics (kCenter), cam_from_world, z_near / z_far
  CameraViews views;  // look_at (target at the points' median depth), frustum, perspective, GL
  // The input's convention (FitOptions::pixel_origin): that of fixed_parameters' cx, cy, of the
  // checks' summaries and of FitSummaryText; the camera and the sigmas are in kCenter.
  PixelOrigin pixel_origin = PixelOrigin::kCenter;

  // Per point: predicted - observed, px, in input order (infinite for a point behind the camera,
  // possible only among RANSAC's outliers).
  std::vector<Eigen::Vector2d> residuals_px;
  // Indices of the points left out of the fit: RANSAC's (FitOptions::ransac), or FitCameraAuto's
  // outlier stage (then also in left_out, with their residuals).
  std::vector<int> outliers;
  std::vector<LeftOutPoint> left_out;
  std::string outlier_method;  // "", "ransac", "leave-one-out", "leave-two-out", "lo-ransac"
  ConsistencyCheck consistency;
  DeterminationCheck determination;
  PointReliability reliability;
  double rms_px = 0.0;     // sqrt(mean(du^2 + dv^2))
  double median_px = 0.0;  // median |residual|
  double max_px = 0.0;

  // The model: "pose" followed by its free intrinsics, e.g. "pose+focal+principal-point".
  std::string model;
  // FitCameraAuto only: every model tried in order, the criterion ("AIC" / "BIC") and the pixel
  // noise it used.
  std::vector<ModelCandidate> candidates;
  std::string criterion;
  double selection_sigma_px = 0.0;

  // "dlt", "homography", "pnp", "pnp-focal-sweep" ("affine": orthographic; "ransac+...": the
  // consensus's). FitCameraAuto, where it refits the chosen model from the selection's own fit
  // of it (from 20 points on, or where it is the screen's model): the closed form that began it.
  std::string start_method;
  bool planar = false;       // the points are (numerically) coplanar
  std::vector<std::string> free_parameters;   // names in the covariance's order
  std::vector<FixedParameter> fixed_parameters;

  // Condition number of the Jacobian at the solution, its columns scaled to unit norm (pose in
  // the fitter's centred, unit-RMS world): sqrt(largest / smallest eigenvalue of the scaled
  // J^T J). Refused as undetermined (SceneError kDegenerate) above 1e6.
  double jacobian_condition = 0.0;

  int iterations = 0;
  // What refined the camera: "levenberg-marquardt" (the project's own LM on accumulated normal
  // equations, then undamped Gauss-Newton steps: least squares by default), "ceres" (the same
  // with ceres::Solver for LM: FitOptions::refiner = kCeres; also the orthographic fit's), "ceres, huber loss
  // 2 px" / "ceres, cauchy loss 2 px" (FitOptions::loss: a ceres::Problem) or "none"
  // (FitOptions::refine = false).
  std::string refiner;
  std::string termination;  // why it stopped, in the refiner's words
  double time_ms = 0.0;
  std::vector<TraceEntry> trace;

  // Uncertainty: sigma used (given or estimated), covariance of the free parameters in the
  // order of free_parameters (pose as rotation_x/y/z_deg about the camera axes and eye_x/y/z in
  // world units; intrinsics in px), sigmas of every reported parameter, strong correlations.
  // Least squares: pixel_sigma^2 (J^T J)^-1. A robust loss (perspective): Huber's estimate for
  // an M-estimator, v (J^T J)^-1 with v = K^2 E[psi^2] / E[psi']^2 (psi the loss's influence:
  // fit/assess.cc, RobustVariancePx2), from the residuals or, given pixel_sigma, its Gaussian;
  // an estimated pixel_sigma is then sqrt(v), the noise at which least squares would scatter as
  // the robust fit does.
  double pixel_sigma = 0.0;
  bool pixel_sigma_estimated = true;
  bool covariance_available = false;
  // Why there is no covariance where one was asked for (compute_uncertainty); empty otherwise.
  std::string no_uncertainty_why;
  Eigen::MatrixXd covariance;
  std::vector<ParameterSigma> sigmas;
  std::vector<Correlation> strong_correlations;
  LinearityCheck linearity;
};

// Fits a camera to points_in_world[i] observed at observed_pixels[i] (in options.pixel_origin).
// Throws std::invalid_argument for bad options or mismatched sizes, SceneError for a refusal.
FitResult FitCamera(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_FIT_H_

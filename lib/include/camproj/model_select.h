// Automatic model selection: fit only the intrinsics the scene determines and needs.
//
// Starting from pose + focal length (a gluPerspective camera: square pixels, principal point at
// the image centre), FitCameraAuto frees one group at a time among principal point (an off-axis
// frustum), aspect, skew, k1 and k2 (k2 only after k1), each round keeping the group that lowers
// the criterion most, and stops when none does, or when the next model would leave fewer than
// min_redundancy equations to spare. Whether the chosen camera is then determined well enough is
// the assessment's question (AutoFitOptions::max_uncertainty_px), not the ladder's: a group the
// residuals ask for is never left out because its own sigma is large -- except a distortion (k1,
// k2) the criterion takes only weakly (by at most kEqualFitCriterion) that moves the image's
// border by more than max_uncertainty_px: beyond the points it is their noise extrapolated.
// Criterion (geometric AIC, Kanatani; the 3D points are exact, so it is J / sigma^2 + 2 p):
//   AIC = J / sigma^2 + 2 p,   BIC = J / sigma^2 + p ln(2 N),
// J the sum of squared reprojection errors (px^2), p the number of parameters (pose 6 + free
// intrinsics), sigma the pixel noise: given, or the prior combined with the residuals of the
// richest model the scene supports, sqrt((prior_weight prior_sigma_px^2 + J) / (prior_weight +
// 2N - p)), floored at kMinNoisePx (AutoFitOptions). Details: docs/model-selection.md.
#ifndef CAMPROJ_MODEL_SELECT_H_
#define CAMPROJ_MODEL_SELECT_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"

namespace camproj {

enum class ModelCriterion { kAic, kBic };

// Noise below this is not believed (subpixel detectors reach ~0.01 px): on exact synthetic data
// rounding would otherwise count as evidence for every extra parameter.
inline constexpr double kMinNoisePx = 1e-4;

// Two models "fit about as well" when their criteria differ by at most this (a BIC difference
// below 6 is not strong evidence for either: Kass & Raftery 1995).
inline constexpr double kEqualFitCriterion = 6.0;

struct AutoFitOptions {
  // Everything but the model: pixel origin, RANSAC, sigma, near/far, stopping rules. Its
  // intrinsics decide what the ladder may change: kDefault = a candidate (left at its default
  // unless freed), kFree = free in every model (forced), kFixed = given, never freed. Unlike
  // FitOptions' own defaults, aspect and principal point start as candidates here. A robust loss
  // is refused (the criterion is for least squares; use RANSAC for outliers). known_intrinsics:
  // pose only, nothing to select.
  FitOptions fit = [] {
    FitOptions o;
    o.aspect = ParameterMode::Default();
    o.principal_point = ParameterMode::Default();
    return o;
  }();
  // BIC by default: it keeps a parameter that does not matter with probability P(chi2_1 >
  // ln 2N) (5 % at N = 20, 1 % at N = 500), AIC with P(chi2_1 > 2) = 16 % per candidate.
  ModelCriterion criterion = ModelCriterion::kBic;
  // The returned camera must be determined to this many pixels (1 sigma, linearized) over the
  // scene: the box the kept points span and the points themselves, where they are in the image
  // (FitResult::determination). A camera this uncertain is refused
  // (SceneError kDegenerate, saying where points are missing); so is one that a model fitting
  // about as well (BIC within kEqualFitCriterion) puts more than this much elsewhere
  // (kAmbiguous). At 6-8 clicked points this is what stands between a fit that passes every
  // residual test and a camera that is tens of pixels off across the rest of the object. So is
  // one whose own confidence region has no edge (FitResult::linearity infinite: within the
  // 99.99 % region a camera sees points from behind, or fits as well; kDegenerate), whose
  // linearized sigmas therefore say nothing. So is one that stands on a click no other point
  // checks (a mis-click of it anywhere in the image would leave less than the noise in its
  // residual; FitResult::reliability; kDegenerate). Infinity: none of these refusals.
  double max_uncertainty_px = 5.0;
  // Points of the object that were not clicked (e.g. the vertices of the model being mapped), in
  // the world of points_in_world: the determination check judges the camera, its rivals and
  // their average at those in front of it and in its image too. The box the clicks span can miss
  // parts of the object where a camera that explains every click is still more than the bound
  // off; only the user knows where the rest of the object is (docs/model-selection.md, "Rules
  // tried").
  std::vector<Eigen::Vector3d> object_points_in_world;
  // Also consider an orthographic camera (scale, then aspect and skew): chosen when the
  // criterion prefers it to pose + focal (the perspective is not observable: a telephoto or
  // satellite-like view whose depth range is tiny against its distance), or when no perspective
  // camera fits.
  bool allow_orthographic = true;

  // The outlier stage (docs/model-selection.md): when the least-squares fit of every point fails
  // the consistency gate, find the points that disagree -- by an exhaustive leave-one-out /
  // leave-two-out search up to exhaustive_max_points, by LO-RANSAC above -- and select the
  // model again on the rest. false (camproj fit --keep-all): every point is kept, and a
  // contaminated scene is refused by the gate. FitOptions::ransac forces RANSAC at its threshold.
  bool find_outliers = true;
  int exhaustive_max_points = 12;

  // The pixel noise assumed when FitOptions::pixel_sigma is unset (clicked points: about 1 px).
  // The model selection's noise is this prior combined with the residuals of the richest model
  // the scene supports, the prior counting as prior_weight residual degrees of freedom (a
  // scaled-inverse-chi-square prior): at 6-12 points the prior decides, at hundreds the data.
  double prior_sigma_px = 1.0;
  double prior_weight = 10.0;

  // The consistency gate, at significance `significance` (per test): (1) the noise estimate
  // sqrt(J / (2N - p)) is at most noise_tolerance times the noise (given, else the prior):
  // J <= (noise_tolerance * noise)^2 * chi2_{2N-p}(1 - significance); (2) no kept point's
  // residual exceeds sqrt(2 ln(N / significance)) times the robust noise estimate (median
  // residual, corrected for the fit's leverage). Failing either is SceneError kInconsistent.
  double significance = 1e-3;
  double noise_tolerance = 1.5;
  // The screen (every point fitted before the model selection) runs the same tests with this
  // tolerance in place of noise_tolerance: failing it only sends the points to the outlier
  // stage, which names a point only where leaving it out (and no other) passes the gate. So the
  // screen looks for mis-clicks wherever the residuals exceed what the noise explains, while a
  // camera is refused only for residuals beyond noise_tolerance times it. In [1,
  // noise_tolerance].
  double screen_noise_tolerance = 1.0;

  // A model is only freed beyond pose + focal when it leaves at least this many redundant
  // equations (2N - p): with fewer, its residuals cannot show that it is wrong. When the screen
  // (pose + focal + principal point) fails and no outliers explain why, a richer model needs N
  // redundant equations: at 8 points skew, k1 and k2 would otherwise absorb a mis-click.
  int min_redundancy = 3;

  // Names of the points in messages and FitResult's text (the CSV's ids); empty: "point 1",
  // "point 2", ... Its size must match the points' when given.
  std::vector<std::string> point_names;

  void Check() const;  // throws std::invalid_argument naming the field
};

// Fits the simplest model the data support. The result is FitCamera's for the chosen model,
// plus FitResult::model, ::candidates (every model tried, in order) and, in fixed_parameters,
// every candidate left out with the reason ("left out: BIC 2.15 above pose+focal's: its better
// fit does not pay for its extra parameters"). Throws like FitCamera when even the simplest model is refused.
// A candidate's RMS and criterion are its fit's where the Gauss-Newton polish passes its
// convergence test (the sum of squares within ~1e-6 sigma^2 of its minimum's); the chosen
// model's own fit polishes on until a step settles under 1e-9 px, as FitCamera's.
//
// This is what `camproj fit` runs, as a pipeline: a screen of every point with pose + focal +
// principal point (gated) -> if it fails, the outlier stage -> model selection on the points
// kept, gated (a failure with every point kept also gets the outlier stage) -> the mirror test
// and the gate on the returned camera. A result
// is returned only if FitResult::consistency.passed; every refusal of well-formed input is a
// SceneError whose message says what to fix (std::invalid_argument only for bad options or
// mismatched sizes). FitResult::rms_px etc. are recomputed from the returned camera in world
// coordinates, as a reader of the camera file would recompute them.
FitResult FitCameraAuto(const std::vector<Eigen::Vector3d>& points_in_world,
                        const std::vector<Eigen::Vector2d>& observed_pixels,
                        const ImageSize& image_size, const AutoFitOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_MODEL_SELECT_H_

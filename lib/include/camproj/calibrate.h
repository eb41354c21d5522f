// Calibration from many views (issue #14): one camera or projector seen in several views of known
// points — a chessboard moved in front of it, or a 3D rig — with its intrinsics shared by every
// view and one pose per view, refined jointly by Ceres. Conventions: docs/conventions.md; the
// intrinsics are the fitter's pinhole with OpenCV's lens (intrinsics.h): k1, k2, p1, p2, k3, each
// free only where the options say.
//
// What runs (docs/calibration.md):
//   start      planar views: a homography each, then Zhang's closed form for K (pixels scaled to
//              the image size first); 3D views: the normalized DLT each, K the median of theirs;
//              mixtures: the planar views' K where Zhang's form determines it, else the 3D
//              views'. Each view's pose from its homography and K if planar, else by SQPnP.
//   refinement one ceres::Problem: per view one residual block of its points' analytic
//              residuals (the single-view fitter's), a 6-vector pose block per view (a rotation
//              vector about the view's start, the centre), one block of the free intrinsics
//              shared by all views; DENSE_SCHUR with the poses eliminated.
//   views      a view that does not fit the camera the others share is left out by name and
//              the rest calibrated again (CalibrateOptions::refuse_inconsistent_views).
//   uncertainty ceres::Covariance of the shared intrinsics (sparse QR), scaled by the residual
//              variance s^2 = sum |r|^2 / (2N - p); the even and the odd views calibrated apart
//              and compared in the image (CrossValidation).
#ifndef CAMPROJ_CALIBRATE_H_
#define CAMPROJ_CALIBRATE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/conventions.h"
#include "camproj/fit.h"
#include "camproj/intrinsics.h"
#include "camproj/pose.h"

namespace camproj {

// One view: points in that view's world frame (a board's own frame is fine: each view has its own
// pose) and their pixels (kCenter).
struct CalibrationView {
  std::string name;  // for messages and the result, e.g. the file's name
  std::vector<Eigen::Vector3d> points_in_world;
  std::vector<Eigen::Vector2d> pixels;
  // Optional: a name per point for messages (the file's ids); empty: "1", "2", ... in order.
  std::vector<std::string> ids;
};

// Which intrinsics the views share and refine. The default is cv::calibrateCamera's model
// without tangential distortion and k3: fx, fy, cx, cy, k1, k2 free, no skew.
struct CalibrateOptions {
  ImageSize image_size;
  bool aspect_free = true;           // fy / fx; false: fy = fx
  bool principal_point_free = true;  // false: the image centre, ((W - 1) / 2, (H - 1) / 2)
  bool skew_free = false;
  int num_radial = 2;                // 0 (none), 1 (k1), 2 (k1, k2) or 3 (k1, k2, k3)
  bool tangential_free = false;      // p1, p2
  bool compute_uncertainty = true;
  // Refuse views that do not fit the shared camera: after the joint fit, the worst view whose
  // sum of squared residuals, in units of the other views' noise estimate, exceeds the
  // chi-square bound (2n - 6 degrees of freedom, level 0.001 / views) and whose RMS is more than
  // 2.5 times the others' is left out and the rest calibrated again, until none is or 3 views
  // remain. Needs >= 4 views.
  bool refuse_inconsistent_views = true;
  // Leave out single points that do not fit (a mis-detected corner, a mis-click): after the joint
  // fit (and the view refusal), every point whose residual |r| exceeds its view's bound
  // sigma sqrt(2 ln(N / 0.001)) — the level-0.001 bound over all N points of a Rayleigh |r|,
  // sigma = median |r| / sqrt(2 ln 2) (robust to the outliers themselves), the larger of the
  // view's own and all views' together — is left out and the rest calibrated again, once (bounds
  // taken again would peel the boards' edge columns). A view with more than 30 % of its points
  // beyond the bound, or fewer than 4 left, keeps them: that is a view that does not fit
  // (refuse_inconsistent_views), not a few bad points.
  bool remove_outliers = true;
  // Also calibrate the even and the odd views apart and compare them (Calibration::
  // cross_validation); needs compute_uncertainty and >= 4 views.
  bool cross_validate = true;
  // Choose the model the views need (SelectCalibrationModel below): the free flags above then say
  // what the ladder may free (a group whose flag is off is never freed), not what is free.
  bool select_model = false;
  // Pixel noise for the selection's criterion (px, 1 sigma); 0: estimated from the richest
  // model the flags allow, sqrt(J / (2N - p)), floored at kMinNoisePx.
  double pixel_sigma = 0.0;
  int max_iterations = 200;
  // Stops at a relative cost change below function_tolerance (1e-12: a parameter ~2e-5 sigma from
  // the optimum at 500 degrees of freedom) or a relative step below parameter_tolerance.
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-15;
  double parameter_tolerance = 1e-10;  // relative step

  // Throws std::invalid_argument naming the field unless the image size is positive,
  // num_radial is 0 to 3, and the iteration count and tolerances are positive.
  void Check() const;
};

// One rung of the model ladder across views: a group of intrinsics, whether it was freed, why.
struct CalibrationModelChoice {
  std::string group;   // "principal-point", "aspect", "skew", "k1", "k2", "tangential", "k3"
  bool free = false;
  // "freed: BIC -412.3", "left out: BIC +6.2 (J falls by 0.7 sigma^2, p ln 2N = 6.9)",
  // "not a candidate", "left out: needs k1 first", "left out: not determined (...)".
  std::string reason;
};

struct CalibratedView {
  std::string name;
  // The shared intrinsics with this view's pose (cam_from_world: the view's world frame ->
  // camera), and near / far around its points' depths (depth margin 0.1, as a fit's).
  Camera camera;
  int num_points = 0;
  double rms_px = 0.0;    // sqrt(mean |r|^2) over this view's points
};

// Two calibrations from disjoint halves of the views (even and odd positions), compared where it
// matters — in the image (as mrcal does): a grid of 16 x 12 pixels over the image is taken to rays
// by half A's intrinsics and back to pixels by half B's; the distance is what using one half's
// camera in place of the other's would cost there. Its RMS over the grid against the RMS that the
// two halves' covariances predict for it (to first order, their sum pushed through the same map):
// a ratio well above 1 says the halves differ by more than their noise — views that do not share
// one camera, or a model too simple for the lens.
struct CrossValidation {
  bool done = false;
  std::string why_not;      // when not done: the reason (too few views, a half refused, ...)
  int views_a = 0;          // even positions: 1st, 3rd, ...
  int views_b = 0;
  double rms_px = 0.0;      // RMS over the grid of |pixel_B(ray_A(u)) - u|
  double max_px = 0.0;
  double predicted_rms_px = 0.0;  // sqrt(mean over the grid of trace(Cov_A + Cov_B) there)
};

// A point left out because it does not fit the calibrated camera (CalibrateOptions::
// remove_outliers).
struct OutlierPoint {
  std::string view;
  std::string id;            // CalibrationView::ids, or its 1-based number in the view
  double residual_px = 0.0;  // |r| in the calibration that left it out
  double bound_px = 0.0;     // the bound it exceeded
};

// A view left out: it does not fit the camera the other views share (the numbers below), or it
// cannot be started (`reason` says why; the numbers are 0).
struct RefusedView {
  std::string name;
  int num_points = 0;
  double rms_px = 0.0;         // against the camera calibrated with it
  double others_rms_px = 0.0;  // the other views' RMS in that calibration
  double statistic = 0.0;      // its sum of squares / the other views' noise variance
  double bound = 0.0;          // the chi-square bound it exceeded
  std::string reason;          // empty for a view that does not fit; else why it has no start
};

struct Calibration {
  ImageSize image_size;
  Intrinsics intrinsics;  // kCenter; entries not free hold their fixed values
  std::vector<CalibratedView> views;  // in the order given, without the refused ones
  std::vector<RefusedView> refused_views;  // in the order they were refused
  std::vector<OutlierPoint> outliers;       // points left out, in the order they were
  int num_points = 0;                 // over all views
  int num_parameters = 0;             // 6 per view + the free intrinsics
  double rms_px = 0.0;                // sqrt(sum |r|^2 / num_points), as cv::calibrateCamera's
  // 1-sigma of each free intrinsic ("fx", "fy", "cx", "cy", "skew", "k1", "k2", "p1", "p2", "k3"),
  // px or unitless,
  // from the covariance above; empty unless compute_uncertainty.
  std::vector<ParameterSigma> intrinsics_sigma;
  // The covariance of the intrinsics block [fx, fy / fx, cx, cy, skew, k1, k2, p1, p2, k3] (px, 1,
  // px, px,
  // px, 1, 1), zero rows and columns for fixed entries; zero unless compute_uncertainty.
  Eigen::Matrix<double, 10, 10> intrinsics_covariance = Eigen::Matrix<double, 10, 10>::Zero();
  // What the covariance means in the image: the 1-sigma of the pixel a fixed ray lands on,
  // sqrt(trace(J C J^T)) with J = d pixel / d intrinsics, at the image centre and the worst of
  // its 4 outer corners (kCenter (-0.5, -0.5) ... (W - 0.5, H - 0.5); a corner beyond the lens's
  // fold is skipped). px; 0 unless compute_uncertainty.
  double projection_sigma_center_px = 0.0;
  double projection_sigma_corner_px = 0.0;
  CrossValidation cross_validation;
  // With CalibrateOptions::select_model: every group of the ladder in its order, freed or not
  // and why; the noise the criterion used and whether it was given.
  std::vector<CalibrationModelChoice> model_choice;
  double selection_sigma_px = 0.0;
  bool selection_sigma_given = false;
  Intrinsics start;                   // the closed-form start's intrinsics
  int iterations = 0;
  std::string termination;            // Ceres' words
};

// Calibrates the shared intrinsics and a pose per view. Throws std::invalid_argument on bad
// options or on a view with fewer than 4 points, with non-finite numbers, with points and
// pixels of different counts, or with the same points and pixels as another view (naming the
// views), for a pixel more than kMaxImageSide px outside the image or more than half of them
// outside it (a wrong image size); SceneError kDegenerate when the views cannot determine the
// free intrinsics (fewer equations than unknowns, no closed-form start, or a joint fit that does
// not reach its minimum within max_iterations: say which intrinsics to fix), kNumerical when the
// refinement fails.
Calibration Calibrate(const std::vector<CalibrationView>& views, const CalibrateOptions& options);

// The options of a model named by its intrinsics groups (`camproj calibrate --model`, --fix):
//   "auto"    select_model on, every ladder group a candidate but skew (sensors have square
//             grids, and a fitted skew takes up other model errors) and those `fixed`;
//   "opencv"  cv::calibrateCamera's default model: principal point, aspect, k1, k2, tangential
//             (p1, p2), k3 free;
//   groups    among focal, principal-point, aspect, skew, k1, k2, tangential, k3 joined by '+':
//             exactly those free (k2 needs k1, k3 needs k2: the ladder's order).
// Fixing k1 fixes k2 and k3, fixing k2 fixes k3. Throws std::invalid_argument naming the group:
// an unknown one, a radial term without the one before it, or (but for auto) one both freed and
// fixed. image_size and the other options keep their defaults.
CalibrateOptions CalibrateOptionsForModel(const std::string& model,
                                          const std::vector<std::string>& fixed);

// The model ladder across views (CalibrateOptions::select_model; docs/calibration.md). From the
// focal length alone (square pixels, the principal point at the image centre, no skew, no lens)
// it frees one group at a time among principal point, aspect, skew, k1, k2 (after k1), p1 + p2
// ("tangential") and k3 (after k2) — those the options allow — each round the one that lowers
//   BIC = J / sigma^2 + p ln(2N)
// most (J the sum of squared residuals over every view, p = 6 per view + the free intrinsics, N
// the points), until none lowers it: the single-view ladder's criterion (model_select.h). The
// views are those the richest allowed model keeps (its refused views are left out of the ladder;
// the final calibration refuses again). Returns the options of the chosen model (select_model
// off) and fills `choice` with every group's reason and `sigma_px` with the noise used.
CalibrateOptions SelectCalibrationModel(const std::vector<CalibrationView>& views,
                                        const CalibrateOptions& options,
                                        std::vector<CalibrationModelChoice>* choice,
                                        double* sigma_px);

}  // namespace camproj

#endif  // CAMPROJ_CALIBRATE_H_

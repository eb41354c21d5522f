// How well the points determine the camera where it is used (private; part of the assessment):
// the linearized reprojection uncertainty of test points across the scene, from the covariance
// of the fitted parameters. A fit of few points can pass every residual test and still put the
// rest of the scene tens of pixels off; this is the number that shows it.
#ifndef CAMPROJ_SRC_FIT_DETERMINATION_H_
#define CAMPROJ_SRC_FIT_DETERMINATION_H_

#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "fit/selection.h"

namespace camproj {
namespace internal {

// The points where the camera is judged: the corners and face centres of the box the fitted
// points span along their principal axes (flat for a plane), and the points themselves, kept
// where they are in front of `camera` and inside its image. With min_thickness > 0 the box is
// first widened about its centre so that no side is shorter than min_thickness times its longest.
std::vector<Eigen::Vector3d> SceneTestPoints(const Camera& camera,
                                             const std::vector<Eigen::Vector3d>& points_in_world,
                                             double min_thickness = 0.0);

// For each test point, the 1-sigma length of its reprojection error, sqrt(trace(C)) with
// C = sigma_px^2 J_x (J^T J)^-1 J_x^T, J the Jacobian of the fitted points' pixels and J_x the
// test point's, both with respect to the parameters `model` frees (pose; focal, aspect,
// principal point, skew, k1, k2 as free there), at `camera`. The result does not depend on how
// the pose is parameterized. +inf for every point where J^T J is singular. Throws
// std::invalid_argument if a fitted point is not in front of the camera.
std::vector<double> ReprojectionSigmaPx(const Camera& camera, const FitOptions& model,
                                        const std::vector<Eigen::Vector3d>& fitted_points,
                                        double sigma_px,
                                        const std::vector<Eigen::Vector3d>& test_points);

// ReprojectionSigmaPx read from a fit's own normal equations at its answer (the determination
// check's fitted rivals) instead of a pass over the fitted points: the same sigmas, to the step
// between those normal equations and the answer (the points in the world, as the fit's).
std::vector<double> ReprojectionSigmaFromFitPx(const ChartLinearization& fit,
                                               const std::vector<Eigen::Vector3d>& fitted_points,
                                               double sigma_px,
                                               const std::vector<Eigen::Vector3d>& test_points);

// The assessment's check of a selection fitted on `kept_points` (model_select.h,
// AutoFitOptions::max_uncertainty_px): the test points' uncertainty at the noise the selection's
// sigmas use, and the largest shift of a test point by a rival that fits about as well, over the
// box widened to kRivalBoxThickness (a rival that agrees on the clicked points can still put the
// object behind them elsewhere). Pixels in messages are in options.fit.pixel_origin.
// With `reliability` not null, also the least checked kept point (PointReliability: its index
// among kept_points, redundancy and direction; the caller words it).
DeterminationCheck CheckDetermination(const Selection& selection,
                                      const std::vector<Eigen::Vector3d>& kept_points,
                                      const AutoFitOptions& options,
                                      PointReliability* reliability = nullptr);

// Whether an orthographic answer's perspective is observable: the test of "the depth spread is
// small against the distance". The orthographic camera is the limit e = 0 of the perspective
// strength e (pixel = c + (u_ortho - c) / (1 + e z_cam), ParametersOf in pixel_uncertainty.cc);
// freeing e would lower the kept points' sum of squares J by removed_px2 = r^T H r, linearized
// (H the hat matrix of the Jacobian with e free, r the selection's residuals, kept points in
// order). The statistic is that in units of the noise with e free: options.fit.pixel_sigma if
// given, else the prior combined with J - removed_px2 over 2N - p - 1 degrees of freedom
// (CombinedNoise: as the selection's noise comes from its richest model, and e is one parameter
// richer than the orthographic camera). Above chi2_1(1 - significance) (10.83 at 0.1 %) the
// points show a perspective the orthographic camera leaves out. Not checked (checked = false)
// for a perspective answer.
struct PerspectiveTest {
  bool checked = false;
  bool observable = false;  // statistic > bound
  double sum_squares_px2 = 0.0;  // J
  double removed_px2 = 0.0;
  double sigma_px = 0.0;
  double statistic = 0.0;
  double bound = 0.0;
};
PerspectiveTest TestPerspectiveStrength(const Selection& selection,
                                        const std::vector<Eigen::Vector3d>& kept_points,
                                        const AutoFitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_DETERMINATION_H_

// The consistency gate (private): are a fit's residuals consistent with the pixel noise?
// FitCameraAuto runs it on the least-squares fit of every point (a failure sends the scene to
// the outlier stage), on every subset the outlier stage tries, and on the returned camera (a
// failure there is a refusal). The tests and their significance: model_select.h,
// AutoFitOptions::significance; docs/model-selection.md.
#ifndef CAMPROJ_SRC_FIT_GATE_H_
#define CAMPROJ_SRC_FIT_GATE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/conventions.h"
#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// "3.14 px": a pixel distance in messages.
std::string Px(double value);

// "(505, 714)": a pixel (kCenter) in messages, rounded, in `origin`'s convention.
std::string PixelText(const Eigen::Vector2d& pixel_center, PixelOrigin origin);

// The noise the residuals are tested against: FitOptions::pixel_sigma when given, else
// AutoFitOptions::prior_sigma_px.
struct NoiseReference {
  double sigma_px = 1.0;
  bool given = false;
  std::string Source() const;  // "given" / "default prior for clicked points"
};

NoiseReference NoiseReferenceOf(const AutoFitOptions& options);

// Which correspondences repeat an earlier one exactly (the same point with the same pixel): one
// observation written twice, which adds no redundancy.
std::vector<bool> Repeats(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& pixels);

// Tests the residual lengths (px) of the points a fit kept, for a model of num_params
// parameters, counting each observation once (`repeats`: Repeats of those points, the copies
// to leave out; empty: none), N observations: (1) chi-square: sum r^2 <= (tolerance *
// noise)^2 * chi2_{2N-p}(1 - alpha); (2) largest residual <= sqrt(2 ln(N / alpha)) *
// max(robust noise, noise), the robust noise being median |r| / sqrt(2 ln 2), scaled by
// sqrt(2N / (2N - p)) for the fit's leverage. With no redundant equation (2N <= p) nothing can
// be tested and the check passes, saying so. rms_px and max_residual_px are over every point
// kept.
ConsistencyCheck CheckConsistency(const std::vector<double>& residual_lengths_px,
                                  const std::vector<bool>& repeats, int num_params,
                                  const NoiseReference& noise, const AutoFitOptions& options);

// Whether residuals that failed CheckConsistency (its record `check`, over check.observations
// observations, N) show outliers rather than noise larger than the reference: the largest residual
// beyond the outlier bound (test 2 above), or the noise estimate sqrt(J / (2N - p)) above the
// robust noise (median-based) by more than Gaussian residuals' at significance alpha. For those
// log(noise estimate / robust noise) is asymptotically normal, mean 0, variance
// kNoiseRatioLogVariance / N (gate.cc); at 13-30 observations its tail is heavier than that, so
// Gaussian residuals are called contaminated up to 0.6 % of the time instead of 0.1 %.
bool ShowsOutliers(const ConsistencyCheck& check, const AutoFitOptions& options);

// Whether the robust noise of a CheckConsistency record (the median's, which no outlier among
// fewer than half the points moves far) exceeds the bound on the noise estimate by more than its
// own sampling error at significance alpha: for Gaussian residuals the log of the median's
// estimate has variance ln(2)^-2 / (4N) (gate.cc), 0.52 / N. The points' own noise is then
// beyond what the gate accepts, with or without outliers.
bool RobustNoiseBeyondTheBound(const ConsistencyCheck& check, const AutoFitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_GATE_H_

// The outlier stage (private): which points to leave out so that the rest is consistent with
// the pixel noise (gate.h). FitCameraAuto runs it when the least-squares fit of every point
// fails the gate. Up to AutoFitOptions::exhaustive_max_points points (a handful of clicks) every
// leave-one-out and then leave-two-out subset is fitted: exact, and cheap at that size; above, LO-RANSAC
// (FitOptions::ransac) at a threshold derived from the noise. Where the screen passes, a
// mis-click the fit absorbed is looked for at that size too (FindAbsorbedOutlier). The inliers
// found still go through the model selection and the final gate.
#ifndef CAMPROJ_SRC_FIT_OUTLIERS_H_
#define CAMPROJ_SRC_FIT_OUTLIERS_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "fit/gate.h"
#include "fit/selection.h"

namespace camproj {
namespace internal {

struct OutlierSearch {
  bool found = false;
  std::vector<int> outliers;  // sorted indices into the caller's points
  std::string method;         // "leave-one-out", "leave-two-out", "lo-ransac"
  std::string why_not;        // when !found: what the search saw, in words (names points)
  bool too_few_points = false;  // when !found: more points would let the search decide
};

// The screen: every point fitted with the simplest model that can show a mis-click -- pose +
// focal + principal point where the scene determines it with min_redundancy equations to spare,
// else pose + focal (the caller's forced or given intrinsics as they are) -- and gated at
// AutoFitOptions::screen_noise_tolerance. Run before the model selection, whose richer models
// (skew, k1, k2 at 8 points) can absorb a mis-click.
struct Screen {
  bool consistent = false;
  std::string summary;  // the gate's verdict, or the last refusal
  ConsistencyCheck check;  // the gate's record, where a model was fitted
  std::optional<Prefit> fit;  // the model fitted and its fit, unless every model was refused
  std::optional<SceneError> refusal;  // the last model's, when every model was refused
};

Screen ScreenPoints(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const AutoFitOptions& options,
                    const NoiseReference& noise);

// `names` name the points in messages. Never throws a SceneError: a search that finds no unique
// subset says why in why_not.
OutlierSearch FindOutliers(const std::vector<Eigen::Vector3d>& points_in_world,
                           const std::vector<Eigen::Vector2d>& observed_pixels,
                           const ImageSize& image_size, const AutoFitOptions& options,
                           const NoiseReference& noise, const std::vector<std::string>& names);

// The mis-click a fit absorbed: after a screen that passed, at up to exhaustive_max_points
// points, each point left out in turn and the screen's model fitted to the rest from its closed
// form. A mis-click can move the fit of every point into another minimum where all of them fit
// within the noise (seen: 8 clicks, one 187 px off, explained by a 144 deg view at 1.74 px rms;
// without it the other 7 fit at 0.43 px). The test is the likelihood ratio for one outlier: the
// drop in the sum of squares when point i is left out, J_all - J_rest, against sigma^2
// chi2_2(1 - alpha / N) (alpha: AutoFitOptions::significance, over N points; for a model linear
// near one minimum each drop of a clean point is sigma^2 chi2_2). A point is found when its drop
// and no other's exceeds the bound, and the rest pass the gate; the rest must keep
// min_redundancy + 2 equations to spare (as FindOutliers' subsets). Never throws a SceneError.
OutlierSearch FindAbsorbedOutlier(const std::vector<Eigen::Vector3d>& points_in_world,
                                  const std::vector<Eigen::Vector2d>& observed_pixels,
                                  const ImageSize& image_size, const AutoFitOptions& options,
                                  const NoiseReference& noise, const Screen& screen);

// LO-RANSAC's inlier threshold at n points: the gate's outlier bound at the largest noise it
// accepts, sqrt(2 ln(n / alpha)) * noise_tolerance * noise.
double RansacThresholdPx(int n, const AutoFitOptions& options, const NoiseReference& noise);

// Whether points left out could make a gate failure over every point (`check`) pass, so that
// the outlier stage is worth running: always at up to exhaustive_max_points observations (exact
// and cheap there); above, unless the residuals look like Gaussian noise around a camera most
// points agree with, and that noise is beyond what the gate accepts: no outlier shows
// (ShowsOutliers, gate.h), the median residual is within RansacThresholdPx (so LO-RANSAC's
// consensus would be about every point; at 50 % random pixels the least-squares camera is far
// from every point and the median far beyond it), and the robust noise exceeds the gate's bound
// on the noise estimate by more than its sampling error (RobustNoiseBeyondTheBound, gate.h).
bool MayBeOutliers(const ConsistencyCheck& check, const AutoFitOptions& options,
                   const NoiseReference& noise);

// The points whose residual (every point's, against one camera) exceeds the gate's outlier
// bound for the robust noise of the points kept (`kept_check`, the gate's record over them):
// LO-RANSAC's consensus re-read at the noise the data show.
std::vector<int> OutliersAgainst(const std::vector<Eigen::Vector2d>& residuals_px,
                                 const ConsistencyCheck& kept_check, const NoiseReference& noise,
                                 const AutoFitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_OUTLIERS_H_

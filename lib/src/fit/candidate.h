// FitCamera as the model selection scores a candidate model (private): the same stages and the
// same result, except for what a candidate does not need (fit/common.h, FitEffort: below) and
// what it takes from the selection (CandidateReuse): a candidate one group richer than the
// ladder's current model starts where that model's fit ended (fit/start.h, WarmStart) instead
// of at a closed form, and every candidate's scene is made from the points prepared once.
//
// With radial distortion and the principal point free, the refinement also restarts from a
// principal point beyond each edge of the image (refine.cc: minima on either side of a principal
// point far off centre). That costs four more refinements per fit. A candidate only needs its
// criterion, and a fit already consistent with the noise cannot gain a significant drop in it,
// so a candidate skips the restarts when its sum of squares is within the chi-square quantile
// at `consistent_at_px`. The chosen model's own fit (and every FitCamera call) always restarts:
// a fit can be consistent with the noise and still sit in a minimum far from the truth.
//
// Nor does a candidate check its covariance's linearization (FitResult::linearity, 2p more
// evaluations of the residuals), compute its covariance, its views (FitResult::views), its
// median residual or its fixed parameters' description: the selection reads a candidate's
// residuals and camera, and the chosen model's fit reports the rest.
//
// The warm start leaves out the closed form (at 6 points the DLT, its pose re-solved, and the
// second start from the image centre) and reaches the same minimum wherever the scene has one
// (tests/candidate_test.cc); where it has several, the nested model's minimum is the one the
// ladder asks about: whether freeing the group pays at this camera. A warm start goes straight
// to the Gauss-Newton polish (least_squares.h): from the nested minimum the new one is usually a
// step or two away, and Levenberg-Marquardt runs only where the polish does not converge.
// Every refinement of a candidate, from any start, stops at the polish's convergence test
// (least_squares.h, PolishUntil::kConverged: the last step under 1e-3 of the noise), not when a
// step settles under 1e-9 px: its sum of squares is then within ~1e-6 sigma^2 of the minimum's,
// and the passes over the points that would confirm it are saved (the default path 3 / 7 / 9 /
// 16 / 16 / 17 % cheaper at 6 / 8 / 12 / 20 / 100 / 1000 points, bench --stage-cost; on the
// click benchmark the same answers, 3 of 6600 refusals' reasons changed); and where the last
// two steps predict the next within that test, at the step before it (the default path 0.2 /
// 0.9 / 1.2 / 4.0 / 4.5 / 6.6 % cheaper at 6 / 8 / 12 / 20 / 100 / 1000 points; on the click
// benchmark the same answers and refusals, 11 of 42 500 rows with a refusal's number one unit
// off in its third digit; the returned cameras the same to 3e-14 relative). The chosen model is
// refitted with everything computed and its restarts: from scratch below 20 points where it
// frees the principal point and is not the screen's model (whose fit from scratch the ladder
// holds), else from the ladder's camera (FitReusing; selection.cc says why).
#ifndef CAMPROJ_SRC_FIT_CANDIDATE_H_
#define CAMPROJ_SRC_FIT_CANDIDATE_H_

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "fit/normal_equations.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// What a candidate may take from the selection instead of computing it; either may be null.
struct CandidateReuse {
  // A camera of a model nested in this one, fitted to the same points: the start instead of
  // the closed form (fit/start.h, WarmStart).
  const Camera* warm_start = nullptr;
  // The same points prepared once (fit/scene.h, PrepareScene), for options.pixel_origin.
  const SceneGeometry* geometry = nullptr;
  // Not a reuse but a return: if not null, receives the fit's normal equations at its answer
  // (a perspective fit's; left empty otherwise), for the determination check's rivals.
  ChartLinearization* linearization = nullptr;
};

// As FitCamera (fit.h), with the restarts skipped for a fit consistent at `consistent_at_px`
// (> 0, px per axis; nullopt: never skipped, for a fit the selection may refit its answer from,
// the screen's), FitResult::linearity, ::views, ::median_px, ::fixed_parameters and the
// covariance not computed, and what `reuse` holds reused.
FitResult FitCandidate(const std::vector<Eigen::Vector3d>& points_in_world,
                       const std::vector<Eigen::Vector2d>& observed_pixels,
                       const ImageSize& image_size, const FitOptions& options,
                       std::optional<double> consistent_at_px, const CandidateReuse& reuse = {});

// As FitCamera (fit.h), everything computed, restarts included, but started and prepared as
// `reuse` says: the model selection's chosen model refitted with its covariance, from the
// ladder's fit of it or (warm_start null) from its closed form, its normal equations returned
// where reuse.linearization is not null. FitResult::start_method is "warm" where
// reuse.warm_start is not null.
FitResult FitReusing(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options,
                    const CandidateReuse& reuse);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_CANDIDATE_H_

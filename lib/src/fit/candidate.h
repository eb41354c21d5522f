// FitCamera as the model selection scores a candidate model (private): the same stages and the
// same result, except for two things a candidate does not need (fit/common.h, FitEffort).
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
// evaluations of the residuals): the chosen model's fit reports it.
#ifndef CAMPROJ_SRC_FIT_CANDIDATE_H_
#define CAMPROJ_SRC_FIT_CANDIDATE_H_

#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"

namespace camproj {
namespace internal {

// As FitCamera (fit.h), with the restarts skipped for a fit consistent at `consistent_at_px`
// (> 0, px per axis) and FitResult::linearity not checked.
FitResult FitCandidate(const std::vector<Eigen::Vector3d>& points_in_world,
                       const std::vector<Eigen::Vector2d>& observed_pixels,
                       const ImageSize& image_size, const FitOptions& options,
                       double consistent_at_px);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_CANDIDATE_H_

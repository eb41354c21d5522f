// The assessment's verdicts in words (private; FitCameraAuto's last stage, model_select.cc): the
// refusals a returned camera can still meet -- not determined to the bound, another model or a
// mirrored reading that fits about as well, perspective an orthographic answer leaves out, a
// confidence region without an edge, a click no other point checks -- each saying what to fix,
// and the least checked point's summary. Pixels in messages are in the caller's convention.
#ifndef CAMPROJ_SRC_FIT_VERDICTS_H_
#define CAMPROJ_SRC_FIT_VERDICTS_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/conventions.h"
#include "camproj/fit.h"
#include "fit/determination.h"

namespace camproj {
namespace internal {

// "c4 (118 px from where the camera puts it), point 7 (64 px ...)": the points in `left_out`
// (indices into `residuals` and `names`), for the refusals below.
std::string LeftOutText(const std::vector<Eigen::Vector2d>& residuals,
                        const std::vector<int>& left_out, const std::vector<std::string>& names);

// Each throws SceneError when its verdict is a refusal and returns otherwise; `left_out` is
// LeftOutText's (empty: no point left out), named first in the advice ("Fix or drop ...").

// The determination check's (fit/determination.h): a camera the points do not pin down to the
// bound (kDegenerate), or one that a model fitting about as well, or the mirrored reading, puts
// elsewhere (kAmbiguous). `model`: the returned camera's model name.
void RefuseIfUndetermined(const DeterminationCheck& check, const std::string& model,
                          const std::string& left_out, PixelOrigin pixel_origin);

// An orthographic camera chosen where the points show perspective (TestPerspectiveStrength): it
// can only stand in for a perspective camera the points did not determine (kDegenerate).
void RefuseIfPerspectiveShows(const PerspectiveTest& test, const std::string& left_out);

// A camera whose confidence region has no edge (FitResult::linearity infinite): its sigmas
// describe nothing, and the determination check cannot see how far it may be off (kDegenerate).
void RefuseIfRegionUnbounded(const FitResult& fit, const std::string& left_out);

// The least checked kept point (CheckDetermination's, its index among the kept points) in the
// caller's indices (`left_out` sorted) and words: PointReliability::summary.
PointReliability WordReliability(PointReliability least, const std::vector<int>& left_out,
                                 const std::vector<std::string>& names);

// A click no other point checks: `least` (worded) keeps so little of a mis-click along its
// direction that one anywhere in the image would leave less than the noise (`sigma_px`) in its
// residual (kDegenerate).
void RefuseIfUnchecked(const PointReliability& least, const std::vector<std::string>& names,
                       const ImageSize& size, double sigma_px, const std::string& left_out);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_VERDICTS_H_

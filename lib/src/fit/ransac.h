// RANSAC, the robust stage on a fixed threshold (private; FitOptions::ransac): minimal
// closed-form samples of the validated scene -- SQPnP for known intrinsics, the constrained
// homography for a plane, the DLT otherwise -- each scored by the points it reprojects within
// options.ransac_threshold_px, with a local optimization whenever the best consensus grows and
// the adaptive stopping rule. Takes the scene; returns the consensus, which FitCamera then fits
// without RANSAC before reporting every point against that camera.
#ifndef CAMPROJ_SRC_FIT_RANSAC_H_
#define CAMPROJ_SRC_FIT_RANSAC_H_

#include <vector>

#include "camproj/fit.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// The largest consensus found (indices into scene.points), drawn with options.ransac_seed.
// Throws SceneError kDegenerate when it has fewer points than a sample (4 or 6) or than half the
// unknowns.
std::vector<int> RansacConsensus(const Scene& scene, const FitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_RANSAC_H_

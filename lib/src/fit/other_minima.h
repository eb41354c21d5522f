// Other minima of the chosen model (private), for the default path at six points: the model
// refined from principal points the closed forms did not start from. With six points the DLT
// (11 unknowns, 12 equations) and the screen's start have one redundant equation, their
// principal point says little under noise, and two minima of the same model can fit within the
// noise while putting the scene far apart (seen: cy 336 px at RMS 0.76 px and the lens shift's
// cy 1074 px at RMS 0.47 px; tests/fit_test.cc SixPointLocalMinimumIsNotAnswered). The
// determination check weighs each as a rival (selection.h, Rival::same_model).
#ifndef CAMPROJ_SRC_FIT_OTHER_MINIMA_H_
#define CAMPROJ_SRC_FIT_OTHER_MINIMA_H_

#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "fit/reading.h"

namespace camproj {
namespace internal {

// The rival's model name where it counts (DeterminationCheck::rival).
inline constexpr char kOtherMinimumName[] = "the same model at another of its minima";

// `model` (principal point free) fitted by LM (one round of at most 20 iterations) from an SQPnP
// pose with `chosen`'s intrinsics but the principal point at each midpoint of the image's edges:
// the proper cameras found with every point in front, each with its RMS. `chosen` is `model`'s
// fit of the same points, with `chosen_rms_px`: a refit that comes back to it stops in its
// neighbourhood and is not returned (least_squares.h, KnownMinimum), as the determination check
// would drop it as the same minimum again.
std::vector<Reading> FitFromEdgePrincipalPoints(const std::vector<Eigen::Vector3d>& points_in_world,
                                                const std::vector<Eigen::Vector2d>& observed_pixels,
                                                const ImageSize& image_size,
                                                const FitOptions& model, const Camera& chosen,
                                                double chosen_rms_px);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_OTHER_MINIMA_H_

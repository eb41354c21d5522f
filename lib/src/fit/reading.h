// Another reading of the data (private): a camera refined from a start the default path chooses
// (the mirrored world's, another principal point's) with its RMS, for the rivals the
// determination check weighs against the chosen camera (fit/mirror.h, fit/other_minima.h).
#ifndef CAMPROJ_SRC_FIT_READING_H_
#define CAMPROJ_SRC_FIT_READING_H_

#include <limits>
#include <optional>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "camproj/intrinsics.h"
#include "fit/closed_form.h"
#include "fit/least_squares.h"
#include "fit/model.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

struct Reading {
  Camera camera;  // in the world the scene was validated in
  double rms_px = 0.0;
};

// `model` with its free slots at `intrinsics`, distortion included.
Model ModelAt(const Model& model, const Intrinsics& intrinsics);

// LM (one round of options.max_iterations) in `scene`'s normalized world from `start`: the
// camera as `like` (projection, image size, depth range) with the refined pose and intrinsics,
// and its RMS; nothing if a point ends behind it or its focal length or aspect is not positive.
// `out_of_reach_px2`, `known`: RefineLeastSquares' (fit/least_squares.h); nothing either where it
// stops at the known minimum.
std::optional<Reading> RefineReading(
    const Scene& scene, const StartCamera& start, const Model& start_model,
    const FitOptions& options, const Camera& like,
    double out_of_reach_px2 = std::numeric_limits<double>::infinity(),
    const KnownMinimum* known = nullptr);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_READING_H_

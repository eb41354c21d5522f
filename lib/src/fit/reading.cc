#include "fit/reading.h"

#include <cmath>

#include "camproj/pose.h"
#include "fit/least_squares.h"

namespace camproj {
namespace internal {

Model ModelAt(const Model& model, const Intrinsics& intrinsics) {
  Model at = ProjectOntoModel(model, intrinsics);
  if (at.free[5]) at.value[5] = intrinsics.k1;
  if (at.free[6]) at.value[6] = intrinsics.k2;
  return at;
}

std::optional<Reading> RefineReading(const Scene& scene, const StartCamera& start,
                                     const Model& start_model, const FitOptions& options,
                                     const Camera& like, double out_of_reach_px2,
                                     const KnownMinimum* known) {
  const LeastSquaresOutcome outcome = RefineLeastSquares(
      scene.points, scene.pixels, start.rotation, start.center, start_model, options,
      Clock::now(), /*max_rounds=*/1, PolishFirst::kNo, PolishUntil::kSettled, out_of_reach_px2,
      known);
  if (!outcome.ok) return std::nullopt;
  Reading reading;
  reading.camera = like;
  reading.camera.intrinsics = outcome.model.ToIntrinsics();
  reading.camera.intrinsics.skew += 0.0;  // no -0
  reading.camera.cam_from_world =
      CamFromWorldFromCenter(outcome.rotation, scene.centroid + scene.scale * outcome.center);
  reading.rms_px = std::sqrt(outcome.normal.cost / static_cast<double>(scene.NumPoints()));
  return reading;
}

}  // namespace internal
}  // namespace camproj

#include "fit/mirror.h"

#include <cmath>

#include "camproj/pose.h"
#include "fit/common.h"
#include "fit/least_squares.h"
#include "fit/model.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

Camera NeckerReversal(const Camera& camera, const std::vector<Eigen::Vector3d>& points_in_world) {
  const double centroid_depth = (camera.cam_from_world * Centroid(points_in_world)).z();
  const Eigen::Matrix3d flip = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  Camera reversed = camera;
  reversed.cam_from_world.rotation = flip * camera.cam_from_world.rotation * flip;
  reversed.cam_from_world.translation = flip * camera.cam_from_world.translation;
  reversed.cam_from_world.translation.z() += 2.0 * centroid_depth;
  return reversed;
}

std::optional<double> MirroredReadingRmsPx(const Camera& camera, const FitOptions& model,
                                           const std::vector<Eigen::Vector3d>& points_in_world,
                                           const std::vector<Eigen::Vector2d>& observed_pixels) {
  // The readings a weak perspective cannot tell apart differ from the reversal at second order
  // in depth / distance: LM from there settles in a few iterations. A strong perspective leaves
  // the reversal far from any camera that fits, and LM would crawl for hundreds of iterations
  // (at 100 points that cost 10 times the rest of the default path) towards a cost it cannot
  // bring near ours. Stopping early only raises the cost found -- a camera with that cost
  // exists -- so it can miss a refusal but never make a wrong one.
  constexpr int kMirrorIterations = 20;
  const std::vector<Eigen::Vector3d> mirrored = MirroredZ(points_in_world);
  const Camera reversed = NeckerReversal(camera, points_in_world);
  FitOptions options = model;
  options.max_iterations = kMirrorIterations;
  try {
    const Scene scene = ValidateScene(mirrored, observed_pixels, camera.image_size, options);
    const Eigen::Vector3d start_center =
        (CameraCenterInWorld(reversed.cam_from_world) - scene.centroid) / scene.scale;
    Model start_model = ProjectOntoModel(scene.model, camera.intrinsics);
    if (start_model.free[5]) start_model.value[5] = camera.intrinsics.k1;
    if (start_model.free[6]) start_model.value[6] = camera.intrinsics.k2;
    const LeastSquaresOutcome outcome =
        RefineLeastSquares(scene.points, scene.pixels, reversed.cam_from_world.rotation,
                           start_center, start_model, options, Clock::now(), /*max_rounds=*/1);
    if (!outcome.ok) return std::nullopt;  // a point behind it, or a mirror image of its own
    return std::sqrt(outcome.normal.cost / static_cast<double>(mirrored.size()));
  } catch (const SceneError&) {
    return std::nullopt;  // the mirrored scene has no valid start (ValidateScene's refusals)
  }
}

}  // namespace internal
}  // namespace camproj

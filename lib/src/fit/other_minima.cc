#include "fit/other_minima.h"

#include <limits>

#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

std::vector<Reading> FitFromEdgePrincipalPoints(const std::vector<Eigen::Vector3d>& points_in_world,
                                                const std::vector<Eigen::Vector2d>& observed_pixels,
                                                const ImageSize& image_size,
                                                const FitOptions& model, const Camera& chosen,
                                                double chosen_rms_px) {
  // As the mirror test's fresh start (fit/mirror.cc): enough for LM to settle from SQPnP.
  constexpr int kIterations = 20;
  FitOptions options = model;
  options.max_iterations = kIterations;
  std::vector<Reading> readings;
  try {
    const Scene scene = ValidateScene(points_in_world, observed_pixels, image_size, options);
    Camera like;
    like.image_size = image_size;
    const Eigen::Matrix3d& rotation = chosen.cam_from_world.rotation;
    const Eigen::Vector3d center_in_world =
        -rotation.transpose() * chosen.cam_from_world.translation;
    const KnownMinimum known{rotation, (center_in_world - scene.centroid) / scene.scale,
                             ModelAt(scene.model, chosen.intrinsics).value,
                             chosen_rms_px * chosen_rms_px * scene.NumPoints()};
    for (const Eigen::Vector2d& principal_point : EdgeMidpoints(image_size, 0.0)) {
      Intrinsics k = chosen.intrinsics;
      k.cx = principal_point.x();
      k.cy = principal_point.y();
      StartCamera start;
      if (!PnpStart(scene.points, scene.pixels, k, &start)) continue;
      if (auto reading = RefineReading(scene, start, ModelAt(scene.model, k), options, like,
                                       std::numeric_limits<double>::infinity(), &known)) {
        readings.push_back(*reading);
      }
    }
  } catch (const SceneError&) {
    // No valid scene: no readings.
  }
  return readings;
}

}  // namespace internal
}  // namespace camproj

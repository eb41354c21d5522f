#include "fit/other_minima.h"

#include "fit/closed_form.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

std::vector<Reading> FitFromEdgePrincipalPoints(const std::vector<Eigen::Vector3d>& points_in_world,
                                                const std::vector<Eigen::Vector2d>& observed_pixels,
                                                const ImageSize& image_size,
                                                const FitOptions& model,
                                                const Intrinsics& intrinsics) {
  // As the mirror test's fresh start (fit/mirror.cc): enough for LM to settle from SQPnP.
  constexpr int kIterations = 20;
  FitOptions options = model;
  options.max_iterations = kIterations;
  std::vector<Reading> readings;
  try {
    const Scene scene = ValidateScene(points_in_world, observed_pixels, image_size, options);
    const double w = image_size.width;
    const double h = image_size.height;
    const double cx = 0.5 * (w - 1.0);  // the image centre, kCenter px
    const double cy = 0.5 * (h - 1.0);
    const Eigen::Vector2d edge_midpoints[] = {{-0.5, cy}, {w - 0.5, cy}, {cx, -0.5}, {cx, h - 0.5}};
    Camera like;
    like.image_size = image_size;
    for (const Eigen::Vector2d& principal_point : edge_midpoints) {
      Intrinsics k = intrinsics;
      k.cx = principal_point.x();
      k.cy = principal_point.y();
      StartCamera start;
      if (!PnpStart(scene.points, scene.pixels, k, &start)) continue;
      if (auto reading = RefineReading(scene, start, ModelAt(scene.model, k), options, like)) {
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

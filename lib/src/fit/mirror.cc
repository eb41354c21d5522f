#include "fit/mirror.h"

#include <cmath>
#include <optional>
#include <vector>

#include "camproj/pose.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/reading.h"
#include "fit/scene.h"
#include "fit/start.h"

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

namespace {

// The mirrored readings' LM iterations (one round each). Where no proper camera of the mirrored
// world fits, LM crawls for hundreds of iterations (at 100 points that cost 10 times the rest of
// the default path) towards a cost it cannot bring near ours; stopping early only raises the cost
// found -- a camera with that cost exists -- so it can miss a mirrored reading, never invent one.
// From the depth reversal: the readings a weak perspective cannot tell apart differ from it at
// second order in depth / distance, and LM settles in a few iterations (10 and 20 give the same
// click benchmark and weak-perspective outcomes; 10 keeps a clean fit within 1.2x of 40af1d1 at
// 100 and 1000 points, bench --stage-cost). From a fresh start, at <= 8 points only: 10 misses
// one of the two mirrored 6-click scenes of tests/fit_auto_test.cc, 20 finds both.
constexpr int kReversalIterations = 10;
constexpr int kFreshStartIterations = 20;

// A refinement stops where the Gauss-Newton model's minimum is above this many times the sum of
// squares the caller reads it below (fit/least_squares.h). The reversal: at 100 points a strong
// perspective leaves the mirrored world 10^3-10^4 times the proper one's cost after 10
// iterations, and those iterations were 13 % of the default path. Measured over 3540 reversals
// (bench --stage-cost at N = 6-1000 and bench --clicks): at 10 it stops 2882 of them, saving 67 %
// of their iterations; every one it stops ended the 10 iterations at least 24 times above the
// cost read (at 3: 15 times), and none that ended below it is stopped. The fresh starts (at <= 8
// points) come closer: over 2904 of them (bench --stage-cost at N = 6-20, bench --clicks on
// scenes 0-299) 30 stops 1899, saving 56 % of their iterations, each ending its 20 iterations
// at least 12.6 times above; at 10 that margin is 3.3, and at 3 two readings that end below the
// cost read are stopped.
constexpr double kReversalOutOfReach = 10.0;
constexpr double kFreshStartOutOfReach = 30.0;

// The mirrored world's scene for `options`: from `mirrored_world` where the caller prepared it.
Scene MirroredScene(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options,
                    const SceneGeometry* mirrored_world) {
  return mirrored_world != nullptr
             ? ValidateScene(*mirrored_world, options)
             : ValidateScene(MirroredZ(points_in_world), observed_pixels, image_size, options);
}

}  // namespace

std::optional<MirroredReading> FitMirroredReading(
    const Camera& camera, const FitOptions& model,
    const std::vector<Eigen::Vector3d>& points_in_world,
    const std::vector<Eigen::Vector2d>& observed_pixels, const SceneGeometry* mirrored_world,
    double read_below_px2) {
  const Camera reversed = NeckerReversal(camera, points_in_world);
  FitOptions options = model;
  options.max_iterations = kReversalIterations;
  try {
    const Scene scene = MirroredScene(points_in_world, observed_pixels, camera.image_size,
                                      options, mirrored_world);
    StartCamera start;
    start.rotation = reversed.cam_from_world.rotation;
    start.center = (CameraCenterInWorld(reversed.cam_from_world) - scene.centroid) / scene.scale;
    return RefineReading(scene, start, ModelAt(scene.model, camera.intrinsics), options, camera,
                         kReversalOutOfReach * read_below_px2);
  } catch (const SceneError&) {
    return std::nullopt;  // the mirrored scene has no valid start (ValidateScene's refusals)
  }
}

std::vector<std::optional<MirroredReading>> FitMirroredWorld(
    const std::vector<Eigen::Vector3d>& points_in_world,
    const std::vector<Eigen::Vector2d>& observed_pixels, const ImageSize& image_size,
    const std::vector<FitOptions>& models, const Intrinsics& intrinsics,
    const SceneGeometry* mirrored_world, double read_below_px2) {
  // The SQPnP pose at `intrinsics` does not depend on the model: solved at most once.
  bool pnp_solved = false;
  std::optional<StartCamera> pnp;
  auto fit = [&](const FitOptions& model) -> std::optional<MirroredReading> {
    FitOptions options = model;
    options.max_iterations = kFreshStartIterations;
    try {
      const Scene scene =
          MirroredScene(points_in_world, observed_pixels, image_size, options, mirrored_world);
      StartCamera start;
      Model start_model;
      // The DLT reads the mirrored world as mirrored where it reads the given one as proper:
      // SQPnP then, from the intrinsics the given world was fitted with.
      if (model.known_intrinsics || scene.planar_start || scene.num_distinct_points < 6 ||
          !DltStartOf(scene).mirrored) {
        const Start closed_form = ClosedFormStart(scene, options, Clock::now());
        start = closed_form.camera;
        start_model = closed_form.model;
      } else {
        if (!pnp_solved) {
          pnp_solved = true;
          StartCamera solved;
          if (PnpStart(scene.points, scene.pixels, intrinsics, &solved)) pnp = solved;
        }
        if (!pnp) return std::nullopt;
        start = *pnp;
        start_model = ModelAt(scene.model, intrinsics);
      }
      Camera like;
      like.image_size = image_size;
      return RefineReading(scene, start, start_model, options, like,
                           kFreshStartOutOfReach * read_below_px2);
    } catch (const SceneError&) {
      return std::nullopt;  // no start, or no valid scene
    }
  };
  std::vector<std::optional<MirroredReading>> readings;
  for (const FitOptions& model : models) readings.push_back(fit(model));
  return readings;
}

}  // namespace internal
}  // namespace camproj

#include "fit/ransac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "check.h"
#include "fit/closed_form.h"
#include "fit/model.h"

namespace camproj {
namespace internal {

namespace {

// Indices of the points within `threshold` px of the camera (rotation, center, model).
std::vector<int> InliersOf(const std::vector<Eigen::Vector3d>& points,
                           const std::vector<Eigen::Vector2d>& pixels,
                           const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                           const Model& model, double threshold) {
  std::vector<int> inliers;
  const double threshold2 = threshold * threshold;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Eigen::Vector2d> pixel =
        PixelOfCamPoint(model, rotation * (points[i] - center));
    if (pixel && (*pixel - pixels[i]).squaredNorm() <= threshold2) {
      inliers.push_back(static_cast<int>(i));
    }
  }
  return inliers;
}

// A closed-form camera from the points `subset`: SQPnP for known intrinsics, the constrained
// homography for a plane, the DLT otherwise. False where the subset is degenerate.
bool SolveSubset(const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Eigen::Vector2d>& pixels, const std::vector<int>& subset,
                 const Model& model, bool known, bool planar, const Eigen::Matrix3d& plane_basis,
                 StartCamera* camera, Model* fitted_model) {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Vector2d> u;
  for (const int i : subset) {
    x.push_back(points[i]);
    u.push_back(pixels[i]);
  }
  const Intrinsics guess = model.ToIntrinsics();
  bool ok = false;
  if (known) {
    ok = PnpStart(x, u, guess, camera);
  } else if (planar) {
    ok = HomographyStart(x, u, plane_basis, guess, model.free[0], model.free[1], camera);
  } else {
    const std::optional<StartCamera> dlt = DltStartIfInFront(x, u);
    ok = dlt && !dlt->mirrored;  // a mirrored sample is no camera of this world
    if (ok) *camera = *dlt;
  }
  if (!ok || !camera->rotation.allFinite() || !camera->center.allFinite()) return false;
  *fitted_model = known ? model : ProjectOntoModel(model, camera->intrinsics);
  return std::all_of(fitted_model->value.begin(), fitted_model->value.end(),
                     [](double v) { return std::isfinite(v); }) &&
         fitted_model->value[0] > 0.0 && fitted_model->value[1] > 0.0;
}

// Points per minimal sample: 4 for known intrinsics or a plane, 6 for the DLT.
int SampleSize(bool known, bool planar) { return known || planar ? 4 : 6; }

// RANSAC on minimal closed-form samples (4 points for known intrinsics or a plane, 6 for the
// DLT), with a local optimization (the closed form on all inliers) whenever the best consensus
// grows, and the adaptive stopping rule k = log(1 - confidence) / log(1 - w^s).
std::vector<int> RansacInliers(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector2d>& pixels, const Model& model,
                               bool known, bool planar, const Eigen::Matrix3d& plane_basis,
                               const FitOptions& options) {
  const int n = static_cast<int>(points.size());
  const int sample_size = SampleSize(known, planar);
  std::mt19937_64 rng(options.ransac_seed);
  std::vector<int> best;
  long iterations_needed = options.ransac_max_iterations;
  std::vector<int> sample(sample_size);
  for (long iteration = 0; iteration < iterations_needed; ++iteration) {
    for (int j = 0; j < sample_size; ++j) {
      int candidate = 0;
      do {
        candidate = static_cast<int>(rng() % static_cast<uint64_t>(n));
      } while (std::find(sample.begin(), sample.begin() + j, candidate) != sample.begin() + j);
      sample[j] = candidate;
    }
    StartCamera camera;
    Model fitted;
    if (!SolveSubset(points, pixels, sample, model, known, planar, plane_basis, &camera, &fitted)) {
      continue;
    }
    std::vector<int> inliers = InliersOf(points, pixels, camera.rotation, camera.center, fitted,
                                         options.ransac_threshold_px);
    if (inliers.size() <= best.size()) continue;
    // Local optimization: the closed form on the consensus, repeated while it grows.
    for (int round = 0; round < 3 && static_cast<int>(inliers.size()) > sample_size; ++round) {
      StartCamera refit;
      Model refit_model;
      if (!SolveSubset(points, pixels, inliers, model, known, planar, plane_basis, &refit,
                       &refit_model)) {
        break;
      }
      std::vector<int> grown = InliersOf(points, pixels, refit.rotation, refit.center,
                                         refit_model, options.ransac_threshold_px);
      if (grown.size() <= inliers.size()) break;
      inliers.swap(grown);
    }
    best.swap(inliers);
    const double w = static_cast<double>(best.size()) / n;
    const double all_inliers = std::pow(w, sample_size);
    if (all_inliers >= 1.0) break;
    const double needed = std::log(1.0 - options.ransac_confidence) / std::log(1.0 - all_inliers);
    iterations_needed = std::min<long>(options.ransac_max_iterations,
                                       static_cast<long>(std::ceil(needed)));
  }
  return best;
}

}  // namespace

std::vector<int> RansacConsensus(const Scene& scene, const FitOptions& options) {
  const bool known = options.known_intrinsics.has_value();
  // A sample draws distinct rows: with fewer rows than a sample there is none to draw.
  const int sample_size = SampleSize(known, scene.planar_start);
  if (scene.NumPoints() < sample_size) {
    throw SceneError(SceneError::Reason::kTooFewPoints,
                     Concat("RANSAC draws samples of ", sample_size, " points",
                            known ? " (known intrinsics)" : scene.planar_start ? " (a plane)" : "",
                            "; got ", scene.NumPoints()),
                     "Drop --ransac, or add points");
  }
  const std::vector<int> inliers = RansacInliers(scene.points, scene.pixels, scene.model, known,
                                                 scene.planar_start, scene.plane_basis, options);
  const int num_params = 6 + scene.model.NumFree();
  const int minimum = std::max(sample_size, (num_params + 1) / 2);
  if (static_cast<int>(inliers.size()) < minimum) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     Concat("RANSAC found no camera that ", minimum,
                            " or more points agree on within ", options.ransac_threshold_px,
                            " px"),
                     "Check the correspondences or raise the threshold");
  }
  return inliers;
}

}  // namespace internal
}  // namespace camproj

#include "camproj/fit.h"

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "check.h"
#include "fit/assess.h"
#include "fit/candidate.h"
#include "fit/common.h"
#include "fit/orthographic_fit.h"
#include "fit/ransac.h"
#include "fit/refine.h"
#include "fit/scene.h"
#include "fit/start.h"

namespace camproj {

using internal::Require;

void FitOptions::Check() const {
  if (projection == Projection::kOrthographic) {
    Require(!principal_point.IsFree(),
            "an orthographic camera's principal point is not determined (it trades exactly with "
            "its position): leave it at the image centre or give it");
    Require(!k1.IsFree() && !k2.IsFree() && (k1.kind != ParameterMode::Kind::kFixed || k1.value == 0.0) &&
                (k2.kind != ParameterMode::Kind::kFixed || k2.value == 0.0),
            "an orthographic camera has no radial distortion (k1, k2)");
    Require(!ransac, "RANSAC is for perspective cameras: use a robust loss with the orthographic one");
    Require(!known_intrinsics, "known intrinsics are for perspective cameras");
  }
  Require(focal.kind != ParameterMode::Kind::kDefault || known_intrinsics.has_value(),
          "focal has no default: make it free or fix it at a value");
  auto check_fixed = [](const ParameterMode& mode, const char* name) {
    if (mode.kind != ParameterMode::Kind::kFixed) return;
    internal::RequireFinite(mode.value, name);
    internal::RequireFinite(mode.value2, name);
  };
  check_fixed(focal, "fixed focal");
  check_fixed(aspect, "fixed aspect");
  check_fixed(principal_point, "fixed principal point");
  check_fixed(skew, "fixed skew");
  check_fixed(k1, "fixed k1");
  check_fixed(k2, "fixed k2");
  Require(focal.kind != ParameterMode::Kind::kFixed || focal.value > 0.0,
          "fixed focal must be positive, got ", focal.value);
  Require(aspect.kind != ParameterMode::Kind::kFixed || aspect.value > 0.0,
          "fixed aspect (fy/fx) must be positive, got ", aspect.value);
  if (known_intrinsics) known_intrinsics->Check();
  Require(std::isfinite(ransac_threshold_px) && ransac_threshold_px > 0.0,
          "RANSAC threshold must be positive (px), got ", ransac_threshold_px);
  Require(ransac_confidence > 0.0 && ransac_confidence < 1.0,
          "RANSAC confidence must be in (0, 1), got ", ransac_confidence);
  Require(ransac_max_iterations >= 1, "RANSAC iterations must be >= 1, got ", ransac_max_iterations);
  Require(std::isfinite(loss_scale_px) && loss_scale_px > 0.0,
          "loss scale must be positive (px), got ", loss_scale_px);
  Require(!pixel_sigma || (std::isfinite(*pixel_sigma) && *pixel_sigma > 0.0),
          "pixel sigma must be positive, got ", pixel_sigma.value_or(0.0));
  Require(max_iterations >= 0, "max iterations must be >= 0, got ", max_iterations);
  Require(function_tolerance >= 0.0 && gradient_tolerance >= 0.0 && parameter_tolerance >= 0.0,
          "tolerances must be >= 0");
  Require(!z_near || (std::isfinite(*z_near) && *z_near > 0.0), "near must be positive, got ",
          z_near.value_or(0.0));
  Require(!z_far || (!std::isnan(*z_far) && *z_far > z_near.value_or(0.0)),
          "far must be greater than near, got ", z_far.value_or(0.0));
  Require(std::isfinite(depth_margin) && depth_margin >= 0.0, "depth margin must be >= 0, got ",
          depth_margin);
  Require(strong_correlation > 0.0 && strong_correlation <= 1.0,
          "strong correlation threshold must be in (0, 1], got ", strong_correlation);
}

namespace {

// The stages in lib/src/fit/, in the order the data flows: scene -> (RANSAC: the consensus, fitted
// without RANSAC) -> closed-form start -> refinement -> assessment. `effort` says what the fit may
// leave out (fit/candidate.h).
FitResult Fit(const std::vector<Eigen::Vector3d>& points_in_world,
              const std::vector<Eigen::Vector2d>& observed_pixels, const ImageSize& image_size,
              const FitOptions& options, const internal::FitEffort& effort) {
  const internal::Clock::time_point start_time = internal::Clock::now();
  options.Check();
  image_size.Check();
  internal::CheckCorrespondences(points_in_world, observed_pixels);
  if (options.projection == Projection::kOrthographic) {
    return internal::FitOrthographic(points_in_world, observed_pixels, image_size, options);
  }
  const internal::Scene scene =
      effort.geometry != nullptr
          ? internal::ValidateScene(*effort.geometry, options)
          : internal::ValidateScene(points_in_world, observed_pixels, image_size, options);

  if (options.ransac) {
    // Find the consensus, fit it without RANSAC, then report every point against that camera.
    const std::vector<int> inliers = internal::RansacConsensus(scene, options);
    FitOptions inner = options;
    inner.ransac = false;
    std::vector<Eigen::Vector3d> inlier_points;
    std::vector<Eigen::Vector2d> inlier_pixels;
    for (const int i : inliers) {
      inlier_points.push_back(points_in_world[i]);
      inlier_pixels.push_back(observed_pixels[i]);
    }
    FitResult result = Fit(inlier_points, inlier_pixels, image_size, inner, effort);
    result.residuals_px = internal::ResidualsAgainst(result.camera, points_in_world,
                                                     observed_pixels, options.pixel_origin);
    for (int i = 0; i < scene.NumPoints(); ++i) {
      if (!(result.residuals_px[i].norm() <= options.ransac_threshold_px)) {
        result.outliers.push_back(i);
      }
    }
    result.start_method = "ransac+" + result.start_method;
    result.time_ms = internal::MicrosecondsSince(start_time) / 1000.0;
    return result;
  }

  // A model whose minimum is found in closed form starts there, from any start offered.
  std::optional<internal::Start> at_minimum = internal::PlaneAspectStart(scene, options);
  const internal::Start start = at_minimum                    ? std::move(*at_minimum)
                                : effort.warm_start != nullptr
                                    ? internal::WarmStart(scene, *effort.warm_start)
                                    : internal::ClosedFormStart(scene, options, start_time);
  internal::RefinedCamera refined =
      internal::RefineCamera(scene, start, options, effort, start_time);
  FitResult result = internal::AssessFit(scene, start.method, std::move(refined), options, effort);
  result.time_ms = internal::MicrosecondsSince(start_time) / 1000.0;
  return result;
}

}  // namespace

FitResult FitCamera(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options) {
  return Fit(points_in_world, observed_pixels, image_size, options, internal::FitEffort{});
}

namespace internal {

FitResult FitCandidate(const std::vector<Eigen::Vector3d>& points_in_world,
                       const std::vector<Eigen::Vector2d>& observed_pixels,
                       const ImageSize& image_size, const FitOptions& options,
                       std::optional<double> consistent_at_px, const CandidateReuse& reuse) {
  Require(!consistent_at_px || (std::isfinite(*consistent_at_px) && *consistent_at_px > 0.0),
          "a candidate's noise must be positive (px), got ", consistent_at_px.value_or(0.0));
  FitEffort effort;
  effort.warm_start = reuse.warm_start;
  effort.geometry = reuse.geometry;
  effort.skip_restarts_when_consistent_at_px = consistent_at_px;
  effort.check_linearity = false;
  effort.describe = false;
  effort.linearization = reuse.linearization;
  return Fit(points_in_world, observed_pixels, image_size, options, effort);
}

FitResult FitReusing(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options,
                    const CandidateReuse& reuse) {
  FitEffort effort;  // everything else computed
  effort.warm_start = reuse.warm_start;
  effort.geometry = reuse.geometry;
  effort.linearization = reuse.linearization;
  return Fit(points_in_world, observed_pixels, image_size, options, effort);
}

}  // namespace internal

}  // namespace camproj

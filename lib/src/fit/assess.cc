#include "fit/assess.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/pose.h"
#include "check.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/normal_equations.h"
#include "fit/statistics.h"

namespace camproj {
namespace internal {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
// Below this reciprocal condition number of the Jacobi-scaled normal equations the parameters
// are not determined by the points (double precision leaves ~1e-16; 1e-12 keeps a margin).
constexpr double kSingularRcond = 1e-12;

// Parameter names in the user parameterization, in the covariance's order.
std::vector<std::string> ParameterNames(const Model& model) {
  std::vector<std::string> names = {"rotation_x_deg", "rotation_y_deg", "rotation_z_deg",
                                    "eye_x", "eye_y", "eye_z"};
  const char* user_slot_names[] = {"fx", "fy", "cx", "cy", "skew", "k1", "k2"};
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (model.free[slot]) names.push_back(user_slot_names[slot]);
  }
  return names;
}

// FitResult::model: "pose" and the free intrinsics.
std::string ModelName(const Model& model) {
  std::string name = "pose";
  const char* model_slot_names[] = {"focal", "aspect", "principal-point", "", "skew", "k1", "k2"};
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (model.free[slot] && slot != 3) name += std::string("+") + model_slot_names[slot];
  }
  return name;
}

// The refusal of singular normal equations. Names the parameters that move along the
// unconstrained direction, and the free intrinsic that moves most along it: the pose cannot be
// fixed, an intrinsic can.
[[noreturn]] void RefuseUndetermined(const JacobiScaledNormal<ParamMatrix>& scaled_normal,
                                     const std::vector<std::string>& names) {
  const int num_params = static_cast<int>(names.size());
  const ParamVector direction = scaled_normal.eigen.eigenvectors().col(0);
  std::string involved;
  int intrinsic = -1;
  for (int j = 0; j < num_params; ++j) {
    if (std::abs(direction(j)) > 0.3) involved += (involved.empty() ? "" : ", ") + names[j];
    if (j >= 6 && (intrinsic < 0 || std::abs(direction(j)) > std::abs(direction(intrinsic)))) {
      intrinsic = j;
    }
  }
  const std::string fix =
      intrinsic >= 0 ? "fix " + names[intrinsic] + " (the free intrinsic that moves most along "
                                                    "it, e.g. with --model or a value)"
                     : "fix intrinsics";
  throw SceneError(SceneError::Reason::kDegenerate,
                   Concat("the points do not determine ", involved,
                          " (singular normal equations, reciprocal condition ",
                          std::max(scaled_normal.rcond, 0.0), "): ", fix,
                          ", or add points that spread further in depth and across the image"));
}

// The covariance in user units with its sigmas (fields of view included) and strong
// correlations, from result->pixel_sigma and result->camera. `scale`: the scene's.
void SetCovariance(const JacobiScaledNormal<ParamMatrix>& scaled_normal,
                   const std::vector<std::string>& names, const Model& model, double scale,
                   const FitOptions& options, FitResult* result) {
  const int num_params = static_cast<int>(names.size());
  const Camera& camera = result->camera;
  // Sigma_u = sigma^2 (J^T J)^-1 in u, then to user units by the linear map L.
  const ParamMatrix covariance_u =
      result->pixel_sigma * result->pixel_sigma * scaled_normal.Inverse();
  ParamMatrix l = ParamMatrix::Identity(num_params, num_params);
  for (int j = 0; j < 3; ++j) l(j, j) = kDegPerRad;
  for (int j = 3; j < 6; ++j) l(j, j) = scale;
  if (model.free[1]) {
    // fy = aspect * f: d fy = aspect d f + f d aspect.
    const int aspect_index = 6 + (model.free[0] ? 1 : 0);
    l(aspect_index, aspect_index) = model.value[0];
    if (model.free[0]) l(aspect_index, 6) = model.value[1];
  }
  result->covariance = l * covariance_u * l.transpose();
  result->covariance_available = true;

  std::vector<double> values = {0.0, 0.0, 0.0};
  for (int j = 0; j < 3; ++j) values.push_back(CameraCenterInWorld(camera.cam_from_world)(j));
  const Intrinsics& k = camera.intrinsics;
  const double slot_values[] = {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2};
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (model.free[slot]) values.push_back(slot_values[slot]);
  }
  for (int j = 0; j < num_params; ++j) {
    const std::string unit =
        j < 3 ? "deg" : j < 6 ? "world" : (j >= 6 && names[j][0] == 'k') ? "" : "px";
    result->sigmas.push_back({names[j], values[j], std::sqrt(result->covariance(j, j)), unit});
  }
  // Fields of view from fx, fy: fov = 2 atan(extent / (2 f)), d fov / d f = -extent / (f^2 +
  // extent^2 / 4).
  auto index_of = [&](const char* name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  const int fx_index = index_of("fx");
  const int fy_index = index_of("fy");
  auto fov_sigma = [&](double f, double extent, double var_f) {
    const double derivative = extent / (f * f + 0.25 * extent * extent);
    return std::abs(derivative) * std::sqrt(var_f) * kDegPerRad;
  };
  const double var_fx = fx_index >= 0 ? result->covariance(fx_index, fx_index) : 0.0;
  double var_fy = fy_index >= 0 ? result->covariance(fy_index, fy_index) : 0.0;
  if (fy_index < 0 && fx_index >= 0) var_fy = var_fx * model.value[1] * model.value[1];
  const ImageSize& image_size = camera.image_size;
  result->sigmas.push_back({"fovx_deg",
                            2.0 * std::atan(0.5 * image_size.width / k.fx) * kDegPerRad,
                            fov_sigma(k.fx, image_size.width, var_fx), "deg"});
  result->sigmas.push_back({"fovy_deg",
                            2.0 * std::atan(0.5 * image_size.height / k.fy) * kDegPerRad,
                            fov_sigma(k.fy, image_size.height, var_fy), "deg"});
  result->strong_correlations =
      StrongCorrelations(result->covariance, names, options.strong_correlation);
}

}  // namespace

FitResult AssessFit(const Scene& scene, const std::string& start_method, RefinedCamera refined,
                    const FitOptions& options) {
  const int n = scene.NumPoints();
  const Model& model = refined.model;
  const int num_params = 6 + model.NumFree();
  FitResult result;
  result.iterations = refined.iterations;
  result.refiner = std::move(refined.refiner);
  result.termination = std::move(refined.termination);
  result.trace = std::move(refined.trace);

  // Residuals and depths.
  Camera& camera = result.camera;
  camera.image_size = scene.image_size;
  camera.intrinsics = model.ToIntrinsics();
  camera.intrinsics.skew += 0.0;  // no -0 in files
  camera.cam_from_world =
      CamFromWorldFromCenter(refined.rotation, scene.centroid + scene.scale * refined.center);
  std::vector<double> depths(n);
  std::vector<double> norms(n);
  double sum_squares = 0.0;
  int behind = 0;
  result.residuals_px.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = refined.rotation * (scene.points[i] - refined.center);
    depths[i] = p.z() * scene.scale;
    const std::optional<Eigen::Vector2d> pixel = PixelOfCamPoint(model, p);
    if (!pixel) {
      ++behind;
      continue;
    }
    result.residuals_px[i] = *pixel - scene.pixels[i];
    norms[i] = result.residuals_px[i].norm();
    sum_squares += norms[i] * norms[i];
  }
  if (behind > 0) {
    throw SceneError(SceneError::Reason::kPointsBehindCamera,
                     Concat(behind, " of ", n, " points are behind the fitted camera: the "
                            "correspondences are inconsistent (mismatched or mis-clicked "
                            "points); check them or use a robust loss"));
  }
  result.rms_px = std::sqrt(sum_squares / n);
  result.median_px = Median(norms);
  result.max_px = *std::max_element(norms.begin(), norms.end());
  result.start_method = start_method;
  result.planar = scene.planar;

  // Depth range and views.
  const auto [min_depth, max_depth] = std::minmax_element(depths.begin(), depths.end());
  camera.z_near = options.z_near.value_or(*min_depth / (1.0 + options.depth_margin));
  camera.z_far = options.z_far.value_or(*max_depth * (1.0 + options.depth_margin));
  Require(camera.z_far > camera.z_near, "near (", camera.z_near, ") must be less than far (",
          camera.z_far, ")");
  result.views = ViewsOfCamera(camera, Median(depths));

  const std::vector<std::string> names = ParameterNames(model);
  result.free_parameters = names;
  result.model = ModelName(model);
  result.fixed_parameters = model.fixed;

  // Uncertainty, in u = [omega, center, free slots] (ComputeNormalEquations). Fixed-capacity
  // types (ParamMatrix): no allocation, and Eigen's small-matrix products.
  const JacobiScaledNormal<ParamMatrix> scaled_normal(refined.normal.jtj);
  if (!(scaled_normal.rcond > kSingularRcond)) RefuseUndetermined(scaled_normal, names);
  result.jacobian_condition = scaled_normal.JacobianCondition();
  const bool have_sigma = SetPixelSigma(options, sum_squares, 2 * n - num_params, &result);
  if (options.compute_uncertainty && have_sigma) {
    SetCovariance(scaled_normal, names, model, scene.scale, options, &result);
  }
  return result;
}

}  // namespace internal
}  // namespace camproj

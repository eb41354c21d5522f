#include "camproj/fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "check.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/least_squares.h"
#include "fit/model.h"
#include "fit/normal_equations.h"
#include "fit/orthographic_fit.h"
#include "fit/ransac.h"
#include "fit/reprojection_error.h"
#include "fit/scene.h"
#include "fit/start.h"
#include "fit/statistics.h"

namespace camproj {

using internal::Clock;
using internal::ComputeNormalEquations;
using internal::LeastSquaresOutcome;
using internal::MicrosecondsSince;
using internal::Model;
using internal::NormalEquations;
using internal::ParamMatrix;
using internal::ParamVector;
using internal::PixelOfCamPoint;
using internal::RefineLeastSquares;
using internal::Require;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
// Below this reciprocal condition number of the Jacobi-scaled normal equations the parameters
// are not determined by the points (double precision leaves ~1e-16; 1e-12 keeps a margin).
constexpr double kSingularRcond = 1e-12;
// Below this many points a DLT start with the principal point free gets a second start from
// the image centre (the DLT's principal point is poorly determined there).
constexpr int kSecondStartBelowPoints = 20;

// Records (iteration, elapsed, RMS) after every Ceres iteration.
class TraceCallback : public ceres::IterationCallback {
 public:
  TraceCallback(const std::vector<Eigen::Vector3d>& points,
                const std::vector<Eigen::Vector2d>& pixels, const double* rotation,
                const double* center, const double* intrinsics, Clock::time_point start,
                std::vector<TraceEntry>* trace)
      : points_(points), pixels_(pixels), rotation_(rotation), center_(center),
        intrinsics_(intrinsics), start_(start), trace_(trace) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0 && !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    const double n = static_cast<double>(points_.size());
    // With a robust loss the cost is robustified: recompute the plain RMS.
    const Eigen::Map<const Eigen::Quaterniond> q(rotation_);
    const Eigen::Map<const Eigen::Vector3d> c(center_);
    double sum = 0.0;
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p = q * (points_[i] - c);
      double pixel[2];
      internal::PixelFromFitIntrinsics(intrinsics_, p.x() / p.z(), p.y() / p.z(), pixel);
      sum += (Eigen::Vector2d(pixel[0], pixel[1]) - pixels_[i]).squaredNorm();
    }
    trace_->push_back({summary.iteration, MicrosecondsSince(start_), std::sqrt(sum / n)});
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  const double* rotation_;
  const double* center_;
  const double* intrinsics_;
  Clock::time_point start_;
  std::vector<TraceEntry>* trace_;
};

}  // namespace

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

// The stages in lib/src/fit/, in the order the data flows: scene -> (RANSAC: the consensus, fitted
// without RANSAC) -> closed-form start -> refinement -> assessment.
FitResult FitCamera(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options) {
  const internal::Clock::time_point start_time = internal::Clock::now();
  options.Check();
  image_size.Check();
  internal::CheckCorrespondences(points_in_world, observed_pixels);
  if (options.projection == Projection::kOrthographic) {
    return internal::FitOrthographic(points_in_world, observed_pixels, image_size, options);
  }
  const internal::Scene scene =
      internal::ValidateScene(points_in_world, observed_pixels, image_size, options);

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
    FitResult result = FitCamera(inlier_points, inlier_pixels, image_size, inner);
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

  const internal::Start start = internal::ClosedFormStart(scene, options, start_time);
  const std::vector<Eigen::Vector3d>& points = scene.points;
  const std::vector<Eigen::Vector2d>& pixels = scene.pixels;
  const int n = scene.NumPoints();
  const Model& start_model = scene.model;
  const int num_params = 6 + start_model.NumFree();
  const std::string& start_method = start.method;
  Model model = start.model;

  // Refinement: without a loss, Levenberg-Marquardt on normal equations accumulated point by
  // point (MinimizeLevenbergMarquardt: TinySolver's algorithm) on the chart R = exp(omega) R_start,
  // then the Gauss-Newton polish; with a robust loss, a ceres::Problem with one block per point,
  // the rotation on EigenQuaternionManifold and fixed intrinsics held by a SubsetManifold.
  FitResult result;
  Eigen::Matrix3d rotation_matrix = start.camera.rotation;
  Eigen::Vector3d center = start.camera.center;
  NormalEquations normal_equations;
  if (options.refine && options.loss == LossType::kNone) {
    LeastSquaresOutcome best = RefineLeastSquares(points, pixels, start.camera.rotation,
                                                  start.camera.center, model, options, start_time);
    if (start_method == "dlt" && n < kSecondStartBelowPoints && start_model.free[2]) {
      // With few points the DLT's principal point can be far off and LM stop in a local minimum
      // (seen at 6 points: cy 96 px for 540). Refine also from the image centre (SQPnP pose for
      // the DLT's focal length there) and keep the lower cost.
      Model centred = model;
      centred.value[2] = start_model.value[2];
      centred.value[3] = start_model.value[3];
      internal::StartCamera second;
      if (internal::PnpStart(points, pixels, centred.ToIntrinsics(), &second)) {
        LeastSquaresOutcome other = RefineLeastSquares(points, pixels, second.rotation,
                                                       second.center, centred, options, start_time);
        if (other.ok && (!best.ok || other.normal.cost < best.normal.cost * (1.0 - 1e-9))) {
          best = std::move(other);
        }
      }
    }
    if (!best.ok) {
      if (best.normal.jtj.size() > 0 && best.model.value[1] <= 0.0) {
        throw SceneError(SceneError::Reason::kMirroredWorld,
                         "the best camera has a negative aspect (fy < 0): the points are seen as "
                         "through a mirror, i.e. the world frame is left-handed. Flip one world "
                         "axis (e.g. negate Z of every point, and again in anything you render) "
                         "and refit");
      }
      throw SceneError(SceneError::Reason::kPointsBehindCamera,
                       "the refined camera has points behind it (or a negative focal length): "
                       "the correspondences are inconsistent (mismatched or mis-clicked points); "
                       "check them or use --ransac");
    }
    if (!best.converged) {
      throw SceneError(SceneError::Reason::kDegenerate,
                       internal::Concat("the refinement did not reach the minimum in ",
                                        best.iterations, " iterations: the points barely "
                                        "determine the model (a nearly flat, curved valley of "
                                        "cameras that fit about equally well; ",
                                        best.termination, "). Fix intrinsics (e.g. "
                                        "--model focal), or add points spread further in depth"));
    }
    rotation_matrix = best.rotation;
    center = best.center;
    model = best.model;
    normal_equations = std::move(best.normal);
    result.iterations = best.iterations;
    result.termination = best.termination;
    result.trace = std::move(best.trace);
  } else if (options.refine) {
    Eigen::Quaterniond rotation(start.camera.rotation);
    rotation.normalize();
    std::array<double, internal::kFitIntrinsicsSize> intrinsics = model.value;
    ceres::Problem problem;
    ceres::LossFunction* loss = options.loss == LossType::kHuber
                                    ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(options.loss_scale_px))
                                    : new ceres::CauchyLoss(options.loss_scale_px);
    // A robust loss weighs each point's squared distance, so each point has its own block.
    for (int i = 0; i < n; ++i) {
      problem.AddResidualBlock(new internal::PointReprojectionCost(points[i], pixels[i]), loss,
                               rotation.coeffs().data(), center.data(), intrinsics.data());
    }
    problem.SetManifold(rotation.coeffs().data(), new ceres::EigenQuaternionManifold);
    std::vector<int> constant_slots;
    for (int slot = 0; slot < internal::kFitIntrinsicsSize; ++slot) {
      if (!model.free[slot]) constant_slots.push_back(slot);
    }
    if (constant_slots.size() == internal::kFitIntrinsicsSize) {
      problem.SetParameterBlockConstant(intrinsics.data());
    } else if (!constant_slots.empty()) {
      problem.SetManifold(intrinsics.data(),
                          new ceres::SubsetManifold(internal::kFitIntrinsicsSize, constant_slots));
    }
    ceres::Solver::Options solver_options;
    // p <= 13 unknowns: the normal equations (O(N p^2)) beat QR of the 2N x p Jacobian.
    solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver_options.max_num_iterations = options.max_iterations;
    solver_options.function_tolerance = options.function_tolerance;
    solver_options.gradient_tolerance = options.gradient_tolerance;
    solver_options.parameter_tolerance = options.parameter_tolerance;
    solver_options.logging_type = ceres::SILENT;
    solver_options.num_threads = 1;
    solver_options.update_state_every_iteration = true;
    TraceCallback trace_callback(points, pixels, rotation.coeffs().data(), center.data(),
                                 intrinsics.data(), start_time, &result.trace);
    solver_options.callbacks.push_back(&trace_callback);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (summary.termination_type == ceres::FAILURE) {
      throw SceneError(SceneError::Reason::kDegenerate,
                       "the refinement failed: " + summary.message +
                           ": check the correspondences");
    }
    if (summary.termination_type == ceres::NO_CONVERGENCE) {
      // As for least squares: never a camera short of the minimum.
      throw SceneError(SceneError::Reason::kDegenerate,
                       internal::Concat("the robust refinement did not converge in ",
                                        options.max_iterations, " iterations (", summary.message,
                                        "): the points barely determine the model; fix "
                                        "intrinsics, add points, or raise --max-iterations"));
    }
    model.value = intrinsics;
    rotation.normalize();
    rotation_matrix = rotation.toRotationMatrix();
    result.iterations = static_cast<int>(summary.iterations.size()) - 1;
    result.termination = std::string(ceres::TerminationTypeToString(summary.termination_type)) +
                         ": " + summary.message;
  } else {
    result.termination = "not refined (closed-form start only)";
  }
  if (!(options.refine && options.loss == LossType::kNone)) {
    ComputeNormalEquations(points, pixels, rotation_matrix, center, model, &normal_equations);
  }

  // Residuals and depths.
  Camera& camera = result.camera;
  camera.image_size = scene.image_size;
  camera.intrinsics = model.ToIntrinsics();
  camera.intrinsics.skew += 0.0;  // no -0 in files
  camera.cam_from_world = CamFromWorldFromCenter(rotation_matrix, scene.centroid + scene.scale * center);
  std::vector<double> depths(n);
  std::vector<double> norms(n);
  double sum_squares = 0.0;
  int behind = 0;
  result.residuals_px.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = rotation_matrix * (points[i] - center);
    depths[i] = p.z() * scene.scale;
    const std::optional<Eigen::Vector2d> pixel = PixelOfCamPoint(model, p);
    if (!pixel) {
      ++behind;
      continue;
    }
    result.residuals_px[i] = *pixel - pixels[i];
    norms[i] = result.residuals_px[i].norm();
    sum_squares += norms[i] * norms[i];
  }
  if (behind > 0) {
    throw SceneError(SceneError::Reason::kPointsBehindCamera,
                     internal::Concat(behind, " of ", n, " points are behind the fitted camera: "
                                      "the correspondences are inconsistent (mismatched or "
                                      "mis-clicked points); check them or use a robust loss"));
  }
  result.rms_px = std::sqrt(sum_squares / n);
  result.median_px = internal::Median(norms);
  result.max_px = *std::max_element(norms.begin(), norms.end());
  result.start_method = start_method;
  result.planar = scene.planar;

  // Depth range and views.
  const auto [min_depth, max_depth] = std::minmax_element(depths.begin(), depths.end());
  camera.z_near = options.z_near.value_or(*min_depth / (1.0 + options.depth_margin));
  camera.z_far = options.z_far.value_or(*max_depth * (1.0 + options.depth_margin));
  Require(camera.z_far > camera.z_near, "near (", camera.z_near, ") must be less than far (",
          camera.z_far, ")");
  result.views = ViewsOfCamera(camera, internal::Median(depths));

  // Parameter names in the user parameterization.
  std::vector<std::string> names = {"rotation_x_deg", "rotation_y_deg", "rotation_z_deg",
                                    "eye_x", "eye_y", "eye_z"};
  const char* user_slot_names[] = {"fx", "fy", "cx", "cy", "skew", "k1", "k2"};
  for (int slot = 0; slot < internal::kFitIntrinsicsSize; ++slot) {
    if (model.free[slot]) names.push_back(user_slot_names[slot]);
  }
  result.free_parameters = names;
  result.model = "pose";
  const char* model_slot_names[] = {"focal", "aspect", "principal-point", "", "skew", "k1", "k2"};
  for (int slot = 0; slot < internal::kFitIntrinsicsSize; ++slot) {
    if (model.free[slot] && slot != 3) result.model += std::string("+") + model_slot_names[slot];
  }
  result.fixed_parameters = model.fixed;

  // Uncertainty: Sigma_u = sigma^2 (J^T J)^-1 in u, then to user units by the linear map L.
  // Fixed-capacity types (ParamMatrix): no allocation, and Eigen's small-matrix products.
  const internal::JacobiScaledNormal<ParamMatrix> scaled_normal(normal_equations.jtj);
  const double rcond = scaled_normal.rcond;
  if (!(rcond > kSingularRcond)) {
    // Name the parameters that move along the unconstrained direction, and the free intrinsic
    // that moves most along it: the pose cannot be fixed, an intrinsic can.
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
                     internal::Concat("the points do not determine ", involved,
                                      " (singular normal equations, reciprocal condition ",
                                      std::max(rcond, 0.0), "): ", fix,
                                      ", or add points that spread further in depth and across "
                                      "the image"));
  }
  result.jacobian_condition = scaled_normal.JacobianCondition();
  const bool have_sigma = internal::SetPixelSigma(options, sum_squares, 2 * n - num_params, &result);
  if (options.compute_uncertainty && have_sigma) {
    const ParamMatrix covariance_u =
        result.pixel_sigma * result.pixel_sigma * scaled_normal.Inverse();
    ParamMatrix l = ParamMatrix::Identity(num_params, num_params);
    for (int j = 0; j < 3; ++j) l(j, j) = kDegPerRad;
    for (int j = 3; j < 6; ++j) l(j, j) = scene.scale;
    if (model.free[1]) {
      // fy = aspect * f: d fy = aspect d f + f d aspect.
      const int aspect_index = 6 + (model.free[0] ? 1 : 0);
      l(aspect_index, aspect_index) = model.value[0];
      if (model.free[0]) l(aspect_index, 6) = model.value[1];
    }
    result.covariance = l * covariance_u * l.transpose();
    result.covariance_available = true;

    std::vector<double> values = {0.0, 0.0, 0.0};
    for (int j = 0; j < 3; ++j) values.push_back(CameraCenterInWorld(camera.cam_from_world)(j));
    const Intrinsics& k = camera.intrinsics;
    const double slot_values[] = {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2};
    for (int slot = 0; slot < internal::kFitIntrinsicsSize; ++slot) {
      if (model.free[slot]) values.push_back(slot_values[slot]);
    }
    for (int j = 0; j < num_params; ++j) {
      const std::string unit = j < 3 ? "deg" : j < 6 ? "world" : (j >= 6 && names[j][0] == 'k') ? "" : "px";
      result.sigmas.push_back({names[j], values[j], std::sqrt(result.covariance(j, j)), unit});
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
    const double var_fx = fx_index >= 0 ? result.covariance(fx_index, fx_index) : 0.0;
    double var_fy = fy_index >= 0 ? result.covariance(fy_index, fy_index) : 0.0;
    if (fy_index < 0 && fx_index >= 0) var_fy = var_fx * model.value[1] * model.value[1];
    result.sigmas.push_back({"fovx_deg", 2.0 * std::atan(0.5 * image_size.width / k.fx) * kDegPerRad,
                             fov_sigma(k.fx, image_size.width, var_fx), "deg"});
    result.sigmas.push_back({"fovy_deg", 2.0 * std::atan(0.5 * image_size.height / k.fy) * kDegPerRad,
                             fov_sigma(k.fy, image_size.height, var_fy), "deg"});
    result.strong_correlations =
        internal::StrongCorrelations(result.covariance, names, options.strong_correlation);
  }
  result.time_ms = MicrosecondsSince(start_time) / 1000.0;
  return result;
}

}  // namespace camproj

#include "fit/assess.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/QR>

#include "camproj/camera.h"
#include "camproj/number_text.h"
#include "camproj/pose.h"
#include "check.h"
#include "fit/ceres_minimize.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/normal_equations.h"
#include "fit/reprojection_error.h"
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
  const char* user_slot_names[] = {"fx", "fy", "cx", "cy", "skew", "k1", "k2", "p1", "p2", "k3"};
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (model.free[slot]) names.push_back(user_slot_names[slot]);
  }
  return names;
}

// FitResult::model: "pose" and the free intrinsics.
std::string ModelName(const Model& model) {
  std::string name = "pose";
  const char* model_slot_names[] = {"focal", "aspect", "principal-point", "", "skew",
                                    "k1",    "k2",     "p1",              "p2", "k3"};
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
      intrinsic >= 0 ? "Fix " + names[intrinsic] + " (the free intrinsic that moves most along "
                                                    "that direction, e.g. with --model or a value)"
                     : "Fix intrinsics";
  throw SceneError(SceneError::Reason::kDegenerate,
                   Concat("the points do not determine ", involved,
                          " (singular normal equations, reciprocal condition ",
                          std::max(scaled_normal.rcond, 0.0), ")"),
                   fix + ", or add points that spread further in depth and across the image");
}

// The most median residuals, in scales of a Cauchy loss, for which RobustVariancePx2 answers.
constexpr double kMaxCauchyMedianScales = 2.0;

// With a robust loss, the variance (px^2) that scales the plain normal equations' inverse:
// Huber's estimate for an M-estimator (Huber 1981, 7.6, "H1"), K^2 E[psi^2] / E[psi']^2, which
// is J / (2N - p) for least squares. Per point, with s = |r|^2 and rho(s) the loss:
// psi = rho'(s) r, |psi|^2 = rho'^2 s, and d psi / d r = rho' I + 2 rho'' r r^T, of slope rho'
// across r and rho' + 2 rho'' s along it. Estimated (no given noise): E[psi^2] per component
// = sum rho'^2 s / (2N - p), E[psi'] the mean slope m over the 2N components, K = 1 + p / (2N)
// Var(slope) / m^2. Given a noise sigma: the same ratio's expectation under N(0, sigma^2) per
// axis (s = 2 sigma^2 t, t ~ Exp(1)), K = 1. None where m <= 0, or for a Cauchy loss whose scale
// is far below the residuals (below).
// Before session 44 the sigmas were least squares' with the noise from the raw sum of squares,
// down-weighted outliers in full: data/projector/misclicked.csv, huber:2, fx 1476 +- 801 px
// for a true 1483.6 at a "pixel noise 38.9 px".
std::optional<double> RobustVariancePx2(const FitOptions& options,
                                        const std::vector<double>& norms, int num_params) {
  const std::unique_ptr<ceres::LossFunction> loss = LossOf(options);
  const auto derivatives = [&](double s) {
    double rho[3];
    loss->Evaluate(s, rho);
    return std::pair<double, double>(rho[1], rho[2]);
  };
  const int n = static_cast<int>(norms.size());
  const double components = 2.0 * n;
  // A redescending (Cauchy) loss whose scale is far below the residuals seeks a mode the
  // asymptotics do not describe. Measured over 100 `camproj synth` scenes of 30 points at 1 px
  // noise, median residual 1.2 px (the RMS of error / sigma, 1 for calibrated sigmas; least
  // squares 1.04-1.14): Cauchy at 0.1 px 9.8 and at 0.5 px 1.35-1.63, hence the bound (2.4
  // scales at 0.5); Cauchy 1 and 2 px 1.04-1.18; Huber 0.1, 0.2, 0.5 and 2 px 1.03-1.34 (Huber
  // is convex: one minimum, whatever its scale). A given noise's median residual is
  // kRayleighMedian sigma.
  const double median_px = options.pixel_sigma ? kRayleighMedian * *options.pixel_sigma
                                               : Median(norms);
  if (options.loss == LossType::kCauchy &&
      !(median_px <= kMaxCauchyMedianScales * options.loss_scale_px)) {
    return std::nullopt;
  }
  if (options.pixel_sigma) {
    // E over t ~ Exp(1) by the trapezoid rule on [0, 50] (e^-50 ~ 2e-22 beyond).
    constexpr int kSteps = 5000;
    const double sigma2 = *options.pixel_sigma * *options.pixel_sigma;
    double psi2 = 0.0, slope = 0.0;
    for (int k = 0; k <= kSteps; ++k) {
      const double t = 50.0 * k / kSteps;
      const double weight = (k == 0 || k == kSteps ? 0.5 : 1.0) * 50.0 / kSteps * std::exp(-t);
      const double s = 2.0 * sigma2 * t;
      const auto [d1, d2] = derivatives(s);
      psi2 += weight * d1 * d1 * s / 2.0;  // per component
      slope += weight * (d1 + d2 * s);     // the mean of its two components' slopes
    }
    if (!(slope > 0.0)) return std::nullopt;
    return psi2 / (slope * slope);
  }
  const double dof = components - num_params;
  double psi2 = 0.0, slope_sum = 0.0, slope_squares = 0.0;
  for (const double r : norms) {
    const double s = r * r;
    const auto [d1, d2] = derivatives(s);
    psi2 += d1 * d1 * s;
    for (const double slope : {d1, d1 + 2.0 * d2 * s}) {
      slope_sum += slope;
      slope_squares += slope * slope;
    }
  }
  const double m = slope_sum / components;
  if (!(m > 0.0) || !(dof > 0.0)) return std::nullopt;
  const double slope_variance = std::max(0.0, slope_squares / components - m * m);
  const double k = 1.0 + num_params / components * slope_variance / (m * m);
  return k * k * (psi2 / dof) / (m * m);
}

// The covariance in user units with its sigmas (fields of view included) and strong
// correlations, from `variance_px2` times the inverse of the normal equations (least squares:
// result->pixel_sigma squared) and result->camera. `scale`: the scene's.
void SetCovariance(const JacobiScaledNormal<ParamMatrix>& scaled_normal,
                   const std::vector<std::string>& names, const Model& model, double scale,
                   const FitOptions& options, double variance_px2, FitResult* result) {
  const int num_params = static_cast<int>(names.size());
  const Camera& camera = result->camera;
  // Sigma_u = sigma^2 (J^T J)^-1 in u, then to user units by the linear map L.
  const ParamMatrix covariance_u = variance_px2 * scaled_normal.Inverse();
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
  const double slot_values[] = {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3};
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

// The camera at `u` (ComputeNormalEquations' parameters: omega with R = exp(omega) rotation,
// center, the free slots in slot order) from (rotation, center, model).
struct MovedCamera {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d center;
  Model model;
};

MovedCamera MoveCamera(const RefinedCamera& at, const ParamVector& u) {
  const Eigen::Vector3d omega = u.head<3>();
  const double angle = omega.norm();
  MovedCamera moved{angle > 0.0 ? Eigen::Matrix3d(Eigen::AngleAxisd(angle, omega / angle) *
                                                  at.rotation)
                                : at.rotation,
                    at.center + u.segment<3>(3), at.model};
  int index = 6;
  for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
    if (moved.model.free[slot]) moved.model.value[slot] += u(index++);
  }
  return moved;
}

// Sum of squared residuals of the scene at `u` from `at`; infinite when a point is not in front.
double SumOfSquaresAt(const Scene& scene, const RefinedCamera& at, const ParamVector& u) {
  const MovedCamera moved = MoveCamera(at, u);
  // The residuals as the fit's normal equations compute them (ResidualOfCamPoint, whose cost
  // at.normal.cost is), without their derivatives.
  auto sum_of_squares = [&](auto radial_only) {
    double sum = 0.0;
    for (int i = 0; i < scene.NumPoints(); ++i) {
      const Eigen::Vector3d p = moved.rotation * (scene.points[i] - moved.center);
      if (!(p.z() > 0.0)) return std::numeric_limits<double>::infinity();
      double r[2];
      ResidualOfCamPoint<decltype(radial_only)::value>(moved.model.value.data(), p,
                                                       scene.pixels[i], r, nullptr, nullptr);
      sum += r[0] * r[0] + r[1] * r[1];
    }
    return sum;
  };
  return RadialOnly(moved.model.value.data()) ? sum_of_squares(std::true_type())
                                              : sum_of_squares(std::false_type());
}

// The profile of the sum of squares at `u`: its minimum over the hyperplane through u orthogonal
// to `normal` (kProfileSteps Gauss-Newton steps, each kept only if it lowers the sum; the steps'
// rotation part, in the chart at the moved camera, is added to u's: first order, and only
// accepted where it helps). Starts from `at_u`, the sum at u.
double ProfileAt(const Scene& scene, const RefinedCamera& at, ParamVector u, double at_u,
                 const ParamVector& normal) {
  constexpr int kProfileSteps = 4;
  const int p = static_cast<int>(u.size());
  // An orthonormal basis of the hyperplane: the last p - 1 columns of the Householder Q of the
  // normal.
  const ParamMatrix q = Eigen::HouseholderQR<ParamMatrix>(ParamMatrix(normal)).householderQ();
  const ParamMatrix basis = q.rightCols(p - 1);
  double best = at_u;
  for (int step = 0; step < kProfileSteps && std::isfinite(best); ++step) {
    const MovedCamera moved = MoveCamera(at, u);
    NormalEquations normal_equations;
    if (!ComputeNormalEquations(scene.points, scene.pixels, moved.rotation, moved.center,
                                moved.model, &normal_equations)) {
      break;
    }
    const ParamMatrix reduced = basis.transpose() * normal_equations.jtj * basis;
    const ParamVector zeta = reduced.ldlt().solve(-(basis.transpose() * normal_equations.jtr));
    const ParamVector candidate = u + basis * zeta;
    const double sum = SumOfSquaresAt(scene, at, candidate);
    if (!(sum < best)) break;
    best = sum;
    u = candidate;
  }
  return best;
}

// FitResult::linearity. Along each eigenvector w of the Jacobi-scaled J^T J (eigenvalue mu),
// the step delta = c sigma D w / sqrt(mu) (D the scaling) reaches the quadratic model's
// kLinearityLevel region, delta^T J^T J delta = c^2 sigma^2 with c^2 = chi^2_p(level): there the
// model predicts the sum of squares up by P = c^2 sigma^2 (+- 2 delta^T J^T r). The straight line
// gives L; where L departs from P by more than kProfileTrigger, the profile across the line
// (re-minimized over the hyperplane J^T J-orthogonal to delta) gives F <= L. The true region's
// edge along the valley is then at radius c sqrt(P / F) (the profile quadratic), where the
// floor sits (L - F) / sigma^2 off the line: the linearized NEES of an error there is
// (P / F) (1 + (L - F) / P) = (P + L - F) / F times its true chi-square. The deviation reported
// is that factor minus 1 (0 for a linear model; negative where the walls are steeper than the
// quadratic model, i.e. the sigmas overstate the error).
LinearityCheck CheckLinearity(const Scene& scene, const RefinedCamera& refined,
                              const JacobiScaledNormal<ParamMatrix>& scaled_normal,
                              const std::vector<std::string>& names, double pixel_sigma) {
  // Below this relative departure of the straight line from the prediction, the profile (a few
  // Gauss-Newton solves) is not computed: F = L.
  constexpr double kProfileTrigger = 0.1;
  LinearityCheck check;
  check.checked = true;
  check.level = kLinearityLevel;
  check.bound = kMaxLinearityDeviation;
  check.worst_deviation = -std::numeric_limits<double>::infinity();
  const int p = static_cast<int>(names.size());
  const double c2 = ChiSquareQuantile(p, kLinearityLevel);
  const double cost = refined.normal.cost;
  const ParamMatrix covariance = scaled_normal.Inverse();
  for (int d = 0; d < p; ++d) {
    const double mu = scaled_normal.eigen.eigenvalues()(d);
    const ParamVector w = scaled_normal.eigen.eigenvectors().col(d);
    const ParamVector delta =
        (std::sqrt(c2) * pixel_sigma / std::sqrt(mu)) * scaled_normal.column_scale.cwiseProduct(w);
    const double slope = 2.0 * delta.dot(refined.normal.jtr);
    for (const double sign : {1.0, -1.0}) {
      const double predicted = c2 * pixel_sigma * pixel_sigma + sign * slope;
      const double at_line = SumOfSquaresAt(scene, refined, sign * delta);
      const double line = at_line - cost;
      double profile = line;
      if (!(std::abs(line - predicted) <= kProfileTrigger * predicted)) {
        profile = ProfileAt(scene, refined, sign * delta, at_line,
                            ParamVector(refined.normal.jtj * delta)) -
                  cost;
      }
      // A point behind the camera within the region, or a profile at or below the minimum's
      // cost (the region has no edge along this valley): not linear at all.
      const double deviation = std::isfinite(line) && profile > 0.0
                                   ? (predicted + line - profile) / profile - 1.0
                                   : std::numeric_limits<double>::infinity();
      if (!(deviation <= check.worst_deviation)) {
        check.worst_deviation = deviation;
        // The parameter that moves most in units of its own sigma: |delta_j| / sqrt(cov_jj).
        int most = 0;
        for (int j = 1; j < p; ++j) {
          if (std::abs(delta(j)) / std::sqrt(covariance(j, j)) >
              std::abs(delta(most)) / std::sqrt(covariance(most, most))) {
            most = j;
          }
        }
        check.worst_direction = names[most];
      }
    }
  }
  check.linear = check.worst_deviation <= check.bound;
  return check;
}

}  // namespace

FitResult AssessFit(const Scene& scene, const std::string& start_method, RefinedCamera refined,
                    const FitOptions& options, const FitEffort& effort) {
  const int n = scene.NumPoints();
  const Model& model = refined.model;
  const int num_params = 6 + model.NumFree();
  if (effort.linearization != nullptr) {
    *effort.linearization = ChartLinearization{
        refined.normal.jtj, refined.rotation, refined.center, model, scene.centroid, scene.scale,
        refined.normal_predicted_step_back};
  }
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
                     Concat(behind, " of ", n, behind == 1 ? " points is" : " points are",
                            " behind the fitted camera: the "
                            "correspondences are inconsistent (mismatched or mis-clicked "
                            "points)"),
                     "Check the correspondences or use a robust loss");
  }
  result.rms_px = std::sqrt(sum_squares / n);
  // A fit not described is scored by its sum of squares: its median is read nowhere (the default
  // path's is recomputed over the points kept).
  if (effort.describe) result.median_px = Median(norms);
  result.max_px = *std::max_element(norms.begin(), norms.end());
  result.start_method = start_method;
  result.planar = scene.planar;

  // Depth range and views.
  const auto [min_depth, max_depth] = std::minmax_element(depths.begin(), depths.end());
  const DepthRange range = DepthRangeOfPoints(options, *min_depth, *max_depth);
  camera.z_near = range.z_near;
  camera.z_far = range.z_far;
  if (effort.describe) result.views = ViewsOfFittedCamera(camera, Median(depths));

  const std::vector<std::string> names = ParameterNames(model);
  result.free_parameters = names;
  result.model = ModelName(model);
  result.pixel_origin = options.pixel_origin;
  if (effort.describe) result.fixed_parameters = DescribeFixed(options, scene.image_size);

  // Uncertainty, in u = [omega, center, free slots] (ComputeNormalEquations). Fixed-capacity
  // types (ParamMatrix): no allocation, and Eigen's small-matrix products.
  // The eigenvectors only where they are read: the covariance and linearity check of a described
  // fit; a refusal's null direction recomputes them. (A candidate of the model selection, a
  // screen's or a mirror test's fit reads the reciprocal condition alone.)
  // A fit not described reads the condition only to refuse: where the Cholesky bound already
  // clears the refusal by kBoundMargin, its eigenvalues are not computed (jacobian_condition is
  // then NaN: no report shows it).
  constexpr double kBoundMargin = 1e3;
  const bool needs_vectors = options.compute_uncertainty && effort.describe;
  std::optional<JacobiScaledNormal<ParamMatrix>> scaled_normal;
  if (effort.describe ||
      !(ReciprocalConditionLowerBound(refined.normal.jtj) > kBoundMargin * kSingularRcond)) {
    scaled_normal.emplace(refined.normal.jtj, needs_vectors ? Eigen::ComputeEigenvectors
                                                            : Eigen::EigenvaluesOnly);
    if (!(scaled_normal->rcond > kSingularRcond)) {
      if (needs_vectors) RefuseUndetermined(*scaled_normal, names);
      RefuseUndetermined(JacobiScaledNormal<ParamMatrix>(refined.normal.jtj), names);
    }
    result.jacobian_condition = scaled_normal->JacobianCondition();
  } else {
    result.jacobian_condition = std::numeric_limits<double>::quiet_NaN();
  }
  const int dof = 2 * n - num_params;
  bool have_sigma = SetPixelSigma(options, sum_squares, dof, &result);
  double variance_px2 = result.pixel_sigma * result.pixel_sigma;
  if (have_sigma && options.loss != LossType::kNone) {
    const std::optional<double> robust = RobustVariancePx2(options, norms, num_params);
    have_sigma = robust.has_value();
    if (!robust) {
      result.no_uncertainty_why =
          "the robust loss's scale is far below the residuals (a Cauchy loss: their median, or "
          "a given noise's, more than 2 scales), and the fit a mode of them that sigmas cannot "
          "describe: a scale about the pixel noise gives them";
    } else {
      variance_px2 = *robust;
      if (!options.pixel_sigma) result.pixel_sigma = std::sqrt(variance_px2);
    }
  }
  if (options.compute_uncertainty && have_sigma && effort.describe) {
    SetCovariance(*scaled_normal, names, model, scene.scale, options, variance_px2, &result);
    // The check probes the plain sum of squares, which a robust loss does not minimise.
    if (effort.check_linearity && options.loss == LossType::kNone &&
        refined.normal.jtr.size() == refined.normal.jtj.rows()) {
      result.linearity =
          CheckLinearity(scene, refined, *scaled_normal, names, result.pixel_sigma);
    }
  }
  return result;
}

CameraViews ViewsOfFittedCamera(const Camera& camera, double target_distance) {
  camera.Check();  // outside the try: an invalid camera is a bug, not an overflow
  try {
    return ViewsOfCamera(camera, target_distance);
  } catch (const std::invalid_argument& e) {
    throw TooLargeForDouble(e.what());
  }
}

void SetGivenDepthRange(const FitOptions& options,
                        const std::vector<Eigen::Vector3d>& kept_points_in_world, FitResult* fit) {
  if (!options.z_near && !options.z_far) return;
  Camera& camera = fit->camera;
  std::vector<double> depths;
  for (const Eigen::Vector3d& x : kept_points_in_world) {
    depths.push_back((camera.cam_from_world * x).z());
  }
  const auto [min_depth, max_depth] = std::minmax_element(depths.begin(), depths.end());
  const DepthRange range = DepthRangeOfPoints(options, *min_depth, *max_depth);
  camera.z_near = range.z_near;
  camera.z_far = range.z_far;
  const CameraViews& views = fit->views;
  fit->views = ViewsOfFittedCamera(camera, (views.look_at.target - views.look_at.eye).stableNorm());
}

DepthRange DepthRangeOfPoints(const FitOptions& options, double min_depth, double max_depth) {
  DepthRange range;
  range.z_near = options.z_near.value_or(min_depth / (1.0 + options.depth_margin));
  range.z_far = options.z_far.value_or(max_depth * (1.0 + options.depth_margin));
  // FitOptions::Check orders two given planes. One given alone clips every point where it is
  // past them all; the tight plane then falls on its wrong side, or (a given near plane
  // between the farthest point and the tight far plane) a frustum holds none of them.
  const bool near_past_every_point =
      options.z_near && !options.z_far && !(*options.z_near < max_depth);
  const bool far_before_every_point =
      options.z_far && !options.z_near && !(*options.z_far > min_depth);
  if (range.z_far > range.z_near && !near_past_every_point && !far_before_every_point) return range;
  const std::string depths = Concat(": the fitted camera sees the points at depths ",
                                    GeneralDouble(min_depth, 6), " to ",
                                    GeneralDouble(max_depth, 6), ", so its frustum would clip "
                                    "them all");
  if (options.z_near) {
    throw SceneError(SceneError::Reason::kPointsBehindCamera,
                     Concat("every point is nearer than the given near plane ",
                            ShortestDouble(*options.z_near), depths),
                     Concat("Give a near plane below the nearest point's depth (--near), or a "
                            "far plane beyond ", ShortestDouble(*options.z_near),
                            " as well (--far)"));
  }
  throw SceneError(SceneError::Reason::kPointsBehindCamera,
                   Concat("every point is beyond the given far plane ",
                          ShortestDouble(*options.z_far), depths),
                   Concat("Give a far plane beyond the farthest point's depth (--far), or a near "
                          "plane below ", ShortestDouble(*options.z_far), " as well (--near)"));
}

}  // namespace internal
}  // namespace camproj

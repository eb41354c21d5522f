#include "fit/orthographic_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Dense>

#include "check.h"
#include "fit/assess.h"
#include "fit/common.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
// Below this ratio of the point cloud's smallest to middle RMS extent the points are taken as
// coplanar (as in scene.cc): a plane seen orthographically has two mirror-image poses.
constexpr double kOrthoPlanarRatio = 1e-6;
constexpr double kOrthoCollinearRatio = 1e-9;
// Reciprocal condition of the Jacobi-scaled normal equations below which parameters are not
// determined (as in assess.cc).
constexpr double kOrthoSingularRcond = 1e-12;

// Intrinsics block: [scale, aspect, skew] in px per normalized world unit; fx = scale,
// fy = aspect * scale.
constexpr int kOrthoIntrinsics = 3;

// pixel = K2 (exp(omega) R0 X)_xy + offset, X in the normalized world, R0 X precomputed.
struct OrthographicReprojection {
  OrthographicReprojection(const Eigen::Vector3d& rotated_point, const Eigen::Vector2d& observed)
      : p_(rotated_point), observed_(observed) {}

  template <typename T>
  bool operator()(const T* omega, const T* offset, const T* k, T* residual) const {
    const T p[3] = {T(p_.x()), T(p_.y()), T(p_.z())};
    T q[3];
    ceres::AngleAxisRotatePoint(omega, p, q);
    residual[0] = k[0] * q[0] + k[2] * q[1] + offset[0] - T(observed_.x());
    residual[1] = k[1] * k[0] * q[1] + offset[1] - T(observed_.y());
    return true;
  }

 private:
  Eigen::Vector3d p_;
  Eigen::Vector2d observed_;
};

// Upper-triangular K2 = [[fx, s], [0, fy]] and orthonormal rows R2 with A = K2 R2.
void AffineRq(const Eigen::Matrix<double, 2, 3>& a, Eigen::Matrix2d* k2, Eigen::Matrix3d* r) {
  const Eigen::Vector3d a2 = a.row(1).transpose();
  const double fy = a2.norm();
  const Eigen::Vector3d r2 = a2 / fy;
  const double skew = a.row(0).dot(r2.transpose());
  const Eigen::Vector3d rest = a.row(0).transpose() - skew * r2;
  const double fx = rest.norm();
  const Eigen::Vector3d r1 = rest / fx;
  *k2 << fx, skew, 0.0, fy;
  r->row(0) = r1.transpose();
  r->row(1) = r2.transpose();
  r->row(2) = r1.cross(r2).transpose();  // proper: the depth order a right-handed world implies
}

SceneError NoAffineCamera() {
  return SceneError(SceneError::Reason::kDegenerate,
                    "no affine camera fits these points (their image is degenerate)",
                    "Check the correspondences");
}

// The orthographic family's linear part, shared by FitOrthographic and AffineSumSquaresPx2: the
// normalized world (centred, unit RMS distance), kCenter pixels, and the affine camera
// [X 1] a_row = u, v by least squares (4 x 4 normal equations), after the refusals every
// orthographic fit makes (too few points, collinear or coplanar points, coordinates too large).
struct AffineScene {
  std::vector<Eigen::Vector3d> points;  // normalized world
  std::vector<Eigen::Vector2d> pixels;  // kCenter
  Eigen::Vector3d centroid;
  double scale = 1.0;
  double shift = 0.0;  // pixel origin shift to kCenter
  Eigen::Matrix<double, 4, 2> solution;  // rows: A^T (3), b^T
};

AffineScene PrepareAffine(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& observed_pixels,
                          const FitOptions& options, int num_params) {
  const int n = static_cast<int>(points_in_world.size());
  if (2 * n < num_params || n < 4) {
    throw SceneError(SceneError::Reason::kTooFewPoints,
                     Concat(n, " points give ", 2 * n, " equations; the orthographic model has ",
                            num_params, " unknowns and its linear start needs 4 points off a "
                            "plane"),
                     "Add points");
  }
  AffineScene scene;
  scene.shift = PixelOriginShift(options.pixel_origin, PixelOrigin::kCenter);
  scene.centroid = Centroid(points_in_world);
  {
    Eigen::MatrixXd centred(n, 3);
    for (int i = 0; i < n; ++i) centred.row(i) = (points_in_world[i] - scene.centroid).transpose();
    scene.scale = RmsRowLength(centred);
  }
  const double scale = scene.scale;
  if (!std::isfinite(scale)) throw TooLargeForDouble();
  scene.points.resize(n);
  scene.pixels.resize(n);
  // The shape from the normalized points (the scatter of the raw ones overflows above ~1e154).
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    scene.points[i] = (points_in_world[i] - scene.centroid) / scale;  // as centred.row(i) / scale
    scene.pixels[i] = observed_pixels[i] + Eigen::Vector2d(scene.shift, scene.shift);
    scatter += scene.points[i] * scene.points[i].transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> shape(scatter);
  const Eigen::Vector3d extents = shape.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // ascending
  if (!(scale > 0.0) || extents(1) <= kOrthoCollinearRatio * extents(2)) {
    throw SceneError(SceneError::Reason::kCollinearPoints,
                     "the 3D points are collinear (or coincide)", "Add points off the line");
  }
  if (extents(0) <= kOrthoPlanarRatio * extents(1)) {
    throw SceneError(SceneError::Reason::kPlanarUnderdetermined,
                     "the points are coplanar: a plane seen orthographically has two mirror-image "
                     "poses (the sign of its tilt is not in the image)",
                     "Add points off the plane or fit a perspective camera");
  }
  CheckOffset(points_in_world, scale, scene.pixels);

  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 2> rhs = Eigen::Matrix<double, 4, 2>::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4d h = scene.points[i].homogeneous();
    normal += h * h.transpose();
    rhs += h * scene.pixels[i].transpose();
  }
  scene.solution = normal.ldlt().solve(rhs);
  return scene;
}

// The intrinsics an orthographic fit frees among scale (focal), aspect and skew; the principal
// point never (it trades exactly with the position).
struct OrthoModel {
  explicit OrthoModel(const FitOptions& options)
      : scale_free(options.focal.IsFree() || options.focal.kind == ParameterMode::Kind::kDefault),
        aspect_free(options.aspect.IsFree()),
        skew_free(options.skew.IsFree()) {}
  int NumParams() const { return 5 + (scale_free ? 1 : 0) + (aspect_free ? 1 : 0) + (skew_free ? 1 : 0); }

  bool scale_free;
  bool aspect_free;
  bool skew_free;
};

// An orthographic camera in the normalized world: pixel = K2 (exp(omega) R X)_xy + offset with
// K2 = [[k[0], k[2]], [0, k[1] k[0]]]; omega is 0 between the stages (R absorbs each step).
struct OrthoParameters {
  Eigen::Matrix3d rotation;
  std::array<double, 2> offset;
  std::array<double, kOrthoIntrinsics> k;  // scale, aspect, skew (px per normalized unit)
  std::array<double, 3> omega = {0.0, 0.0, 0.0};
};

// The affine camera's RQ factors projected onto the model: fixed values (px per world unit)
// converted to the normalized world, a fixed aspect kept with the scale that keeps fx fy.
OrthoParameters AffineStart(const AffineScene& scene, const FitOptions& options,
                            const OrthoModel& model) {
  const Eigen::Matrix<double, 4, 2>& solution = scene.solution;
  Eigen::Matrix<double, 2, 3> a = solution.topRows<3>().transpose();
  Eigen::Matrix2d k2;
  OrthoParameters p;
  AffineRq(a, &k2, &p.rotation);
  if (!(k2(0, 0) > 0.0 && k2(1, 1) > 0.0) || !p.rotation.allFinite()) throw NoAffineCamera();
  p.k = {k2(0, 0), k2(1, 1) / k2(0, 0), k2(0, 1)};
  if (!model.aspect_free) {
    const double aspect = options.aspect.kind == ParameterMode::Kind::kFixed ? options.aspect.value : 1.0;
    p.k[0] = std::sqrt(k2(0, 0) * k2(1, 1) / aspect);
    p.k[1] = aspect;
  }
  if (!model.scale_free) p.k[0] = options.focal.value * scene.scale;
  if (!model.skew_free) {
    p.k[2] = options.skew.kind == ParameterMode::Kind::kFixed ? options.skew.value * scene.scale : 0.0;
  }
  p.offset = {solution(3, 0), solution(3, 1)};
  return p;
}

// One residual block per point at `p` (R X precomputed; omega, offset and k its parameters).
void AddOrthographicResiduals(const AffineScene& scene, OrthoParameters* p,
                              ceres::LossFunction* loss, ceres::Problem* problem) {
  for (size_t i = 0; i < scene.points.size(); ++i) {
    problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<OrthographicReprojection, 2, 3, 2, kOrthoIntrinsics>(
            new OrthographicReprojection(p->rotation * scene.points[i], scene.pixels[i])),
        loss, p->omega.data(), p->offset.data(), p->k.data());
  }
}

// Ceres from `p` over the free parameters (the rotation on the chart exp(omega) R, so omega's
// are about the camera axes), with the options' robust loss; the refiner's report in `result`.
void RefineOrthographic(const AffineScene& scene, const FitOptions& options,
                        const OrthoModel& model, OrthoParameters* p, FitResult* result) {
  // One loss object shared by every block (the problem does not own it).
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.loss == LossType::kHuber) loss.reset(new ceres::HuberLoss(options.loss_scale_px));
  if (options.loss == LossType::kCauchy) loss.reset(new ceres::CauchyLoss(options.loss_scale_px));
  ceres::Problem problem(problem_options);
  AddOrthographicResiduals(scene, p, loss.get(), &problem);
  std::vector<int> constant;
  if (!model.scale_free) constant.push_back(0);
  if (!model.aspect_free) constant.push_back(1);
  if (!model.skew_free) constant.push_back(2);
  if (constant.size() == kOrthoIntrinsics) {
    problem.SetParameterBlockConstant(p->k.data());
  } else if (!constant.empty()) {
    problem.SetManifold(p->k.data(), new ceres::SubsetManifold(kOrthoIntrinsics, constant));
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = 1e-15;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.gradient_tolerance = 1e-16;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (summary.termination_type == ceres::FAILURE) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the orthographic refinement failed: " + summary.message,
                     "Check the correspondences");
  }
  result->iterations = static_cast<int>(summary.iterations.size()) - 1;
  result->refiner = "ceres";
  result->termination = std::string(ceres::TerminationTypeToString(summary.termination_type)) +
                        ": " + summary.message;
  Eigen::Matrix3d step;
  ceres::AngleAxisToRotationMatrix(p->omega.data(), ceres::ColumnMajorAdapter3x3(step.data()));
  p->rotation = step * p->rotation;
  p->omega = {0.0, 0.0, 0.0};
}

// The refinement may cross to a negative scale or fy: the same image as positive ones with the
// camera's x and/or y axis turned over (and z with them, keeping the rotation proper).
void TurnAxesUpright(const OrthoModel& model, OrthoParameters* p) {
  std::array<double, kOrthoIntrinsics>& k = p->k;
  const double sign_x = k[0] < 0.0 ? -1.0 : 1.0;
  const double sign_y = k[1] * k[0] < 0.0 ? -1.0 : 1.0;
  if (sign_y < 0.0 && !model.skew_free && k[2] != 0.0) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the orthographic camera that fits these points has its image's y axis "
                     "turned over, which the given skew does not allow",
                     "Free the skew or check the correspondences");
  }
  p->rotation = Eigen::Vector3d(sign_x, sign_y, sign_x * sign_y).asDiagonal() * p->rotation;
  k = {sign_x * k[0], sign_x * sign_y * k[1], sign_y * k[2]};
}

// The residuals at `p` and the free parameters' columns of their Jacobian (omega = 0): omega
// (3), offset (2), then the free intrinsics, with their names in that order.
struct OrthoLinearization {
  std::vector<double> residuals;
  Eigen::MatrixXd j_free;
  std::vector<int> columns;
  std::vector<std::string> names;
};

OrthoLinearization LinearizeOrthographic(const AffineScene& scene, const OrthoModel& model,
                                         OrthoParameters p) {
  const int n = static_cast<int>(scene.points.size());
  ceres::Problem problem;
  AddOrthographicResiduals(scene, &p, nullptr, &problem);
  OrthoLinearization linearization;
  ceres::CRSMatrix jacobian_crs;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, &linearization.residuals, nullptr,
                   &jacobian_crs);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(2 * n, 8);
  for (int row = 0; row < jacobian_crs.num_rows; ++row) {
    for (int j = jacobian_crs.rows[row]; j < jacobian_crs.rows[row + 1]; ++j) {
      jacobian(row, jacobian_crs.cols[j]) = jacobian_crs.values[j];
    }
  }
  std::vector<int>& columns = linearization.columns;
  std::vector<std::string>& names = linearization.names;
  columns = {0, 1, 2, 3, 4};
  names = {"rotation_x_deg", "rotation_y_deg", "rotation_z_deg", "eye_along_x", "eye_along_y"};
  if (model.scale_free) columns.push_back(5), names.push_back("fx");
  if (model.aspect_free) columns.push_back(6), names.push_back("fy");
  if (model.skew_free) columns.push_back(7), names.push_back("skew");
  linearization.j_free.resize(2 * n, static_cast<int>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) {
    linearization.j_free.col(static_cast<int>(c)) = jacobian.col(columns[c]);
  }
  return linearization;
}

// Where the camera is (normalized world): the principal point fixed (given, else the image
// centre); the eye on the axis through it, its lateral position g = K2^-1 (principal - offset)
// along the camera's x and y, one normalized unit (the points' RMS distance from their
// centroid) in front of the nearest point (any depth gives the same image).
struct OrthoPlacement {
  Eigen::Vector2d principal;
  Eigen::Matrix2d k2;
  Eigen::Vector2d lateral;
  Eigen::Vector3d eye_in_cam_axes;
};

OrthoPlacement PlaceOrthographic(const AffineScene& scene, const ImageSize& image_size,
                                 const FitOptions& options, const OrthoParameters& p) {
  OrthoPlacement place;
  place.principal =
      options.principal_point.kind == ParameterMode::Kind::kFixed
          ? Eigen::Vector2d(options.principal_point.value + scene.shift,
                            options.principal_point.value2 + scene.shift)
          : Eigen::Vector2d(0.5 * (image_size.width - 1.0), 0.5 * (image_size.height - 1.0));
  const std::array<double, kOrthoIntrinsics>& k = p.k;
  place.k2 << k[0], k[2], 0.0, k[1] * k[0];
  place.lateral =
      place.k2.inverse() * (place.principal - Eigen::Vector2d(p.offset[0], p.offset[1]));
  double min_depth = std::numeric_limits<double>::infinity();
  for (const auto& x : scene.points) min_depth = std::min(min_depth, p.rotation.row(2).dot(x));
  place.eye_in_cam_axes = Eigen::Vector3d(place.lateral.x(), place.lateral.y(), min_depth - 1.0);
  return place;
}

// The residuals' statistics, the depth range (near and far from the points' depths unless
// given) and views, the model's name and its fixed parameters, into `result` (its camera set).
// Returns the residuals' sum of squares (px^2).
double DescribeOrthographic(const AffineScene& scene, const FitOptions& options,
                          const OrthoModel& model, const OrthoParameters& p,
                          const OrthoPlacement& place, const OrthoLinearization& linearization,
                          FitResult* result) {
  const int n = static_cast<int>(scene.points.size());
  Camera& camera = result->camera;
  std::vector<double> depths(n);
  std::vector<double> norms(n);
  double sum_squares = 0.0;
  result->residuals_px.resize(n);
  for (int i = 0; i < n; ++i) {
    result->residuals_px[i] =
        Eigen::Vector2d(linearization.residuals[2 * i], linearization.residuals[2 * i + 1]);
    norms[i] = result->residuals_px[i].norm();
    sum_squares += norms[i] * norms[i];
    depths[i] = (p.rotation.row(2).dot(scene.points[i]) - place.eye_in_cam_axes.z()) * scene.scale;
  }
  result->rms_px = std::sqrt(sum_squares / n);
  std::vector<double> sorted = norms;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  result->median_px = sorted[n / 2];
  if (n % 2 == 0) {
    result->median_px =
        0.5 * (result->median_px + *std::max_element(sorted.begin(), sorted.begin() + n / 2));
  }
  result->max_px = *std::max_element(norms.begin(), norms.end());
  const auto [near_it, far_it] = std::minmax_element(depths.begin(), depths.end());
  const DepthRange range = DepthRangeOfPoints(options, *near_it, *far_it);
  camera.z_near = range.z_near;
  camera.z_far = range.z_far;
  std::vector<double> depths_sorted = depths;
  std::nth_element(depths_sorted.begin(), depths_sorted.begin() + n / 2, depths_sorted.end());
  result->views = ViewsOfFittedCamera(camera, depths_sorted[n / 2]);
  result->start_method = "affine";
  result->pixel_origin = options.pixel_origin;
  result->planar = false;
  result->free_parameters = linearization.names;
  result->model = std::string("orthographic") + (model.aspect_free ? "+aspect" : "") +
                  (model.skew_free ? "+skew" : "");
  if (!model.scale_free) result->model += " (scale given)";
  auto fixed = [&](const char* name, const std::string& value, const ParameterMode& mode,
                   const char* default_why) {
    result->fixed_parameters.push_back(
        {name, value, mode.kind == ParameterMode::Kind::kFixed ? "given" : default_why});
  };
  if (!model.scale_free) {
    fixed("scale", Concat(camera.intrinsics.fx, " px per world unit"), options.focal, "given");
  }
  if (!model.aspect_free) fixed("aspect", Concat(p.k[1]), options.aspect, "default: square pixels");
  if (!model.skew_free) fixed("skew", Concat(camera.intrinsics.skew), options.skew, "default: no skew");
  fixed("principal point",
        Concat(place.principal.x() - scene.shift, ", ", place.principal.y() - scene.shift),
        options.principal_point,
        "not determined: it trades exactly with the position in an orthographic view");
  return sum_squares;
}

// The covariance in the user's units from the normalized one (scaled_normal's inverse):
// omega -> degrees; the eye's lateral position g = K2^-1 (c - offset) (world units, along the
// camera's x and y) by its derivatives; scale, fy and skew / scale. Sigmas and strong
// correlations with it.
void SetOrthographicCovariance(const JacobiScaledNormal<Eigen::MatrixXd>& scaled_normal,
                               const AffineScene& scene, const FitOptions& options,
                               const OrthoModel& model, const OrthoParameters& p,
                               const OrthoPlacement& place,
                               const OrthoLinearization& linearization, FitResult* result) {
  const int num_params = static_cast<int>(linearization.columns.size());
  const double scale = scene.scale;
  const std::array<double, kOrthoIntrinsics>& k = p.k;
  const Eigen::MatrixXd inverse = scaled_normal.Inverse();
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(num_params, num_params);
  for (int j = 0; j < 3; ++j) l(j, j) = kDegPerRad;
  const Eigen::Matrix2d k2_inverse = place.k2.inverse();
  l.block<2, 2>(3, 3) = -scale * k2_inverse;
  // d g / d K2 entries: d(K2^-1) = -K2^-1 dK2 K2^-1.
  auto dg = [&](const Eigen::Matrix2d& dk2) {
    return Eigen::Vector2d(-scale * k2_inverse * dk2 * place.lateral);
  };
  int col = 5;
  if (model.scale_free) {
    Eigen::Matrix2d d;
    d << 1.0, 0.0, 0.0, k[1];
    l.block<2, 1>(3, col) = dg(d);
    l(col, col) = 1.0 / scale;
    ++col;
  }
  if (model.aspect_free) {
    Eigen::Matrix2d d;
    d << 0.0, 0.0, 0.0, k[0];
    l.block<2, 1>(3, col) = dg(d);
    l(col, col) = k[0] / scale;  // fy = aspect * scale / s
    if (model.scale_free) l(col, 5) = k[1] / scale;
    ++col;
  }
  if (model.skew_free) {
    Eigen::Matrix2d d;
    d << 0.0, 1.0, 0.0, 0.0;
    l.block<2, 1>(3, col) = dg(d);
    l(col, col) = 1.0 / scale;
  }
  result->covariance = result->pixel_sigma * result->pixel_sigma * l * inverse * l.transpose();
  result->covariance_available = true;
  const Camera& camera = result->camera;
  const Eigen::Vector2d lateral_world = scale * place.lateral;
  const std::vector<double> values = {0.0, 0.0, 0.0, lateral_world.x(), lateral_world.y(),
                                      camera.intrinsics.fx, camera.intrinsics.fy,
                                      camera.intrinsics.skew};
  for (int j = 0; j < num_params; ++j) {
    const int value_index = j < 5 ? j : linearization.columns[j];
    const std::string unit = j < 3 ? "deg" : j < 5 ? "world" : "px per world unit";
    result->sigmas.push_back({linearization.names[j], values[value_index],
                              std::sqrt(result->covariance(j, j)), unit});
  }
  result->strong_correlations =
      StrongCorrelations(result->covariance, linearization.names, options.strong_correlation);
}

}  // namespace

double AffineSumSquaresPx2(const std::vector<Eigen::Vector3d>& points_in_world,
                           const std::vector<Eigen::Vector2d>& observed_pixels,
                           const FitOptions& options) {
  const AffineScene scene = PrepareAffine(points_in_world, observed_pixels, options, 8);
  const Eigen::Matrix<double, 2, 3> a = scene.solution.topRows<3>().transpose();
  const Eigen::Vector2d b = scene.solution.row(3).transpose();
  Eigen::Matrix2d k2;
  Eigen::Matrix3d rotation;
  AffineRq(a, &k2, &rotation);
  if (!(k2(0, 0) > 0.0 && k2(1, 1) > 0.0) || !rotation.allFinite()) throw NoAffineCamera();
  double sum_squares = 0.0;
  for (size_t i = 0; i < scene.points.size(); ++i) {
    sum_squares += (scene.pixels[i] - a * scene.points[i] - b).squaredNorm();
  }
  return sum_squares;
}

FitResult FitOrthographic(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& observed_pixels,
                          const ImageSize& image_size, const FitOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  const OrthoModel model(options);
  const AffineScene scene = PrepareAffine(points_in_world, observed_pixels, options, model.NumParams());
  OrthoParameters parameters = AffineStart(scene, options, model);
  FitResult result;
  if (options.refine) {
    RefineOrthographic(scene, options, model, &parameters, &result);
  } else {
    result.refiner = "none";
    result.termination = "not refined (closed-form start only)";
  }
  TurnAxesUpright(model, &parameters);
  const OrthoLinearization linearization = LinearizeOrthographic(scene, model, parameters);
  const OrthoPlacement place = PlaceOrthographic(scene, image_size, options, parameters);

  Camera& camera = result.camera;
  camera.image_size = image_size;
  camera.projection = Projection::kOrthographic;
  const std::array<double, kOrthoIntrinsics>& k = parameters.k;
  camera.intrinsics.fx = k[0] / scene.scale;
  camera.intrinsics.fy = k[1] * k[0] / scene.scale;
  camera.intrinsics.skew = k[2] / scene.scale + 0.0;
  camera.intrinsics.cx = place.principal.x();
  camera.intrinsics.cy = place.principal.y();
  const Eigen::Vector3d eye = parameters.rotation.transpose() * place.eye_in_cam_axes;
  camera.cam_from_world =
      CamFromWorldFromCenter(parameters.rotation, scene.centroid + scene.scale * eye);
  const double sum_squares =
      DescribeOrthographic(scene, options, model, parameters, place, linearization, &result);

  // Uncertainty, as in FitCamera: Jacobi-scaled normal equations, refusal when singular.
  const Eigen::MatrixXd& j_free = linearization.j_free;
  const JacobiScaledNormal<Eigen::MatrixXd> scaled_normal(j_free.transpose() * j_free);
  const double rcond = scaled_normal.rcond;
  if (!(rcond > kOrthoSingularRcond)) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     Concat("the points do not determine the orthographic camera (singular "
                            "normal equations, reciprocal condition ", rcond, ")"),
                     "Add points spread across the image, or fix the aspect and skew");
  }
  result.jacobian_condition = scaled_normal.JacobianCondition();
  const bool have_sigma = SetPixelSigma(options, sum_squares,
                                        2 * static_cast<int>(scene.points.size()) -
                                            static_cast<int>(linearization.columns.size()),
                                        &result);
  if (options.compute_uncertainty && have_sigma) {
    SetOrthographicCovariance(scaled_normal, scene, options, model, parameters, place,
                              linearization, &result);
  }
  result.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace internal
}  // namespace camproj

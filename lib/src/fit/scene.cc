#include "fit/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "camproj/conventions.h"
#include "camproj/model_select.h"
#include "check.h"
#include "fit/common.h"
#include "fit/start.h"

namespace camproj {
namespace internal {

namespace {

// The point cloud's singular values s1 >= s2 >= s3 (RMS extents along its principal axes):
// collinear below s2 / s1 = kCollinearRatio, exactly planar (for counting what a plane
// determines) below s3 / s2 = kPlanarRatio, started from a homography below kPlanarStartRatio
// (the DLT's 3D information is then too weak to trust under noise). Thickness is measured
// against s2, not s1: a narrow field of view makes a deep but slender cloud, not a plane.
constexpr double kCollinearRatio = 1e-9;
constexpr double kPlanarRatio = 1e-9;
constexpr double kPlanarStartRatio = 1e-2;

// Double precision's unit roundoff (2^-53): the relative rounding of every coordinate.
constexpr double kUnitRoundoff = 0.5 * std::numeric_limits<double>::epsilon();
// The most the rounding of the coordinates may move the pixels: a tenth of the smallest pixel
// noise the model selection believes (kMinNoisePx), so that an offset never changes its
// decisions, even on noise-free data.
constexpr double kMaxOffsetRoundingPx = 0.1 * kMinNoisePx;

// The SVD (singular values, descending, and V) of `centred` (n x 3) from its R factor
// accumulated over blocks of rows (TSQR: R of [R; next block] until the rows run out): centred =
// Q R and R = U S V^T give centred = (Q U) S V^T, the same values and V as the whole matrix's SVD
// to rounding (V's columns up to sign), in the memory of one block rather than of n rows. The rows are
// first scaled by a power of two (exact) that brings the largest entry to [1, 2), so that the
// Householder norms neither overflow above ~1e154 nor underflow.
Eigen::JacobiSVD<Eigen::Matrix3d> SvdOfRows(const Eigen::MatrixXd& centred) {
  const double largest = centred.cwiseAbs().maxCoeff();
  if (!(largest > 0.0 && std::isfinite(largest))) {
    return Eigen::JacobiSVD<Eigen::Matrix3d>(Eigen::Matrix3d::Zero(), Eigen::ComputeFullV);
  }
  const double unit = std::ldexp(1.0, -std::ilogb(largest));
  constexpr Eigen::Index kBlockRows = 256;
  Eigen::Matrix<double, Eigen::Dynamic, 3> stacked(kBlockRows + 3, 3);
  Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
  for (Eigen::Index begin = 0; begin < centred.rows(); begin += kBlockRows) {
    const Eigen::Index rows = std::min(kBlockRows, centred.rows() - begin);
    stacked.resize(rows + 3, 3);
    stacked.topRows<3>() = r;
    stacked.bottomRows(rows) = unit * centred.middleRows(begin, rows);
    const Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, 3>> qr(stacked);
    r = qr.matrixQR().topRows<3>().triangularView<Eigen::Upper>();
  }
  return Eigen::JacobiSVD<Eigen::Matrix3d>(r / unit, Eigen::ComputeFullV);
}

}  // namespace

SceneError TooLargeForDouble() {
  return SceneError(SceneError::Reason::kNonFiniteInput,
                    "the 3D points' coordinates are too large for double precision (their sum or "
                    "differences overflow)",
                    "Divide every coordinate by a common factor (change units) and refit");
}

SceneError TooLargeForDouble(const std::string& overflow) {
  const SceneError refusal = TooLargeForDouble();
  return SceneError(refusal.reason(),
                    "the 3D points' coordinates are too large for double precision: the fitted "
                    "camera's GL matrices overflow (" + overflow + ")",
                    refusal.fix());
}

void CheckOffset(const std::vector<Eigen::Vector3d>& points_in_world, double scale,
                 const std::vector<Eigen::Vector2d>& pixels) {
  double largest = 0.0;
  for (const auto& x : points_in_world) largest = std::max(largest, x.cwiseAbs().maxCoeff());
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pixels) mean += p / static_cast<double>(pixels.size());
  Eigen::MatrixXd centred(pixels.size(), 2);
  for (size_t i = 0; i < pixels.size(); ++i) centred.row(i) = (pixels[i] - mean).transpose();
  const double offset = largest / scale;  // in units of the points' spread
  const double rounding = kUnitRoundoff * offset;
  const double rounding_px = rounding * RmsRowLength(centred);
  if (rounding_px > kMaxOffsetRoundingPx) {
    throw SceneError(
        SceneError::Reason::kNonFiniteInput,
        Concat("the 3D points are ", GeneralDouble(offset, 2),
               " times as far from the origin as from each other: double precision rounds their "
               "positions relative to each other by ", GeneralDouble(rounding, 2),
               " of their spread, which moves their pixels by about ",
               GeneralDouble(rounding_px, 2), " px, and so would the camera written with these "
               "coordinates"),
        "Subtract a common offset from every point (e.g. the first point), refit, and use the "
        "camera with the offset subtracted");
  }
}

std::string PointName(const std::string& name) {
  const bool number = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
  return number ? "point " + name : name;
}

void CheckCorrespondences(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& observed_pixels,
                          const std::vector<std::string>& point_names) {
  Require(points_in_world.size() == observed_pixels.size(), "got ", points_in_world.size(),
          " 3D points but ", observed_pixels.size(), " pixels");
  const int n = static_cast<int>(points_in_world.size());
  for (int i = 0; i < n; ++i) {
    if (!points_in_world[i].allFinite() || !observed_pixels[i].allFinite()) {
      // Numbered from 1, as the summary and the points file's rows number them.
      const std::string name = i < static_cast<int>(point_names.size())
                                   ? PointName(point_names[i])
                                   : Concat("point ", i + 1);
      throw SceneError(SceneError::Reason::kNonFiniteInput,
                       Concat(name, " is not finite (X = ", points_in_world[i].transpose(),
                              ", pixel = ", observed_pixels[i].transpose(), ")"),
                       Concat("Remove or fix ", name));
    }
  }
}

SceneGeometry PrepareScene(const std::vector<Eigen::Vector3d>& points_in_world,
                           const std::vector<Eigen::Vector2d>& observed_pixels,
                           const ImageSize& image_size, PixelOrigin pixel_origin) {
  SceneGeometry geometry;
  geometry.pixel_origin = pixel_origin;
  geometry.num_points = static_cast<int>(points_in_world.size());
  Scene& scene = geometry.scene;
  scene.image_size = image_size;
  const int n = geometry.num_points;
  // Fewer than 4 points never pass ValidateScene's first check; nothing below is defined for
  // them.
  if (n < 4) return geometry;

  // Pixels in kCenter; the world centred and scaled to unit RMS distance, so neither units nor
  // offsets reach the numerics.
  const double shift = PixelOriginShift(pixel_origin, PixelOrigin::kCenter);
  scene.pixels = observed_pixels;
  for (auto& p : scene.pixels) p += Eigen::Vector2d(shift, shift);
  const Eigen::Vector3d centroid = Centroid(points_in_world);
  Eigen::MatrixXd centred(n, 3);
  for (int i = 0; i < n; ++i) centred.row(i) = (points_in_world[i] - centroid).transpose();
  const double scale = RmsRowLength(centred);
  if (!std::isfinite(scale)) {
    geometry.refusal = TooLargeForDouble();
    return geometry;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> shape = SvdOfRows(centred);
  if (shape.info() != Eigen::Success) {
    // The extents overflow where each coordinate and the RMS spread do not (coordinates near
    // 1e308 of both signs): Eigen leaves the singular values unset, and reading them made the
    // refusal depend on the stack's contents.
    geometry.refusal = TooLargeForDouble();
    return geometry;
  }
  const Eigen::Vector3d extents = shape.singularValues();
  if (!(scale > 0.0) || extents(1) <= kCollinearRatio * extents(0)) {
    geometry.refusal = SceneError(
        SceneError::Reason::kCollinearPoints,
        "the 3D points are collinear (or coincide): a line does not determine a camera's "
        "rotation about it",
        "Add points off the line");
    return geometry;
  }
  // The distinct points, counted on sorted indices (4 bytes a point, not a copy of 24).
  std::vector<int> sorted(n);
  for (int i = 0; i < n; ++i) sorted[i] = i;
  auto less = [&](int a, int b) {
    const double* x = points_in_world[a].data();
    const double* y = points_in_world[b].data();
    return std::lexicographical_compare(x, x + 3, y, y + 3);
  };
  std::sort(sorted.begin(), sorted.end(), less);
  auto same = [&](int a, int b) { return points_in_world[a] == points_in_world[b]; };
  scene.num_distinct_points =
      static_cast<int>(std::unique(sorted.begin(), sorted.end(), same) - sorted.begin());
  try {
    CheckOffset(points_in_world, scale, scene.pixels);
  } catch (const SceneError& error) {
    geometry.offset_refusal = error;
  }
  scene.centroid = centroid;
  scene.scale = scale;
  scene.points.resize(n);
  for (int i = 0; i < n; ++i) scene.points[i] = centred.row(i).transpose() / scale;
  scene.planar = extents(2) <= kPlanarRatio * extents(1);
  scene.planar_start = extents(2) <= kPlanarStartRatio * extents(1);
  scene.plane_basis =
      shape.matrixV().determinant() > 0
          ? Eigen::Matrix3d(shape.matrixV())
          : Eigen::Matrix3d(shape.matrixV() * Eigen::Vector3d(1, 1, -1).asDiagonal());
  scene.dlt = std::make_shared<DltReading>();
  return geometry;
}

Scene ValidateScene(SceneGeometry geometry, const FitOptions& options) {
  Require(options.pixel_origin == geometry.pixel_origin,
          "the scene was prepared for another pixel origin");
  Model model = MakeModel(options, geometry.scene.image_size);
  const int n = geometry.num_points;
  const int num_params = 6 + model.NumFree();
  // Three points fix a pose only up to P3P's four-fold ambiguity: four is the least for one.
  // `count`: the distinct points, as a point given twice adds no equation.
  auto require_points = [&](int count) {
    if (2 * count >= num_params && count >= 4) return;
    throw SceneError(SceneError::Reason::kTooFewPoints,
                     Concat(n, " points", count < n ? Concat(" (", count, " distinct)") : "",
                            " give ", 2 * count, " equations, but the model has ",
                            num_params, " unknowns (pose 6 + ", model.NumFree(),
                            " free intrinsics) and a unique pose needs 4 points"),
                     Concat("Add points (at least ", std::max(4, (num_params + 1) / 2),
                            ") or fix intrinsics"));
  };
  // In the order of the checks of one scene: the count, the coordinates' range, the shape, the
  // distinct count, the offset, what a plane determines.
  require_points(n);
  if (geometry.refusal) throw *geometry.refusal;
  require_points(geometry.scene.num_distinct_points);
  if (geometry.offset_refusal) throw *geometry.offset_refusal;
  if (geometry.scene.planar && model.NumFreeLinear() > 2) {
    throw SceneError(
        SceneError::Reason::kPlanarUnderdetermined,
        "the points are coplanar: one view of a plane determines at most 2 of focal, aspect, "
        "principal point (2) and skew, but " + FreeLinearNames(model) +
            " are free",
        "Fix the principal point (at the image centre by default) and the aspect (square "
        "pixels), or add points off the plane");
  }
  Scene scene = std::move(geometry.scene);
  scene.model = std::move(model);
  return scene;
}

Scene ValidateScene(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options) {
  return ValidateScene(
      PrepareScene(points_in_world, observed_pixels, image_size, options.pixel_origin), options);
}

}  // namespace internal
}  // namespace camproj

#include "camproj/calibrate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <ceres/ceres.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "camproj/model_select.h"
#include "camproj/number_text.h"
#include "check.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/reprojection_error.h"
#include "fit/statistics.h"
#include "fit/zhang.h"

namespace camproj {

void CalibrateOptions::Check() const {
  image_size.Check();
  if (num_radial < 0 || num_radial > 3) {
    throw std::invalid_argument("CalibrateOptions.num_radial must be 0, 1, 2 or 3, got " +
                                std::to_string(num_radial));
  }
  if (max_iterations <= 0) {
    throw std::invalid_argument("CalibrateOptions.max_iterations must be positive");
  }
  if (!(pixel_sigma >= 0.0) || !std::isfinite(pixel_sigma)) {
    throw std::invalid_argument("CalibrateOptions.pixel_sigma must be >= 0 (0: estimated), got " +
                                std::to_string(pixel_sigma));
  }
  if (!(function_tolerance > 0.0) || !(gradient_tolerance > 0.0) ||
      !(parameter_tolerance > 0.0)) {
    throw std::invalid_argument("CalibrateOptions tolerances must be positive");
  }
}

namespace {

using internal::kFitIntrinsicsSize;

// Intrinsics block entries (reprojection_error.h): [f, aspect, cx, cy, skew, k1, k2].
constexpr int kAspect = 1, kCx = 2, kCy = 3, kSkew = 4, kK1 = 5, kK2 = 6, kP1 = 7, kP2 = 8,
              kK3 = 9;
// Pose block: a rotation vector w (cam_from_world = Exp(w) R0, R0 the view's start), then the
// camera centre.
constexpr int kPoseSize = 6;
using IntrinsicsLayout = Eigen::Matrix<double, kFitIntrinsicsSize, 1>;
// A view is read as planar for the start when its points' thinnest extent is below this share of
// their widest (the refinement always uses the points as given).
constexpr double kPlanarShare = 1e-3;
// Each view's near / far planes sit this share outside its points' depths (FitOptions' default).
constexpr double kDepthMargin = 0.1;
// A view is refused only if its RMS is also this many times the other views' (see
// WorstInconsistentView). On OpenCV's sample chessboards the chi-square test alone refuses 3 of
// 13 left views, at 0.30-1.24 px against 0.15-0.23 px; with 2.5x it refuses left02 alone (1.24 px,
// 5x the rest), keeping left13 (0.47 px, 1.9x). A view of another lens is refused only where
// it differs that much: one pincushion view (k1 +0.15) among barrel ones (-0.21) came out at
// 1.7-2.8x, by where the board sat in the image (docs/calibration.md).
constexpr double kViewRmsFactor = 2.5;

// The rotation Exp(w) of a rotation vector w (angle |w| about w / |w|) and the left Jacobian
// J_l(w) of SO(3): d/dw (Exp(w) R0 v) = -[Exp(w) R0 v]x J_l(w).
//   J_l(w) = I + (1 - cos a) / a^2 [w]x + (a - sin a) / a^3 [w]x^2,  a = |w|
// (series below a = 1e-4, where the truncation is below 1e-17).
void ExpWithLeftJacobian(const double* w, Eigen::Matrix3d* rotation, Eigen::Matrix3d* left_jacobian) {
  const Eigen::Vector3d v(w[0], w[1], w[2]);
  const double a2 = v.squaredNorm();
  const double a = std::sqrt(a2);
  Eigen::Matrix3d wx;
  wx << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  double sin_term, cos_term, cube_term;  // sin a / a, (1 - cos a) / a^2, (a - sin a) / a^3
  if (a < 1e-4) {
    sin_term = 1.0 - a2 / 6.0;
    cos_term = 0.5 - a2 / 24.0;
    cube_term = 1.0 / 6.0 - a2 / 120.0;
  } else {
    sin_term = std::sin(a) / a;
    cos_term = (1.0 - std::cos(a)) / a2;
    cube_term = (a - std::sin(a)) / (a2 * a);
  }
  const Eigen::Matrix3d wx2 = wx * wx;
  *rotation = Eigen::Matrix3d::Identity() + sin_term * wx + cos_term * wx2;
  if (left_jacobian != nullptr) {
    *left_jacobian = Eigen::Matrix3d::Identity() + cos_term * wx + cube_term * wx2;
  }
}

// A view's points as the joint problem holds them: x = (X - origin) / unit, the origin their
// centroid and the unit the power of two at or below their RMS distance from it (scaling by it is
// exact). The pixels depend on X - C only through its direction, so the camera centre is fitted
// in this frame: in world units its Jacobian columns scale as 1 / the board's size and the
// covariance's rank test refused boards measured in units 1e9 times a square (a rotation's
// columns do not scale); about the world's origin, boards far from it (survey coordinates) lost
// X - C's digits, and at 1e9 squares from it the calibration moved cx by 0.8 px.
struct ViewFrame {
  explicit ViewFrame(const std::vector<Eigen::Vector3d>& points_in_world) {
    origin = Eigen::Vector3d::Zero();
    for (const auto& p : points_in_world) origin += p;
    origin /= static_cast<double>(points_in_world.size());
    double sum_squares = 0.0;
    for (const auto& p : points_in_world) sum_squares += (p - origin).squaredNorm();
    const double rms = std::sqrt(sum_squares / static_cast<double>(points_in_world.size()));
    unit = rms > 0.0 && std::isfinite(rms) ? std::ldexp(1.0, std::ilogb(rms)) : 1.0;
    for (const auto& p : points_in_world) points.push_back((p - origin) / unit);
  }
  Eigen::Vector3d InWorld(const Eigen::Vector3d& x) const { return origin + unit * x; }
  Eigen::Vector3d InFrame(const Eigen::Vector3d& point_in_world) const {
    return (point_in_world - origin) / unit;
  }

  Eigen::Vector3d origin;
  double unit;
  std::vector<Eigen::Vector3d> points;
};

// All points of one view, analytic: per point the single-view fitter's residual of the camera
// point (ResidualOfCamPoint). Parameter blocks: the view's pose [w, c] (cam_from_world rotation
// Exp(w) R0 about the start's R0, the camera centre c in the view's frame; |w| stays far below pi
// from a closed-form start) and the free intrinsics (FitLayout entries at `free_slots`, the
// others held at their values in `k`). Plain vectors, no manifolds, one block per view: Ceres'
// per-block costs (the manifolds' Jacobian products, the evaluation bookkeeping) were 40 % of the
// joint solve (bench --calibrate, callgrind).
class ViewCost : public ceres::CostFunction {
 public:
  ViewCost(const CalibrationView& view, const ViewFrame& frame,
           const Eigen::Matrix3d& reference_rotation, const IntrinsicsLayout& k,
           const std::vector<int>& free_slots)
      : points_(frame.points), pixels_(view.pixels),
        reference_rotation_(reference_rotation), k_(k), free_slots_(free_slots) {
    set_num_residuals(2 * static_cast<int>(pixels_.size()));
    mutable_parameter_block_sizes()->assign({kPoseSize, static_cast<int>(free_slots.size())});
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    IntrinsicsLayout k = k_;
    for (size_t i = 0; i < free_slots_.size(); ++i) k(free_slots_[i]) = parameters[1][i];
    double* pose_jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    double* k_jacobian = jacobians != nullptr ? jacobians[1] : nullptr;
    Eigen::Matrix3d exp_w, left_jacobian;
    ExpWithLeftJacobian(pose, &exp_w, pose_jacobian != nullptr ? &left_jacobian : nullptr);
    const Eigen::Matrix3d rotation = exp_w * reference_rotation_;
    const Eigen::Vector3d center(pose[3], pose[4], pose[5]);
    const int num_free = static_cast<int>(free_slots_.size());
    for (size_t j = 0; j < pixels_.size(); ++j) {
      const Eigen::Vector3d p = rotation * (points_[j] - center);
      if (!(p.z() > 0.0)) return false;  // behind the camera: an invalid step
      Eigen::Matrix<double, 2, kFitIntrinsicsSize, Eigen::RowMajor> jk;
      Eigen::Matrix<double, 2, 3, Eigen::RowMajor> d_pixel_d_p;
      internal::ResidualOfCamPoint(k.data(), p, pixels_[j], residuals + 2 * j,
                                   k_jacobian != nullptr ? jk.data() : nullptr,
                                   pose_jacobian != nullptr ? d_pixel_d_p.data() : nullptr);
      if (k_jacobian != nullptr) {
        for (int row = 0; row < 2; ++row) {
          for (int i = 0; i < num_free; ++i) {
            k_jacobian[(2 * j + row) * num_free + i] = jk(row, free_slots_[i]);
          }
        }
      }
      if (pose_jacobian != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 2, kPoseSize, Eigen::RowMajor>> jp(
            pose_jacobian + 2 * j * kPoseSize);
        Eigen::Matrix3d p_cross;
        p_cross << 0.0, -p.z(), p.y(), p.z(), 0.0, -p.x(), -p.y(), p.x(), 0.0;
        jp.leftCols<3>() = -d_pixel_d_p * p_cross * left_jacobian;
        jp.rightCols<3>() = -d_pixel_d_p * rotation;
      }
    }
    return true;
  }

 private:
  const std::vector<Eigen::Vector3d>& points_;  // in the view's frame; it and the view outlive
  const std::vector<Eigen::Vector2d>& pixels_;   // the problem
  Eigen::Matrix3d reference_rotation_;
  const IntrinsicsLayout& k_;  // the joint problem's: fixed entries' values
  std::vector<int> free_slots_;
};

void CheckView(const CalibrationView& view, size_t index) {
  const std::string name = "view " + std::to_string(index + 1) +
                           (view.name.empty() ? "" : " (" + view.name + ")");
  if (view.points_in_world.size() != view.pixels.size()) {
    throw std::invalid_argument(name + " has " + std::to_string(view.points_in_world.size()) +
                                " points but " + std::to_string(view.pixels.size()) + " pixels");
  }
  if (!view.ids.empty() && view.ids.size() != view.pixels.size()) {
    throw std::invalid_argument(name + " has " + std::to_string(view.ids.size()) + " ids for " +
                                std::to_string(view.pixels.size()) + " points");
  }
  if (view.points_in_world.size() < 4) {
    throw std::invalid_argument(name + " has " + std::to_string(view.points_in_world.size()) +
                                " points; a view needs at least 4");
  }
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    if (!view.points_in_world[i].allFinite() || !view.pixels[i].allFinite()) {
      throw std::invalid_argument(name + ": point " + std::to_string(i + 1) +
                                  " has a non-finite coordinate");
    }
  }
}

std::string ViewName(const CalibrationView& view, size_t index) {
  return view.name.empty() ? "view " + std::to_string(index + 1) : view.name;
}

// Throws std::invalid_argument for pixels no camera of `size` could have seen: one farther than
// kMaxImageSide px outside the image (naming its view and point: a pixel of 1e155 overflowed the
// closed form, refused as "the views do not determine the intrinsics"), or more than half of
// them outside it (a wrong image size: 64 x 48 for a 640 x 480 camera was calibrated, cx 342).
void CheckPixelsInImage(const std::vector<CalibrationView>& views, const ImageSize& size) {
  const Eigen::Vector2d low(-0.5, -0.5);
  const Eigen::Vector2d high(size.width - 0.5, size.height - 0.5);
  size_t outside = 0;
  size_t total = 0;
  Eigen::Vector2d min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d max = -min;
  for (size_t v = 0; v < views.size(); ++v) {
    for (size_t i = 0; i < views[v].pixels.size(); ++i) {
      const Eigen::Vector2d& pixel = views[v].pixels[i];
      const double beyond = std::max((low - pixel).maxCoeff(), (pixel - high).maxCoeff());
      if (beyond > kMaxImageSide) {
        throw std::invalid_argument(internal::Concat(
            ViewName(views[v], v), ": point ",
            views[v].ids.empty() ? std::to_string(i + 1) : views[v].ids[i], ": pixel (",
            pixel.x(), ", ", pixel.y(), ") lies more than ", kMaxImageSide, " px outside the ",
            size.width, " x ", size.height, " image"));
      }
      outside += beyond > 0.0 ? 1 : 0;
      ++total;
      min = min.cwiseMin(pixel);
      max = max.cwiseMax(pixel);
    }
  }
  if (2 * outside > total) {
    throw std::invalid_argument(internal::Concat(
        outside, " of the ", total, " pixels lie outside the ", size.width, " x ", size.height,
        " image (they span u ", GeneralDouble(min.x(), 4), " to ", GeneralDouble(max.x(), 4),
        ", v ", GeneralDouble(min.y(), 4), " to ", GeneralDouble(max.y(), 4),
        "): check the image size"));
  }
}

// Throws std::invalid_argument naming two views with the same points and pixels: a view given
// twice (a file copied under another name) counts its points twice and adds no constraint, and
// the joint fit then took it for two views (seen: left01 beside its copy, fx 13.6 +- 748 px for
// a true ~534, exit 0).
void CheckNoViewRepeated(const std::vector<CalibrationView>& views) {
  // Views with the same point count and first pixel, compared in full.
  std::map<std::tuple<size_t, double, double>, std::vector<size_t>> alike;
  for (size_t i = 0; i < views.size(); ++i) {
    const Eigen::Vector2d& first = views[i].pixels.front();
    std::vector<size_t>& earlier = alike[{views[i].pixels.size(), first.x(), first.y()}];
    for (const size_t j : earlier) {
      if (views[j].pixels == views[i].pixels &&
          views[j].points_in_world == views[i].points_in_world) {
        throw std::invalid_argument(ViewName(views[i], i) + " has the same points and pixels as " +
                                    ViewName(views[j], j) + ": a view given twice counts its "
                                    "points twice (give each view once)");
      }
    }
    earlier.push_back(i);
  }
}

// A planar view read in its plane: point_in_plane = plane_from_world * (point_in_world -
// centroid), the plane's normal along the third row; the homography from (u, v) to the pixels.
struct PlanarView {
  Eigen::Vector3d centroid;
  Eigen::Matrix3d plane_from_world;  // rows: the widest axis, the second, their cross product
  std::vector<Eigen::Vector2d> coordinates;
  Eigen::Matrix3d homography;        // NormalizedHomography(coordinates, pixels)
};

// How points spread: their centroid, and the extents (RMS distance from the centroid, ascending)
// along the principal axes (the columns of `axes`, in the same order).
struct Spread {
  Eigen::Vector3d centroid;
  Eigen::Vector3d extent;
  Eigen::Matrix3d axes;
};

Spread SpreadOf(const std::vector<Eigen::Vector3d>& points) {
  Spread spread;
  spread.centroid = internal::Centroid(points);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - spread.centroid) * (p - spread.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  spread.extent = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  spread.axes = eigen.eigenvectors();
  return spread;
}

// Whether the points lie on a line (their second extent below kPlanarShare of the first): no
// pose is determined from them.
bool Collinear(const Spread& spread) {
  return !(spread.extent(1) > kPlanarShare * spread.extent(2));
}

// The view read in its best-fitting plane, if its points are planar (see kPlanarShare).
std::optional<PlanarView> PlanarViewOf(const CalibrationView& view, const Spread& spread) {
  const std::vector<Eigen::Vector3d>& points = view.points_in_world;
  const Eigen::Vector3d& extent = spread.extent;
  if (!(extent(2) > 0.0) || extent(0) > kPlanarShare * extent(2)) return std::nullopt;
  const Eigen::Vector3d& centroid = spread.centroid;
  PlanarView plane;
  plane.centroid = centroid;
  plane.plane_from_world.row(0) = spread.axes.col(2).transpose();
  plane.plane_from_world.row(1) = spread.axes.col(1).transpose();
  plane.plane_from_world.row(2) =
      plane.plane_from_world.row(0).cross(plane.plane_from_world.row(1));
  plane.coordinates.reserve(points.size());
  for (const auto& p : points) {
    plane.coordinates.push_back((plane.plane_from_world * (p - centroid)).head<2>());
  }
  plane.homography = internal::NormalizedHomography(plane.coordinates, view.pixels);
  return plane;
}

// A planar view whose points fit no image of a plane: the RMS (px) its best homography leaves
// is above kScrambledHomographyPx and kScrambledHomographyFactor times the median over the
// planar views (at least 3). A real board through a lens fits one to its distortion: OpenCV's
// 26 chessboard views leave 0.8-2.3 px; one whose correspondences were shuffled 5.7e4 px (the
// homography then sends points near infinity), and it broke the joint refinement's evaluation
// ("please report it") or the closed-form start, with no view named (before session 37). Runs
// on every call that may refuse views: the top-level one, the chosen model's and each rest's
// (a homography per view, small beside the calibration; not shared between the calls).
constexpr double kScrambledHomographyPx = 10.0;
constexpr double kScrambledHomographyFactor = 10.0;

double HomographyRmsPx(const PlanarView& plane, const std::vector<Eigen::Vector2d>& pixels) {
  double sum = 0.0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector3d q = plane.homography * plane.coordinates[i].homogeneous();
    sum += (q.hnormalized() - pixels[i]).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(pixels.size()));
}

// Why each planar view is left out as fitting no image of a plane (nullopt: kept).
std::vector<std::optional<std::string>> ScrambledPlanarViews(const std::vector<CalibrationView>& views) {
  std::vector<std::optional<std::string>> why(views.size());
  std::vector<std::pair<size_t, double>> rms;
  for (size_t i = 0; i < views.size(); ++i) {
    const Spread spread = SpreadOf(views[i].points_in_world);
    if (Collinear(spread)) continue;
    if (const std::optional<PlanarView> plane = PlanarViewOf(views[i], spread)) {
      rms.emplace_back(i, HomographyRmsPx(*plane, views[i].pixels));
    }
  }
  if (rms.size() < 3) return why;
  std::vector<double> values;
  for (const auto& r : rms) values.push_back(r.second);
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double median = values[values.size() / 2];
  for (const auto& [i, value] : rms) {
    if (value > kScrambledHomographyPx && value > kScrambledHomographyFactor * median) {
      char numbers[96];
      std::snprintf(numbers, sizeof numbers, "%.3g px RMS, the views' median %.3g px", value, median);
      why[i] = std::string("its points fit no view of a plane: the best homography leaves ") +
               numbers + " (wrong or shuffled correspondences, or another board; "
                         "--keep-all-views keeps it)";
    }
  }
  return why;
}

// A planar view's pose from its homography and K (Zhang, section 3.1): K^-1 H = lambda [r1 r2 t]
// up to sign, the sign that puts the board's centroid in front; the rotation the nearest to
// [r1 r2 r1 x r2]. The refinement starts from it, as cv::calibrateCamera's does: it costs a 3x3
// SVD where SQPnP costs ~0.7 M instructions per view (bench --calibrate). std::nullopt when the
// centroid would sit on the image plane.
std::optional<internal::StartCamera> HomographyPose(const PlanarView& plane,
                                                    const Intrinsics& intrinsics) {
  Eigen::Matrix3d m = intrinsics.K().inverse() * plane.homography;
  const double scale = 2.0 / (m.col(0).norm() + m.col(1).norm());
  m *= m(2, 2) < 0.0 ? -scale : scale;
  if (!(m(2, 2) > 0.0)) return std::nullopt;
  Eigen::Matrix3d r;
  r << m.col(0), m.col(1), m.col(0).cross(m.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d cam_from_plane = svd.matrixU() * svd.matrixV().transpose();
  if (cam_from_plane.determinant() < 0.0) return std::nullopt;
  // point_in_cam = cam_from_plane * plane_from_world * (point_in_world - centroid) + t.
  internal::StartCamera start;
  start.rotation = cam_from_plane * plane.plane_from_world;
  start.center = plane.centroid - start.rotation.transpose() * m.col(2);
  start.intrinsics = intrinsics;
  return start;
}

// The fixed entries of the intrinsics: their values where the options fix them.
Intrinsics WithFixedEntries(Intrinsics intrinsics, const CalibrateOptions& options) {
  if (!options.principal_point_free) {
    intrinsics.cx = 0.5 * (options.image_size.width - 1);
    intrinsics.cy = 0.5 * (options.image_size.height - 1);
  }
  if (!options.aspect_free) intrinsics.fx = intrinsics.fy = std::sqrt(intrinsics.fx * intrinsics.fy);
  if (!options.skew_free) intrinsics.skew = 0.0;
  intrinsics.k1 = intrinsics.k2 = intrinsics.p1 = intrinsics.p2 = intrinsics.k3 = 0.0;
  return intrinsics;
}

// The closed-form intrinsics: Zhang's from the planar views when there are enough of them,
// else the median of the 3D views' DLT. std::nullopt when neither determines K.
std::optional<Intrinsics> StartIntrinsics(
    const std::vector<CalibrationView>& views,
    const std::vector<std::optional<PlanarView>>& planes,
    const CalibrateOptions& options) {
  const internal::ZhangModel model{options.aspect_free, options.principal_point_free,
                                   options.skew_free};
  std::vector<Eigen::Matrix3d> homographies;
  std::vector<double> fx, fy, cx, cy, skew;
  for (size_t i = 0; i < views.size(); ++i) {
    const CalibrationView& view = views[i];
    if (planes[i]) {
      homographies.push_back(planes[i]->homography);
      continue;
    }
    if (view.points_in_world.size() < 6) continue;
    // The DLT in a world centred and scaled to unit RMS distance (K does not change).
    const Eigen::Vector3d centroid = internal::Centroid(view.points_in_world);
    double sum_squares = 0.0;
    for (const auto& p : view.points_in_world) sum_squares += (p - centroid).squaredNorm();
    const double scale = std::sqrt(sum_squares / view.points_in_world.size());
    std::vector<Eigen::Vector3d> normalized;
    for (const auto& p : view.points_in_world) normalized.push_back((p - centroid) / scale);
    try {
      const internal::StartCamera start = internal::DltStart(normalized, view.pixels);
      fx.push_back(start.intrinsics.fx);
      fy.push_back(start.intrinsics.fy);
      cx.push_back(start.intrinsics.cx);
      cy.push_back(start.intrinsics.cy);
      skew.push_back(start.intrinsics.skew);
    } catch (const SceneError&) {
      // This view starts nothing; the refinement still uses it.
    }
  }
  if (!homographies.empty()) {
    if (auto zhang = internal::ZhangIntrinsics(homographies, options.image_size, model)) {
      return WithFixedEntries(*zhang, options);
    }
  }
  if (!fx.empty()) {
    Intrinsics intrinsics;
    intrinsics.fx = internal::Median(fx);
    intrinsics.fy = internal::Median(fy);
    intrinsics.cx = internal::Median(cx);
    intrinsics.cy = internal::Median(cy);
    intrinsics.skew = internal::Median(skew);
    return WithFixedEntries(intrinsics, options);
  }
  // Last: the principal point at the centre, square pixels, the focal length alone.
  if (!homographies.empty()) {
    if (auto focal = internal::ZhangIntrinsics(homographies, options.image_size, {false, false, false})) {
      return WithFixedEntries(*focal, options);
    }
  }
  return std::nullopt;
}

std::vector<int> FixedIntrinsicEntries(const CalibrateOptions& options) {
  std::vector<int> fixed;
  if (!options.aspect_free) fixed.push_back(kAspect);
  if (!options.principal_point_free) {
    fixed.push_back(kCx);
    fixed.push_back(kCy);
  }
  if (!options.skew_free) fixed.push_back(kSkew);
  if (options.num_radial < 1) fixed.push_back(kK1);
  if (options.num_radial < 2) fixed.push_back(kK2);
  if (!options.tangential_free) {
    fixed.push_back(kP1);
    fixed.push_back(kP2);
  }
  if (options.num_radial < 3) fixed.push_back(kK3);
  return fixed;
}

// The fit layout [f, aspect, cx, cy, skew, k1, k2] of intrinsics.
Eigen::Matrix<double, kFitIntrinsicsSize, 1> FitLayout(const Intrinsics& k) {
  Eigen::Matrix<double, kFitIntrinsicsSize, 1> p;
  p << k.fx, k.fy / k.fx, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3;
  return p;
}

Intrinsics FromFitLayout(const Eigen::Matrix<double, kFitIntrinsicsSize, 1>& p) {
  Intrinsics k;
  k.fx = p(0);
  k.fy = p(1) * p(0);
  k.cx = p(kCx);
  k.cy = p(kCy);
  k.skew = p(kSkew);
  k.k1 = p(kK1);
  k.k2 = p(kK2);
  k.p1 = p(kP1);
  k.p2 = p(kP2);
  k.k3 = p(kK3);
  return k;
}

// pixel_B(ray_A(pixel)): the pixel half B's camera gives the ray half A's camera sees at `pixel`.
// std::nullopt where A's lens folds before that pixel (no ray).
std::optional<Eigen::Vector2d> Transfer(const Intrinsics& a, const Intrinsics& b,
                                        const Eigen::Vector2d& pixel) {
  try {
    const Eigen::Vector3d ray = CamRayFromPixel(a, pixel);
    return PixelFromCam(b, ray);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

CrossValidation CrossValidate(const std::vector<CalibrationView>& views,
                              const CalibrateOptions& options) {
  CrossValidation cv;
  if (!options.compute_uncertainty) {
    cv.why_not = "needs the covariance (compute_uncertainty)";
    return cv;
  }
  if (views.size() < 4) {
    cv.why_not = "needs at least 4 views (2 per half), got " + std::to_string(views.size());
    return cv;
  }
  std::vector<CalibrationView> half[2];
  for (size_t i = 0; i < views.size(); ++i) half[i % 2].push_back(views[i]);
  CalibrateOptions half_options = options;
  half_options.cross_validate = false;
  Calibration c[2];
  for (int h = 0; h < 2; ++h) {
    try {
      c[h] = Calibrate(half[h], half_options);
    } catch (const SceneError& e) {
      cv.why_not = std::string(h == 0 ? "the even" : "the odd") + " views alone: " + e.what();
      return cv;
    }
  }
  cv.views_a = static_cast<int>(half[0].size());
  cv.views_b = static_cast<int>(half[1].size());
  const Eigen::Matrix<double, kFitIntrinsicsSize, 1> pa = FitLayout(c[0].intrinsics);
  const Eigen::Matrix<double, kFitIntrinsicsSize, 1> pb = FitLayout(c[1].intrinsics);
  constexpr int kGridX = 16, kGridY = 12;
  double sum_squares = 0.0, sum_predicted = 0.0;
  int count = 0;
  for (int gy = 0; gy < kGridY; ++gy) {
    for (int gx = 0; gx < kGridX; ++gx) {
      const Eigen::Vector2d pixel((options.image_size.width - 1) * gx / (kGridX - 1.0),
                                  (options.image_size.height - 1) * gy / (kGridY - 1.0));
      const std::optional<Eigen::Vector2d> moved = Transfer(c[0].intrinsics, c[1].intrinsics, pixel);
      if (!moved) continue;
      // d moved / d (each half's parameters) by central differences, steps relative to each
      // parameter's sigma (the covariance's scale, where the map is linear enough).
      Eigen::Matrix<double, 2, 2> predicted = Eigen::Matrix2d::Zero();
      bool ok = true;
      for (int h = 0; h < 2 && ok; ++h) {
        const Eigen::Matrix<double, kFitIntrinsicsSize, 1>& p = h == 0 ? pa : pb;
        const Eigen::Matrix<double, kFitIntrinsicsSize, kFitIntrinsicsSize>& cov =
            c[h].intrinsics_covariance;
        Eigen::Matrix<double, 2, kFitIntrinsicsSize> jacobian = Eigen::Matrix<double, 2, kFitIntrinsicsSize>::Zero();
        for (int j = 0; j < kFitIntrinsicsSize && ok; ++j) {
          const double sigma = std::sqrt(cov(j, j));
          if (!(sigma > 0.0)) continue;
          const double step = 1e-3 * sigma;
          // Half h's parameter j moved by +-step, the other half as calibrated.
          Intrinsics plus[2] = {c[0].intrinsics, c[1].intrinsics};
          Intrinsics minus[2] = {c[0].intrinsics, c[1].intrinsics};
          Eigen::Matrix<double, kFitIntrinsicsSize, 1> moved_p = p;
          moved_p(j) += step;
          plus[h] = FromFitLayout(moved_p);
          moved_p(j) -= 2.0 * step;
          minus[h] = FromFitLayout(moved_p);
          const auto up = Transfer(plus[0], plus[1], pixel);
          const auto down = Transfer(minus[0], minus[1], pixel);
          if (!up || !down) {
            ok = false;
            break;
          }
          jacobian.col(j) = (*up - *down) / (2.0 * step);
        }
        predicted += jacobian * cov * jacobian.transpose();
      }
      if (!ok) continue;
      const double distance = (*moved - pixel).norm();
      sum_squares += distance * distance;
      sum_predicted += predicted.trace();
      cv.max_px = std::max(cv.max_px, distance);
      ++count;
    }
  }
  if (count == 0) {
    cv.why_not = "no pixel of the grid has a ray in both halves' lenses";
    return cv;
  }
  cv.rms_px = std::sqrt(sum_squares / count);
  cv.predicted_rms_px = std::sqrt(sum_predicted / count);
  cv.done = true;
  return cv;
}

// The view that fits the shared camera worst, if it fits beyond the noise of the others: its sum
// of squares over the others' variance estimate s^2 = their sum / (their 2n - their share of
// the parameters), against chi-square with 2n - 6 degrees of freedom (its pose; its share of the
// shared intrinsics is small) at level 0.001 / views (Bonferroni over the views).
// Returns the view's index into result.views with the record.
std::optional<std::pair<size_t, RefusedView>> WorstInconsistentView(const Calibration& result,
                                                                    double sum_squares,
                                                                    int num_parameters) {
  const int num_views = static_cast<int>(result.views.size());
  const int shared = num_parameters - 6 * num_views;
  std::optional<std::pair<size_t, RefusedView>> worst;
  for (size_t index = 0; index < result.views.size(); ++index) {
    const CalibratedView& view = result.views[index];
    const double view_sum = view.rms_px * view.rms_px * view.num_points;
    const double others_dof = 2.0 * (result.num_points - view.num_points) - 6.0 * (num_views - 1) - shared;
    if (!(others_dof > 0.0)) continue;
    const double others_variance = (sum_squares - view_sum) / others_dof;
    if (!(others_variance > 0.0)) continue;
    const double dof = 2.0 * view.num_points - 6.0;
    if (!(dof > 0.0)) continue;
    const double statistic = view_sum / others_variance;
    const double bound = internal::ChiSquareQuantile(dof, 1.0 - 0.001 / num_views);
    if (statistic <= bound) continue;
    // And beyond kViewRmsFactor times the others' RMS: real views differ in noise (focus, blur)
    // by more than one Gaussian allows, which the chi-square test alone would refuse.
    const double others_rms = std::sqrt((sum_squares - view_sum) / (result.num_points - view.num_points));
    if (view.rms_px <= kViewRmsFactor * others_rms) continue;
    if (worst && statistic / bound <= worst->second.statistic / worst->second.bound) continue;
    RefusedView refused;
    refused.name = view.name;
    refused.num_points = view.num_points;
    refused.rms_px = view.rms_px;
    refused.others_rms_px = others_rms;
    refused.statistic = statistic;
    refused.bound = bound;
    worst = std::make_pair(index, refused);
  }
  return worst;
}


// What to do where the views do not determine the camera matrix: other tilts, or fix those of
// its entries the options still free (the advice named the principal point and the aspect also
// where both were fixed).
constexpr char kOtherTilts[] =
    "Add views of the board at other tilts (10-45 degrees, in different directions)";
std::string MoreTiltsOrFix(const CalibrateOptions& options) {
  const std::string tilts = kOtherTilts;
  if (options.principal_point_free && options.aspect_free) {
    return tilts + ", or fix the principal point and the aspect (--fix principal-point,aspect)";
  }
  if (options.principal_point_free) {
    return tilts + ", or fix the principal point (--fix principal-point)";
  }
  if (options.aspect_free) return tilts + ", or fix the aspect (--fix aspect)";
  return tilts;
}

// Throws SceneError unless the views can determine the free intrinsics: more equations than
// unknowns, and (planar views alone) no more of K's entries free than twice their number.
void CheckDetermined(const std::vector<CalibrationView>& views, int num_points,
                     int num_parameters, int free_intrinsics, int planar_views,
                     const CalibrateOptions& options) {
  if (2 * num_points <= num_parameters) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     std::to_string(num_points) + " points in " + std::to_string(views.size()) +
                         " views give " + std::to_string(2 * num_points) +
                         " equations for " + std::to_string(num_parameters) +
                         " unknowns (6 per view and " + std::to_string(free_intrinsics) +
                         " intrinsics)",
                     "Add views or points, or fix intrinsics");
  }
  // A plane's homography gives two constraints on K (Zhang): planar views alone determine at
  // most twice their number of K's entries, whatever distortion adds in theory.
  const int free_k_entries = 1 + (options.aspect_free ? 1 : 0) +
                             (options.principal_point_free ? 2 : 0) + (options.skew_free ? 1 : 0);
  if (planar_views == static_cast<int>(views.size()) && 2 * planar_views < free_k_entries) {
    throw SceneError(SceneError::Reason::kPlanarUnderdetermined,
                     std::to_string(planar_views) + " planar view" +
                         (planar_views == 1 ? " determines" : "s determine") + " at most " +
                         std::to_string(2 * planar_views) + " of the camera matrix's " +
                         std::to_string(free_k_entries) +
                         " free entries (a plane gives two constraints)",
                     MoreTiltsOrFix(options));
  }
}

// A joint fit stopped at its iteration cap is short of its minimum: where the views barely
// determine the model, LM crawls along a valley of cameras that fit about equally well (seen:
// the same view given twice, fx 13.6 +- 748 px for a true ~534; eight boards tilted 1 degree,
// fx 41028 +- 22982 px for 800, at 3x the noise's RMS). Never a calibration from there. A type
// of its own: the model selection holds groups of a richest model refused so
// (RichestCalibration), and of no other.
class Unconverged : public SceneError {
 public:
  explicit Unconverged(int iterations)
      : SceneError(Reason::kDegenerate,
                   internal::Concat("the joint refinement did not reach the minimum in ",
                                    iterations, " iterations: the views barely determine the "
                                    "model (boards nearly parallel to the image or to each "
                                    "other)"),
                   std::string(kOtherTilts) + ", or fix intrinsics (--fix, --model)") {}
};

// The views but the refused ones (by index) calibrated, their records first in refused_views.
Calibration CalibrateRest(const std::vector<CalibrationView>& views,
                          const std::vector<std::pair<size_t, RefusedView>>& refused,
                          const CalibrateOptions& options) {
  std::vector<CalibrationView> rest;
  for (size_t i = 0; i < views.size(); ++i) {
    const bool left_out = std::any_of(refused.begin(), refused.end(),
                                      [&](const auto& r) { return r.first == i; });
    if (!left_out) rest.push_back(views[i]);
  }
  Calibration calibration = Calibrate(rest, options);
  for (auto r = refused.rbegin(); r != refused.rend(); ++r) {
    calibration.refused_views.insert(calibration.refused_views.begin(), r->second);
  }
  return calibration;
}

// With views that cannot be used (why_not[i] set): the others calibrated, those named in
// refused_views with the reason; std::nullopt when every view can be used. Throws SceneError
// kDegenerate, naming the first, when none can.
std::optional<Calibration> CalibrateWithout(const std::vector<CalibrationView>& views,
                                            const std::vector<std::optional<std::string>>& why_not,
                                            const CalibrateOptions& options) {
  std::vector<std::pair<size_t, RefusedView>> refused;
  for (size_t i = 0; i < views.size(); ++i) {
    if (!why_not[i]) continue;
    RefusedView view;
    view.name = ViewName(views[i], i);
    view.reason = *why_not[i];
    view.num_points = static_cast<int>(views[i].pixels.size());
    refused.emplace_back(i, view);
  }
  if (refused.empty()) return std::nullopt;
  if (refused.size() == views.size()) {
    const RefusedView& first = refused.front().second;
    throw SceneError(SceneError::Reason::kDegenerate,
                     "no view can be used; " + first.name + ": " + first.reason,
                     "Check the views' correspondences, or add views");
  }
  return CalibrateRest(views, refused, options);
}

// A view's start pose with the start's K: from its homography if planar, else (or where that
// fails) by SQPnP; the reason when there is none.
std::optional<std::string> ViewStart(const CalibrationView& view,
                                     const std::optional<PlanarView>& plane,
                                     const Intrinsics& start, internal::StartCamera* camera) {
  if (auto from_homography = plane ? HomographyPose(*plane, start) : std::nullopt) {
    *camera = *from_homography;
    return std::nullopt;
  }
  if (internal::PnpStart(view.points_in_world, view.pixels, start, camera)) return std::nullopt;
  return std::string("no pose from its points with the start's intrinsics (SQPnP failed): check "
                     "its correspondences");
}

// The joint problem: a pose block per view (from ViewStart) and one block of the free intrinsics
// shared by all views.
struct JointProblem {
  std::vector<Eigen::Matrix3d> reference_rotations;  // each view's start
  std::vector<ViewFrame> frames;
  std::vector<std::array<double, kPoseSize>> poses;  // [w, c], see ViewCost
  IntrinsicsLayout k;                                 // every entry; free ones as of Solve
  std::vector<int> free_slots;
  std::vector<double> free_k;                         // the shared block
  ceres::Problem problem;

  JointProblem(const std::vector<CalibrationView>& views,
               const std::vector<internal::StartCamera>& starts, const Intrinsics& start,
               const std::vector<int>& fixed)
      : reference_rotations(views.size()), poses(views.size()), k(FitLayout(start)) {
    frames.reserve(views.size());  // the costs hold references to the frames' points
    for (const auto& view : views) frames.emplace_back(view.points_in_world);
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (std::find(fixed.begin(), fixed.end(), slot) == fixed.end()) {
        free_slots.push_back(slot);
        free_k.push_back(k(slot));
      }
    }
    for (size_t i = 0; i < views.size(); ++i) {
      const internal::StartCamera& camera = starts[i];
      reference_rotations[i] = camera.rotation;
      const Eigen::Vector3d center = frames[i].InFrame(camera.center);
      poses[i] = {0.0, 0.0, 0.0, center.x(), center.y(), center.z()};
      problem.AddResidualBlock(
          new ViewCost(views[i], frames[i], reference_rotations[i], k, free_slots), nullptr,
          poses[i].data(), free_k.data());
    }
  }

  Eigen::Matrix3d CamFromWorldRotation(size_t view) const {
    Eigen::Matrix3d exp_w;
    ExpWithLeftJacobian(poses[view].data(), &exp_w, nullptr);
    return exp_w * reference_rotations[view];
  }
  Eigen::Vector3d CenterInFrame(size_t view) const {
    return Eigen::Vector3d(poses[view][3], poses[view][4], poses[view][5]);
  }

  // DENSE_SCHUR with the poses eliminated first; throws kNumerical when Ceres fails.
  ceres::Solver::Summary Solve(const CalibrateOptions& options) {
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_SCHUR;
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (auto& pose : poses) ordering->AddElementToGroup(pose.data(), 0);
    ordering->AddElementToGroup(free_k.data(), 1);
    solver_options.linear_solver_ordering = ordering;
    solver_options.max_num_iterations = options.max_iterations;
    solver_options.function_tolerance = options.function_tolerance;
    solver_options.gradient_tolerance = options.gradient_tolerance;
    solver_options.parameter_tolerance = options.parameter_tolerance;
    solver_options.num_threads = 1;
    // The closed-form start is near the optimum: LM's first steps need little damping. Ceres'
    // default radius 1e4 damped them for an iteration or two more (callgrind, bench --calibrate
    // at 5 views: 11 % fewer instructions at 1e6, the same optimum; 1e8 and 1e12 no better).
    solver_options.initial_trust_region_radius = 1e6;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    for (size_t i = 0; i < free_slots.size(); ++i) k(free_slots[i]) = free_k[i];
    if (summary.termination_type == ceres::FAILURE &&
        summary.message.find("Residual and Jacobian evaluation failed") != std::string::npos) {
      // A residual block refused its point: behind its view's camera from the start (a view
      // whose correspondences fit no camera), not a numerical failure.
      throw SceneError(SceneError::Reason::kDegenerate,
                       "the joint refinement cannot start: points of a view are behind its "
                       "start camera (a view whose correspondences fit no camera)",
                       "Check the views' correspondences, or leave out --keep-all-views so that "
                       "such a view is left out by name");
    }
    if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost)) {
      throw SceneError(SceneError::Reason::kNumerical,
                       "the joint refinement failed: " + summary.message,
                       internal::kReportNumericalFailure);
    }
    return summary;
  }
};

// Each view's camera, RMS and depth range at the joint optimum; returns the sum of squares over
// every view.
double AssembleViews(const std::vector<CalibrationView>& views, const JointProblem& joint,
                     const CalibrateOptions& options, Calibration* result,
                     std::vector<std::vector<double>>* residual_norms) {
  residual_norms->assign(views.size(), {});
  double sum_squares = 0.0;
  for (size_t i = 0; i < views.size(); ++i) {
    const ViewFrame& frame = joint.frames[i];
    const Eigen::Matrix3d rotation = joint.CamFromWorldRotation(i);
    const Eigen::Vector3d center = joint.CenterInFrame(i);
    CalibratedView view;
    view.name = ViewName(views[i], i);
    view.camera.image_size = options.image_size;
    view.camera.intrinsics = result->intrinsics;
    view.camera.cam_from_world = CamFromWorldFromCenter(rotation, frame.InWorld(center));
    view.num_points = static_cast<int>(views[i].pixels.size());
    double view_sum = 0.0;
    double min_depth = std::numeric_limits<double>::infinity(), max_depth = 0.0;
    for (size_t j = 0; j < views[i].pixels.size(); ++j) {
      double residual[2];
      // In the frame's unit: the pixel as the joint fit saw it (scaling the unit out is exact).
      const Eigen::Vector3d point_in_cam = rotation * (frame.points[j] - center);
      if (!(point_in_cam.z() > 0.0)) {
        throw SceneError(SceneError::Reason::kPointsBehindCamera,
                         view.name + ": point " + std::to_string(j + 1) +
                             " is behind the calibrated camera",
                         "Check that view's correspondences (ids, order)");
      }
      internal::ResidualOfCamPoint(joint.k.data(), point_in_cam, views[i].pixels[j], residual,
                                   nullptr, nullptr);
      view_sum += residual[0] * residual[0] + residual[1] * residual[1];
      (*residual_norms)[i].push_back(std::hypot(residual[0], residual[1]));
      min_depth = std::min(min_depth, frame.unit * point_in_cam.z());
      max_depth = std::max(max_depth, frame.unit * point_in_cam.z());
    }
    view.camera.z_near = min_depth / (1.0 + kDepthMargin);
    view.camera.z_far = max_depth * (1.0 + kDepthMargin);
    view.rms_px = std::sqrt(view_sum / view.num_points);
    sum_squares += view_sum;
    result->views.push_back(view);
  }
  return sum_squares;
}

// A view may lose at most this share of its points as outliers; beyond it the view as a whole
// does not fit (wrong correspondences, another camera) and is the view refusal's question.
constexpr double kMaxOutlierShare = 0.3;
// Familywise level of the outlier bound over all points.
constexpr double kOutlierLevel = 0.001;

// Each view's outlier bound (CalibrateOptions::remove_outliers): |r| of a 2D Gaussian residual is
// Rayleigh(sigma), with median sigma sqrt(2 ln 2) and P(|r| > b) = exp(-b^2 / (2 sigma^2));
// sigma the larger of the view's own (from its median: real views differ in noise, OpenCV's left
// chessboards 0.15 to 0.47 px RMS, and one sigma for all would cut the noisy views' ordinary
// points) and all views' together (a view's median of 30-54 points is ~10 % uncertain, and a
// low draw would cut a good point: seen at 30 points, 1.28 px against a bound of 1.28), b at
// level kOutlierLevel over all N points.
std::vector<double> OutlierBounds(const std::vector<std::vector<double>>& residual_norms) {
  std::vector<double> all;
  for (const auto& norms : residual_norms) all.insert(all.end(), norms.begin(), norms.end());
  const double rayleigh_median = std::sqrt(2.0 * std::log(2.0));
  const double pooled_sigma = std::max(kMinNoisePx, internal::Median(all) / rayleigh_median);
  const double quantile = std::sqrt(2.0 * std::log(static_cast<double>(all.size()) / kOutlierLevel));
  std::vector<double> bounds;
  for (const auto& norms : residual_norms) {
    bounds.push_back(std::max(pooled_sigma, internal::Median(norms) / rayleigh_median) * quantile);
  }
  return bounds;
}

// The view with the points keep(index, id) accepts, each with its id (CalibrationView::ids, or its
// 1-based number in the view when it has none), so that ids stay the file's through removals.
template <typename Keep>
CalibrationView ViewKeeping(const CalibrationView& view, Keep keep) {
  CalibrationView kept{view.name, {}, {}, {}};
  for (size_t j = 0; j < view.pixels.size(); ++j) {
    const std::string id = view.ids.empty() ? std::to_string(j + 1) : view.ids[j];
    if (!keep(j, id)) continue;
    kept.points_in_world.push_back(view.points_in_world[j]);
    kept.pixels.push_back(view.pixels[j]);
    kept.ids.push_back(id);
  }
  return kept;
}

// The views without the points beyond `bound`, or std::nullopt when there are none; the points
// left out into *outliers.
std::optional<std::vector<CalibrationView>> WithoutOutliers(
    const std::vector<CalibrationView>& views,
    const std::vector<std::vector<double>>& residual_norms, const std::vector<double>& bounds,
    std::vector<OutlierPoint>* outliers) {
  std::vector<CalibrationView> cleaned;
  bool any = false;
  for (size_t i = 0; i < views.size(); ++i) {
    const std::vector<double>& norms = residual_norms[i];
    const double bound = bounds[i];
    const auto beyond = std::count_if(norms.begin(), norms.end(), [&](double r) { return r > bound; });
    const size_t kept_points = norms.size() - static_cast<size_t>(beyond);
    if (beyond == 0 || beyond > kMaxOutlierShare * norms.size() || kept_points < 4) {
      cleaned.push_back(views[i]);
      continue;
    }
    any = true;
    cleaned.push_back(ViewKeeping(views[i], [&](size_t j, const std::string& id) {
      if (norms[j] <= bound) return true;
      outliers->push_back({ViewName(views[i], i), id, norms[j], bound});
      return false;
    }));
  }
  if (!any) return std::nullopt;
  return cleaned;
}

// The view stage: the view that does not fit the camera the others share
// (WorstInconsistentView) refused and the rest calibrated; std::nullopt when there is none, or
// when the rest alone cannot determine the camera (every view kept: its RMS shows it). With the
// point stage on, a view whose misfit is a few points — its median |r| within kViewRmsFactor of
// the other views' (pooled), though its RMS is not — is kept for that stage instead.
std::optional<Calibration> WithoutWorstView(const std::vector<CalibrationView>& views,
                                            const Calibration& result, double sum_squares,
                                            const std::vector<std::vector<double>>& residual_norms,
                                            const CalibrateOptions& options) {
  const auto refused = WorstInconsistentView(result, sum_squares, result.num_parameters);
  if (!refused) return std::nullopt;
  if (options.remove_outliers) {
    std::vector<double> others;
    for (size_t i = 0; i < views.size(); ++i) {
      if (i != refused->first) {
        others.insert(others.end(), residual_norms[i].begin(), residual_norms[i].end());
      }
    }
    if (internal::Median(residual_norms[refused->first]) <=
        kViewRmsFactor * internal::Median(others)) {
      return std::nullopt;
    }
  }
  try {
    return CalibrateRest(views, {*refused}, options);
  } catch (const SceneError&) {
    return std::nullopt;
  }
}

// The point stage: the points beyond their view's bound left out and the rest calibrated, once
// (bounds taken again without them would be tighter and peel further: measured on the
// chessboards, 4 rounds, every point at a board's edge column); std::nullopt when there are none.
std::optional<Calibration> WithoutOutlierPoints(
    const std::vector<CalibrationView>& views,
    const std::vector<std::vector<double>>& residual_norms, const CalibrateOptions& options) {
  std::vector<OutlierPoint> outliers;
  const auto cleaned =
      WithoutOutliers(views, residual_norms, OutlierBounds(residual_norms), &outliers);
  if (!cleaned) return std::nullopt;
  CalibrateOptions rest_options = options;
  rest_options.remove_outliers = false;
  Calibration rest = Calibrate(*cleaned, rest_options);
  if (!rest.refused_views.empty()) {
    // A view refused only once points were left out (its median fit, so the view stage had
    // deferred to this one) bent the fit those points were judged against: judge them again
    // without it (seen: two swapped rows of a board among 10 good ones cost 5 good points
    // elsewhere, fx 0.42 px from the good views' own calibration; CalibrateTest.
    // ViewsThatDoNotFitAreRefusedByName at seed offset 6000). `cleaned` keeps every view in
    // place, so a refused view's name is that of the view at the same index here.
    std::vector<std::pair<size_t, RefusedView>> refused;
    for (const RefusedView& view : rest.refused_views) {
      for (size_t i = 0; i < views.size(); ++i) {
        if (ViewName(views[i], i) == view.name) refused.emplace_back(i, view);
      }
    }
    if (refused.size() == rest.refused_views.size()) {
      try {
        return CalibrateRest(views, refused, options);
      } catch (const SceneError&) {
        // The rest alone cannot determine the camera: keep the calibration as it stands.
      }
    }
  }
  rest.outliers.insert(rest.outliers.begin(), outliers.begin(), outliers.end());
  return rest;
}

// The intrinsics' covariance (scaled by s^2) and the sigmas of the free ones into *result.
void AddUncertainty(JointProblem& joint, double sum_squares, const CalibrateOptions& options,
                    Calibration* result) {
  ceres::Covariance::Options covariance_options;
  // SPARSE_QR fails on a rank-deficient Jacobian: refused below, never pseudo-inverted. (DENSE_SVD
  // decomposes the whole 2N x (6 views + 7) Jacobian: 1.2 s at 50 views, bench --calibrate.)
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  const double* free_k = joint.free_k.data();
  const std::vector<std::pair<const double*, const double*>> blocks = {{free_k, free_k}};
  if (!covariance.Compute(blocks, &joint.problem)) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the views do not determine every free intrinsic (the covariance is "
                     "singular)",
                     "Add views at other angles, or fix the principal point, the aspect or the "
                     "distortion");
  }
  const int num_free = static_cast<int>(joint.free_slots.size());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> free_c(num_free, num_free);
  covariance.GetCovarianceBlock(free_k, free_k, free_c.data());
  Eigen::Matrix<double, kFitIntrinsicsSize, kFitIntrinsicsSize> c =
      Eigen::Matrix<double, kFitIntrinsicsSize, kFitIntrinsicsSize>::Zero();
  for (int a = 0; a < num_free; ++a) {
    for (int b = 0; b < num_free; ++b) c(joint.free_slots[a], joint.free_slots[b]) = free_c(a, b);
  }
  const double* k = joint.k.data();
  c *= sum_squares / (2.0 * result->num_points - result->num_parameters);
  result->intrinsics_covariance = c;
  auto add = [&](const std::string& name, double value, double variance, const std::string& unit) {
    result->intrinsics_sigma.push_back({name, value, std::sqrt(std::max(variance, 0.0)), unit});
  };
  add("fx", k[0], c(0, 0), "px");
  if (options.aspect_free) {
    // fy = aspect * f: its gradient in (f, aspect) is (aspect, f).
    const Eigen::Vector2d g(k[kAspect], k[0]);
    add("fy", result->intrinsics.fy, g.dot(c.topLeftCorner<2, 2>() * g), "px");
  }
  if (options.principal_point_free) {
    add("cx", k[kCx], c(kCx, kCx), "px");
    add("cy", k[kCy], c(kCy, kCy), "px");
  }
  if (options.skew_free) add("skew", k[kSkew], c(kSkew, kSkew), "px");
  if (options.num_radial >= 1) add("k1", k[kK1], c(kK1, kK1), "");
  if (options.num_radial >= 2) add("k2", k[kK2], c(kK2, kK2), "");
  if (options.tangential_free) {
    add("p1", k[kP1], c(kP1, kP1), "");
    add("p2", k[kP2], c(kP2, kP2), "");
  }
  if (options.num_radial >= 3) add("k3", k[kK3], c(kK3, kK3), "");

  // The covariance in the image: the pixel of the ray through each place, moved by the
  // intrinsics' uncertainty.
  auto projection_sigma = [&](const Eigen::Vector2d& pixel) {
    const Eigen::Vector3d ray = CamRayFromPixel(result->intrinsics, pixel);
    double residual[2];
    Eigen::Matrix<double, 2, kFitIntrinsicsSize, Eigen::RowMajor> jacobian;
    internal::ResidualOfCamPoint(k, ray, pixel, residual, jacobian.data(), nullptr);
    return std::sqrt(std::max(0.0, (jacobian * c * jacobian.transpose()).trace()));
  };
  const double w = options.image_size.width, h = options.image_size.height;
  result->projection_sigma_center_px = projection_sigma({0.5 * (w - 1.0), 0.5 * (h - 1.0)});
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
                                       Eigen::Vector2d(-0.5, h - 0.5),
                                       Eigen::Vector2d(w - 0.5, h - 0.5)}) {
    try {
      result->projection_sigma_corner_px =
          std::max(result->projection_sigma_corner_px, projection_sigma(corner));
    } catch (const std::domain_error&) {
      // Beyond the lens's fold: no ray there.
    }
  }
}

}  // namespace

namespace {

// The ladder's groups in their order (SelectCalibrationModel): whether `o` frees the group, how
// to free it, and the group it needs first.
struct LadderGroup {
  const char* name;
  const char* needs;  // nullptr or the group that must be free first
  bool (*is_free)(const CalibrateOptions& o);
  void (*free)(CalibrateOptions* o);
  void (*hold)(CalibrateOptions* o);  // the reverse of free (and what needs it held too)
};

const LadderGroup kLadder[] = {
    {"principal-point", nullptr, [](const CalibrateOptions& o) { return o.principal_point_free; },
     [](CalibrateOptions* o) { o->principal_point_free = true; },
     [](CalibrateOptions* o) { o->principal_point_free = false; }},
    {"aspect", nullptr, [](const CalibrateOptions& o) { return o.aspect_free; },
     [](CalibrateOptions* o) { o->aspect_free = true; },
     [](CalibrateOptions* o) { o->aspect_free = false; }},
    {"skew", nullptr, [](const CalibrateOptions& o) { return o.skew_free; },
     [](CalibrateOptions* o) { o->skew_free = true; },
     [](CalibrateOptions* o) { o->skew_free = false; }},
    {"k1", nullptr, [](const CalibrateOptions& o) { return o.num_radial >= 1; },
     [](CalibrateOptions* o) { o->num_radial = std::max(o->num_radial, 1); },
     [](CalibrateOptions* o) { o->num_radial = 0; }},
    {"k2", "k1", [](const CalibrateOptions& o) { return o.num_radial >= 2; },
     [](CalibrateOptions* o) { o->num_radial = std::max(o->num_radial, 2); },
     [](CalibrateOptions* o) { o->num_radial = std::min(o->num_radial, 1); }},
    {"tangential", nullptr, [](const CalibrateOptions& o) { return o.tangential_free; },
     [](CalibrateOptions* o) { o->tangential_free = true; },
     [](CalibrateOptions* o) { o->tangential_free = false; }},
    {"k3", "k2", [](const CalibrateOptions& o) { return o.num_radial >= 3; },
     [](CalibrateOptions* o) { o->num_radial = std::max(o->num_radial, 3); },
     [](CalibrateOptions* o) { o->num_radial = std::min(o->num_radial, 2); }},
};

// The richest model `options` allow that the views determine, calibrated: every group free,
// else groups held from the top of the ladder (k3 first) while its calibration does not converge
// (a model the views barely determine: boards nearly parallel to the image with the lens free).
// Rethrows the richest model's refusal where none is left to hold.
Calibration RichestCalibration(const std::vector<CalibrationView>& views,
                               const CalibrateOptions& options) {
  CalibrateOptions trial = options;
  std::optional<Unconverged> refusal;
  for (auto group = std::rbegin(kLadder);; ++group) {
    try {
      return Calibrate(views, trial);
    } catch (const Unconverged& e) {
      if (!refusal) refusal = e;
    }
    while (group != std::rend(kLadder) && !group->is_free(trial)) ++group;
    if (group == std::rend(kLadder)) throw *refusal;
    group->hold(&trial);
  }
}

const LadderGroup* FindGroup(const std::string& name) {
  for (const LadderGroup& group : kLadder) {
    if (name == group.name) return &group;
  }
  return nullptr;
}

bool IsFreeIn(const char* group_name, const CalibrateOptions& options) {
  const LadderGroup* group = FindGroup(group_name);
  return group && group->is_free(options);
}

// "+1.234" / "-1.234".
std::string Signed(double value) {
  std::ostringstream text;
  text.precision(1);
  text << std::fixed << std::showpos << value;
  return text.str();
}

}  // namespace

CalibrateOptions CalibrateOptionsForModel(const std::string& model,
                                          const std::vector<std::string>& fixed) {
  const bool automatic = model == "auto";
  const bool opencv = model == "opencv";
  std::vector<std::string> groups;
  if (automatic || opencv) {
    // Every ladder group but skew: sensors have square grids, and a fitted skew takes up other
    // model errors (the left chessboards: 0.39 +- 0.12 px at BIC -4.3, docs/calibration.md).
    for (const LadderGroup& group : kLadder) {
      if (std::string(group.name) != "skew") groups.push_back(group.name);
    }
  } else {
    std::stringstream list(model);
    for (std::string group; std::getline(list, group, '+');) {
      if (std::find(groups.begin(), groups.end(), group) != groups.end()) {
        throw std::invalid_argument("group \"" + group + "\" is named twice in \"" + model + "\"");
      }
      groups.push_back(group);
    }
  }
  auto listed = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  const std::string kGroups = "groups among principal-point, aspect, skew, k1, k2, tangential, k3";
  for (const std::string& name : fixed) {
    if (!FindGroup(name)) {
      throw std::invalid_argument("unknown group \"" + name + "\" to fix; expected " + kGroups);
    }
  }
  // A fixed group holds every group that needs it: k1 holds k2 and k3, k2 holds k3.
  auto is_fixed = [&](const LadderGroup& group) {
    for (const LadderGroup* g = &group; g; g = g->needs ? FindGroup(g->needs) : nullptr) {
      if (listed(fixed, g->name)) return true;
    }
    return false;
  };
  CalibrateOptions options;
  options.select_model = automatic;
  options.aspect_free = options.principal_point_free = options.skew_free = false;
  options.tangential_free = false;
  options.num_radial = 0;
  for (const std::string& name : groups) {
    if (name == "focal") continue;  // always free
    const LadderGroup* group = FindGroup(name);
    if (!group) {
      throw std::invalid_argument("unknown group \"" + name + "\"; expected auto, opencv or " +
                                  kGroups + " joined by '+'");
    }
    if (is_fixed(*group)) {
      if (automatic) continue;  // not a candidate
      throw std::invalid_argument(name + " is both freed and fixed");
    }
    if (group->needs && !automatic && !opencv && !listed(groups, group->needs)) {
      throw std::invalid_argument(name + " needs " + group->needs + " too");
    }
    group->free(&options);
  }
  return options;
}

CalibrateOptions SelectCalibrationModel(const std::vector<CalibrationView>& views,
                                        const CalibrateOptions& options,
                                        std::vector<CalibrationModelChoice>* choice,
                                        double* sigma_px) {
  options.Check();
  CalibrateOptions quiet = options;
  quiet.select_model = false;
  quiet.compute_uncertainty = false;
  quiet.cross_validate = false;
  // The richest model the options allow and the views determine: the views it keeps, and the
  // noise they show.
  const Calibration richest = RichestCalibration(views, quiet);
  std::vector<CalibrationView> kept;
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string name = ViewName(views[i], i);
    const bool refused = std::any_of(richest.refused_views.begin(), richest.refused_views.end(),
                                     [&](const RefusedView& r) { return r.name == name; });
    if (refused) continue;
    // Without the points the richest model left out.
    kept.push_back(ViewKeeping(views[i], [&](size_t, const std::string& id) {
      return std::none_of(richest.outliers.begin(), richest.outliers.end(),
                          [&](const OutlierPoint& o) { return o.view == name && o.id == id; });
    }));
  }
  auto sum_squares = [](const Calibration& c) { return c.rms_px * c.rms_px * c.num_points; };
  const double sigma =
      options.pixel_sigma > 0.0
          ? options.pixel_sigma
          : std::max(kMinNoisePx, std::sqrt(sum_squares(richest) /
                                            (2.0 * richest.num_points - richest.num_parameters)));
  const double log_2n = std::log(2.0 * richest.num_points);
  auto bic = [&](const Calibration& c) {
    return sum_squares(c) / (sigma * sigma) + c.num_parameters * log_2n;
  };

  // From the focal length alone, one group per round.
  quiet.refuse_inconsistent_views = false;
  quiet.remove_outliers = false;
  CalibrateOptions current = quiet;
  current.principal_point_free = current.aspect_free = current.skew_free = false;
  current.tangential_free = false;
  current.num_radial = 0;
  Calibration current_fit = Calibrate(kept, current);
  std::map<std::string, std::string> reasons;
  while (true) {
    const LadderGroup* best = nullptr;
    Calibration best_fit;
    CalibrateOptions best_options;
    for (const LadderGroup& group : kLadder) {
      if (!group.is_free(options) || group.is_free(current)) continue;
      if (group.needs != nullptr && !IsFreeIn(group.needs, current)) {
        reasons[group.name] = std::string("left out: needs ") + group.needs + " first";
        continue;
      }
      CalibrateOptions trial = current;
      group.free(&trial);
      try {
        Calibration fit = Calibrate(kept, trial);
        const double change = bic(fit) - bic(current_fit);
        const int added = fit.num_parameters - current_fit.num_parameters;
        reasons[group.name] =
            "left out: BIC " + Signed(change) + " if freed (J / sigma^2 falls by " +
            Signed((sum_squares(current_fit) - sum_squares(fit)) / (sigma * sigma)).substr(1) +
            " for " + std::to_string(added) + " more parameter" + (added == 1 ? "" : "s") +
            " at ln 2N = " + Signed(log_2n).substr(1) + " each)";
        if (change < 0.0 && (best == nullptr || bic(fit) < bic(best_fit))) {
          best = &group;
          best_fit = std::move(fit);
          best_options = trial;
        }
      } catch (const SceneError& e) {
        reasons[group.name] = std::string("left out: not determined (") + e.why() + ")";
      }
    }
    if (best == nullptr) break;
    reasons[best->name] = "freed: BIC " + Signed(bic(best_fit) - bic(current_fit));
    current = best_options;
    current_fit = std::move(best_fit);
  }

  choice->clear();
  for (const LadderGroup& group : kLadder) {
    CalibrationModelChoice entry;
    entry.group = group.name;
    entry.free = group.is_free(current);
    entry.reason = group.is_free(options) ? reasons[group.name]
                                          : "not a candidate (held by the options)";
    choice->push_back(entry);
  }
  *sigma_px = sigma;
  CalibrateOptions chosen = options;
  chosen.select_model = false;
  chosen.principal_point_free = current.principal_point_free;
  chosen.aspect_free = current.aspect_free;
  chosen.skew_free = current.skew_free;
  chosen.tangential_free = current.tangential_free;
  chosen.num_radial = current.num_radial;
  return chosen;
}

Calibration Calibrate(const std::vector<CalibrationView>& views, const CalibrateOptions& options) {
  options.Check();
  if (views.empty()) throw std::invalid_argument("Calibrate needs at least one view");
  for (size_t i = 0; i < views.size(); ++i) CheckView(views[i], i);
  CheckNoViewRepeated(views);
  CheckPixelsInImage(views, options.image_size);
  // Before the model selection, whose fits would carry such a view (they do not refuse views).
  if (options.refuse_inconsistent_views) {
    if (auto rest = CalibrateWithout(views, ScrambledPlanarViews(views), options)) return *rest;
  }
  if (options.select_model) {
    std::vector<CalibrationModelChoice> choice;
    double sigma = 0.0;
    const CalibrateOptions chosen = SelectCalibrationModel(views, options, &choice, &sigma);
    Calibration result = Calibrate(views, chosen);
    result.model_choice = std::move(choice);
    result.selection_sigma_px = sigma;
    result.selection_sigma_given = options.pixel_sigma > 0.0;
    return result;
  }

  // A view whose points lie on a line has no pose: left out by name before it enters the
  // closed-form start (its homography is degenerate), the rest calibrated.
  std::vector<Spread> spreads;
  std::vector<std::optional<std::string>> collinear(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    spreads.push_back(SpreadOf(views[i].points_in_world));
    if (Collinear(spreads[i])) {
      collinear[i] = "its points lie on a line: no pose (a view needs points spanning a plane or "
                     "a volume)";
    }
  }
  if (auto rest = CalibrateWithout(views, collinear, options)) return *rest;

  const std::vector<int> fixed = FixedIntrinsicEntries(options);
  const int free_intrinsics = kFitIntrinsicsSize - static_cast<int>(fixed.size());
  int num_points = 0;
  for (const auto& view : views) num_points += static_cast<int>(view.pixels.size());
  const int num_parameters = 6 * static_cast<int>(views.size()) + free_intrinsics;
  std::vector<std::optional<PlanarView>> planes;
  int planar_views = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    planes.push_back(PlanarViewOf(views[i], spreads[i]));
    planar_views += planes.back() ? 1 : 0;
  }
  CheckDetermined(views, num_points, num_parameters, free_intrinsics, planar_views, options);

  const std::optional<Intrinsics> start = StartIntrinsics(views, planes, options);
  if (!start) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the views do not determine the intrinsics in closed form (planar boards "
                     "need at least 2-3 views at different tilts; a 3D view at least 6 points)",
                     MoreTiltsOrFix(options));
  }
  // Views without a start pose are left out by name and the rest calibrated.
  std::vector<internal::StartCamera> starts(views.size());
  std::vector<std::optional<std::string>> unstarted(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    unstarted[i] = ViewStart(views[i], planes[i], *start, &starts[i]);
  }
  if (auto rest = CalibrateWithout(views, unstarted, options)) return *rest;
  JointProblem joint(views, starts, *start, fixed);
  const ceres::Solver::Summary summary = joint.Solve(options);

  Calibration result;
  result.image_size = options.image_size;
  result.start = *start;
  result.intrinsics = FromFitLayout(joint.k);
  result.num_points = num_points;
  result.num_parameters = num_parameters;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.termination = summary.message;
  std::vector<std::vector<double>> residual_norms;
  const double sum_squares = AssembleViews(views, joint, options, &result, &residual_norms);
  result.rms_px = std::sqrt(sum_squares / num_points);

  // Views first: a view that does not fit bends the joint fit, and points of good views would
  // be left out for it.
  if (options.refuse_inconsistent_views && views.size() >= 4) {
    if (auto rest = WithoutWorstView(views, result, sum_squares, residual_norms, options)) {
      return *rest;
    }
  }
  if (options.remove_outliers) {
    if (auto rest = WithoutOutlierPoints(views, residual_norms, options)) return *rest;
  }
  // Only now: a view or points that do not fit can keep the joint fit from settling, and the
  // calibration without them (above) is judged by its own call.
  if (summary.termination_type == ceres::NO_CONVERGENCE) throw Unconverged(options.max_iterations);
  if (options.compute_uncertainty) AddUncertainty(joint, sum_squares, options, &result);
  if (options.cross_validate) result.cross_validation = CrossValidate(views, options);
  return result;
}

}  // namespace camproj

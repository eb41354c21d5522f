#include "camproj/synth.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "check.h"

namespace camproj {

using internal::Require;

namespace {

constexpr double kPi = 3.14159265358979323846;
// A box face is used where it faces the eye at more than this cosine from its normal (84
// degrees): a face seen edge-on squeezes its points onto a line in the image.
constexpr double kMinFaceCosine = 0.1;

// Uniform and standard normal draws from the raw 64-bit engine, so the numbers do not depend on
// the standard library's distribution implementations.
double Uniform01(std::mt19937_64& rng) { return (rng() >> 11) * 0x1.0p-53; }
double Uniform(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * Uniform01(rng); }
double Normal(std::mt19937_64& rng) {
  // Box-Muller; 1 - u keeps the logarithm finite.
  const double u = 1.0 - Uniform01(rng);
  const double v = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * v);
}

// Vectors of independent draws, drawn last coordinate first. C++ leaves the order in which a
// call's arguments are evaluated unspecified (GCC goes right to left, clang left to right), so
// Vector3d(Uniform(rng, ...), ...) would make another scene from the same seed with another
// compiler; last-first is the order the files written so far (GCC) were drawn in.
Eigen::Vector3d UniformVector3(std::mt19937_64& rng, double lo, double hi) {
  const double z = Uniform(rng, lo, hi);
  const double y = Uniform(rng, lo, hi);
  const double x = Uniform(rng, lo, hi);
  return {x, y, z};
}
Eigen::Vector2d NormalVector2(std::mt19937_64& rng) {
  const double y = Normal(rng);
  const double x = Normal(rng);
  return {x, y};
}

}  // namespace

void SynthOptions::Check() const {
  Require(num_points >= 1 && num_points <= 100000000, "points must be in [1, 1e8], got ", num_points);
  Require(std::isfinite(noise_px) && noise_px >= 0.0, "noise must be >= 0 px, got ", noise_px);
  image_size.Check();
  Require(std::isfinite(fovy_deg) && fovy_deg > 0.0 && fovy_deg < 180.0,
          "fovy must be in (0, 180) degrees, got ", fovy_deg);
  Require(principal_point_offset.allFinite() && principal_point_offset.cwiseAbs().maxCoeff() <= 2.0,
          "principal point offset must be within +-2 image sizes, got ",
          principal_point_offset.transpose());
  Require(std::isfinite(aspect) && aspect > 0.0, "aspect must be positive, got ", aspect);
  Require(std::isfinite(object_size) && object_size > 0.0, "object size must be positive, got ",
          object_size);
}

SynthObject SynthObjectFromString(const std::string& text) {
  if (text == "cloud") return SynthObject::kCloud;
  if (text == "box") return SynthObject::kBox;
  if (text == "plane") return SynthObject::kPlane;
  throw std::invalid_argument("object must be cloud, box or plane, got \"" + text + "\"");
}

// A point on a face of the box with half extents `half`, and that face's outward normal.
Eigen::Vector3d DrawBoxPoint(std::mt19937_64& rng, const Eigen::Vector3d& half,
                             Eigen::Vector3d* normal) {
  Eigen::Vector3d x = UniformVector3(rng, -1, 1);
  const int axis = static_cast<int>(rng() % 3);
  x[axis] = x[axis] < 0 ? -1.0 : 1.0;
  *normal = Eigen::Vector3d::Zero();
  (*normal)[axis] = x[axis];
  return x.cwiseProduct(half);
}

// Whether the eye sees the face with this outward normal at more than kMinFaceCosine from its
// centre (then every point of the face is in front of it).
bool FaceSeen(const Eigen::Vector3d& normal, const Eigen::Vector3d& half,
              const Eigen::Vector3d& eye) {
  const Eigen::Vector3d to_eye = eye - normal.cwiseProduct(half);
  return normal.dot(to_eye) > kMinFaceCosine * to_eye.norm();
}

SynthScene SynthesizeScene(const SynthOptions& options) {
  options.Check();
  std::mt19937_64 rng(options.seed);
  const ImageSize& size = options.image_size;
  Intrinsics k;
  k.fy = 0.5 * size.height / std::tan(0.5 * options.fovy_deg * kPi / 180.0);
  k.fx = k.fy / options.aspect;
  k.cx = 0.5 * (size.width - 1) + options.principal_point_offset.x() * size.width;
  k.cy = 0.5 * (size.height - 1) + options.principal_point_offset.y() * size.height;

  // Viewing direction: azimuth all round, elevation 15..45 degrees above the object (y up).
  const double azimuth = Uniform(rng, 0.0, 2.0 * kPi);
  const double elevation = Uniform(rng, 15.0, 45.0) * kPi / 180.0;
  const Eigen::Vector3d to_eye(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                               std::cos(elevation) * std::cos(azimuth));

  // The object, centred on the origin: box half extents (1, 0.6, 0.8) * size / 2.
  const Eigen::Vector3d half = 0.5 * options.object_size * Eigen::Vector3d(1.0, 0.6, 0.8);
  std::vector<Eigen::Vector3d> points;
  points.reserve(options.num_points);
  std::vector<Eigen::Vector3d> face_normals;  // the box's: each point's face
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitY();
  if (options.object == SynthObject::kPlane) {
    // A plane through the origin tilted 25..60 degrees away from facing the camera.
    const double tilt = Uniform(rng, 25.0, 60.0) * kPi / 180.0;
    const Eigen::Vector3d side = to_eye.cross(Eigen::Vector3d::UnitY()).normalized();
    plane_normal = Eigen::AngleAxisd(tilt, side) * to_eye;
  }
  const Eigen::Vector3d plane_u = plane_normal.unitOrthogonal();
  const Eigen::Vector3d plane_v = plane_normal.cross(plane_u);
  while (static_cast<int>(points.size()) < options.num_points) {
    if (options.object == SynthObject::kBox) {
      // Keep the point if its face looks towards the eye's direction (and, below, once the
      // eye's distance is known, if the eye sees it).
      Eigen::Vector3d normal;
      const Eigen::Vector3d x = DrawBoxPoint(rng, half, &normal);
      if (normal.dot(to_eye) <= kMinFaceCosine) continue;
      points.push_back(x);
      face_normals.push_back(normal);
      continue;
    }
    const Eigen::Vector3d x = UniformVector3(rng, -1, 1);
    if (options.object == SynthObject::kCloud) {
      points.push_back(x.cwiseProduct(half));
    } else {
      points.push_back(0.5 * options.object_size * (x.x() * plane_u + x.y() * plane_v));
    }
  }

  // Aim the image centre's ray (not the optical axis: the principal point may be off-centre)
  // at the object's centre, with the world's y up, then back off until every point is inside.
  // Near the box the eye can be inside a face's slab, where that face is hidden (13 % of the
  // points at fovy 40, 54 % at 150): such points are drawn again on faces the eye sees.
  const Eigen::Vector3d centre_ray =
      CamRayFromPixel(k, Eigen::Vector2d(0.5 * (size.width - 1), 0.5 * (size.height - 1))).normalized();
  const Eigen::Matrix3d tilt_to_centre_ray =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), centre_ray).toRotationMatrix();
  double distance = 0.4 * options.object_size / std::tan(0.5 * options.fovy_deg * kPi / 180.0);
  SynthScene scene;
  Camera& camera = scene.truth;
  camera.image_size = size;
  camera.intrinsics = k;
  for (int attempt = 0;; ++attempt) {
    Require(attempt < 400, "cannot fit the object into the image with these options");
    const LookAt look_at{distance * to_eye, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()};
    const Rigid3 aimed = CamFromWorldFromLookAt(look_at);
    camera.cam_from_world.rotation = tilt_to_centre_ray * aimed.rotation;
    camera.cam_from_world.translation = -camera.cam_from_world.rotation * look_at.eye;
    bool inside = true;
    for (const auto& x : points) {
      const Eigen::Vector3d p = camera.cam_from_world * x;
      if (!(p.z() > 0.0)) { inside = false; break; }
      const Eigen::Vector2d pixel = PixelFromCam(k, p);
      // A 2 % margin keeps noisy pixels inside the image too.
      if (pixel.x() < 0.02 * size.width || pixel.x() > 0.98 * size.width - 1 ||
          pixel.y() < 0.02 * size.height || pixel.y() > 0.98 * size.height - 1) {
        inside = false;
        break;
      }
    }
    if (!inside) {
      distance *= 1.05;
      continue;
    }
    const auto seen = [&](const Eigen::Vector3d& normal) {
      return FaceSeen(normal, half, look_at.eye);
    };
    bool any_face_seen = face_normals.empty();  // not a box: nothing to see
    for (int axis = 0; axis < 3 && !any_face_seen; ++axis) {
      any_face_seen = seen(Eigen::Vector3d::Unit(axis)) || seen(-Eigen::Vector3d::Unit(axis));
    }
    if (!any_face_seen) {  // the eye is inside the box
      distance *= 1.05;
      continue;
    }
    bool redrawn = false;
    for (size_t i = 0; i < face_normals.size(); ++i) {
      if (seen(face_normals[i])) continue;
      do {
        points[i] = DrawBoxPoint(rng, half, &face_normals[i]);
      } while (!seen(face_normals[i]));
      redrawn = true;
    }
    if (!redrawn) break;  // else the new points are checked against the image again
  }

  double min_depth = kInfinity;
  double max_depth = 0.0;
  Correspondences& c = scene.correspondences;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = camera.cam_from_world * points[i];
    min_depth = std::min(min_depth, p.z());
    max_depth = std::max(max_depth, p.z());
    const Eigen::Vector2d noise = NormalVector2(rng);
    c.points_in_world.push_back(points[i]);
    c.pixels.push_back(PixelFromCam(k, p) + options.noise_px * noise);
    c.ids.push_back(std::to_string(i + 1));
    c.line_numbers.push_back(static_cast<int>(i) + 2);
  }
  camera.z_near = min_depth / 1.1;
  camera.z_far = max_depth * 1.1;
  return scene;
}

void CalibrationSynthOptions::Check() const {
  if (num_views < 1) {
    throw std::invalid_argument("CalibrationSynthOptions.num_views must be >= 1, got " +
                                std::to_string(num_views));
  }
  if (!(noise_px >= 0.0) || !std::isfinite(noise_px)) {
    throw std::invalid_argument("CalibrationSynthOptions.noise_px must be finite and >= 0");
  }
  image_size.Check();
  intrinsics.Check();
}

std::vector<CalibrationView> SynthesizeCalibrationViews(const CalibrationSynthOptions& options) {
  options.Check();
  std::vector<Eigen::Vector3d> points;
  if (options.planar) {
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 9; ++x) points.emplace_back(x, y, 0.0);
  } else {
    for (int z = 0; z < 3; ++z)
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) points.emplace_back(2.0 * x, 2.0 * y, 2.0 * z);
  }
  const Eigen::Vector3d center = options.planar ? Eigen::Vector3d(4.0, 2.5, 0.0) : Eigen::Vector3d(3.0, 3.0, 2.0);
  const double width = options.image_size.width, height = options.image_size.height;
  std::mt19937_64 rng(options.seed);
  std::vector<CalibrationView> views;
  // A camera that sees no pose with the whole target inside its image is a bad argument, not a
  // hang: give up after many draws.
  constexpr int kMaxDraws = 100000;
  int draws = 0;
  while (static_cast<int>(views.size()) < options.num_views) {
    if (++draws > kMaxDraws) {
      throw std::invalid_argument("SynthesizeCalibrationViews: no pose in " + std::to_string(kMaxDraws) +
                                  " draws keeps the target inside the image; widen the field of view");
    }
    const double spin = Uniform(rng, -0.3, 0.3), tilt_x = Uniform(rng, -0.6, 0.6),
                 tilt_y = Uniform(rng, -0.6, 0.6), distance = Uniform(rng, 13.0, 20.0);
    const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) *
                                      Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()))
                                         .toRotationMatrix();
    const Eigen::Vector3d translation = Eigen::Vector3d(0.0, 0.0, distance) - rotation * center;
    CalibrationView view;
    view.name = "view" + std::to_string(views.size() + 1);
    bool inside = true;
    for (const auto& point : points) {
      const Eigen::Vector3d in_cam = rotation * point + translation;
      if (!(in_cam.z() > 0.0)) {
        inside = false;
        break;
      }
      const Eigen::Vector2d pixel = PixelFromCam(options.intrinsics, in_cam);
      if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= width - 1 && pixel.y() <= height - 1)) {
        inside = false;
        break;
      }
      view.points_in_world.push_back(point);
      view.pixels.push_back(pixel);
    }
    if (!inside) continue;
    for (auto& pixel : view.pixels) {
      pixel += options.noise_px * NormalVector2(rng);
    }
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace camproj

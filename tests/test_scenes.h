// Seeded random cameras and scenes for the property tests, and the named tolerances they use.
#ifndef CAMPROJ_TESTS_TEST_SCENES_H_
#define CAMPROJ_TESTS_TEST_SCENES_H_

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "camproj/conventions.h"
#include "camproj/intrinsics.h"
#include "camproj/pose.h"

namespace camproj {
namespace testing {

// Exact algebra in double: a few dozen roundings of unit-sized quantities.
inline constexpr double kExactRelative = 1e-12;

// GL export, in unit roundoffs per term: world -> gl_eye (a 4-term dot product: 4), clip (4),
// the divide (1), viewport and pixel origin (3), and the entries of the matrices themselves (3),
// about 15; 32 leaves a margin of 2. Applied to the magnitudes each stage handles.
inline constexpr double kGlRoundings = 32.0;

// The rounding bound of a pixel that a camera's path computes from `point_in_world` (the pinhole
// path K [R|t] or GL's P V X -> divide -> viewport): the cam coordinates err by ~kGlRoundings unit
// roundoffs of |X|_1 + |t|_1, which move the pixel by `sensitivity` per unit of them
// ((fx + fy + |skew| + |u - cx| + |v - cy|) / z for a perspective camera, fx + fy + |skew| for an
// orthographic one), and the projection itself errs by ~kGlRoundings unit roundoffs of the
// magnitudes it adds up (the pixel, the principal point, the viewport).
inline double PixelRoundingBound(const Intrinsics& k, const ImageSize& size,
                                 const Rigid3& cam_from_world,
                                 const Eigen::Vector3d& point_in_world,
                                 const Eigen::Vector2d& pixel, double sensitivity) {
  const double cam_rounding = point_in_world.lpNorm<1>() + cam_from_world.translation.lpNorm<1>();
  return kGlRoundings * 0x1p-53 *
         (sensitivity * cam_rounding + std::abs(pixel.x()) + std::abs(pixel.y()) +
          std::abs(k.cx) + std::abs(k.cy) + size.width + size.height);
}

inline double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// log-uniform in [lo, hi], for scales such as focal lengths spanning decades.
inline double LogUniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(Uniform(rng, std::log(lo), std::log(hi)));
}

// Independent draws as a vector: `draw()` is called once per coordinate, the last coordinate
// first. C++ leaves the order in which a call's arguments are evaluated unspecified (GCC: right
// to left, clang: left to right), so Eigen::Vector3d(Uniform(rng, ...), ...) drew another scene
// from the same seed with each compiler; last-first is the order the tests' scenes were drawn in
// when they were written (GCC). A braced list {a(), b()} is evaluated left to right.
template <typename Draw>
Eigen::Vector2d DrawVector2(Draw&& draw) {
  const double y = draw();
  const double x = draw();
  return {x, y};
}
template <typename Draw>
Eigen::Vector3d DrawVector3(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return {x, y, z};
}

// Each coordinate uniform in [lo, hi), in DrawVector3's order.
inline Eigen::Vector3d UniformVector3(std::mt19937_64& rng, double lo, double hi) {
  return DrawVector3([&] { return Uniform(rng, lo, hi); });
}
// Coordinate i uniform in [lo(i), hi(i)), in DrawVector3's order.
inline Eigen::Vector3d UniformVector3(std::mt19937_64& rng, const Eigen::Vector3d& lo,
                                      const Eigen::Vector3d& hi) {
  const double z = Uniform(rng, lo.z(), hi.z());
  const double y = Uniform(rng, lo.y(), hi.y());
  const double x = Uniform(rng, lo.x(), hi.x());
  return {x, y, z};
}

inline Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  // Drawn z, y, x, w (see DrawVector3).
  const double z = normal(rng), y = normal(rng), x = normal(rng), w = normal(rng);
  return Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
}

struct RandomCameraOptions {
  double min_fov_deg = 1.0;          // field of view range across the wider side (narrow to wide)
  double max_fov_deg = 150.0;
  double max_aspect_ratio = 2.0;     // fy/fx in [1/r, r]
  double max_principal_offset = 1.0; // cx, cy within the image +- this many image sizes
  double max_skew_ratio = 0.2;       // |skew| <= this * fx
  double max_center_distance = 10.0; // camera centre within this radius of the origin
};

struct RandomCamera {
  ImageSize size;
  Intrinsics intrinsics;  // kCenter
  Rigid3 cam_from_world;
};

inline RandomCamera MakeRandomCamera(std::mt19937_64& rng, const RandomCameraOptions& options = {}) {
  constexpr double kPi = 3.14159265358979323846;
  RandomCamera camera;
  camera.size.width = static_cast<int>(Uniform(rng, 32, 4096));
  camera.size.height = static_cast<int>(Uniform(rng, 32, 4096));
  const double fov = Uniform(rng, options.min_fov_deg, options.max_fov_deg) * kPi / 180.0;
  Intrinsics& k = camera.intrinsics;
  const double w = camera.size.width;
  const double h = camera.size.height;
  // The field of view spans the image's wider angular side: width and height are drawn
  // independently (a 53 x 2107 strip is possible), and a view set across the width alone gave
  // such a strip ~170 degrees along its length, beyond any lens the tests mean to model.
  const double aspect = LogUniform(rng, 1.0 / options.max_aspect_ratio, options.max_aspect_ratio);
  const double widest_half_tangent = std::max(0.5 * w, 0.5 * h / aspect);  // in units of fx
  k.fx = widest_half_tangent / std::tan(0.5 * fov);
  k.fy = k.fx * aspect;
  k.cx = Uniform(rng, -options.max_principal_offset * w, (1.0 + options.max_principal_offset) * w);
  k.cy = Uniform(rng, -options.max_principal_offset * h, (1.0 + options.max_principal_offset) * h);
  k.skew = Uniform(rng, -options.max_skew_ratio, options.max_skew_ratio) * k.fx;
  const Eigen::Vector3d center = options.max_center_distance * UniformVector3(rng, -1, 1);
  camera.cam_from_world = CamFromWorldFromCenter(RandomRotation(rng), center);
  return camera;
}

// A world point that projects to `pixel` (kCenter) at depth z_cam = depth.
inline Eigen::Vector3d WorldPointAtPixel(const RandomCamera& camera, const Eigen::Vector2d& pixel,
                                         double depth) {
  const Eigen::Vector3d ray = CamRayFromPixel(camera.intrinsics, pixel);
  return Inverse(camera.cam_from_world) * (depth * ray);
}

// A pixel anywhere in the image (to the outer edges), kCenter.
inline Eigen::Vector2d RandomPixelInImage(std::mt19937_64& rng, const ImageSize& size) {
  return {Uniform(rng, -0.5, size.width - 0.5), Uniform(rng, -0.5, size.height - 0.5)};
}

struct SceneOptions {
  int num_points = 20;
  bool planar = false;          // all points on one plane (tilted against the image plane)
  double min_depth = 2.0;       // depth range in front of the camera (z_cam)
  double max_depth = 4.0;
  double pixel_noise = 0.0;     // Gaussian sigma per axis, px
};

struct Scene {
  std::vector<Eigen::Vector3d> points_in_world;
  std::vector<Eigen::Vector2d> true_pixels;      // kCenter
  std::vector<Eigen::Vector2d> observed_pixels;  // true + noise
};

// Points that project inside the image at depths in [min_depth, max_depth]. Planar scenes put
// them on a plane through the point seen at the image centre at the middle depth, tilted by
// 20..70 degrees against that viewing ray. Throws if the camera cannot produce the scene.
inline Scene MakeScene(std::mt19937_64& rng, const RandomCamera& camera,
                       const SceneOptions& options) {
  Scene scene;
  const Rigid3 world_from_cam = Inverse(camera.cam_from_world);
  const double mid_depth = 0.5 * (options.min_depth + options.max_depth);
  constexpr double kPi = 3.14159265358979323846;
  const Eigen::Vector3d center_ray =
      options.planar ? CamRayFromPixel(camera.intrinsics,
                                       Eigen::Vector2d(0.5 * (camera.size.width - 1),
                                                       0.5 * (camera.size.height - 1)))
                     : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d anchor = mid_depth * center_ray;
  const Eigen::Vector3d view = center_ray.normalized();
  const Eigen::Vector3d side = view.unitOrthogonal();
  const double tilt = Uniform(rng, 20.0, 70.0) * kPi / 180.0;
  const Eigen::Vector3d normal =
      Eigen::AngleAxisd(tilt, Eigen::AngleAxisd(Uniform(rng, 0.0, 2.0 * kPi), view) * side) * -view;
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int attempt = 0; static_cast<int>(scene.points_in_world.size()) < options.num_points; ++attempt) {
    if (attempt > 1000 * options.num_points + 100000) {
      throw std::runtime_error("MakeScene: this camera cannot see the requested scene");
    }
    const Eigen::Vector2d pixel = RandomPixelInImage(rng, camera.size);
    Eigen::Vector3d ray;
    try {
      ray = CamRayFromPixel(camera.intrinsics, pixel);
    } catch (const std::domain_error&) {
      continue;  // beyond the distortion's fold
    }
    double depth = Uniform(rng, options.min_depth, options.max_depth);
    if (options.planar) {
      const double denominator = normal.dot(ray);
      if (std::abs(denominator) < 1e-9) continue;
      depth = normal.dot(anchor) / denominator;
      if (!(depth > 0.2 * options.min_depth && depth < 5.0 * options.max_depth)) continue;
    }
    scene.points_in_world.push_back(world_from_cam * (depth * ray));
    scene.true_pixels.push_back(PixelFromCam(camera.intrinsics, depth * ray));
    scene.observed_pixels.push_back(scene.true_pixels.back() +
                                    options.pixel_noise * DrawVector2([&] { return noise(rng); }));
  }
  return scene;
}

}  // namespace testing
}  // namespace camproj

#endif  // CAMPROJ_TESTS_TEST_SCENES_H_

#include "camproj/fit.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "test_scenes.h"

namespace camproj {
namespace {

using testing::MakeRandomCamera;
using testing::MakeScene;
using testing::RandomCamera;
using testing::RandomCameraOptions;
using testing::Scene;
using testing::SceneOptions;

// Noise-free recovery: LM converges quadratically to the exact camera; what is left is rounding
// amplified by the problem's conditioning (narrow fields of view couple focal and distance).
constexpr double kRecoveryRelative = 1e-9;

double RotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

struct Recovery {
  double focal = 0, aspect = 0, principal = 0, skew = 0, distortion = 0, center = 0, rotation = 0;
};

Recovery Compare(const RandomCamera& truth, const FitResult& fit, double scene_distance) {
  Recovery r;
  const Intrinsics& k = fit.camera.intrinsics;
  const Intrinsics& t = truth.intrinsics;
  r.focal = std::abs(k.fx - t.fx) / t.fx;
  r.aspect = std::abs(k.fy - t.fy) / t.fy;
  const double size = std::max(truth.size.width, truth.size.height);
  r.principal = std::max(std::abs(k.cx - t.cx), std::abs(k.cy - t.cy)) / size;
  r.skew = std::abs(k.skew - t.skew) / t.fx;
  r.distortion = std::max(std::abs(k.k1 - t.k1), std::abs(k.k2 - t.k2));
  r.center = (CameraCenterInWorld(fit.camera.cam_from_world) -
              CameraCenterInWorld(truth.cam_from_world)).norm() / scene_distance;
  r.rotation = RotationAngle(fit.camera.cam_from_world.rotation, truth.cam_from_world.rotation);
  return r;
}

void ExpectRecovered(const Recovery& r, const std::string& label) {
  EXPECT_LT(r.focal, kRecoveryRelative) << label;
  EXPECT_LT(r.aspect, kRecoveryRelative) << label;
  EXPECT_LT(r.principal, kRecoveryRelative) << label;
  EXPECT_LT(r.skew, kRecoveryRelative) << label;
  EXPECT_LT(r.distortion, kRecoveryRelative) << label;
  EXPECT_LT(r.center, kRecoveryRelative) << label;
  EXPECT_LT(r.rotation, kRecoveryRelative) << label;
}

TEST(FitTest, NoiseFreeNonPlanarFullProjectiveCamera) {
  std::mt19937_64 rng(100);
  for (int i = 0; i < 60; ++i) {
    RandomCameraOptions camera_options;
    camera_options.min_fov_deg = 5;
    camera_options.max_fov_deg = 150;
    const RandomCamera camera = MakeRandomCamera(rng, camera_options);
    SceneOptions scene_options;
    scene_options.num_points = 6 + i % 40;
    const Scene scene = MakeScene(rng, camera, scene_options);
    FitOptions options;
    options.skew = ParameterMode::Free();
    const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    ExpectRecovered(Compare(camera, fit, 3.0), "camera " + std::to_string(i));
    EXPECT_EQ(fit.start_method, "dlt");
  }
}

}  // namespace
}  // namespace camproj

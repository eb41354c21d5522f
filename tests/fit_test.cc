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

// Each case: a camera family, a scene, and the parameter set that scene determines.
struct NoiseFreeCase {
  const char* name;
  int count;
  bool planar;
  int min_points;
  int max_points;
  bool distortion;   // the true camera has k1, k2 (and they are fitted)
  bool skew;         // the true camera has skew (fitted)
  bool centred;      // principal point at the image centre, square pixels (a gluPerspective camera)
  bool known_intrinsics;
};

class NoiseFreeTest : public ::testing::TestWithParam<NoiseFreeCase> {};

TEST_P(NoiseFreeTest, RecoversTheCameraExactly) {
  const NoiseFreeCase& c = GetParam();
  std::mt19937_64 rng(std::hash<std::string>{}(c.name));
  for (int i = 0; i < c.count; ++i) {
    RandomCameraOptions camera_options;
    camera_options.min_fov_deg = 5;
    camera_options.max_fov_deg = 150;
    camera_options.max_skew_ratio = c.skew ? 0.2 : 0.0;
    if (c.planar || c.centred) camera_options.max_aspect_ratio = 1.0;
    if (c.distortion) {
      // Keep the image inside the radial map's invertible part.
      camera_options.max_fov_deg = 70;
      camera_options.max_principal_offset = 0.2;
      camera_options.max_aspect_ratio = 1.2;
    }
    RandomCamera camera = MakeRandomCamera(rng, camera_options);
    if (c.centred) {
      camera.intrinsics.cx = 0.5 * (camera.size.width - 1);
      camera.intrinsics.cy = 0.5 * (camera.size.height - 1);
    }
    if (c.distortion) {
      camera.intrinsics.k1 = testing::Uniform(rng, -0.2, 0.1);
      camera.intrinsics.k2 = testing::Uniform(rng, -0.02, 0.02);
    }
    SceneOptions scene_options;
    scene_options.planar = c.planar;
    scene_options.num_points =
        c.min_points + static_cast<int>(rng() % static_cast<unsigned>(c.max_points - c.min_points + 1));
    Scene scene;
    try {
      scene = MakeScene(rng, camera, scene_options);
    } catch (const std::exception& e) {
      ADD_FAILURE() << c.name << " camera " << i << ": " << e.what();
      continue;
    }
    FitOptions options;
    const Intrinsics& t = camera.intrinsics;
    if (c.known_intrinsics) {
      options.known_intrinsics = t;
    } else if (c.centred) {
      options.aspect = ParameterMode::Default();
      options.principal_point = ParameterMode::Default();
    } else if (c.planar) {
      // A plane determines two intrinsics: here focal and aspect, the principal point given.
      options.principal_point = ParameterMode::Fixed(t.cx, t.cy);
    }
    if (c.skew) options.skew = ParameterMode::Free();
    if (c.distortion && !c.known_intrinsics) {
      options.k1 = ParameterMode::Free();
      options.k2 = ParameterMode::Free();
    }
    const std::string label = std::string(c.name) + " camera " + std::to_string(i) + " N " +
                              std::to_string(scene_options.num_points);
    try {
      const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
      ExpectRecovered(Compare(camera, fit, 3.0), label + " start " + fit.start_method);
      EXPECT_LT(fit.rms_px, 1e-6) << label;
      EXPECT_EQ(fit.planar, c.planar) << label;
    } catch (const std::exception& e) {
      ADD_FAILURE() << label << ": " << e.what();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Families, NoiseFreeTest,
    ::testing::Values(
        //            name                count planar min max  dist   skew   centred known
        NoiseFreeCase{"OffAxisPinhole",     60, false, 6,  60, false, false, false, false},
        NoiseFreeCase{"SkewedProjective",   30, false, 6,  60, false, true,  false, false},
        NoiseFreeCase{"GluPerspective",     40, false, 4,  30, false, false, true,  false},
        NoiseFreeCase{"PlanarFocalAspect",  30, true,  4,  60, false, false, false, false},
        NoiseFreeCase{"PlanarCentred",      20, true,  4,  60, false, false, true,  false},
        NoiseFreeCase{"RadialDistortion",   30, false, 12, 80, true,  false, false, false},
        NoiseFreeCase{"KnownIntrinsics",    30, false, 4,  40, true,  false, false, true}),
    [](const ::testing::TestParamInfo<NoiseFreeCase>& info) { return info.param.name; });

}  // namespace
}  // namespace camproj

#include "camproj/fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <regex>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/camera_file.h"
#include "camproj/fit_request.h"
#include "camproj/model_select.h"
#include "camproj/number_text.h"
#include "camproj/synth.h"
#include "seeds.h"
#include "test_scenes.h"
#include "truth_condition.h"

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

// A noise-free fit (fitted with pixel_sigma 1: its covariance is (J^T J)^-1) against the truth:
// within the first-order bound of what perturbs it (truth_condition.h).
void ExpectRecovered(const RandomCamera& truth, const Scene& scene, const FitResult& fit,
                     const std::string& label) {
  testing::ExpectWithinFirstOrderBound(fit, scene.points_in_world, scene.observed_pixels,
                                       truth.cam_from_world.rotation,
                                       CameraCenterInWorld(truth.cam_from_world), truth.intrinsics,
                                       label);
}

// Each case: a camera family, a scene, and the parameter set that scene determines.
struct NoiseFreeCase {
  const char* name;
  int count;
  bool planar;
  int min_points;
  int max_points;
  bool distortion;   // the true camera has k1, k2 (fitted unless known; known: p1, p2, k3 too)
  bool skew;         // the true camera has skew (fitted)
  bool centred;      // principal point at the image centre, square pixels (a gluPerspective camera)
  bool known_intrinsics;
};

class NoiseFreeTest : public ::testing::TestWithParam<NoiseFreeCase> {};

TEST_P(NoiseFreeTest, RecoversTheCameraExactly) {
  const NoiseFreeCase& c = GetParam();
  std::mt19937_64 rng(testing::Seed(std::hash<std::string>{}(c.name)));
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
      if (c.known_intrinsics) {
        // A pose against a calibration with OpenCV's whole lens: p1, p2, k3 held in the fit.
        camera.intrinsics.p1 = testing::Uniform(rng, -0.005, 0.005);
        camera.intrinsics.p2 = testing::Uniform(rng, -0.005, 0.005);
        camera.intrinsics.k3 = testing::Uniform(rng, -0.01, 0.01);
      }
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
    options.pixel_sigma = 1.0;  // the covariance (J^T J)^-1 that the first-order bound reads
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
      ExpectRecovered(camera, scene, fit, label + " start " + fit.start_method);
      EXPECT_LT(fit.rms_px, 1e-6) << label;
      EXPECT_EQ(fit.planar, c.planar) << label;
    } catch (const SceneError& e) {
      // Refused as undetermined: right where the truth itself is (a plane tilted about an image
      // axis cannot tell fx from fy; seen at 4-6 points): its scaled Jacobian's condition number,
      // computed independently, above the fitter's limit.
      const double condition =
          testing::ConditionAtTruth(scene.points_in_world, camera.cam_from_world.rotation,
                                    CameraCenterInWorld(camera.cam_from_world), t, options);
      EXPECT_TRUE(e.reason() == SceneError::Reason::kDegenerate &&
                  condition > testing::kFitterConditionLimit)
          << label << ": condition at the truth " << condition << ": " << e.what();
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

// Regression cases of NoiseFreeTest RadialDistortion (seed offsets 1 and 4, issue #17): the
// principal point off the image, strong barrel distortion, the model with k1 and k2 free. The
// fit from the DLT's principal point ended on the image's other side with k2 bending (RMS 8 px,
// fx 5 % off), noise-free; the restarts beyond the image's edges (refine.cc) find the truth.
TEST(SceneErrorTest, WhatIsWhyThenFixAndCopiesKeepTheParts) {
  const SceneError apart(SceneError::Reason::kDegenerate, "the points do not say", "Add points");
  EXPECT_STREQ(apart.what(), "the points do not say. Add points");
  EXPECT_EQ(apart.why(), "the points do not say");
  EXPECT_EQ(apart.fix(), "Add points");
  SceneError copy(SceneError::Reason::kTooFewPoints, "x");
  copy = apart;
  EXPECT_EQ(copy.reason(), SceneError::Reason::kDegenerate);
  EXPECT_EQ(copy.why(), "the points do not say");
  EXPECT_EQ(copy.fix(), "Add points");
  // One text: the advice is within the reason, and there is no fix apart.
  const SceneError one(SceneError::Reason::kDegenerate, "the points do not say: add points");
  EXPECT_EQ(one.why(), one.what());
  EXPECT_EQ(one.fix(), "");
}

// What FitCamera refuses says what to do apart (SceneError::fix), for each kind of refusal it
// makes on well-formed input here.
TEST(SceneErrorTest, FitCameraRefusalsSayWhatToDoApart) {
  const std::vector<Eigen::Vector2d> pixels = {{100, 200}, {137, 211}, {174, 244}, {211, 299},
                                               {248, 376}, {285, 475}, {322, 596}, {359, 739}};
  auto fix_of = [&](const std::vector<Eigen::Vector3d>& points) {
    try {
      FitCamera(points, std::vector<Eigen::Vector2d>(pixels.begin(),
                                                     pixels.begin() + points.size()),
                {640, 480}, FitOptions{});
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()), e.why() + ". " + e.fix());
      return e.fix();
    }
    ADD_FAILURE() << "answered";
    return std::string();
  };
  EXPECT_EQ(fix_of({{0, 0, -2}, {1, 0, -2}, {0, 1, -2}}).rfind("Add points (at least", 0), 0u);
  std::vector<Eigen::Vector3d> line;
  for (int t = 0; t < 8; ++t) line.emplace_back(t, 2 * t, -2 - t);
  EXPECT_EQ(fix_of(line), "Add points off the line");
}

TEST(FitTest, DistortionWithThePrincipalPointOffTheImage) {
  struct Lens {
    ImageSize size;
    double fx, fy, cx, cy, k1, k2;
    int num_points;
  };
  const Lens lenses[] = {
      {{1903, 610}, 2105.8720435427704, 2522.865906633278, -197.06329084732411,
       724.77726842364461, -0.19047436070470039, -0.013121000524887171, 30},
      {{3041, 373}, 2651.0789864105632, 2387.7765872596901, -259.81370382170184,
       62.053635764105124, -0.18424562062961075, -0.018624520201987266, 12}};
  std::mt19937_64 rng(17);  // literal: a regression case, not a draw
  for (const Lens& lens : lenses) {
    RandomCamera camera;
    camera.size = lens.size;
    camera.intrinsics.fx = lens.fx;
    camera.intrinsics.fy = lens.fy;
    camera.intrinsics.cx = lens.cx;
    camera.intrinsics.cy = lens.cy;
    camera.intrinsics.k1 = lens.k1;
    camera.intrinsics.k2 = lens.k2;
    camera.cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng),
                                                   Eigen::Vector3d(1.0, -2.0, 3.0));
    SceneOptions scene_options;
    scene_options.num_points = lens.num_points;
    const Scene scene = MakeScene(rng, camera, scene_options);
    FitOptions options;
    options.k1 = ParameterMode::Free();
    options.k2 = ParameterMode::Free();
    options.pixel_sigma = 1.0;
    const FitResult fit =
        FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    EXPECT_LT(fit.rms_px, 1e-6) << lens.size.width << "x" << lens.size.height;
    ExpectRecovered(camera, scene, fit, "lens " + std::to_string(lens.size.width));
  }
}

// A projector-like camera: off-axis principal point (lens shift), fx != fy, moderate field of view.
RandomCamera ProjectorLikeCamera(std::mt19937_64& rng) {
  RandomCamera camera;
  camera.size = {1280, 800};
  camera.intrinsics.fx = testing::Uniform(rng, 900, 1500);
  camera.intrinsics.fy = camera.intrinsics.fx * testing::Uniform(rng, 0.97, 1.03);
  camera.intrinsics.cx = testing::Uniform(rng, 500, 780);
  camera.intrinsics.cy = testing::Uniform(rng, 500, 799);
  // The centre is drawn before the rotation (testing::DrawVector3 says why).
  const Eigen::Vector3d center = testing::UniformVector3(rng, -5, 5);
  camera.cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng), center);
  return camera;
}

// The estimation error in the fit's user parameterization (truth_condition.h).
Eigen::VectorXd EstimationError(const FitResult& fit, const RandomCamera& truth) {
  return testing::EstimationError(fit, truth.cam_from_world.rotation,
                                  CameraCenterInWorld(truth.cam_from_world), truth.intrinsics);
}

struct NoisyCase {
  int num_points;
  int trials;
  double rms_tolerance;  // relative, on the mean of RMS^2 (see the test)
};

class NoisyFitTest : public ::testing::TestWithParam<NoisyCase> {};

// With sigma = 1 px per axis, the sum of squared residuals at the least-squares optimum is
// sigma^2 chi^2 with 2N - p degrees of freedom (to first order), so E[RMS^2] = sigma^2 (2N - p)/N.
// Over T trials the mean of RMS^2 has relative standard deviation sqrt(2 / ((2N - p) T)):
// 1.4 % for N = 10, T = 1000 (bound 5 %: 3.5 sd) and 0.58 % for N = 100, T = 300 (bound 3 %).
// NEES = e^T Sigma^-1 e with the given sigma is chi^2_p: its mean over T trials has relative sd
// sqrt(2 / (p T)) = 2.6 % for p = 10, T = 300 (bound 10 %: 3.9 sd).
TEST_P(NoisyFitTest, ResidualsAndReportedSigmasMatchTheirDistributions) {
  const NoisyCase& c = GetParam();
  std::mt19937_64 rng(testing::Seed(1000 + c.num_points));
  double sum_rms2 = 0.0;
  double sum_nees = 0.0;
  int linear = 0;  // draws the fit reports linear (FitResult::linearity): NEES is over them
  int p = 0;
  for (int trial = 0; trial < c.trials; ++trial) {
    const RandomCamera camera = ProjectorLikeCamera(rng);
    SceneOptions scene_options;
    scene_options.num_points = c.num_points;
    scene_options.pixel_noise = 1.0;
    const Scene scene = MakeScene(rng, camera, scene_options);
    FitOptions options;  // focal, aspect, principal point free: p = 10
    options.pixel_sigma = 1.0;
    const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    p = static_cast<int>(fit.free_parameters.size());
    sum_rms2 += fit.rms_px * fit.rms_px;
    ASSERT_TRUE(fit.covariance_available);
    const Eigen::VectorXd e = EstimationError(fit, camera);
    if (fit.linearity.linear) {
      sum_nees += e.dot(fit.covariance.ldlt().solve(e));
      ++linear;
    }
  }
  ASSERT_EQ(p, 10);
  const double expected_rms2 = (2.0 * c.num_points - p) / c.num_points;
  const double mean_rms2 = sum_rms2 / c.trials;
  EXPECT_NEAR(mean_rms2 / expected_rms2, 1.0, c.rms_tolerance)
      << "mean RMS^2 " << mean_rms2 << " expected " << expected_rms2;
  const double mean_nees = sum_nees / linear;
  std::printf("[ NEES     ] N = %d: mean %.3f over the %d of %d draws reported linear\n",
              c.num_points, mean_nees, linear, c.trials);
  EXPECT_NEAR(mean_nees / p, 1.0, 0.10) << "mean NEES " << mean_nees << " for p = " << p;
  RecordProperty("rms2_ratio", std::to_string(mean_rms2 / expected_rms2));
  RecordProperty("nees_ratio", std::to_string(mean_nees / p));
}

INSTANTIATE_TEST_SUITE_P(SigmaOnePixel, NoisyFitTest,
                         ::testing::Values(NoisyCase{10, 1000, 0.05}, NoisyCase{100, 300, 0.03},
                                           NoisyCase{1000, 300, 0.03}),
                         [](const ::testing::TestParamInfo<NoisyCase>& info) {
                           return "N" + std::to_string(info.param.num_points);
                         });

// The same scene in metres, in millimetres, and in millimetres offset by 4e6 (projected map
// coordinates) must give the same camera: the fitter centres and scales the world first.
// The points are put on a 2^-20 m grid so that x 1000 and + 4e6 are exact in double: the three
// inputs are then the same geometry bit for bit, and any difference is the fitter's. (Without
// it, rounding 4e6 + x moves a point by ~5e-13 m, which a weak planar fit -- sigma_eye ~ 0.1 m --
// turns into ~5e-9 relative: a property of the data, not of the fitter.)
TEST(FitTest, InvariantToWorldUnitsAndOffsets) {
  std::mt19937_64 rng(testing::Seed(77));
  for (int i = 0; i < 20; ++i) {
    const RandomCamera camera = ProjectorLikeCamera(rng);
    SceneOptions scene_options;
    scene_options.num_points = 30;
    scene_options.pixel_noise = 1.0;
    scene_options.planar = i % 4 == 3;
    Scene scene = MakeScene(rng, camera, scene_options);
    for (auto& x : scene.points_in_world) x = (x * 0x1p20).array().round().matrix() * 0x1p-20;
    FitOptions options;
    if (scene_options.planar) {
      options.principal_point = ParameterMode::Default();
      options.aspect = ParameterMode::Default();
    }
    const FitResult metres = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    const Eigen::Vector3d offset(4e6, 4e6, 1e3);
    for (const bool with_offset : {false, true}) {
      std::vector<Eigen::Vector3d> points = scene.points_in_world;
      for (auto& x : points) x = 1000.0 * x + (with_offset ? offset : Eigen::Vector3d::Zero());
      const FitResult mm = FitCamera(points, scene.observed_pixels, camera.size, options);
      const Intrinsics& a = metres.camera.intrinsics;
      const Intrinsics& b = mm.camera.intrinsics;
      constexpr double kInvariance = 1e-9;
      EXPECT_NEAR(b.fx, a.fx, kInvariance * a.fx) << i;
      EXPECT_NEAR(b.fy, a.fy, kInvariance * a.fy) << i;
      EXPECT_NEAR(b.cx, a.cx, kInvariance * a.fx) << i;
      EXPECT_NEAR(b.cy, a.cy, kInvariance * a.fx) << i;
      const Eigen::Vector3d eye_m = CameraCenterInWorld(metres.camera.cam_from_world);
      const Eigen::Vector3d eye_mm =
          (CameraCenterInWorld(mm.camera.cam_from_world) - (with_offset ? offset : Eigen::Vector3d::Zero())) / 1000.0;
      EXPECT_LT((eye_mm - eye_m).norm(), kInvariance * (eye_m.norm() + 1.0)) << i;
      EXPECT_LT(RotationAngle(mm.camera.cam_from_world.rotation, metres.camera.cam_from_world.rotation),
                kInvariance) << i;
      EXPECT_NEAR(mm.rms_px, metres.rms_px, kInvariance * metres.rms_px) << i;
    }
  }
}

// Beyond ~1e154 the squares of the coordinates overflow, below ~1e-154 they underflow, so the
// fitter's normalization must not square them. Times 2^k the input is exact, and so are its
// centroid and RMS distance: the normalized world is the same bit for bit, and so is every
// number of the fit (the translation and an orthographic scale in world units times 2^k, 2^-k).
// (Before: the small scales were refused as collinear, the large ones ended in "K must be
// finite".)
TEST(FitTest, ExtremeWorldScalesGiveTheSameCameraBitForBit) {
  std::mt19937_64 rng(testing::Seed(78));
  const RandomCamera camera = ProjectorLikeCamera(rng);
  SceneOptions scene_options;
  scene_options.num_points = 30;
  scene_options.pixel_noise = 0.5;
  const Scene scene = MakeScene(rng, camera, scene_options);
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    FitOptions options;
    options.projection = projection;
    if (projection == Projection::kOrthographic) options.principal_point = ParameterMode::Default();
    const FitResult unit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    const double scale_power = projection == Projection::kOrthographic ? -1.0 : 0.0;
    for (const int k : {-1000, -500, 500, 1000}) {
      std::vector<Eigen::Vector3d> points = scene.points_in_world;
      for (auto& x : points) x = std::ldexp(1.0, k) * x;
      const FitResult scaled = FitCamera(points, scene.observed_pixels, camera.size, options);
      const Intrinsics& a = unit.camera.intrinsics;
      const Intrinsics& b = scaled.camera.intrinsics;
      EXPECT_EQ(b.fx, std::ldexp(a.fx, static_cast<int>(scale_power * k))) << k;
      EXPECT_EQ(b.fy, std::ldexp(a.fy, static_cast<int>(scale_power * k))) << k;
      EXPECT_EQ(b.skew, std::ldexp(a.skew, static_cast<int>(scale_power * k))) << k;
      EXPECT_EQ(b.cx, a.cx) << k;
      EXPECT_EQ(b.cy, a.cy) << k;
      EXPECT_EQ(scaled.camera.cam_from_world.rotation, unit.camera.cam_from_world.rotation) << k;
      EXPECT_EQ(scaled.camera.cam_from_world.translation,
                std::ldexp(1.0, k) * unit.camera.cam_from_world.translation) << k;
      EXPECT_EQ(scaled.rms_px, unit.rms_px) << k;
      // The camera file too: its look-at target distance (|target - eye|, ~2^k) once squared
      // overflowed at 2^1000 (1e301), and `camproj fit` ended in exit 2 after its fit.
      const Camera read = CameraFromJsonText(FitCameraFileText(scaled, PixelOrigin::kCenter), "fit");
      EXPECT_EQ(read.cam_from_world.translation, scaled.camera.cam_from_world.translation) << k;
      EXPECT_EQ(read.intrinsics.fx, b.fx) << k;
    }
    // Near 2^1017 (1.4e306) the fit is still exact but its GL frustum overflows a double:
    // refused as too large, with the advice to change units (was kNumerical, "frustum left must
    // be finite").
    std::vector<Eigen::Vector3d> points = scene.points_in_world;
    for (auto& x : points) x = std::ldexp(1.0, 1017) * x;
    try {
      FitCamera(points, scene.observed_pixels, camera.size, options);
      if (projection == Projection::kPerspective) ADD_FAILURE() << "2^1017 was not refused";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.reason(), SceneError::Reason::kNonFiniteInput) << e.what();
      EXPECT_NE(e.why().find("too large for double precision"), std::string::npos) << e.what();
    }
  }
}

// A given near plane beyond every point (or far plane before every point) leaves no depth range
// that holds a point once the other plane is fitted: a refusal that says so, naming the points'
// depths, never a numerical failure (was "near (5) must be less than far (2.75)", kNumerical
// from FitCameraAuto). Both planes given are the user's range, taken as given.
TEST(FitTest, AGivenNearOrFarPastEveryPointIsRefused) {
  std::mt19937_64 rng(testing::Seed(79));
  const RandomCamera camera = ProjectorLikeCamera(rng);
  const Scene scene = MakeScene(rng, camera, SceneOptions{});
  const FitResult free = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size);
  const double nearest = free.camera.z_near * 1.1;
  const double farthest = free.camera.z_far / 1.1;
  // Past every point by far, and only just: a near plane between the farthest point and the
  // tight far plane (1.1 x its depth), or a far plane between the tight near plane and the
  // nearest point, made a frustum that held no point (answered, exit 0).
  for (const auto& [near_given, factor] : {std::pair<bool, double>{true, 2.0}, {true, 1.05},
                                           {false, 0.5}, {false, 1.0 / 1.05}}) {
    SCOPED_TRACE(std::string(near_given ? "near" : "far") + " x " + ShortestDouble(factor));
    FitOptions options;
    if (near_given) options.z_near = factor * farthest;
    else options.z_far = factor * nearest;
    try {
      FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
      ADD_FAILURE() << "not refused";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.reason(), SceneError::Reason::kPointsBehindCamera) << e.what();
      EXPECT_NE(e.why().find(near_given ? "nearer than the given near plane"
                                        : "beyond the given far plane"), std::string::npos)
          << e.what();
      EXPECT_NE(e.why().find("at depths"), std::string::npos) << e.what();
      EXPECT_NE(e.fix().find(near_given ? "--near" : "--far"), std::string::npos) << e.what();
    }
    AutoFitOptions auto_options;
    auto_options.fit = options;
    try {
      FitCameraAuto(scene.points_in_world, scene.observed_pixels, camera.size, auto_options);
      ADD_FAILURE() << "not refused";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.reason(), SceneError::Reason::kPointsBehindCamera) << e.what();
    }
  }
  // In the automatic model the planes are the answer's: the same camera as without them (the
  // selection judged its candidates with the given planes, refusing those whose depths they did
  // not hold), the given plane as given and the other tight around the answer's points.
  AutoFitOptions tight;
  const FitResult answer =
      FitCameraAuto(scene.points_in_world, scene.observed_pixels, camera.size, tight);
  const double answer_nearest = answer.camera.z_near * 1.1;
  const double answer_farthest = answer.camera.z_far / 1.1;
  for (const bool near_given : {true, false}) {
    AutoFitOptions given = tight;
    if (near_given) given.fit.z_near = 0.5 * (answer_nearest + answer_farthest);
    else given.fit.z_far = 0.5 * (answer_nearest + answer_farthest);
    const FitResult fit =
        FitCameraAuto(scene.points_in_world, scene.observed_pixels, camera.size, given);
    EXPECT_EQ(fit.model, answer.model);
    EXPECT_EQ(fit.camera.cam_from_world.rotation, answer.camera.cam_from_world.rotation);
    EXPECT_EQ(fit.camera.cam_from_world.translation, answer.camera.cam_from_world.translation);
    EXPECT_EQ(fit.rms_px, answer.rms_px);
    // The tight plane from the points' depths in the world's frame rather than the fit's:
    // rounding of ~1e-16 relative.
    if (near_given) {
      EXPECT_EQ(fit.camera.z_near, *given.fit.z_near);
      EXPECT_NEAR(fit.camera.z_far, answer.camera.z_far, 1e-12 * answer.camera.z_far);
    } else {
      EXPECT_EQ(fit.camera.z_far, *given.fit.z_far);
      EXPECT_NEAR(fit.camera.z_near, answer.camera.z_near, 1e-12 * answer.camera.z_near);
    }
    // The views are the camera's with its planes.
    ASSERT_TRUE(fit.views.frustum.has_value());
    EXPECT_EQ(fit.views.frustum->z_near, fit.camera.z_near);
    EXPECT_EQ(fit.views.frustum->z_far, fit.camera.z_far);
  }
  FitOptions both;
  both.z_near = 2.0 * farthest;
  both.z_far = 4.0 * farthest;
  const FitResult given = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, both);
  EXPECT_EQ(given.camera.z_near, *both.z_near);
  EXPECT_EQ(given.camera.z_far, *both.z_far);
}

// A plane and one point off it: the DLT's solutions form a plane (10 equations for 11 unknowns),
// and the one it picks can be a nearly singular camera whose rotation factor is a reflection
// while det M rounds positive. The start must treat it as the mirrored reading it is (and look
// for the proper camera, here by the focal sweep), never hand a reflection to the refinement,
// which ended in std::invalid_argument "rotation has det -1" (exit 2) in 6 of these 200 scenes.
// (Most of them are refused -- kPointsBehindCamera: the underdetermined DLT puts a point behind
// -- which is a refusal, if not the right one.)
TEST(FitTest, APlaneAndOnePointNeverStartFromAReflection) {
  for (uint64_t seed = 0; seed < 200; ++seed) {
    std::mt19937_64 rng(testing::Seed(seed));
    RandomCamera camera = MakeRandomCamera(rng);
    camera.intrinsics.fy = camera.intrinsics.fx;
    camera.intrinsics.skew = 0.0;
    camera.intrinsics.cx = 0.5 * (camera.size.width - 1);
    camera.intrinsics.cy = 0.5 * (camera.size.height - 1);
    SceneOptions plane_options;
    plane_options.num_points = 22;
    plane_options.planar = true;
    plane_options.pixel_noise = 0.5;
    Scene scene = MakeScene(rng, camera, plane_options);
    SceneOptions one;
    one.num_points = 1;
    one.pixel_noise = 0.5;
    const Scene off = MakeScene(rng, camera, one);
    scene.points_in_world.push_back(off.points_in_world[0]);
    scene.observed_pixels.push_back(off.observed_pixels[0]);
    FitOptions options;
    options.aspect = ParameterMode::Default();
    options.principal_point = ParameterMode::Default();
    try {
      FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    } catch (const SceneError&) {
      // A refusal is an answer.
    } catch (const std::exception& e) {
      ADD_FAILURE() << "seed " << seed << ": " << e.what();
    }
  }
}

SceneError::Reason RefusalOf(const std::vector<Eigen::Vector3d>& points,
                             const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                             const FitOptions& options, std::string* message) {
  try {
    FitCamera(points, pixels, size, options);
  } catch (const SceneError& e) {
    *message = e.what();
    return e.reason();
  }
  ADD_FAILURE() << "no refusal";
  return SceneError::Reason::kDegenerate;
}

class RefusalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937_64 rng(testing::Seed(5));
    camera_ = ProjectorLikeCamera(rng);
    SceneOptions options;
    options.num_points = 20;
    scene_ = MakeScene(rng, camera_, options);
  }
  RandomCamera camera_;
  Scene scene_;
  std::string message_;
};

TEST_F(RefusalTest, TooFewPointsForTheFreeParameters) {
  std::vector<Eigen::Vector3d> points(scene_.points_in_world.begin(), scene_.points_in_world.begin() + 4);
  std::vector<Eigen::Vector2d> pixels(scene_.observed_pixels.begin(), scene_.observed_pixels.begin() + 4);
  EXPECT_EQ(RefusalOf(points, pixels, camera_.size, {}, &message_), SceneError::Reason::kTooFewPoints);
  EXPECT_NE(message_.find("10 unknowns"), std::string::npos) << message_;
  // Five non-coplanar points with the principal point free: 10 equations, but no linear start.
  points.push_back(scene_.points_in_world[4]);
  pixels.push_back(scene_.observed_pixels[4]);
  EXPECT_EQ(RefusalOf(points, pixels, camera_.size, {}, &message_), SceneError::Reason::kTooFewPoints);
  EXPECT_NE(message_.find("6 non-coplanar"), std::string::npos) << message_;
}

// A point given more than once adds no equation: 4 distinct points, each three times, determine
// pose + focal (8 equations for 7 unknowns; the focal sweep, as the DLT needs 6 distinct
// points) but not the 10 unknowns of the default model. (Before, the 12 rows counted as 12
// points: the DLT ran on 4 distinct ones and refused the scene as points behind the camera.)
// RANSAC's samples are 6 distinct rows without known intrinsics (4 with them, or on a plane,
// where fewer points are refused before): 5 points with the focal length alone free are a
// valid scene, refused for RANSAC by name instead of searching forever for a sample.
TEST_F(RefusalTest, RansacWithFewerPointsThanASample) {
  std::vector<Eigen::Vector3d> points(scene_.points_in_world.begin(), scene_.points_in_world.begin() + 5);
  std::vector<Eigen::Vector2d> pixels(scene_.observed_pixels.begin(), scene_.observed_pixels.begin() + 5);
  FitOptions options;
  options.aspect = options.principal_point = ParameterMode::Default();
  options.ransac = true;
  EXPECT_EQ(RefusalOf(points, pixels, camera_.size, options, &message_),
            SceneError::Reason::kTooFewPoints);
  EXPECT_NE(message_.find("RANSAC draws samples of 6 points; got 5"), std::string::npos) << message_;
}

TEST_F(RefusalTest, RepeatedPointsCountOnce) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (int copy = 0; copy < 3; ++copy) {
    for (int i = 0; i < 4; ++i) {
      points.push_back(scene_.points_in_world[i]);
      pixels.push_back(scene_.true_pixels[i]);
    }
  }
  const Intrinsics& k = camera_.intrinsics;
  FitOptions focal_only;
  focal_only.aspect = ParameterMode::Fixed(k.fy / k.fx);
  focal_only.principal_point = ParameterMode::Fixed(k.cx, k.cy);
  const FitResult fit = FitCamera(points, pixels, camera_.size, focal_only);
  EXPECT_NEAR(fit.camera.intrinsics.fx, k.fx, kRecoveryRelative * k.fx);
  EXPECT_EQ(RefusalOf(points, pixels, camera_.size, {}, &message_), SceneError::Reason::kTooFewPoints);
  EXPECT_NE(message_.find("12 points (4 distinct) give 8 equations"), std::string::npos) << message_;
}

TEST_F(RefusalTest, CollinearPoints) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (int i = 0; i < 10; ++i) {
    points.push_back(Eigen::Vector3d(1, 2, 3) + i * Eigen::Vector3d(0.3, -0.1, 0.2));
    pixels.push_back(Eigen::Vector2d(100 + i, 200 + 2 * i));
  }
  EXPECT_EQ(RefusalOf(points, pixels, camera_.size, {}, &message_), SceneError::Reason::kCollinearPoints);
  EXPECT_NE(message_.find("collinear"), std::string::npos) << message_;
}

TEST_F(RefusalTest, PlanarSceneWithTooManyFreeIntrinsicsNamesWhatToFix) {
  std::mt19937_64 rng(testing::Seed(6));
  SceneOptions options;
  options.planar = true;
  options.num_points = 30;
  const Scene plane = MakeScene(rng, camera_, options);
  EXPECT_EQ(RefusalOf(plane.points_in_world, plane.observed_pixels, camera_.size, {}, &message_),
            SceneError::Reason::kPlanarUnderdetermined);
  EXPECT_NE(message_.find("focal, aspect, principal point are free"), std::string::npos) << message_;
  EXPECT_NE(message_.find("Fix the principal point"), std::string::npos) << message_;
}

TEST_F(RefusalTest, NonFiniteInputNamesThePoint) {
  std::vector<Eigen::Vector3d> points = scene_.points_in_world;
  points[7].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(RefusalOf(points, scene_.observed_pixels, camera_.size, {}, &message_),
            SceneError::Reason::kNonFiniteInput);
  // Numbered from 1, as the points file's rows and the summary number them.
  EXPECT_NE(message_.find("point 8 is not finite"), std::string::npos) << message_;
  EXPECT_NE(message_.find("Remove or fix point 8"), std::string::npos) << message_;
}

// Finite coordinates whose sum overflows (|X| ~ 1e308) cannot be centred: refused as input a
// double cannot hold, with the advice to change units -- not a NaN camera.
TEST_F(RefusalTest, CoordinatesWhoseSumOverflowsAreRefused) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 12; ++i) {
    points.push_back(1e308 * Eigen::Vector3d(i < 6 ? 1 : -1, (i / 2) % 2 ? 1 : -1, i % 2 ? 1 : -1));
  }
  const std::vector<Eigen::Vector2d> pixels(scene_.observed_pixels.begin(),
                                            scene_.observed_pixels.begin() + 12);
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    FitOptions options;
    options.projection = projection;
    options.principal_point = ParameterMode::Default();
    EXPECT_EQ(RefusalOf(points, pixels, camera_.size, options, &message_),
              SceneError::Reason::kNonFiniteInput);
    EXPECT_NE(message_.find("change units"), std::string::npos) << message_;
  }
}

// 1e12 times farther from the origin than from each other, the points keep ~4 digits of their
// positions relative to each other: a camera written in these coordinates moves their pixels by
// ~0.04 px against the fit's (the refusal's own estimate). Refused, naming the fix; 4e6 mm (a
// site in projected map coordinates) is fitted (InvariantToWorldUnitsAndOffsets).
TEST_F(RefusalTest, OffsetsBeyondDoublePrecisionAreRefused) {
  std::vector<Eigen::Vector3d> points = scene_.points_in_world;
  for (auto& x : points) x += Eigen::Vector3d(1e12, -1e12, 1e12);
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    FitOptions options;
    options.projection = projection;
    options.principal_point = ParameterMode::Default();
    EXPECT_EQ(RefusalOf(points, scene_.observed_pixels, camera_.size, options, &message_),
              SceneError::Reason::kNonFiniteInput);
    EXPECT_NE(message_.find("Subtract a common offset"), std::string::npos) << message_;
    // Its numbers to two digits, at most 7 characters ("0.00011", "9.8e+11"): they are
    // estimates (a shortest round-trip form printed 17 digits).
    const std::string number = "[0-9.e+-]{1,7}";
    EXPECT_TRUE(std::regex_search(
        message_, std::regex("^the 3D points are " + number + " times as far from the origin as "
                             "from each other: double precision rounds their positions relative "
                             "to each other by " + number + " of their spread, which moves their "
                             "pixels by about " + number + " px,")))
        << message_;
  }
}

TEST_F(RefusalTest, PointsBehindTheCamera) {
  // Reflecting half the points through the camera centre keeps their pixels (the projective
  // camera cannot tell) but puts them behind it: no real camera sees all of them.
  const Eigen::Vector3d center = CameraCenterInWorld(camera_.cam_from_world);
  std::vector<Eigen::Vector3d> points = scene_.points_in_world;
  for (size_t i = 0; i < points.size(); i += 2) points[i] = 2.0 * center - points[i];
  EXPECT_EQ(RefusalOf(points, scene_.true_pixels, camera_.size, {}, &message_),
            SceneError::Reason::kPointsBehindCamera);
  EXPECT_NE(message_.find("behind"), std::string::npos) << message_;
}

TEST_F(RefusalTest, MirroredWorldIsNamedWithTheFix) {
  std::vector<Eigen::Vector3d> points = scene_.points_in_world;
  for (auto& x : points) x.z() = -x.z();
  EXPECT_EQ(RefusalOf(points, scene_.true_pixels, camera_.size, {}, &message_),
            SceneError::Reason::kMirroredWorld);
  EXPECT_NE(message_.find("left-handed"), std::string::npos) << message_;
  EXPECT_NE(message_.find("Flip one world axis"), std::string::npos) << message_;
}

TEST_F(RefusalTest, PlaneSeenHeadOnDoesNotDetermineTheFocalLength) {
  // A plane parallel to the image plane: distance and focal length trade off exactly.
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  Intrinsics k;
  k.fx = k.fy = 1000;
  k.cx = 639.5;
  k.cy = 399.5;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 4; ++j) {
      const Eigen::Vector3d point_in_cam(-0.8 + 0.4 * i, -0.6 + 0.4 * j, 3.0);
      points.push_back(point_in_cam);
      pixels.push_back(PixelFromCam(k, point_in_cam));
    }
  }
  FitOptions options;
  options.aspect = ParameterMode::Default();
  options.principal_point = ParameterMode::Default();
  EXPECT_EQ(RefusalOf(points, pixels, {1280, 800}, options, &message_), SceneError::Reason::kDegenerate);
  EXPECT_NE(message_.find("fx"), std::string::npos) << message_;
  // With the focal length given, the same points determine the pose.
  options.focal = ParameterMode::Fixed(1000);
  const FitResult fit = FitCamera(points, pixels, {1280, 800}, options);
  EXPECT_LT((CameraCenterInWorld(fit.camera.cam_from_world)).norm(), 1e-9);
}

TEST_F(RefusalTest, BadOptionsAreInvalidArguments) {
  FitOptions options;
  options.loss = LossType::kHuber;
  options.loss_scale_px = 0;
  EXPECT_THROW(FitCamera(scene_.points_in_world, scene_.observed_pixels, camera_.size, options),
               std::invalid_argument);
  options = {};
  options.focal = ParameterMode::Default();
  EXPECT_THROW(FitCamera(scene_.points_in_world, scene_.observed_pixels, camera_.size, options),
               std::invalid_argument);
  std::vector<Eigen::Vector2d> fewer(scene_.observed_pixels.begin(), scene_.observed_pixels.end() - 1);
  EXPECT_THROW(FitCamera(scene_.points_in_world, fewer, camera_.size, {}), std::invalid_argument);
}

TEST_F(RefusalTest, ResultCarriesTraceViewsAndDepthRange) {
  std::mt19937_64 rng(testing::Seed(9));
  SceneOptions options;
  options.num_points = 20;
  options.pixel_noise = 1.0;
  const Scene noisy = MakeScene(rng, camera_, options);
  const FitResult fit = FitCamera(noisy.points_in_world, noisy.observed_pixels, camera_.size, {});
  ASSERT_GE(fit.trace.size(), 2u);
  EXPECT_EQ(fit.trace.front().iteration, 0);
  EXPECT_LE(fit.trace.back().rms_px, fit.trace.front().rms_px);
  EXPECT_NEAR(fit.trace.back().rms_px, fit.rms_px, 1e-9);
  // Near and far: 10 % margin around the points' depths in the fitted camera (2..4 in the true
  // one, MakeScene; the fit's own differ by its error, ~0.2 % here).
  double nearest = std::numeric_limits<double>::infinity();
  double farthest = 0.0;
  for (const Eigen::Vector3d& x : noisy.points_in_world) {
    const double depth = (fit.camera.cam_from_world * x).z();
    nearest = std::min(nearest, depth);
    farthest = std::max(farthest, depth);
  }
  EXPECT_NEAR(fit.camera.z_near, nearest / 1.1, 1e-12 * nearest);
  EXPECT_NEAR(fit.camera.z_far, farthest * 1.1, 1e-12 * farthest);
  EXPECT_GT(nearest, 2.0 * 0.95);
  EXPECT_LT(farthest, 4.0 * 1.05);
  // The look-at target is on the gaze at the points' median depth.
  const Eigen::Vector3d target_in_cam = fit.camera.cam_from_world * fit.views.look_at.target;
  EXPECT_NEAR(target_in_cam.x(), 0.0, 1e-9);
  EXPECT_GT(target_in_cam.z(), 2.0);
  EXPECT_LT(target_in_cam.z(), 4.0);
  EXPECT_TRUE(fit.views.frustum.has_value());
  EXPECT_FALSE(fit.views.perspective.has_value());  // off-axis
}

// A projector-like scene of 40 points at 0.5 px noise, 3 of them (`bad`) mis-clicked: moved by
// (60, -45) px.
Scene ThreeMisclicksInForty(std::mt19937_64& rng, const RandomCamera& camera,
                            std::vector<int>* bad) {
  SceneOptions scene_options;
  scene_options.num_points = 40;
  scene_options.pixel_noise = 0.5;
  Scene scene = MakeScene(rng, camera, scene_options);
  bad->resize(40);
  std::iota(bad->begin(), bad->end(), 0);
  std::shuffle(bad->begin(), bad->end(), rng);
  bad->resize(3);
  for (const int i : *bad) scene.observed_pixels[i] += Eigen::Vector2d(60, -45);
  return scene;
}

// Three mis-clicked points (75 px off) among 40: a Cauchy loss with a 2 px scale keeps the camera
// where least squares on the 37 good points puts it (plain least squares on all 40 is pulled
// away). Per scene, the robust fit's focal error is within 4 sigma of the good points' own fit
// (pixel sigma 0.5 given): the Cauchy weights w = 1 / (1 + (r / 2)^2) of the good points are
// >= 0.94 at 0.5 px noise (efficiency > 0.97, sigma at most 1.05x) and each outlier pulls with
// weight (2 / 75)^2 ~ 1 / 1400, so |error| > 4 sigma has probability about P(|z| > 3.8) = 1.4e-4;
// the rate asserted over 50 scenes is p = 1e-3 per scene. (One scene, as before, failed in 4 of
// 30 seed offsets: the plain fit's error happened to be small there, which is no property.)
// The outliers stand out in every scene's residuals: moved 75 px, predicted within ~1 px.
TEST(FitTest, RobustLossResistsAFewMisclickedPoints) {
  std::mt19937_64 rng(testing::Seed(31));
  constexpr int kScenes = 50;
  int beyond = 0;
  int plain_beyond = 0;
  for (int scene_index = 0; scene_index < kScenes; ++scene_index) {
    const RandomCamera camera = ProjectorLikeCamera(rng);
    std::vector<int> bad;
    const Scene scene = ThreeMisclicksInForty(rng, camera, &bad);
    std::vector<Eigen::Vector3d> good_points;
    std::vector<Eigen::Vector2d> good_pixels;
    for (int i = 0; i < 40; ++i) {
      if (std::find(bad.begin(), bad.end(), i) == bad.end()) {
        good_points.push_back(scene.points_in_world[i]);
        good_pixels.push_back(scene.observed_pixels[i]);
      }
    }
    FitOptions oracle;
    oracle.pixel_sigma = 0.5;
    const FitResult good = FitCamera(good_points, good_pixels, camera.size, oracle);
    double sigma_fx = 0.0;
    for (const ParameterSigma& s : good.sigmas) {
      if (s.name == "fx") sigma_fx = s.sigma;
    }
    ASSERT_GT(sigma_fx, 0.0);
    FitOptions robust;
    robust.loss = LossType::kCauchy;
    robust.loss_scale_px = 2.0;
    const FitResult b = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, robust);
    const FitResult a = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, {});
    if (std::abs(b.camera.intrinsics.fx - camera.intrinsics.fx) > 4.0 * sigma_fx) ++beyond;
    if (std::abs(a.camera.intrinsics.fx - camera.intrinsics.fx) > 4.0 * sigma_fx) ++plain_beyond;
    for (const int i : bad) EXPECT_GT(b.residuals_px[i].norm(), 40.0) << scene_index << " " << i;
    EXPECT_LT(b.median_px, 1.5) << scene_index;
  }
  std::printf("plain least squares: focal beyond 4 sigma in %d of %d scenes\n", plain_beyond,
              kScenes);
  testing::ExpectRate("robust focal beyond 4 sigma of the good points' fit", beyond, kScenes, 1e-3);
}

// With a robust loss the sigmas are Huber's estimate for an M-estimator, v (J^T J)^-1 with
// v = K^2 E[psi^2] / E[psi']^2 from the residuals (fit/assess.cc, RobustVariancePx2), not least
// squares' with the noise from the raw sum of squares: three 75 px outliers among 40 points read
// as ~15 px of noise, the sigmas ~30x too wide (data/projector/misclicked.csv, huber:2: fx
// 1476 +- 801 px for a true 1483.6, before session 44). Cauchy at 2 px on 0.5 px noise: the
// outliers' influence is ~1/1400 of an inlier's (the test above) and v is estimated from
// 2N - p = 71 degrees of freedom (relative sd ~0.08), so |fx error| / sigma is about Student-t
// with 71 dof: P(> 2) = 0.049 and P(< 0.5) = 0.381. The rates asserted, p = 0.07 and 0.45 per
// scene over 200 scenes, leave room for the estimate's approximations; a sigma 2x too small puts
// 32 % beyond 2, one 30x too wide 97 % within 0.5, and either fails.
TEST(FitTest, RobustLossSigmasCoverTheTruthAmongOutliers) {
  std::mt19937_64 rng(testing::Seed(44));
  constexpr int kScenes = 200;
  int beyond_two = 0;
  int within_half = 0;
  double noise_sum = 0.0;
  for (int scene_index = 0; scene_index < kScenes; ++scene_index) {
    const RandomCamera camera = ProjectorLikeCamera(rng);
    std::vector<int> bad;
    const Scene scene = ThreeMisclicksInForty(rng, camera, &bad);
    FitOptions robust;
    robust.loss = LossType::kCauchy;
    robust.loss_scale_px = 2.0;
    const FitResult fit =
        FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, robust);
    double sigma_fx = 0.0;
    for (const ParameterSigma& s : fit.sigmas) {
      if (s.name == "fx") sigma_fx = s.sigma;
    }
    ASSERT_GT(sigma_fx, 0.0) << scene_index;
    const double z = std::abs(fit.camera.intrinsics.fx - camera.intrinsics.fx) / sigma_fx;
    if (z > 2.0) ++beyond_two;
    if (z < 0.5) ++within_half;
    noise_sum += fit.pixel_sigma;
  }
  testing::ExpectRate("robust fx beyond 2 of its sigmas", beyond_two, kScenes, 0.07);
  testing::ExpectRate("robust fx within half of its sigma", within_half, kScenes, 0.45);
  // The noise reported is sqrt(v), least squares' noise for the same scatter: its mean over the
  // scenes within 10 % of the 0.5 px drawn (the outliers add ~(2 px)^2 / 1400 each; the mean of
  // 200 estimates, each of relative sd ~0.08, has sd ~0.003).
  EXPECT_NEAR(noise_sum / kScenes, 0.5, 0.05);
}

// A Cauchy loss whose scale is far below the residuals (0.1 px on 1 px noise: their median 12
// scales) fits a mode the asymptotics do not describe -- its sigmas came out ~10x too small over
// 100 scenes -- so there are none, and the result says why.
TEST(FitTest, RobustLossFarBelowTheNoiseGivesNoSigmas) {
  std::mt19937_64 rng(testing::Seed(45));
  const RandomCamera camera = ProjectorLikeCamera(rng);
  SceneOptions scene_options;
  scene_options.num_points = 30;
  scene_options.pixel_noise = 1.0;
  const Scene scene = MakeScene(rng, camera, scene_options);
  FitOptions cauchy;
  cauchy.loss = LossType::kCauchy;
  cauchy.loss_scale_px = 0.1;
  const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, cauchy);
  EXPECT_FALSE(fit.covariance_available);
  EXPECT_TRUE(fit.sigmas.empty());
  EXPECT_NE(fit.no_uncertainty_why.find("loss's scale is far below the residuals"),
            std::string::npos)
      << fit.no_uncertainty_why;
  cauchy.pixel_sigma = 1.0;  // the same with the noise given
  EXPECT_FALSE(
      FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, cauchy).covariance_available);
  cauchy.loss_scale_px = 2.0;  // at twice the noise: sigmas
  EXPECT_TRUE(
      FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, cauchy).covariance_available);
  cauchy.pixel_sigma.reset();
  EXPECT_TRUE(
      FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, cauchy).covariance_available);
}

// The result names what refined it (docs say the least-squares path is the project's own LM and
// Ceres runs only for a robust loss and the orthographic fit): one scene, every path.
// FitResult::linearity probes the sum of squares at the edge of the 99.99 % region, whose radius
// is proportional to the pixel sigma: the same fit judged at a smaller sigma probes closer. On
// noise-free pixels the Gauss-Newton J^T J is the exact Hessian at the fit (no residual times
// second derivative), so what departs from the quadratic prediction is the Taylor remainder,
// cubic and higher in the radius: the deviation falls with the sigma (to 0). (With noise the
// residuals' curvature term leaves a floor: ~5e-3 at 0.5 px here.) Far beyond it the model's
// curvature (the perspective division, points crossing behind the camera) shows.
TEST(FitTest, LinearityCheckFollowsTheProbedRadius) {
  std::mt19937_64 rng(testing::Seed(34));
  int checked = 0;
  for (int i = 0; i < 20; ++i) {
    const RandomCamera camera = ProjectorLikeCamera(rng);
    SceneOptions scene_options;
    scene_options.num_points = 30;
    const Scene scene = MakeScene(rng, camera, scene_options);
    double previous = 0.0;
    for (const double sigma : {1e-3, 1e-2, 1e-1, 1.0, 1e2}) {
      FitOptions options;
      options.pixel_sigma = sigma;
      const FitResult fit =
          FitCamera(scene.points_in_world, scene.true_pixels, camera.size, options);
      ASSERT_TRUE(fit.linearity.checked);
      EXPECT_EQ(fit.linearity.level, kLinearityLevel);
      EXPECT_EQ(fit.linearity.linear, fit.linearity.worst_deviation <= kMaxLinearityDeviation);
      const double deviation = std::abs(fit.linearity.worst_deviation);
      if (sigma == 1e-3) {
        EXPECT_LT(deviation, 1e-3) << "scene " << i;
        EXPECT_TRUE(fit.linearity.linear) << "scene " << i;
      } else {
        // Ten times the radius: at least the same relative deviation (a 1e-9 rounding floor).
        EXPECT_GE(deviation, previous - 1e-9) << "scene " << i << " sigma " << sigma;
      }
      if (sigma == 1e2) {
        EXPECT_FALSE(fit.linearity.linear) << "scene " << i;
      }
      previous = deviation;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 100);
}

TEST(FitTest, NamesItsRefiner) {
  std::mt19937_64 rng(testing::Seed(33));
  const RandomCamera camera = ProjectorLikeCamera(rng);
  SceneOptions scene_options;
  scene_options.num_points = 30;
  scene_options.pixel_noise = 0.5;
  const Scene scene = MakeScene(rng, camera, scene_options);
  const auto refiner = [&](const FitOptions& options) {
    return FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options).refiner;
  };
  EXPECT_EQ(refiner(FitOptions{}), "levenberg-marquardt");
  FitOptions huber;
  huber.loss = LossType::kHuber;
  huber.loss_scale_px = 2.0;
  EXPECT_EQ(refiner(huber), "ceres, huber loss 2 px");
  FitOptions cauchy;
  cauchy.loss = LossType::kCauchy;
  cauchy.loss_scale_px = 0.5;
  EXPECT_EQ(refiner(cauchy), "ceres, cauchy loss 0.5 px");
  FitOptions start_only;
  start_only.refine = false;
  EXPECT_EQ(refiner(start_only), "none");
  FitOptions orthographic;
  orthographic.projection = Projection::kOrthographic;
  orthographic.focal = ParameterMode::Free();
  orthographic.aspect = ParameterMode::Default();
  orthographic.principal_point = ParameterMode::Default();
  EXPECT_EQ(refiner(orthographic), "ceres");
  orthographic.refine = false;
  EXPECT_EQ(refiner(orthographic), "none");
  FitOptions ceres;
  ceres.refiner = Refiner::kCeres;
  EXPECT_EQ(refiner(ceres), "ceres");
}

// FitOptions::refiner: ceres::Solver in place of the own LM, before the same Gauss-Newton polish,
// reaches the same optimum on the bench's scenes (SynthesizeScene clouds, 1920x1080, fovy 45 deg,
// sigma 0.5 px, a centred camera and a projector; issue #12).
// - Every fit: the polish ends where its last step moves the residuals by at most 1e-3 of their
//   sigma (its convergence rule), which puts each answer within 1e-3 of the covariance's sigma
//   of the minimum in the joint (Mahalanobis) sense, hence each parameter within 1e-3 of its
//   own sigma, and the two answers within 2e-3 sigma of each other.
// - The bench's model (focal, aspect, principal point): where both polishes settle (a step
//   under 1e-9 px: least_squares.cc, kSettledStepPx), every parameter within 1e-9 of its own
//   scale (fx for fx, fy, cx, cy in px; the distance for t; 1 for R), the bound. At 6
//   points (2 residual degrees of freedom) the cost can be flat to its rounding over a region
//   wider than that (seen: Gauss-Newton steps of 3e-6 - 2e-5 px wandering at costs 1e-11 apart,
//   fx 5e-5 px apart), so the 1e-9 bound is a rate: at most 1 % of the comparisons beyond it.
// - With k1 free at 6 points (11 parameters for 12 equations) the valley is so flat that the two
//   refiners' paths can end at different minima, or one short of a minimum and refused (seen at
//   seed offsets 43000, 64000, 70000): a rate, at most 2 %, not a comparison.
// From 20 points on the own LM's path starts with Gauss-Newton steps from the DLT (refine.cc,
// PolishFirst::kFromClosedForm), Ceres' path does not: the bound holds for that start too, and
// the bench's model settles there without LM in most of those fits (counted).
TEST(FitTest, CeresRefinerFindsTheSameOptimum) {
  // Measured: 15 of 6000 comparisons at seed offsets 0-99000 in steps of 1000.
  constexpr double kNotTo1e9Rate = 0.01;
  // Measured: 3 of 1200 at the same offsets.
  constexpr double kOneSpareApartRate = 0.02;
  int one_spare = 0;
  int one_spare_apart = 0;
  int compared = 0;
  int bench_model = 0;
  int beyond_1e9 = 0;
  int gauss_newton_from_dlt = 0;
  for (const int n : {6, 10, 20, 100, 1000}) {
    for (int seed = 1; seed <= 6; ++seed) {
      for (const double offset_y : {0.0, 0.5}) {
        SynthOptions synth;
        synth.seed = testing::Seed(static_cast<uint64_t>(seed));
        synth.num_points = n;
        synth.object = SynthObject::kCloud;
        synth.image_size = ImageSize{1920, 1080};
        synth.fovy_deg = 45.0;
        synth.principal_point_offset = Eigen::Vector2d(0.0, offset_y);
        synth.noise_px = 0.5;
        const SynthScene scene = SynthesizeScene(synth);
        for (const bool with_k1 : {false, true}) {
          FitOptions lm;
          if (with_k1) lm.k1 = ParameterMode::Free();
          FitOptions ceres = lm;
          ceres.refiner = Refiner::kCeres;
          std::optional<FitResult> a, b;
          std::string refused_a, refused_b;
          try {
            a = FitCamera(scene.correspondences.points_in_world, scene.correspondences.pixels,
                          synth.image_size, lm);
          } catch (const SceneError& e) {
            refused_a = e.what();
          }
          try {
            b = FitCamera(scene.correspondences.points_in_world, scene.correspondences.pixels,
                          synth.image_size, ceres);
          } catch (const SceneError& e) {
            refused_b = e.what();
          }
          SCOPED_TRACE(::testing::Message() << "N " << n << " seed " << seed << " offset "
                                            << offset_y << (with_k1 ? " k1" : ""));
          if (with_k1 && n == 6) {
            // 11 parameters, 12 equations: counted, not compared (below).
            ++one_spare;
            bool same = a.has_value() == b.has_value();
            if (same && a) {
              for (const ParameterSigma& pa : a->sigmas) {
                for (const ParameterSigma& pb : b->sigmas) {
                  if (pb.name == pa.name && !(std::abs(pb.value - pa.value) <= 2e-3 * pa.sigma)) {
                    same = false;
                  }
                }
              }
            }
            one_spare_apart += !same;
            continue;
          }
          ASSERT_EQ(a.has_value(), b.has_value()) << refused_a << " | " << refused_b;
          if (!a) continue;
          ++compared;
          EXPECT_EQ(b->refiner, "ceres");
          if (!with_k1) {
            gauss_newton_from_dlt +=
                a->termination.find("Gauss-Newton from the closed form") != std::string::npos;
            const Intrinsics& ka = a->camera.intrinsics;
            const Intrinsics& kb = b->camera.intrinsics;
            constexpr double kSameOptimum = 1e-9;
            const double px = kSameOptimum * ka.fx;
            const Eigen::Vector3d& ta = a->camera.cam_from_world.translation;
            const bool same = std::abs(kb.fx - ka.fx) <= px && std::abs(kb.fy - ka.fy) <= px &&
                              std::abs(kb.cx - ka.cx) <= px && std::abs(kb.cy - ka.cy) <= px &&
                              (b->camera.cam_from_world.translation - ta).norm() <=
                                  kSameOptimum * ta.norm() &&
                              (b->camera.cam_from_world.rotation -
                               a->camera.cam_from_world.rotation)
                                      .norm() <= kSameOptimum;
            ++bench_model;
            beyond_1e9 += !same;
          }
          constexpr double kSameOptimumSigmas = 2e-3;
          ASSERT_TRUE(a->covariance_available);
          for (const ParameterSigma& pa : a->sigmas) {
            for (const ParameterSigma& pb : b->sigmas) {
              if (pb.name != pa.name) continue;
              EXPECT_LE(std::abs(pb.value - pa.value), kSameOptimumSigmas * pa.sigma) << pa.name;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 100);
  testing::ExpectRate("the bench's model not the same optimum to 1e-9", beyond_1e9, bench_model,
                      kNotTo1e9Rate);
  testing::ExpectRate("k1 at 6 points: another minimum, or one refiner refused", one_spare_apart,
                      one_spare, kOneSpareApartRate);
  // Measured: 34-36 at seed offsets 0, 7, 42, 1000; the rest settle only after LM.
  EXPECT_GE(gauss_newton_from_dlt, 30) << "of the 36 fits of the bench's model at 20-1000 points";
}

// Regression (found at seed offset 7, literal seed 12): six points, a projector, 0.5 px noise,
// a minimum with residuals of ~0.05 px, whose cost the polish computes to ~3e-12 of itself. The
// polish used to refuse a Gauss-Newton step whose cost rose by that rounding (it allowed 1e-12),
// leaving the first start 4e-6 px short of the minimum, and the LM and Ceres answers then 1.7e-6
// px apart in cy: beyond the 1e-9 of fx that CeresRefinerFindsTheSameOptimum asserts.
TEST(FitTest, TheRefinersAgreeAtASmallResidualMinimum) {
  SynthOptions synth;
  synth.seed = 12;
  synth.num_points = 6;
  synth.object = SynthObject::kCloud;
  synth.image_size = ImageSize{1920, 1080};
  synth.fovy_deg = 45.0;
  synth.principal_point_offset = Eigen::Vector2d(0.0, 0.5);
  synth.noise_px = 0.5;
  const SynthScene scene = SynthesizeScene(synth);
  FitOptions lm;
  FitOptions ceres = lm;
  ceres.refiner = Refiner::kCeres;
  const FitResult a = FitCamera(scene.correspondences.points_in_world,
                                scene.correspondences.pixels, synth.image_size, lm);
  const FitResult b = FitCamera(scene.correspondences.points_in_world,
                                scene.correspondences.pixels, synth.image_size, ceres);
  constexpr double kSameOptimum = 1e-9;
  const double px = a.camera.intrinsics.fx;
  EXPECT_NEAR(b.camera.intrinsics.fx, a.camera.intrinsics.fx, kSameOptimum * px);
  EXPECT_NEAR(b.camera.intrinsics.cx, a.camera.intrinsics.cx, kSameOptimum * px);
  EXPECT_NEAR(b.camera.intrinsics.cy, a.camera.intrinsics.cy, kSameOptimum * px);
  const Eigen::Vector3d& ta = a.camera.cam_from_world.translation;
  EXPECT_LE((b.camera.cam_from_world.translation - ta).norm(), kSameOptimum * ta.norm());
}

// Regression (NoiseFreeTest GluPerspective at seed offset 123, camera 25): four noise-free points
// 0.2 % off a plane (planar_start: a homography start), a 2481 x 144 image. From the
// homography's camera LM stopped in a local minimum at RMS 0.35 px, fx 361 px and the rotation
// 172 deg off; the focal sweep's valleys, tried too since, reach the exact camera.
TEST(FitTest, FourPointsNearlyOnAPlaneReachTheExactCamera) {
  RandomCamera truth;
  truth.size = ImageSize{2481, 144};
  truth.intrinsics.fx = truth.intrinsics.fy = 2068.7969895710521;
  truth.intrinsics.cx = 1240;
  truth.intrinsics.cy = 71.5;
  truth.cam_from_world.rotation =
      Eigen::Quaterniond(0.187880821257108, 0.42977245267805719, 0.77288344848463542,
                         -0.42737291793156407)
          .toRotationMatrix();
  const Eigen::Vector3d eye(3.5913749282834866, -2.1652257050371788, 6.421371588326851);
  truth.cam_from_world.translation = -(truth.cam_from_world.rotation * eye);
  Scene scene;
  scene.points_in_world = {{0.75672411463969436, -2.7752702131076599, 4.4396054638876885},
                           {1.7687345669584671, -2.8244721519457894, 5.0303593671405817},
                           {1.5569251880125976, -4.5317428635505035, 4.3322187424632794},
                           {0.95650011554919745, -3.2533612555630191, 4.4006209096294038}};
  scene.observed_pixels = {{2018.3098195783498, 96.341474691502611},
                           {1762.2956991701576, 116.71033114481759},
                           {875.12697735387428, 107.78542091458522},
                           {1684.1015018459318, 98.943756451003978}};
  FitOptions options;
  options.pixel_sigma = 1.0;  // the covariance (J^T J)^-1 that the first-order bound reads
  options.aspect = ParameterMode::Default();
  options.principal_point = ParameterMode::Default();
  const FitResult fit =
      FitCamera(scene.points_in_world, scene.observed_pixels, truth.size, options);
  EXPECT_EQ(fit.start_method, "homography");
  EXPECT_LT(fit.rms_px, 1e-6);
  ExpectRecovered(truth, scene, fit, "four points nearly on a plane");
}

// A 3-degree field of view: focal length and distance trade off almost exactly (a telephoto
// view is nearly affine), and the result says so.
TEST(FitTest, ReportsTheFocalDistanceCorrelationOfANarrowView) {
  std::mt19937_64 rng(testing::Seed(32));
  RandomCamera camera = ProjectorLikeCamera(rng);
  camera.intrinsics.fx = camera.intrinsics.fy = 0.5 * camera.size.width / std::tan(1.5 * M_PI / 180.0);
  camera.intrinsics.cx = 0.5 * (camera.size.width - 1);
  camera.intrinsics.cy = 0.5 * (camera.size.height - 1);
  SceneOptions scene_options;
  scene_options.num_points = 50;
  scene_options.pixel_noise = 0.5;
  scene_options.min_depth = 90;
  scene_options.max_depth = 110;
  const Scene scene = MakeScene(rng, camera, scene_options);
  FitOptions options;
  options.aspect = ParameterMode::Default();
  options.principal_point = ParameterMode::Default();
  const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
  bool found = false;
  for (const Correlation& c : fit.strong_correlations) {
    if ((c.first == "fx" || c.second == "fx") && c.first.rfind("eye", 0) == 0) found = true;
  }
  EXPECT_TRUE(found);
  double fovy_sigma = 0.0;
  for (const ParameterSigma& s : fit.sigmas) if (s.name == "fovy_deg") fovy_sigma = s.sigma;
  EXPECT_GT(fovy_sigma, 0.0);
}

// The RMS of the true camera's pixels against a synth scene's observed ones.
double TruthRmsPx(const SynthScene& scene) {
  const Correspondences& c = scene.correspondences;
  double sum = 0.0;
  for (size_t i = 0; i < c.pixels.size(); ++i) {
    sum += (*PixelFromWorld(scene.truth, c.points_in_world[i]) - c.pixels[i]).squaredNorm();
  }
  return std::sqrt(sum / c.pixels.size());
}

// The options `camproj fit --model focal+principal-point` makes.
AutoFitOptions FocalAndPrincipalPoint() {
  AutoFitOptions forced;
  forced.fit.principal_point = ParameterMode::Free();
  forced.fit.aspect = ParameterMode::Fixed(1.0);
  forced.fit.skew = forced.fit.k1 = forced.fit.k2 = ParameterMode::Fixed(0.0);
  return forced;
}

// The true camera is a feasible point of the model, so the fit's cost can never be above the
// truth's: a fit that ends higher stopped in a local minimum. Six points (the fewest for the
// DLT) is where the DLT's principal point is worst and LM most easily trapped.
//
// FitCamera refines from two starts (the DLT's and the image centre's principal point); that is
// a local method and at six points two minima can both fit within the noise (regression case
// below: cy 336 px at RMS 0.76 px against the lens shift's minimum at RMS 0.47 px). Measured:
// 2 distinct scenes of about 6000 end above the truth's cost (CAMPROJ_SEED_OFFSET 0-60 and
// 1001); the rate asserted is p = 1e-3 per scene, 3x that. Starting also from the four edge
// midpoints finds both, but costs 2.6x the default path's instructions at N = 6 (bench
// --stage-cost), so the default path relies instead on its determination check: what
// `camproj fit --model focal+principal-point` runs (FitCameraAuto, forced model) must never
// answer with a camera above the truth's cost -- every seed.
TEST(FitTest, FewPointsNeverEndAboveTheTruthsCost) {
  constexpr int kSeeds = 300;
  int checked = 0;
  int above = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.num_points = 6 + static_cast<int>(seed % 5);
    synth.noise_px = 0.5;
    synth.fovy_deg = 45;
    synth.principal_point_offset = Eigen::Vector2d(0, seed % 2 ? 0.5 : 0.0);
    const SynthScene scene = SynthesizeScene(synth);
    const Correspondences& c = scene.correspondences;
    const double truth_rms = TruthRmsPx(scene);
    FitOptions options;
    options.aspect = ParameterMode::Default();
    try {
      const FitResult fit = FitCamera(c.points_in_world, c.pixels, synth.image_size, options);
      ++checked;
      if (fit.rms_px > truth_rms * (1.0 + 1e-9)) {
        ++above;
        std::printf("seed %llu (synth seed %llu, N %d): FitCamera ends at rms %.6g px above the "
                    "truth's %.6g px\n", static_cast<unsigned long long>(seed),
                    static_cast<unsigned long long>(synth.seed), synth.num_points, fit.rms_px,
                    truth_rms);
      }
    } catch (const SceneError& e) {
      // A refusal is allowed (never a wrong camera); count them so they cannot hide failures.
      RecordProperty("refused_seed_" + std::to_string(seed), e.what());
    }
    try {
      const FitResult fit = FitCameraAuto(c.points_in_world, c.pixels, synth.image_size,
                                          FocalAndPrincipalPoint());
      EXPECT_LE(fit.rms_px, truth_rms * (1.0 + 1e-9))
          << "seed " << seed << " (synth seed " << synth.seed << "): the default path answered a "
          << "local minimum";
    } catch (const SceneError&) {
      // Refused: the determination check saw the other minimum, or the points do not determine.
    }
  }
  EXPECT_GE(checked, 290);
  testing::ExpectRate("FitCamera above the truth's cost at 6-10 points", above, checked, 1e-3);
}

// The regression case of the test above (camproj synth --seed 309 --points 6 --noise 0.5
// --principal-point-offset 0,0.5 --fovy 45; issue #17): FitCamera from its two starts ends at the
// minimum with cy 336 px (RMS 0.758 px; the truth's RMS is 0.607 px). The default path with that
// model forced (camproj fit --model focal+principal-point) answered it too; it refits the model
// from the image edges' principal points at six points (fit/other_minima.h), finds the lens
// shift's minimum (RMS 0.468 px) and refuses the scene as ambiguous -- or, as asserted, answers
// a camera at or below the truth's cost.
TEST(FitTest, SixPointLocalMinimumIsNotAnswered) {
  SynthOptions synth;
  synth.seed = 309;
  synth.num_points = 6;
  synth.noise_px = 0.5;
  synth.fovy_deg = 45;
  synth.principal_point_offset = Eigen::Vector2d(0, 0.5);
  const SynthScene scene = SynthesizeScene(synth);
  const Correspondences& c = scene.correspondences;
  const double truth_rms = TruthRmsPx(scene);
  try {
    const FitResult fit =
        FitCameraAuto(c.points_in_world, c.pixels, synth.image_size, FocalAndPrincipalPoint());
    EXPECT_LE(fit.rms_px, truth_rms * (1.0 + 1e-9));
    EXPECT_NEAR(fit.camera.intrinsics.cy, 1079.5, 3.0 * 30.0);  // its own sigma: 30 px
  } catch (const SceneError&) {
    // A refusal is as good (never the local minimum).
  }
}

// The six-point search for other minima (fit/other_minima.h) often refits into the returned
// minimum again (to ~1e-12 px). That is no rival: it is never named as the other minimum that
// "fits about as well ... and moves a point by" a micro-pixel (seen: 2.5e-12 px, seed 1 here),
// in an answer's determination or in a refusal's message.
TEST(FitTest, TheSameMinimumFoundAgainIsNoRival) {
  constexpr double kSameMinimumPx = 1e-6;  // fit/determination.cc
  const std::string other_minimum = "the same model at another of its minima fits about as well";
  int named = 0;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    SynthOptions synth;
    synth.seed = seed;
    synth.num_points = 6;
    synth.noise_px = 0.5;
    synth.object = SynthObject::kBox;
    synth.principal_point_offset = Eigen::Vector2d(0, 0.4);
    const SynthScene scene = SynthesizeScene(synth);
    const Correspondences& c = scene.correspondences;
    std::string text;
    try {
      const FitResult fit =
          FitCameraAuto(c.points_in_world, c.pixels, synth.image_size, FocalAndPrincipalPoint());
      text = fit.determination.summary;
      if (!fit.determination.rival.empty()) {
        EXPECT_GT(fit.determination.rival_shift_px, kSameMinimumPx) << "seed " << seed;
      }
    } catch (const SceneError& e) {
      text = e.what();
    }
    const size_t at = text.find(other_minimum);
    if (at == std::string::npos) continue;
    ++named;
    const std::string by = "moves a point by ";
    const size_t shift_at = text.find(by, at);
    ASSERT_NE(shift_at, std::string::npos) << text;
    EXPECT_GT(std::stod(text.substr(shift_at + by.size())), kSameMinimumPx)
        << "seed " << seed << ": " << text;
  }
  std::printf("[ INFO ] other minima named as rivals: %d of 40 scenes\n", named);
}

// Six points of a projector (principal point at the bottom edge) at `noise_px`.
SynthOptions SixPointProjector(uint64_t seed, double noise_px) {
  SynthOptions synth;
  synth.seed = seed;
  synth.num_points = 6;
  synth.noise_px = noise_px;
  synth.principal_point_offset = Eigen::Vector2d(0, 0.5);
  return synth;
}

// Under noise a six-point DLT of a right-handed world can flip its determinant's sign; the fitter
// then refines both readings and believes the mirror only when it fits better. So a right-handed
// scene is never refused as definitely left-handed (a refusal, if any, must say the data cannot
// tell), and any camera it returns is no worse than the truth (the truth is feasible) -- but
// for a rate: LM from the closed forms can still end in a higher local minimum, in 7 of 80000 of
// these fits at synth seeds 1-40000 (rms 3.1-28 px for the truth's 2.6-10), so p 2e-4 per fit,
// above the 99 % upper limit of that rate (1.8e-4). A left-handed copy of a noise-free scene fits
// no proper camera and is always refused.
TEST(FitTest, NoisySixPointScenesAreNotCalledMirrored) {
  constexpr double kAboveTheTruthRate = 2e-4;
  int flipped_refusals = 0, fitted = 0, above_the_truth = 0;
  for (uint64_t seed = 1; seed <= 400; ++seed) {
    for (const double noise_px : {2.0, 5.0}) {
      SynthOptions synth = SixPointProjector(testing::Seed(seed), noise_px);
      const SynthScene scene = SynthesizeScene(synth);
      const Correspondences& c = scene.correspondences;
      try {
        const FitResult fit = FitCamera(c.points_in_world, c.pixels, synth.image_size);
        ++fitted;
        if (!(fit.rms_px <= TruthRmsPx(scene) * (1.0 + 1e-9))) {
          ++above_the_truth;
          std::printf("seed %llu noise %g: rms %g px above the truth's %g px\n",
                      static_cast<unsigned long long>(seed), noise_px, fit.rms_px,
                      TruthRmsPx(scene));
        }
      } catch (const SceneError& e) {
        if (e.reason() != SceneError::Reason::kAmbiguous) continue;
        ++flipped_refusals;
        EXPECT_NE(std::string(e.what()).find("too few points or too much noise to tell"),
                  std::string::npos)
            << "seed " << seed << " noise " << noise_px << ": " << e.what();
      }
      if (noise_px == 2.0 && seed <= 100) {
        synth.noise_px = 0.0;
        const SynthScene exact = SynthesizeScene(synth);
        std::vector<Eigen::Vector3d> mirrored = exact.correspondences.points_in_world;
        for (auto& x : mirrored) x.z() = -x.z();
        try {
          FitCamera(mirrored, exact.correspondences.pixels, synth.image_size);
          ADD_FAILURE() << "seed " << seed << ": a mirrored world was fitted";
        } catch (const SceneError& e) {
          EXPECT_EQ(e.reason(), SceneError::Reason::kMirroredWorld) << e.what();
        }
      }
    }
  }
  RecordProperty("ambiguous_mirror_refusals", flipped_refusals);
  testing::ExpectRate("fits above the truth's cost", above_the_truth, fitted, kAboveTheTruthRate);
}

// Regression (NoisySixPointScenesAreNotCalledMirrored at seed offsets 2024 and 77777): the four
// of synth seeds 1-4000 (at 2 and 5 px) whose fit ended above the truth's cost, each in a minimum
// with an intrinsic no lens has (aspect 0.56 / 2.26 / 1.46 with the principal point 4.5 image
// widths off / 0.67 with it 1.7 heights off): rms 85.7, 7.69, 7.52, 2.40 px for the truth's 6.28,
// 5.45, 3.00, 2.33 px. The focal sweep's valleys, tried there since, reach a lower minimum.
TEST(FitTest, SixNoisyPointsAreNotLeftInAMinimumNoLensHas) {
  const std::pair<uint64_t, double> cases[] = {{1623, 5.0}, {2099, 5.0}, {2232, 2.0}, {3431, 2.0}};
  for (const auto& [seed, noise_px] : cases) {
    const SynthOptions synth = SixPointProjector(seed, noise_px);
    const SynthScene scene = SynthesizeScene(synth);
    const Correspondences& c = scene.correspondences;
    const FitResult fit = FitCamera(c.points_in_world, c.pixels, synth.image_size);
    EXPECT_LE(fit.rms_px, TruthRmsPx(scene) * (1.0 + 1e-9)) << "seed " << seed;
  }
}

// An orthographic camera with skew and aspect, seen through a 3D cloud: noise-free, the affine
// start is exact (the full affine model is linear) and the fit recovers scale, aspect, skew and
// rotation to rounding, and the image offset (the eye's lateral position) too; the principal
// point is not a parameter. With 0.5 px noise the reported sigmas cover the error: each within 5
// sigma (Gaussian two-sided 6e-7 per check).
TEST(OrthographicFitTest, RecoversTheCameraAndReportsItsUncertainty) {
  std::mt19937_64 rng(testing::Seed(21));
  for (int trial = 0; trial < 50; ++trial) {
    Camera truth;
    truth.image_size = {1280, 720};
    truth.projection = Projection::kOrthographic;
    truth.intrinsics.fx = testing::LogUniform(rng, 10, 1000);
    truth.intrinsics.fy = truth.intrinsics.fx * testing::Uniform(rng, 0.9, 1.1);
    truth.intrinsics.skew = truth.intrinsics.fx * testing::Uniform(rng, -0.05, 0.05);
    truth.intrinsics.cx = 639.5;
    truth.intrinsics.cy = 359.5;
    // The centre is drawn before the rotation (testing::DrawVector3 says why).
    const Eigen::Vector2d center_xy = testing::DrawVector2([&] { return testing::Uniform(rng, -5, 5); });
    const Eigen::Vector3d center(center_xy.x(), center_xy.y(), 50.0);
    truth.cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng), center);
    const Rigid3 world_from_cam = Inverse(truth.cam_from_world);
    const double half_width = 600.0 / truth.intrinsics.fx;  // world units across half the image
    for (const double noise : {0.0, 0.5}) {
      std::normal_distribution<double> gaussian(0.0, noise);
      std::vector<Eigen::Vector3d> points;
      std::vector<Eigen::Vector2d> pixels;
      for (int i = 0; i < 40; ++i) {
        const Eigen::Vector3d in_cam = testing::UniformVector3(
            rng, Eigen::Vector3d(-0.9 * half_width, -0.5 * half_width, 5),
            Eigen::Vector3d(0.9 * half_width, 0.5 * half_width, 5 + half_width));
        points.push_back(world_from_cam * in_cam);
        pixels.push_back(*PixelFromWorld(truth, points.back()) +
                         testing::DrawVector2([&] { return gaussian(rng); }));
      }
      FitOptions options;
      options.projection = Projection::kOrthographic;
      options.aspect = ParameterMode::Free();
      options.principal_point = ParameterMode::Default();
      options.skew = ParameterMode::Free();
      const FitResult fit = FitCamera(points, pixels, truth.image_size, options);
      EXPECT_EQ(fit.camera.projection, Projection::kOrthographic);
      EXPECT_EQ(fit.model, "orthographic+aspect+skew");
      const Eigen::Matrix3d rotation_error =
          fit.camera.cam_from_world.rotation * truth.cam_from_world.rotation.transpose();
      const double angle_deg = Eigen::AngleAxisd(rotation_error).angle() * 180.0 / M_PI;
      if (noise == 0.0) {
        EXPECT_LT(fit.rms_px, 1e-9) << "trial " << trial;
        EXPECT_NEAR(fit.camera.intrinsics.fx, truth.intrinsics.fx, 1e-9 * truth.intrinsics.fx);
        EXPECT_NEAR(fit.camera.intrinsics.fy, truth.intrinsics.fy, 1e-9 * truth.intrinsics.fx);
        EXPECT_NEAR(fit.camera.intrinsics.skew, truth.intrinsics.skew, 1e-9 * truth.intrinsics.fx);
        EXPECT_LT(angle_deg, 1e-8) << "trial " << trial;
        for (const Eigen::Vector3d& x : points) {
          EXPECT_LT((*PixelFromWorld(fit.camera, x) - *PixelFromWorld(truth, x)).norm(), 1e-8);
        }
        continue;
      }
      int checked = 0;
      for (const ParameterSigma& s : fit.sigmas) {
        double truth_value = NAN;
        if (s.name == "fx") truth_value = truth.intrinsics.fx;
        if (s.name == "fy") truth_value = truth.intrinsics.fy;
        if (s.name == "skew") truth_value = truth.intrinsics.skew;
        if (std::isnan(truth_value)) continue;
        EXPECT_LE(std::abs(s.value - truth_value), 5.0 * s.sigma) << s.name << " trial " << trial;
        ++checked;
      }
      EXPECT_EQ(checked, 3) << "trial " << trial;
    }
  }
}

// The refinement can cross to a negative scale or fy (most often on points no orthographic
// camera explains, but also on clean perspective scenes): the same image as the positive values
// with the camera's axes turned over. Every fit returns positive fx and fy and a camera that
// reproduces its own residuals -- before, 6 of these 400 ended in std::invalid_argument "fx must
// be positive" (exit 2), and one such candidate aborted the whole automatic selection.
TEST(OrthographicFitTest, ScaleAndAspectComeBackPositive) {
  for (int seed = 0; seed < 400; ++seed) {
    std::mt19937_64 rng(testing::Seed(seed));
    const RandomCamera camera = MakeRandomCamera(rng);
    SceneOptions scene_options;
    scene_options.num_points = 6 + seed % 20;
    scene_options.pixel_noise = 1.0;
    Scene scene = MakeScene(rng, camera, scene_options);
    std::vector<Eigen::Vector2d>& pixels = scene.observed_pixels;
    if (seed % 4 == 1) {
      for (auto& p : pixels) p = testing::RandomPixelInImage(rng, camera.size);
    }
    if (seed % 4 == 2) {
      for (auto& x : scene.points_in_world) x.z() = -x.z();
    }
    if (seed % 4 == 3) std::shuffle(pixels.begin(), pixels.end(), rng);
    FitOptions options;
    options.projection = Projection::kOrthographic;
    options.principal_point = ParameterMode::Default();
    options.aspect = (seed / 4) % 2 ? ParameterMode::Free() : ParameterMode::Default();
    options.skew = (seed / 8) % 2 ? ParameterMode::Free() : ParameterMode::Default();
    FitResult fit;
    try {
      fit = FitCamera(scene.points_in_world, pixels, camera.size, options);
    } catch (const SceneError&) {
      continue;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "seed " << seed << ": " << e.what();
      continue;
    }
    EXPECT_GT(fit.camera.intrinsics.fx, 0.0) << seed;
    EXPECT_GT(fit.camera.intrinsics.fy, 0.0) << seed;
    // The residuals as a reader of the camera recomputes them: the same up to rounding, on the
    // scenes a camera explains (seed % 4 == 0, 2: random or shuffled pixels give fits of any
    // conditioning, e.g. a 5000:1 aspect with skew 150 fx, where the two paths' roundings cancel
    // arbitrarily). The fit computes them in its normalized world (X - centroid) / scale, the
    // reader from the world point through the returned camera (its rotation via a quaternion,
    // its eye mapped back and moved along the view axis in front of the points). Each of the ~50
    // operations on the two paths errs by a unit roundoff of the magnitude it handles, at most
    // (|fx| + |fy| + |skew|) (|X| + |C|) + |c| + |pixel| in pixels; 128 unit roundoffs of that
    // leave a margin of 2.5, and are far below any real discrepancy (a sign or frame error moves
    // pixels by the image's size). (A fixed 1e-9 px failed at 6 of 30 seed offsets: orthographic
    // scales of 1e4-1e5 px per unit on points 10 units from the origin.)
    constexpr double kResidualRoundings = 128.0;
    if (seed % 4 == 1 || seed % 4 == 3) continue;
    const Intrinsics& k = fit.camera.intrinsics;
    const double eye = CameraCenterInWorld(fit.camera.cam_from_world).norm();
    for (size_t i = 0; i < pixels.size(); ++i) {
      const std::optional<Eigen::Vector2d> predicted =
          PixelFromWorld(fit.camera, scene.points_in_world[i]);
      ASSERT_TRUE(predicted) << seed;
      const double magnitude =
          (std::abs(k.fx) + std::abs(k.fy) + std::abs(k.skew)) *
              (scene.points_in_world[i].norm() + eye) +
          std::abs(k.cx) + std::abs(k.cy) + pixels[i].norm();
      EXPECT_LT((*predicted - pixels[i] - fit.residuals_px[i]).norm(),
                kResidualRoundings * 0x1p-53 * magnitude)
          << seed;
    }
  }
}

TEST(OrthographicFitTest, PlanesAndAFreePrincipalPointAreRefused) {
  std::vector<Eigen::Vector3d> plane;
  std::vector<Eigen::Vector2d> pixels;
  for (int i = 0; i < 10; ++i) {
    plane.emplace_back(i % 4, i / 4, 0.0);
    pixels.emplace_back(10.0 * (i % 4), 10.0 * (i / 4) + 0.1 * i);
  }
  FitOptions options;
  options.projection = Projection::kOrthographic;
  options.principal_point = ParameterMode::Default();
  options.aspect = ParameterMode::Default();
  try {
    FitCamera(plane, pixels, {640, 480}, options);
    ADD_FAILURE() << "a plane was fitted orthographically";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kPlanarUnderdetermined);
    EXPECT_NE(std::string(e.what()).find("mirror-image"), std::string::npos) << e.what();
  }
  options.principal_point = ParameterMode::Free();
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

struct RansacCase {
  const char* name;
  double outlier_fraction;
  bool planar;
  bool known_intrinsics;
};

class RansacTest : public ::testing::TestWithParam<RansacCase> {};

// Outliers are pixels anywhere in the image. With 0.5 px noise an inlier lies beyond the 4 px
// threshold with probability exp(-32) and an outlier within it with probability ~1e-4 (a 4 px
// disc in a 1280 x 800 image), so the outlier set must come back exactly; the camera then comes
// from the inliers alone: its focal length and rotation within 4 of its own sigmas (pixel sigma
// 0.5 given) of the truth. |error| > 4 sigma has probability 6.3e-5 per Gaussian parameter; over
// the focal length and the three rotation angles (Bonferroni) p = 1e-3 per trial is asserted as
// a rate over the case's 20 trials.
TEST_P(RansacTest, FindsTheOutliersAndTheCamera) {
  const RansacCase& c = GetParam();
  std::mt19937_64 rng(testing::Seed(std::hash<std::string>{}(c.name)));
  constexpr int kTrials = 20;
  int beyond = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    RandomCamera camera = ProjectorLikeCamera(rng);
    if (c.planar) camera.intrinsics.fy = camera.intrinsics.fx;
    SceneOptions scene_options;
    scene_options.num_points = 80;
    scene_options.pixel_noise = 0.5;
    scene_options.planar = c.planar;
    Scene scene = MakeScene(rng, camera, scene_options);
    std::vector<int> truth_outliers;
    for (int i = 0; i < scene_options.num_points; ++i) {
      if (testing::Uniform(rng, 0, 1) < c.outlier_fraction) {
        scene.observed_pixels[i] = testing::RandomPixelInImage(rng, camera.size);
        if ((scene.observed_pixels[i] - scene.true_pixels[i]).norm() > 8.0) truth_outliers.push_back(i);
        else scene.observed_pixels[i] = scene.true_pixels[i];
      }
    }
    FitOptions options;
    options.ransac = true;
    options.pixel_sigma = 0.5;
    if (c.known_intrinsics) options.known_intrinsics = camera.intrinsics;
    if (c.planar) {
      options.aspect = ParameterMode::Default();
      options.principal_point = ParameterMode::Fixed(camera.intrinsics.cx, camera.intrinsics.cy);
    }
    const FitResult fit = FitCamera(scene.points_in_world, scene.observed_pixels, camera.size, options);
    EXPECT_EQ(fit.outliers, truth_outliers) << c.name << " trial " << trial;
    EXPECT_LT(fit.rms_px, 1.0) << c.name;
    const Eigen::VectorXd error = EstimationError(fit, camera);
    bool within = true;
    for (size_t j = 0; j < fit.free_parameters.size(); ++j) {
      const std::string& name = fit.free_parameters[j];
      if (name != "fx" && name.rfind("rotation_", 0) != 0) continue;
      for (const ParameterSigma& s : fit.sigmas) {
        if (s.name == name && std::abs(error(j)) > 4.0 * s.sigma) within = false;
      }
    }
    if (!within) ++beyond;
  }
  testing::ExpectRate(std::string(c.name) + ": focal or rotation beyond 4 sigma", beyond, kTrials,
                      1e-3);
}

INSTANTIATE_TEST_SUITE_P(
    OutlierFractions, RansacTest,
    ::testing::Values(RansacCase{"Outliers10", 0.1, false, false},
                      RansacCase{"Outliers30", 0.3, false, false},
                      RansacCase{"Outliers50", 0.5, false, false},
                      RansacCase{"Planar30", 0.3, true, false},
                      RansacCase{"KnownIntrinsics50", 0.5, false, true}),
    [](const ::testing::TestParamInfo<RansacCase>& info) { return info.param.name; });

}  // namespace
}  // namespace camproj

#include "camproj/model_select.h"

#include <cmath>
#include <optional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "camproj/synth.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

bool HasWhy(const FitResult& fit, const std::string& name, const std::string& why_prefix) {
  for (const FixedParameter& p : fit.fixed_parameters) {
    if (p.name == name) return p.why.rfind(why_prefix, 0) == 0;
  }
  return false;
}

SynthScene Projector(uint64_t seed, int num_points, double noise_px, double cy_offset,
                     double aspect = 1.0) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = num_points;
  synth.noise_px = noise_px;
  synth.principal_point_offset = Eigen::Vector2d(0.0, cy_offset);
  synth.aspect = aspect;
  return SynthesizeScene(synth);
}

FitResult Auto(const SynthScene& scene, const AutoFitOptions& options = {}) {
  return FitCameraAuto(scene.correspondences.points_in_world, scene.correspondences.pixels,
                       scene.truth.image_size, options);
}

// A gluPerspective camera (square pixels, centred principal point) with 1 px noise: every extra
// group is null, so BIC frees one only when its chi-square(1) drop in J / sigma^2 exceeds
// ln(2N) = ln 60 = 4.09: P = 4.3 % per candidate, at most 4 candidates in the first round, so
// P(overfit) <= 17 % per scene (union bound; the noise estimate's own spread adds a little).
// Over 200 scenes the count of overfits is binomial(200, <= 0.17): mean <= 34, sd 5.3; the
// bound 55 is 4 sd above.
TEST(ModelSelectTest, PerspectiveCameraKeepsTheSimplestModel) {
  int simplest = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    FitResult fit;
    try {
      fit = Auto(Projector(seed, 30, 1.0, 0.0));
    } catch (const SceneError& e) {
      // The one refusal allowed: a chance extra parameter (BIC keeps one with probability
      // P(chi2_1 > ln 60) = 4 %) whose camera the simpler model puts elsewhere (kAmbiguous), or
      // that leaves the camera undetermined over the points' box (the determination check's
      // kDegenerate: seen at seed offset 500, k1 + k2 chosen, 5.66 px at 1 sigma).
      const bool undetermined =
          e.reason() == SceneError::Reason::kDegenerate &&
          std::string(e.what()).find("do not determine the camera well enough") !=
              std::string::npos;
      EXPECT_TRUE(e.reason() == SceneError::Reason::kAmbiguous || undetermined)
          << "seed " << seed << ": " << e.what();
      continue;
    }
    if (fit.model == "pose+focal") ++simplest;
    // Every candidate not in the model is listed with its reason.
    for (const char* name : {"aspect", "principal point", "skew", "k1", "k2"}) {
      if (fit.model.find(name == std::string("principal point") ? "principal-point" : name) ==
          std::string::npos) {
        EXPECT_TRUE(HasWhy(fit, name, "left out: ")) << "seed " << seed << " " << name;
      }
    }
  }
  EXPECT_GE(simplest, 200 - 55);
  RecordProperty("simplest_of_200", simplest);
}

// The fit of `scene`, or nullopt where the determination check refuses it (kAmbiguous: a rival
// that fits about as well puts the scene elsewhere; kDegenerate: too uncertain); any other
// refusal fails the test.
std::optional<FitResult> AutoUnlessUndetermined(const SynthScene& scene) {
  try {
    return Auto(scene);
  } catch (const SceneError& e) {
    EXPECT_TRUE(e.reason() == SceneError::Reason::kAmbiguous ||
                e.reason() == SceneError::Reason::kDegenerate)
        << e.what();
  }
  return std::nullopt;
}

// Clean 30-point scenes are refused as not determined now and then: a rival that fits about as
// well (e.g. + k1 for + principal point, 5.1-5.7 px apart against the 5 px bound). Measured on
// synth seeds 1-2000 (what the two tests below draw, without a seed offset): the projector 1,
// the stretched pixels 4, the 40 deg view 2, the 0.03 deg view 6 of 2000 each. Each test allows
// kUndeterminedAllowed of its fits: at the 99 % upper limit of those rates (2.9e-3 and 3.9e-3
// per fit) P(3 or more) is 0.4 % over 100 fits and 0.06 % over 40.
constexpr int kUndeterminedAllowed = 2;

// Effects far above the noise are always kept: a principal point at the bottom edge moves every
// pixel by ~540 px against 0.5 px noise; an aspect of 1.05 moves the image's top edge by ~27 px.
TEST(ModelSelectTest, KeepsWhatTheDataNeed) {
  int undetermined = 0;
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    if (const std::optional<FitResult> projector =
            AutoUnlessUndetermined(Projector(seed, 30, 0.5, 0.5))) {
      EXPECT_NE(projector->model.find("principal-point"), std::string::npos)
          << "seed " << seed << ": " << projector->model;
    } else {
      ++undetermined;
    }
    if (const std::optional<FitResult> stretched =
            AutoUnlessUndetermined(Projector(seed, 30, 0.5, 0.0, 1.05))) {
      EXPECT_NE(stretched->model.find("aspect"), std::string::npos)
          << "seed " << seed << ": " << stretched->model;
    } else {
      ++undetermined;
    }
  }
  EXPECT_LE(undetermined, kUndeterminedAllowed);
}

// Radial distortion k1 = -0.2 at a 60 degree horizontal field of view in 1280 x 800 (corner at
// normalized radius 0.68) moves the corner by ~70 px against 0.5 px noise: kept, and the fitted
// k1 is within 5 of the reported sigmas of the truth (two-sided Gaussian 5 sigma: 6e-7 per
// check).
TEST(ModelSelectTest, KeepsRadialDistortionWhenTheLensHasIt) {
  std::mt19937_64 rng(testing::Seed(7));
  for (int trial = 0; trial < 20; ++trial) {
    testing::RandomCamera camera = testing::MakeRandomCamera(rng);
    camera.size = {1280, 800};
    Intrinsics& k = camera.intrinsics;
    k.fx = k.fy = 640.0 / std::tan(30.0 * M_PI / 180.0);
    k.cx = 639.5;
    k.cy = 399.5;
    k.skew = 0.0;
    k.k1 = -0.2;
    testing::SceneOptions scene_options;
    scene_options.num_points = 100;
    scene_options.pixel_noise = 0.5;
    const testing::Scene scene = testing::MakeScene(rng, camera, scene_options);
    const FitResult fit =
        FitCameraAuto(scene.points_in_world, scene.observed_pixels, camera.size);
    ASSERT_NE(fit.model.find("k1"), std::string::npos) << "trial " << trial << ": " << fit.model;
    for (const ParameterSigma& s : fit.sigmas) {
      if (s.name == "k1") {
        EXPECT_LE(std::abs(s.value - -0.2), 5.0 * s.sigma) << "trial " << trial;
      }
    }
  }
}

// One view of a plane cannot determine the principal point with the focal length: it is left
// out as not determined (the fit with it is refused), never fitted.
TEST(ModelSelectTest, PlaneLeavesOutWhatItCannotDetermine) {
  SynthOptions synth;
  synth.object = SynthObject::kPlane;
  synth.num_points = 30;
  synth.noise_px = 0.5;
  const SynthScene scene = SynthesizeScene(synth);
  const FitResult fit = Auto(scene);
  EXPECT_EQ(fit.model.find("principal-point"), std::string::npos) << fit.model;
  EXPECT_TRUE(HasWhy(fit, "principal point", "left out: not determined")) << fit.model;
}

// The caller's choices bind: a forced parameter is in every model tried, a given one in none.
TEST(ModelSelectTest, ForcedAndGivenParametersAreRespected) {
  const SynthScene scene = Projector(3, 30, 0.5, 0.5);
  AutoFitOptions options;
  options.fit.skew = ParameterMode::Free();
  options.fit.principal_point = ParameterMode::Fixed(959.5, 1079.5);
  const FitResult fit = Auto(scene, options);
  for (const ModelCandidate& c : fit.candidates) {
    EXPECT_NE(c.name.find("skew"), std::string::npos) << c.name;
    EXPECT_EQ(c.name.find("principal-point"), std::string::npos) << c.name;
  }
  EXPECT_TRUE(HasWhy(fit, "principal point", "given")) << fit.model;
  EXPECT_EQ(fit.candidates.back().verdict.empty(), false);
}

// Noise-free data of an off-axis camera: the selection noise is the prior alone over the
// richest model's residual degrees of freedom (its residuals are zero): 1 px * sqrt(10 / (10 +
// 2 * 20 - 13)) with the prior weight 10 and 13 parameters (pose, focal, aspect, principal point,
// skew, k1, k2); the principal point is kept and the camera recovered exactly (1e-9 relative,
// as FitCamera).
TEST(ModelSelectTest, ExactDataGiveTheExactCamera) {
  const SynthScene scene = Projector(5, 20, 0.0, 0.5);
  const FitResult fit = Auto(scene);
  EXPECT_EQ(fit.model, "pose+focal+principal-point");
  EXPECT_NEAR(fit.selection_sigma_px, std::sqrt(10.0 / 37.0), 1e-12);
  EXPECT_NEAR(fit.camera.intrinsics.fx, scene.truth.intrinsics.fx, 1e-9 * scene.truth.intrinsics.fx);
  EXPECT_NEAR(fit.camera.intrinsics.cy, scene.truth.intrinsics.cy, 1e-9 * scene.truth.intrinsics.fx);
}

// A 0.03 degree telephoto view of a 1-unit cloud: the perspective is not observable and the
// orthographic camera is chosen. synth.cc puts the cloud at 0.4 / tan(fovy / 2), so the depth
// spread moves a point at the image's edge (540 px from the centre) by at most
// 540 x 1 / distance = 1350 tan(fovy / 2) = 0.35 px, ~0.12 px typically: over 30 points a
// chi-square gain of ~30 (0.12 / 0.5)^2 ~ 1.7, below the ln(60) = 4.1 that BIC charges for the
// focal length. (At 0.1 degrees it is 1.2 px at most, a gain that pays in some draws: pose +
// focal was chosen in 6 of 150 seeds there, in 0 of 150 at 0.03 degrees: camproj synth --seed S
// --points 30 --noise 0.5 --fovy F, camproj fit.)
// It must predict the true image:
// over the scene's points, the RMS difference between its pixels and the truth's is within what
// 0.5 px noise on 30 points leaves in a 6-parameter fit, sqrt(6 / 30) * 0.5 * sqrt(2) = 0.32 px
// in expectation; 3x that bounds it. At 40 degrees the perspective is overwhelming (BIC
// differences of thousands): never orthographic.
// (The 0.03 deg view's refusals: its perspective camera chosen by chance, fx ~2e5 px, whose
// confidence region reaches cameras that see points from behind. A perspective fit that ran
// through the orthographic limit to points behind it was refused as inconsistent correspondences
// in 3 more of 2000 before the affine camera's test, selection.cc AffineExplains.)
TEST(ModelSelectTest, OrthographicWhenThePerspectiveIsNotObservable) {
  int undetermined = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.num_points = 30;
    synth.noise_px = 0.5;
    synth.fovy_deg = 0.03;
    const SynthScene tele = SynthesizeScene(synth);
    if (const std::optional<FitResult> fit = AutoUnlessUndetermined(tele)) {
      ASSERT_EQ(fit->camera.projection, Projection::kOrthographic)
          << "seed " << seed << ": " << fit->model;
      double sum = 0.0;
      for (const Eigen::Vector3d& x : tele.correspondences.points_in_world) {
        sum += (*PixelFromWorld(fit->camera, x) - *PixelFromWorld(tele.truth, x)).squaredNorm();
      }
      EXPECT_LT(std::sqrt(sum / 30.0), 3.0 * std::sqrt(6.0 / 30.0) * 0.5 * std::sqrt(2.0))
          << "seed " << seed;
    } else {
      ++undetermined;
    }

    synth.fovy_deg = 40.0;
    if (const std::optional<FitResult> fit = AutoUnlessUndetermined(SynthesizeScene(synth))) {
      EXPECT_EQ(fit->camera.projection, Projection::kPerspective) << "seed " << seed;
    } else {
      ++undetermined;
    }
  }
  EXPECT_LE(undetermined, kUndeterminedAllowed);
}

// Regression (the 0.03 deg view at synth seed 405): the perspective fit runs through the
// orthographic limit to a camera with points behind it, which refused the clean scene as
// inconsistent correspondences; the affine camera explains the points, and the orthographic
// camera is the answer, within the bound above.
TEST(ModelSelectTest, APerspectiveFitLostBeyondTheOrthographicLimitIsNoContamination) {
  SynthOptions synth;
  synth.seed = 405;
  synth.num_points = 30;
  synth.noise_px = 0.5;
  synth.fovy_deg = 0.03;
  const SynthScene tele = SynthesizeScene(synth);
  FitOptions perspective;
  perspective.aspect = ParameterMode::Default();
  perspective.principal_point = ParameterMode::Default();
  try {
    FitCamera(tele.correspondences.points_in_world, tele.correspondences.pixels,
              tele.truth.image_size, perspective);
    ADD_FAILURE() << "the perspective fit is no longer refused: this case tests nothing";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kPointsBehindCamera) << e.what();
  }
  const FitResult fit = Auto(tele);
  EXPECT_EQ(fit.camera.projection, Projection::kOrthographic) << fit.model;
  double sum = 0.0;
  for (const Eigen::Vector3d& x : tele.correspondences.points_in_world) {
    sum += (*PixelFromWorld(fit.camera, x) - *PixelFromWorld(tele.truth, x)).squaredNorm();
  }
  EXPECT_LT(std::sqrt(sum / 30.0), 3.0 * std::sqrt(6.0 / 30.0) * 0.5 * std::sqrt(2.0));
}

TEST(ModelSelectTest, RobustLossIsRefusedWithTheAlternative) {
  AutoFitOptions options;
  options.fit.loss = LossType::kHuber;
  try {
    options.Check();
    ADD_FAILURE() << "a robust loss was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("RANSAC"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace camproj

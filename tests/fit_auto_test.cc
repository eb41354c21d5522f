// The default path (FitCameraAuto: what `camproj fit` runs with no options) on the scenes
// projection-mapping users have: a handful of clicked corners, mis-clicks, mirrored worlds,
// outliers. Each case states the rate it asserts and why that rate.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/model_select.h"
#include "camproj/pose.h"
#include "camproj/synth.h"
#include "seeds.h"

namespace camproj {
namespace {

// A pixel anywhere in a 1920 x 1080 image; y drawn before x, the order in which these tests'
// scenes were drawn when written (GCC evaluates a call's arguments right to left; C++ leaves the
// order unspecified).
Eigen::Vector2d RandomPixel(std::mt19937_64& rng) {
  const double y = std::uniform_real_distribution<double>(0, 1079)(rng);
  const double x = std::uniform_real_distribution<double>(0, 1919)(rng);
  return {x, y};
}

// A projector (lens shift to 0.4 of the image height below the centre) in front of a box, the
// clicks rounded to whole pixels after 0.7 px of noise, as a person clicks corners.
SynthScene Clicks(uint64_t seed, int num_points, SynthObject object = SynthObject::kBox) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = num_points;
  synth.noise_px = 0.7;
  synth.object = object;
  synth.principal_point_offset = Eigen::Vector2d(0.0, 0.4);
  SynthScene scene = SynthesizeScene(synth);
  for (Eigen::Vector2d& u : scene.correspondences.pixels) u = u.array().round();
  return scene;
}

FitResult Auto(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels,
               const AutoFitOptions& options = {}) {
  return FitCameraAuto(points, pixels, {1920, 1080}, options);
}

// Moves point `index` by `distance` px in a seeded direction, inside the image if possible.
void Misclick(std::vector<Eigen::Vector2d>* pixels, int index, double distance, std::mt19937_64& rng) {
  const Eigen::Vector2d original = (*pixels)[index];
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double angle = std::uniform_real_distribution<double>(0.0, 2.0 * M_PI)(rng);
    (*pixels)[index] = original + distance * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d& u = (*pixels)[index];
    if (u.x() >= 0 && u.y() >= 0 && u.x() <= 1919 && u.y() <= 1079) return;
  }
}

// The options `camproj fit --model focal+principal-point` runs: the listed intrinsics free, the
// others fixed at their defaults.
AutoFitOptions Forced() {
  AutoFitOptions options;
  options.fit.principal_point = ParameterMode::Free();
  options.fit.aspect = ParameterMode::Fixed(1.0);
  options.fit.skew = ParameterMode::Fixed(0.0);
  options.fit.k1 = ParameterMode::Fixed(0.0);
  options.fit.k2 = ParameterMode::Fixed(0.0);
  return options;
}

// A world with one axis negated fits no proper camera: refused in the automatic and the forced
// model, at 6, 20 and 300 points -- never answered, by an orthographic camera or any other, in
// any seed (a mirrored world is never right). The refusal names the mirror with its advice in
// every seed at 20 and 300 points; at 6 points some are refused for another reason first (a
// point behind the best linear camera, a camera not determined): the click benchmark's mirrored
// N = 6 band names another reason in 7 of 99 refusals (docs/bench/clicks), so the rate asserted
// is p = 0.15 per scene, twice that. Six clicks that all lie on one face of the box are not a
// mirrored world to the fit: a plane's mirror image is the plane turned over (see
// PlanesAreNeverRefusedAsPossiblyMirrored), so they are left out of this test (seen: box seed
// 9 at seed offset 20000, answered as the plane seen from its other side, rms 0.74 px).
TEST(FitAutoTest, MirroredWorldsAreRefused) {
  int six_point_refusals = 0;
  int six_point_unnamed = 0;
  int coplanar = 0;
  for (const int n : {6, 20, 300}) {
    for (const SynthObject object : {SynthObject::kBox, SynthObject::kCloud}) {
      // Fewer seeds at 300 points: each costs ~100 fits (CI runs this under ASan too).
      for (uint64_t seed = 1; seed <= (n == 300 ? 3u : 10u); ++seed) {
        const SynthScene scene = Clicks(seed, n, object);
        std::vector<Eigen::Vector3d> mirrored = scene.correspondences.points_in_world;
        for (auto& x : mirrored) x.z() = -x.z();
        // On one plane exactly (the box's faces are exact): the smallest principal spread
        // vanishes to rounding against the largest.
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const auto& x : mirrored) mean += x / static_cast<double>(mirrored.size());
        for (const auto& x : mirrored) scatter += (x - mean) * (x - mean).transpose();
        const Eigen::Vector3d spreads = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter)
                                            .eigenvalues();  // ascending
        if (spreads(0) <= 1e-20 * spreads(2)) {
          ++coplanar;
          continue;
        }
        for (const bool forced : {false, true}) {
          try {
            const FitResult fit = Auto(mirrored, scene.correspondences.pixels,
                                       forced ? Forced() : AutoFitOptions());
            ADD_FAILURE() << "n " << n << " seed " << seed << " forced " << forced
                          << ": answered " << fit.model << ", rms " << fit.rms_px;
          } catch (const SceneError& e) {
            const bool named = std::string(e.what()).find("mirror") != std::string::npos;
            if (n == 6) {
              ++six_point_refusals;
              if (!named) ++six_point_unnamed;
            } else {
              EXPECT_TRUE(named) << "n " << n << " seed " << seed << ": " << e.what();
            }
          }
        }
      }
    }
  }
  testing::ExpectRate("mirrored 6-point scenes refused without naming the mirror",
                      six_point_unnamed, six_point_refusals, 0.15);
  std::printf("[ INFO     ] scenes on one plane, left out: %d\n", coplanar);
}

// Six clicked corners of a mirrored world (bench --clicks, band "mirrored N=6", scenes 29 and
// 80, whole-pixel clicks of a projector) that a proper camera fits within the noise: the
// mirrored reading -- the true camera -- fits about as well and puts the box elsewhere, so the
// scene is refused with the mirror named, not answered 90-140 px off.
TEST(FitAutoTest, MirroredSixClicksThatFitAProperCameraAreRefused) {
  struct Row {
    double x, y, z, u, v;
  };
  const std::vector<std::vector<Row>> scenes = {
      {{-0.5203271027039887, -0.7899283666673933, 0, 1048, 780},
       {0.2875220303439668, -0.017636713706684404, 2.303013323331492, 923, 507},
       {0.5203271027039887, -0.7899283666673933, 2.303013323331492, 950, 511},
       {0.2875220303439668, -0.749027023908544, 2.303013323331492, 971, 510},
       {0.2875220303439668, -0.017636713706684404, 3.9959088219695422, 923, 291},
       {-0.2189905565066375, -0.749027023908544, 2.303013323331492, 1022, 509}},
      {{-0.31404640926458827, 0.2428959945270358, -3.844748875960623, 1011, 188},
       {0.2824161813722167, 0.2428959945270358, -2.5521616919715093, 1035, 406},
       {0.6202329628366903, -0.5698906902525691, 0, 937, 783},
       {0.2824161813722167, -0.46495384710136733, -3.844748875960623, 929, 208},
       {-0.31404640926458827, -0.46495384710136733, -2.5521616919715093, 910, 390},
       {0.4543291292373913, -0.49607133996107877, -0.6097512480670046, 938, 693}}};
  for (size_t s = 0; s < scenes.size(); ++s) {
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (const Row& r : scenes[s]) {
      points.emplace_back(r.x, r.y, r.z);
      pixels.emplace_back(r.u, r.v);
    }
    try {
      const FitResult fit = Auto(points, pixels);
      ADD_FAILURE() << "scene " << s << ": answered " << fit.model << ", rms " << fit.rms_px;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("world axis flipped"), std::string::npos)
          << "scene " << s << ": " << e.what();
    }
  }
}

// A click-benchmark scene embedded (bench --clicks --dump): the clicks, and the building's box
// corners with their true pixels.
struct Row {
  double x, y, z, u, v;
};
struct EmbeddedScene {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector2d> vertex_pixels;
};

EmbeddedScene Embed(const std::vector<Row>& clicks, const std::vector<Row>& vertices) {
  EmbeddedScene scene;
  for (const Row& r : clicks) {
    scene.points.emplace_back(r.x, r.y, r.z);
    scene.pixels.emplace_back(r.u, r.v);
  }
  for (const Row& r : vertices) {
    scene.vertices.emplace_back(r.x, r.y, r.z);
    scene.vertex_pixels.emplace_back(r.u, r.v);
  }
  return scene;
}

// The largest distance from a vertex's true pixel to where `camera` puts it (inf if behind).
double WorstVertexErrorPx(const Camera& camera, const EmbeddedScene& scene) {
  double worst_px = 0.0;
  for (size_t i = 0; i < scene.vertices.size(); ++i) {
    const std::optional<Eigen::Vector2d> u = PixelFromWorld(camera, scene.vertices[i]);
    worst_px = std::max(worst_px, u ? (*u - scene.vertex_pixels[i]).norm() : INFINITY);
  }
  return worst_px;
}

// How far `model`, forced (FitCamera), puts the scene's vertices from their true pixels: what a
// test's rule is for.
double ForcedVertexErrorPx(const EmbeddedScene& scene, const FitOptions& model) {
  return WorstVertexErrorPx(FitCamera(scene.points, scene.pixels, {1920, 1080}, model).camera,
                            scene);
}

// The default path's refusal of an embedded scene; an answer is a failure of the calling test,
// reported with how far it is off at the scene's vertices.
std::optional<SceneError> RefusalOf(const EmbeddedScene& scene) {
  try {
    const FitResult fit = Auto(scene.points, scene.pixels);
    ADD_FAILURE() << "answered " << fit.model << ", rms " << fit.rms_px << ", "
                  << WorstVertexErrorPx(fit.camera, scene) << " px off at the vertices";
    return std::nullopt;
  } catch (const SceneError& e) {
    return e;
  }
}

// Scene 55 of the click benchmark's clean 6-point band (TheSixClicksOfScene55AreRefused...,
// below), with two unseen corners of the building and their true pixels.
EmbeddedScene Scene55() {
  const std::vector<Row> clicks = {
      {0.6558947640258102, 0.28275227060358277, 1.0109840491878523, 1050, 710},
      {0.18648979631228613, 0.2535160403830361, 1.0109840491878523, 1015, 704},
      {0.6558947640258102, 0.28275227060358277, 0, 1049, 907},
      {0.6558947640258102, -0.28275227060358277, 1.0109840491878523, 944, 713},
      {0.18648979631228613, -0.265321251757319, 1.0109840491878523, 921, 707},
      {-0.4947159328370735, -0.265321251757319, 1.0109840491878523, 886, 696},
  };
  const std::vector<Row> vertices = {  // unseen corners, true pixels to 1e-3 px
      {-0.6558947640258102, 0.28275227060358277, 0, 971.887, 871.956},
      {-0.4947159328370735, 0.2535160403830361, 2.93755514229067, 976.407, 332.600},
  };
  return Embed(clicks, vertices);
}

// Scene 85 of the click benchmark's clean 8-point band: 8 clicks on the front faces of a 3-box
// building, nearly coplanar (singular values 7.5, 3.3, 0.03 m), and the building's box corners
// with their true pixels.
EmbeddedScene Scene85() {
  const std::vector<Row> clicks = {
      {-0.46658142326420854, 0.9666607848537022, 7.159444992645841, 804, 258},
      {-0.5118561467638958, -1.1313561829389096, 4.509209203986271, 1013, 509},
      {-0.5118561467638958, 1.1910858442418002, 4.509209203986271, 780, 509},
      {-0.5467799195000049, 1.376529513331823, 0, 757, 963},
      {-0.5467799195000049, -1.376529513331823, 0, 1042, 964},
      {-0.5467799195000049, -1.376529513331823, 2.3676037522919504, 1039, 722},
      {-0.5467799195000049, 1.376529513331823, 2.3676037522919504, 760, 721},
      {-0.46658142326420854, 0.03106737102074586, 7.159444992645841, 896, 257},
  };
  const std::vector<Row> vertices = {  // true pixels to 1e-3 px
      {-0.5467799195000049, -1.376529513331823, 0, 1041.471, 962.935},
      {0.5467799195000049, -1.376529513331823, 0, 1029.854, 958.435},
      {-0.5467799195000049, 1.376529513331823, 0, 757.071, 963.075},
      {0.5467799195000049, 1.376529513331823, 0, 767.691, 958.559},
      {-0.5467799195000049, -1.376529513331823, 2.3676037522919504, 1039.082, 720.600},
      {0.5467799195000049, -1.376529513331823, 2.3676037522919504, 1027.827, 734.816},
      {-0.5467799195000049, 1.376529513331823, 2.3676037522919504, 759.412, 720.423},
      {0.5467799195000049, 1.376529513331823, 2.3676037522919504, 769.689, 734.670},
      {-0.5118561467638958, -1.1313561829389096, 2.3676037522919504, 1013.883, 721.074},
      {0.24901973450193893, -1.1313561829389096, 2.3676037522919504, 1007.262, 731.153},
      {-0.5118561467638958, 1.1910858442418002, 2.3676037522919504, 778.578, 720.927},
      {0.24901973450193893, 1.1910858442418002, 2.3676037522919504, 784.831, 731.024},
      {-0.5118561467638958, -1.1313561829389096, 4.509209203986271, 1012.167, 509.233},
      {0.24901973450193893, -1.1313561829389096, 4.509209203986271, 1005.731, 530.594},
      {-0.5118561467638958, 1.1910858442418002, 4.509209203986271, 780.340, 508.860},
      {0.24901973450193893, 1.1910858442418002, 4.509209203986271, 786.412, 530.263},
      {-0.46658142326420854, 0.03106737102074586, 4.509209203986271, 896.184, 510.387},
      {0.21499707040357946, 0.03106737102074586, 4.509209203986271, 896.021, 529.522},
      {-0.46658142326420854, 0.9666607848537022, 4.509209203986271, 803.069, 510.238},
      {0.21499707040357946, 0.9666607848537022, 4.509209203986271, 807.418, 529.388},
      {-0.46658142326420854, 0.03106737102074586, 7.159444992645841, 896.212, 257.434},
      {0.21499707040357946, 0.03106737102074586, 7.159444992645841, 896.050, 288.288},
      {-0.46658142326420854, 0.9666607848537022, 7.159444992645841, 804.765, 257.180},
      {0.21499707040357946, 0.9666607848537022, 7.159444992645841, 808.960, 288.059},
  };
  return Embed(clicks, vertices);
}

// Pose + focal explains scene 85's clicks and is determined to 1.3 px over the box they span,
// but puts the building's back corners more than 10 px off. Given the building's vertices as
// object points, the camera must be determined there too, and it is not.
TEST(FitAutoTest, ObjectPointsJudgeTheCameraWhereTheClicksAreNot) {
  const EmbeddedScene scene = Scene85();
  FitOptions pose_focal;
  pose_focal.aspect = ParameterMode::Default();
  pose_focal.principal_point = ParameterMode::Default();
  EXPECT_GT(ForcedVertexErrorPx(scene, pose_focal), 10.0)
      << "the scene no longer shows what the object points are for";
  AutoFitOptions with_object;
  with_object.object_points_in_world = scene.vertices;
  try {
    const FitResult judged = Auto(scene.points, scene.pixels, with_object);
    ADD_FAILURE() << "answered " << judged.model << ": " << judged.determination.summary;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kAmbiguous) << e.what();
  }
}

// Without object points too: BIC prefers pose + focal by 1.8, but the model with the principal
// point free predicts each click from the other 7 better (PRESS 13.1 against 19.4 px^2) and
// moves the building's far side by 18 px -- within its own 3 sigma, which exempted it before the
// cross-validation rule. It is as good a reading of the clicks, so the scene is refused as
// ambiguous, naming it (docs/model-selection.md, "Rules tried": 3 silent failures fewer for 32
// of 1548 answers on the click benchmark).
TEST(FitAutoTest, ARivalThatPredictsTheClicksBetterCounts) {
  const EmbeddedScene scene = Scene85();
  try {
    const FitResult fit = Auto(scene.points, scene.pixels);
    ADD_FAILURE() << "answered " << fit.model << " " << WorstVertexErrorPx(fit.camera, scene)
                  << " px off: " << fit.determination.summary;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kAmbiguous) << e.what();
    EXPECT_NE(std::string(e.what()).find("pose+focal+principal-point"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("predicts each point from the others better"),
              std::string::npos)
        << e.what();
  }
}

// Scene 61 of the click benchmark's 60-point band with 50 % outliers: the 30 clicks the outlier
// stage keeps, near the middle of a 1920 x 1080 projector image, and two unseen corners of the
// building with their true pixels (to 1e-3 px).
EmbeddedScene Scene61Kept() {
  const std::vector<Row> clicks = {
      {-0.5050950580052331, 0.5104672242716305, 0.1281465667079798, 991, 814},
      {-0.10502129310095687, -0.907688917596584, 0.27233220128451135, 1061, 810},
      {-0.5050950580052331, 0.39226480161093014, 0.26069726513816804, 993, 799},
      {-0.46508718609198013, -0.425324535984071, 1.1888086086427774, 1006, 681},
      {-0.37908362387264094, -0.061662205922987434, 1.7837480060777275, 1014, 603},
      {-0.155718709540597, -0.8293942732647857, 1.9548358163764963, 1055, 571},
      {-0.46508718609198013, -0.08628977145140226, 0.9481518660584374, 1003, 712},
      {-0.07107393502860904, -0.8504753717653778, 0.8599947207438279, 1064, 727},
      {-0.37908362387264094, 0.036653159672614066, 1.6501877774789304, 1012, 621},
      {-0.08563876749038207, -0.8293942732647857, 1.6770665968242464, 1064, 612},
      {-0.4822789380693869, 0.8437543594568352, 0.5614699624728704, 993, 757},
      {-0.46508718609198013, 0.08877626139083916, 0.8237664259674446, 1000, 729},
      {-0.5050950580052331, 0.1655187739727607, 0.5519664881444369, 996, 763},
      {-0.09162675832282019, -0.8293942732647857, 1.761495887101824, 1062, 598},
      {-0.46508718609198013, -0.2528778385111553, 0.7275459383730036, 1003, 743},
      {-0.03779338836723778, -0.8293942732647857, 1.3309839298499337, 1069, 659},
      {-0.46508718609198013, -0.2480636496402111, 1.0571306458049428, 1004, 698},
      {-0.5050950580052331, -0.6578476056240601, 0.22467098025924923, 1001, 815},
      {-0.1067359033814459, -0.8293942732647857, 2.064155479708412, 1061, 554},
      {0.16091902662878038, -0.8504753717653778, 0.7160750299881207, 1097, 748},
      {-0.37908362387264094, -0.6040250711116733, 1.321415919828513, 1020, 662},
      {-0.37908362387264094, 0.365289759858352, 2.0280628760090282, 1010, 575},
      {-0.501041613378226, 0.6441125299142622, 0.5614699624728704, 993, 758},
      {-0.5050950580052331, -0.021922745653106257, 0.43576866808220754, 995, 778},
      {-0.37908362387264094, -0.31814397790478244, 1.6514465303121144, 1016, 619},
      {0.12515922778244698, -0.8504753717653778, 0.6785659373251416, 1093, 753},
      {-0.37908362387264094, -0.2615244427393483, 1.4267289356885748, 1014, 649},
      {-0.37908362387264094, 0.3826826081547523, 2.7215875636167457, 1010, 485},
      {-0.37908362387264094, -0.3956854836211185, 2.4007770323368693, 1017, 513},
      {-0.17185515803901308, -0.8504753717653778, 0.6073401097153084, 1051, 762},
  };
  const std::vector<Row> vertices = {
      {-0.37908362387264094, -0.8293942732647857, 3.0884953151537107, 1021.996, 406.854},
      {0.1289006836235449, -0.8293942732647857, 3.0884953151537107, 1095.266, 406.375},
  };
  return Embed(clicks, vertices);
}

// BIC takes k1 (0.91 +- 0.34, a 66 % stretch at the image's corners) by 2.8 over pose + focal +
// principal point, which is the true model: fitted on clicks near the image centre, k1 is their
// noise extrapolated, 10 px off at the building's top beyond them and ~900 px at the image's
// corner. A distortion the criterion takes only weakly is left out where it moves the image's
// border by more than the determination bound (fit/selection.cc, BorderShiftPx): the answer is
// the true model's, within 3 px at those corners (the true model on these clicks: 2.9 px).
TEST(FitAutoTest, AWeakDistortionThatBendsTheImageBorderIsLeftOut) {
  const EmbeddedScene scene = Scene61Kept();
  FitOptions with_k1;
  with_k1.principal_point = ParameterMode::Free();
  with_k1.k1 = ParameterMode::Free();
  EXPECT_GT(ForcedVertexErrorPx(scene, with_k1), 8.0)
      << "the scene no longer shows what the rule is for";

  const FitResult fit = Auto(scene.points, scene.pixels);
  EXPECT_EQ(fit.model, "pose+focal+principal-point");
  EXPECT_LT(WorstVertexErrorPx(fit.camera, scene), 3.0);
  auto named = [&](const std::string& name) {
    return std::find_if(fit.candidates.begin(), fit.candidates.end(),
                        [&](const ModelCandidate& c) { return c.name == name; });
  };
  const auto k1 = named("pose+focal+principal-point+k1");
  const auto chosen = named(fit.model);
  ASSERT_NE(k1, fit.candidates.end());
  ASSERT_NE(chosen, fit.candidates.end());
  EXPECT_LT(k1->criterion, chosen->criterion) << "the criterion alone would not leave k1 out";
  EXPECT_NE(k1->verdict.find("not determined over the image"), std::string::npos) << k1->verdict;
}

// Scene 335 of the click benchmark's 6-click band with one mis-click (scenes 300-499, drawn after
// every rule but this one), and the building's lower box corners with their true pixels.
EmbeddedScene Scene335() {
  const std::vector<Row> clicks = {
      {-1.1435684005925681, -0.40294333903838386, 0, 944, 962},
      {1.0869486702974152, -0.38662171548805707, 3.7118814587049864, 1107, 339},
      {1.1435684005925681, 0.40294333903838386, 0, 1236, 1038},
      {1.0745329571246507, 0.2724909731839794, 3.7118814587049864, 1227, 403},
      {1.1435684005925681, -0.40294333903838386, 1.0334299374569391, 1124, 890},
      {1.0869486702974152, 0.30239179832633806, 3.7118814587049864, 1234, 403},
  };
  const std::vector<Row> vertices = {  // true pixels to 1e-3 px
      {-1.1435684005925681, -0.40294333903838386, 0, 944.257, 962.055},
      {1.1435684005925681, -0.40294333903838386, 0, 1122.956, 1059.885},
      {-1.1435684005925681, 0.40294333903838386, 0, 1047.180, 944.827},
      {1.1435684005925681, 0.40294333903838386, 0, 1235.694, 1037.654},
      {-1.1435684005925681, -0.40294333903838386, 1.0334299374569391, 941.861, 812.866},
      {1.1435684005925681, -0.40294333903838386, 1.0334299374569391, 1124.956, 891.113},
      {-1.1435684005925681, 0.40294333903838386, 1.0334299374569391, 1047.167, 798.765},
      {1.1435684005925681, 0.40294333903838386, 1.0334299374569391, 1240.558, 872.861},
  };
  return Embed(clicks, vertices);
}

// Pose + focal + principal point absorbs the mis-click: rms 1.35 px at 6 clicks, the principal
// point 680 px right of the image centre, the building's corners up to 116 px off. One click (5) has
// leverage 1 - 4e-6 along (0.30, 0.95): a mis-click of it anywhere in the image would leave under
// 0.01 px in its residual. A camera that stands on one unchecked click is refused, naming it
// (RefuseIfUnchecked, fit/verdicts.cc), with what to add.
TEST(FitAutoTest, ACameraThatStandsOnOneUncheckedClickIsRefused) {
  const EmbeddedScene scene = Scene335();
  FitOptions off_axis;
  off_axis.principal_point = ParameterMode::Free();
  EXPECT_GT(ForcedVertexErrorPx(scene, off_axis), 30.0)
      << "the scene no longer shows what the rule is for";
  const std::optional<SceneError> refusal = RefusalOf(scene);
  ASSERT_TRUE(refusal.has_value());
  EXPECT_EQ(refusal->reason(), SceneError::Reason::kDegenerate) << refusal->what();
  // The message begins with the point's name as the sentence's subject: NamesOf's "point 5"
  // (no names given), "point 5" for the bare number a points file without ids gives, "c5" as is.
  EXPECT_EQ(std::string(refusal->what()).rfind("point 5 is checked by no other point", 0), 0u)
      << refusal->what();
  // The fix stands alone: it names the point again.
  EXPECT_EQ(refusal->fix().rfind("Add a point near point 5, ", 0), 0u) << refusal->what();
  for (const char* prefix : {"", "c"}) {
    AutoFitOptions named;
    for (size_t i = 0; i < scene.points.size(); ++i) {
      named.point_names.push_back(prefix + std::to_string(i + 1));
    }
    const std::string expected =
        std::string(*prefix ? "c5" : "point 5") + " is checked by no other point";
    try {
      Auto(scene.points, scene.pixels, named);
      ADD_FAILURE() << "answered with point names " << prefix << "1, ...";
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(expected, 0), 0u) << e.what();
    }
  }
}

// Scene 64 of the clean 7-point band: pose + focal explains the clicks (rms 0.63 px) and is
// determined to 4.3 px at the back corners, yet is 35 px off there: the projector's lens shift
// was traded for a longer focal length. The model with the principal point free fits about as
// well (BIC 3.2 worse) and puts the scene 8.9 px elsewhere within twice the clicks' box --
// within its own 3 sigma, which exempted it before the lens-shift rival: refused as ambiguous,
// saying how to state the principal point. Stated at the centre (--fix principal-point), it is
// answered: the user's word, not a guess.
TEST(FitAutoTest, APrincipalPointLeftAtTheCentreIsJudgedAgainstTheLensShift) {
  const std::vector<Row> clicks = {
      {-0.4263201812450911, -1.453950580074489, 0.6139920699269872, 1118, 542},
      {-0.4263201812450911, 1.453950580074489, 0, 894, 800},
      {0.4164750327061282, 0.8215297769328793, 0.6139920699269872, 805, 627},
      {-0.4263201812450911, -1.453950580074489, 0, 1115, 642},
      {-0.41637474531839747, -0.31569315730135905, 0.6139920699269872, 1037, 592},
      {-0.4263201812450911, 1.453950580074489, 0.6139920699269872, 892, 685},
      {0.4263201812450911, 1.453950580074489, 0, 746, 774},
  };
  const std::vector<Row> vertices = {  // true pixels to 1e-3 px
      {-0.4263201812450911, -1.453950580074489, 0, 1114.725, 641.431},
      {0.4263201812450911, -1.453950580074489, 0, 987.666, 622.886},
      {-0.4263201812450911, 1.453950580074489, 0, 894.834, 801.987},
      {0.4263201812450911, 1.453950580074489, 0, 748.105, 774.791},
      {-0.4263201812450911, -1.453950580074489, 0.6139920699269872, 1118.308, 541.969},
      {0.4263201812450911, -1.453950580074489, 0.6139920699269872, 988.552, 525.567},
      {-0.4263201812450911, 1.453950580074489, 0.6139920699269872, 893.561, 684.901},
      {0.4263201812450911, 1.453950580074489, 0.6139920699269872, 743.222, 660.629},
      {-0.41637474531839747, -0.31569315730135905, 0.6139920699269872, 1039.019, 591.122},
      {0.4164750327061282, -0.31569315730135905, 0.6139920699269872, 905.030, 572.610},
      {-0.41637474531839747, 0.8215297769328793, 0.6139920699269872, 948.675, 648.474},
      {0.4164750327061282, 0.8215297769328793, 0.6139920699269872, 806.664, 626.848},
      {-0.41637474531839747, -0.31569315730135905, 2.9628547177087423, 1047.978, 138.480},
      {0.4164750327061282, -0.31569315730135905, 2.9628547177087423, 901.399, 131.417},
      {-0.41637474531839747, 0.8215297769328793, 2.9628547177087423, 949.107, 161.015},
      {0.4164750327061282, 0.8215297769328793, 2.9628547177087423, 792.875, 152.625},
  };
  const EmbeddedScene scene = Embed(clicks, vertices);
  AutoFitOptions centred;  // as --fix principal-point
  centred.fit.principal_point = ParameterMode::Fixed(959.5, 539.5);
  const FitResult fit = Auto(scene.points, scene.pixels, centred);
  EXPECT_EQ(fit.model, "pose+focal");
  EXPECT_GT(WorstVertexErrorPx(fit.camera, scene), 10.0)
      << "the scene no longer shows what the rule is for";
  for (const bool with_vertices : {false, true}) {
    AutoFitOptions options;
    if (with_vertices) options.object_points_in_world = scene.vertices;
    try {
      const FitResult judged = Auto(scene.points, scene.pixels, options);
      ADD_FAILURE() << "answered " << judged.model << ": " << judged.determination.summary;
    } catch (const SceneError& e) {
      EXPECT_EQ(e.reason(), SceneError::Reason::kAmbiguous) << e.what();
      EXPECT_NE(std::string(e.what()).find("cannot tell where the principal point is: pose+focal "
                                           "leaves it at the image centre and "
                                           "pose+focal+principal-point frees it"),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("--fix principal-point"), std::string::npos)
          << e.what();
    }
  }
}

// Scene 129 of the click benchmark's clean 7-point band (held out: scenes 100-299 were not used
// to choose the rules before it): a projector with its principal point 272 px below the centre,
// 7 clicks on a 3-box building. Pose + focal with the principal point at the centre explains
// them (rms 0.93 px; BIC preferred it to the model with the principal point free) and passed
// every other check, 33 px off at the building's corners: the lens shift was traded for a longer
// focal length. Averaged over the models fitted, weighted by their BIC, the camera is 6.3 px
// uncertain (1 sigma) near pixel (1309, 816), beside the building; and the model with the
// principal point free alone puts the scene further apart within twice the clicks' box: refused
// as ambiguous by the lens-shift rival, whose message says how to state the principal point.
TEST(FitAutoTest, ALensShiftTradedForTheFocalLengthIsRefused) {
  const std::vector<Row> clicks = {
      {0.813915215565468, 0.2927445003479191, 1.5147533513456182, 810, 712},
      {-0.973197105800201, 0.2927445003479191, 1.5147533513456182, 1129, 698},
      {1.072610618267415, 1.3825596586349582, 0, 780, 1050},
      {-1.072610618267415, 1.3825596586349582, 0, 1181, 1030},
      {0.9539652015847702, 0.3142255239579441, 1.5147533513456182, 785, 714},
      {1.072610618267415, -1.3825596586349582, 0.8369963277890811, 758, 738},
      {1.072610618267415, 1.3825596586349582, 0.8369963277890811, 774, 903},
  };
  const std::vector<Row> vertices = {  // the building's box corners, true pixels to 1e-3 px
      {-1.072610618267415, -1.3825596586349582, 0, 1085.189, 847.439},
      {1.072610618267415, -1.3825596586349582, 0, 762.632, 861.021},
      {-1.072610618267415, 1.3825596586349582, 0, 1181.486, 1028.784},
      {1.072610618267415, 1.3825596586349582, 0, 778.837, 1049.593},
      {-1.072610618267415, -1.3825596586349582, 0.8369963277890811, 1088.282, 727.310},
      {1.072610618267415, -1.3825596586349582, 0.8369963277890811, 758.527, 739.161},
      {-1.072610618267415, 1.3825596586349582, 0.8369963277890811, 1188.045, 882.907},
      {1.072610618267415, 1.3825596586349582, 0.8369963277890811, 774.117, 901.188},
      {-1.0414169378068263, -0.7952243659004319, 0.8369963277890811, 1100.989, 754.994},
      {0.9539652015847702, -0.7952243659004319, 0.8369963277890811, 780.652, 766.971},
      {-1.0414169378068263, 0.3142255239579441, 0.8369963277890811, 1138.610, 814.407},
      {0.9539652015847702, 0.3142255239579441, 0.8369963277890811, 788.435, 828.596},
      {-1.0414169378068263, -0.7952243659004319, 1.5147533513456182, 1103.959, 649.586},
      {0.9539652015847702, -0.7952243659004319, 1.5147533513456182, 777.461, 660.025},
      {-1.0414169378068263, 0.3142255239579441, 1.5147533513456182, 1142.650, 700.170},
      {0.9539652015847702, 0.3142255239579441, 1.5147533513456182, 785.099, 712.557},
      {-0.973197105800201, -0.7427101714939527, 1.5147533513456182, 1094.609, 652.134},
      {0.813915215565468, -0.7427101714939527, 1.5147533513456182, 801.163, 661.550},
      {-0.973197105800201, 0.2927445003479191, 1.5147533513456182, 1129.842, 699.513},
      {0.813915215565468, 0.2927445003479191, 1.5147533513456182, 810.414, 710.561},
      {-0.973197105800201, -0.7427101714939527, 4.456432436418004, 1108.156, 141.449},
      {0.813915215565468, -0.7427101714939527, 4.456432436418004, 787.879, 143.320},
      {-0.973197105800201, 0.2927445003479191, 4.456432436418004, 1148.225, 143.541},
      {0.813915215565468, 0.2927445003479191, 4.456432436418004, 796.743, 145.636},
  };
  const EmbeddedScene scene = Embed(clicks, vertices);
  FitOptions pose_focal;  // what the default answered before the model average
  pose_focal.aspect = ParameterMode::Default();           // 1
  pose_focal.principal_point = ParameterMode::Default();  // the image centre
  EXPECT_GT(ForcedVertexErrorPx(scene, pose_focal), 10.0)
      << "the scene no longer shows what the rule is for";
  try {
    const FitResult fit = Auto(scene.points, scene.pixels);
    ADD_FAILURE() << "answered " << fit.model << ": " << fit.determination.summary;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kAmbiguous) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot tell where the principal point is"),
              std::string::npos)
        << e.what();
  }
}

// The lens-shift rival's price falls on cameras whose principal point is at the centre: 12
// clicks (0.7 px, rounded) on a box seen by a centred camera, judged on 40 more points of the box.
// Measured at seeds 1-1000: 838 answered, none more than 10 px off; 57 refused by the lens-shift
// rival (each saying to give --fix principal-point), 105 for other reasons. In blocks of 100
// seeds the answers ranged 75-90 (mean 83.8, sd 5.3; binomial 3.7) and those refusals 2-10 (mean
// 5.7, sd 2.9): at least 65 answers and at most 17 such refusals are 3.6 and 3.9 of the blocks'
// sd away; a wrong answer, below 1 in 280 (none in 838, 95 %), allows 2 (p < 1e-3).
TEST(FitAutoTest, ACentredCameraIsMostlyAnsweredAtTwelveClicks) {
  constexpr int kScenes = 100;
  constexpr int kClicks = 12;
  constexpr int kUnseen = 40;
  int answered = 0;
  int lens_shift_refusals = 0;
  int wrong = 0;
  std::string wrong_seeds;
  for (int s = 1; s <= kScenes; ++s) {
    SynthOptions synth;
    synth.seed = testing::Seed(s);
    synth.num_points = kClicks + kUnseen;
    synth.noise_px = 0.7;
    synth.object = SynthObject::kBox;
    const SynthScene scene = SynthesizeScene(synth);
    const std::vector<Eigen::Vector3d>& all = scene.correspondences.points_in_world;
    const std::vector<Eigen::Vector3d> points(all.begin(), all.begin() + kClicks);
    std::vector<Eigen::Vector2d> pixels(scene.correspondences.pixels.begin(),
                                        scene.correspondences.pixels.begin() + kClicks);
    for (Eigen::Vector2d& u : pixels) u = u.array().round();
    try {
      const FitResult fit = Auto(points, pixels);
      ++answered;
      double worst_px = 0.0;
      for (size_t i = kClicks; i < all.size(); ++i) {
        const std::optional<Eigen::Vector2d> truth = PixelFromWorld(scene.truth, all[i]);
        const std::optional<Eigen::Vector2d> ours = PixelFromWorld(fit.camera, all[i]);
        if (!truth) continue;
        worst_px = std::max(worst_px, ours ? (*ours - *truth).norm()
                                           : std::numeric_limits<double>::infinity());
      }
      if (worst_px > 10.0) {
        ++wrong;
        wrong_seeds += " " + std::to_string(s);
      }
    } catch (const SceneError& e) {
      const std::string what = e.what();
      if (what.find("cannot tell where the principal point is") != std::string::npos) {
        ++lens_shift_refusals;
        EXPECT_NE(what.find("--fix principal-point"), std::string::npos) << what;
      }
    }
  }
  EXPECT_GE(answered, 65);
  EXPECT_LE(lens_shift_refusals, 17);
  EXPECT_LE(wrong, 2) << "more than 10 px off at seeds" << wrong_seeds;
}

// Scene 101 of the click benchmark's clean 7-point band (held out): 7 clicks on two boxes of a
// building. Pose + focal + principal point fits them (rms 0.58 px) and is determined to 4.6 px;
// + k1 fits them nearly as well and bends the far top corner elsewhere. Averaged over the models
// fitted, weighted by their BIC, the camera is 6.1 px uncertain (1 sigma) near pixel (1200, 86):
// the points cannot tell which model is right well enough, and the refusal names the rival that
// adds most. (The answer would have been right, 1.5 px on the building: a refusal's price.)
TEST(FitAutoTest, TheModelAverageRefusesAnAnswerTheRivalsDoNotPin) {
  const std::vector<Row> clicks = {
      {-1.330040874767157, -0.8137412438974722, 0, 689, 709},
      {-1.3300408747671573, 0.5343686653219202, 2.9674033830028947, 837, 265},
      {1.330040874767157, 0.8137412438974722, 2.3434192623706323, 1151, 369},
      {-4.216122621075646, 0.5343686653219202, 0, 629, 630},
      {-1.3300408747671573, 1.4032297877612014, 2.9674033830028947, 930, 269},
      {-1.330040874767157, -0.8137412438974722, 2.3434192623706323, 679, 359},
      {-4.216122621075646, 0.5343686653219202, 2.9674033830028947, 614, 272},
  };
  const EmbeddedScene scene = Embed(clicks, {});
  try {
    const FitResult fit = Auto(scene.points, scene.pixels);
    ADD_FAILURE() << "answered " << fit.model << ": " << fit.determination.summary;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kAmbiguous) << e.what();
    EXPECT_NE(std::string(e.what()).find("averaged"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pose+focal+principal-point+k1 most"), std::string::npos)
        << e.what();
  }
  // A forced model has no rivals to average over: the check is the model's own.
  AutoFitOptions forced;  // as --model focal+principal-point
  forced.fit.focal = ParameterMode::Free();
  forced.fit.principal_point = ParameterMode::Free();
  forced.fit.aspect = ParameterMode::Fixed(1.0);
  forced.fit.skew = ParameterMode::Fixed(0.0);
  forced.fit.k1 = ParameterMode::Fixed(0.0);
  forced.fit.k2 = ParameterMode::Fixed(0.0);
  forced.allow_orthographic = false;
  try {
    const FitResult fit = Auto(scene.points, scene.pixels, forced);
    EXPECT_EQ(fit.determination.averaged_sigma_px, 0.0) << fit.determination.summary;
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).find("averaged"), std::string::npos) << e.what();
  }
}

// Scene 55 of the click benchmark's clean 6-point band: a projector 12.6 m from a building whose
// six clicked corners (two faces, five of them coplanar) span 1 m in depth and 160 x 210 px of
// the image, with its principal point at the bottom edge (cy 1069 px). The clicks do not
// determine the building: pose + focal (the lens shift left out) has a finite minimum 18 px off
// at its unseen corners, and the true model is as far off. Its DLT's focal length is 6e-10 px,
// so which refusal the default gives depends on where LM walks from there: to the orthographic
// limit, then refused by the perspective test (determination_test.cc,
// PerspectiveTestSeesWhatTheOrthographicCameraLeavesOut); or 190-260 iterations to the finite minimum, whose confidence region holds a
// camera that sees points from behind (fx 2653 +- 628 px), refused as undetermined; or to a
// camera with a point behind it. Rounding decides between the walks (clicks moved by 1e-6 px
// do: 17 of these 30 draws end behind), so every draw is checked: refused, in both the clean
// world and the world with x negated (a mirror: refused as mirrored or as undetermined). A forced orthographic model is answered, and 16 px off.
TEST(FitAutoTest, TheSixClicksOfScene55AreRefusedWhateverTheRounding) {
  constexpr int kDraws = 30;
  constexpr double kMovePx = 1e-6;
  const EmbeddedScene scene = Scene55();
  std::mt19937_64 rng(testing::Seed(55));
  std::uniform_real_distribution<double> move(-kMovePx, kMovePx);
  for (const double flip : {1.0, -1.0}) {  // the clean scene, and the world with x negated
    std::vector<Eigen::Vector3d> points = scene.points;
    for (Eigen::Vector3d& x : points) x.x() *= flip;
    for (int draw = 0; draw < kDraws; ++draw) {
      std::vector<Eigen::Vector2d> pixels = scene.pixels;
      if (draw > 0) {  // draw 0: the clicks as clicked
        for (Eigen::Vector2d& u : pixels) u += Eigen::Vector2d(move(rng), move(rng));
      }
      try {
        const FitResult fit = Auto(points, pixels);
        ADD_FAILURE() << "x " << flip << ", draw " << draw << ": answered " << fit.model
                      << ", rms " << fit.rms_px << ", unseen corners "
                      << WorstVertexErrorPx(fit.camera, scene) << " px off";
      } catch (const SceneError& e) {
        if (flip > 0) {
          EXPECT_TRUE(e.reason() == SceneError::Reason::kDegenerate ||
                      e.reason() == SceneError::Reason::kPointsBehindCamera)
              << e.what();
        }
      }
    }
  }
  AutoFitOptions orthographic;
  orthographic.fit.projection = Projection::kOrthographic;
  const FitResult forced = Auto(scene.points, scene.pixels, orthographic);
  EXPECT_GT(WorstVertexErrorPx(forced.camera, scene), 10.0)
      << "the scene no longer shows what the rule is for";
}

// Scene 55's DLT has a focal length of 6e-10 px (a view wider than any camera's): no start. The
// fit of pose + focal starts from the focal sweep instead and reaches its minimum in a few LM
// iterations (from the DLT it ran to the orthographic limit or crawled 190-260 iterations
// through the flat valley): at most 30 here, the most any answer of the click benchmark takes
// from a DLT being 60.
TEST(FitAutoTest, ADegenerateDltIsNoStart) {
  const EmbeddedScene scene = Scene55();
  FitOptions focal;  // pose + focal
  focal.aspect = ParameterMode::Default();
  focal.principal_point = ParameterMode::Default();
  const FitResult fit = FitCamera(scene.points, scene.pixels, {1920, 1080}, focal);
  EXPECT_EQ(fit.start_method, "pnp-focal-sweep");
  EXPECT_LE(fit.iterations, 30);
  EXPECT_LT(fit.rms_px, 1.0);
}

// Scene 202 of the click benchmark's held-out 6-point mis-click band: point 1 clicked 96.5 px
// from its corner's true pixel (the first vertex below). Pose + focal + principal point (3
// equations to spare) absorbs it: rms 1.85 px, a noise estimate of 2.61 px, within 1.5 times
// the 1 px prior (3.49 px at 0.1 %) but not within the prior itself (2.33 px). The screen tests
// at the prior (AutoFitOptions::screen_noise_tolerance = 1), so the points go to the outlier
// stage, which cannot convict one of 6 points, and the camera richer than pose + focal must
// then leave 6 equations to spare: pose + focal, rms 26.6 px, refused as contaminated. Screened
// at 1.5 times the prior, as the final gate is, the answer was 96.5 px off at that corner.
TEST(FitAutoTest, AMisclickThatOnlyTheAssumedNoiseShowsIsLookedFor) {
  const std::vector<Row> clicks = {
      {4.1293371516901125, -1.1982272111375656, 2.8606300220157954, 645, 198},
      {1.2190322017330113, 1.171661034101891, 0, 1193, 884},
      {4.1293371516901125, -1.1982272111375656, 0, 677, 1035},
      {4.1293371516901125, 0.14428647856093346, 2.8606300220157954, 1097, 122},
      {1.2190322017330113, 1.171661034101891, 1.40069856388935, 1195, 617},
      {0.5893005789887303, 1.0640233293979209, 1.9818795528005135, 1150, 516},
  };
  const std::vector<Row> vertices = {  // true pixels (bench --clicks --dump)
      {4.1293371516901125, -1.1982272111375656, 2.8606300220157954, 659.3018625109014,
       102.42671372237328},
      {4.1293371516901125, -1.0639758421677157, 2.574567019814216, 706.066814628079,
       201.36179242418746},
  };
  const EmbeddedScene scene = Embed(clicks, vertices);
  const std::optional<SceneError> refusal = RefusalOf(scene);
  if (refusal) {
    EXPECT_EQ(refusal->reason(), SceneError::Reason::kContaminated) << refusal->what();
  }
  AutoFitOptions screened_as_gated;
  screened_as_gated.screen_noise_tolerance = screened_as_gated.noise_tolerance;
  const FitResult absorbed = Auto(scene.points, scene.pixels, screened_as_gated);
  EXPECT_GT(WorstVertexErrorPx(absorbed.camera, scene), 10.0)
      << "the scene no longer shows what the rule is for";
}

// Scene 130 of the click benchmark's held-out 8-point mis-click band: point 5 clicked 187 px
// from its corner (the first vertex below). Pose + focal + principal point fits all 8 clicks at
// 1.74 px rms (sum 24.2 px^2, within the gate's 1.5 times the 1 px prior) in another minimum, a
// 144 deg view at fx 312 px for a true 1689, and the selection went on to 12 parameters at 0.76
// px rms. Without point 5 the other 7 fit at a sum of 1.28 px^2: a drop of 22.9 px^2 against
// chi2_2(1 - 0.001 / 8) = 18.0 for the 1 px prior (FindAbsorbedOutlier), the only drop above it
// (the next: 9.9). Left out, the 7 do not determine the camera (the true model on them is 87 px
// off too): refused, naming point 5. With every point kept the answer is 187 px off there.
TEST(FitAutoTest, AMisclickTheFitAbsorbedIsFoundByLeavingEachPointOut) {
  const std::vector<Row> clicks = {
      {0.3364860760467173, -0.5675242268983058, 1.7727279235089262, 876, 361},
      {-0.3364860760467173, -0.5675242268983058, 0, 838, 794},
      {0.3364860760467173, 0.5675242268983058, 0, 1133, 800},
      {0.3123287633677043, 0.2883363758163824, 2.8625271565431207, 1076, 89},
      {-0.2614583682171029, -0.5149762203936403, 2.8625271565431207, 843, 291},
      {0.3364860760467173, -0.5675242268983058, 0, 882, 813},
      {0.3364860760467173, 0.5675242268983058, 1.7727279235089262, 1139, 375},
      {0.3123287633677043, -0.5149762203936403, 2.8625271565431207, 882, 64},
  };
  const std::vector<Row> vertices = {  // true pixels (bench --clicks --dump)
      {-0.2614583682171029, -0.5149762203936403, 2.8625271565431207, 840.6230998787981,
       103.95866086949275},
      {-0.2614583682171029, 0.2883363758163824, 2.8625271565431207, 1021.8117461687118,
       125.1691087071423},
  };
  const EmbeddedScene scene = Embed(clicks, vertices);
  const std::optional<SceneError> refusal = RefusalOf(scene);
  if (refusal) {
    EXPECT_EQ(refusal->fix().rfind("Fix or drop point 5 (", 0), 0u) << refusal->what();
  }
  AutoFitOptions keep_all;
  keep_all.find_outliers = false;
  const FitResult absorbed = Auto(scene.points, scene.pixels, keep_all);
  EXPECT_GT(WorstVertexErrorPx(absorbed.camera, scene), 10.0)
      << "the scene no longer shows what the rule is for";
}

// Object points add test points and nothing else: where they are the fitted points themselves
// (the clicks the answer kept: a left-out click is a point off the fit, which can decide), or
// behind the camera, the answer is the same to the last bit (every seed, 6 to 12 clicks); only
// the determination's wording says they were looked at. 20 seeds per count: about half of these
// scenes are refused (at 6-8 clicks most), and at least 15 must be compared.
TEST(FitAutoTest, ObjectPointsOnlyAddTestPoints) {
  int compared = 0;
  for (const int n : {6, 8, 12}) {
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const SynthScene scene = Clicks(seed, n);
      const Correspondences& c = scene.correspondences;
      FitResult plain;
      try {
        plain = Auto(c.points_in_world, c.pixels);
      } catch (const SceneError&) {
        continue;
      }
      AutoFitOptions with_object;
      for (size_t i = 0; i < c.points_in_world.size(); ++i) {
        if (std::find(plain.outliers.begin(), plain.outliers.end(), static_cast<int>(i)) ==
            plain.outliers.end()) {
          with_object.object_points_in_world.push_back(c.points_in_world[i]);
        }
      }
      const Eigen::Vector3d eye = CameraCenterInWorld(plain.camera.cam_from_world);
      const Eigen::Vector3d centroid = c.points_in_world[0];
      with_object.object_points_in_world.push_back(eye + (eye - centroid));  // behind the eye
      const FitResult judged = Auto(c.points_in_world, c.pixels, with_object);
      EXPECT_EQ(judged.model, plain.model) << "n " << n << " seed " << seed;
      EXPECT_EQ(judged.camera.intrinsics.fx, plain.camera.intrinsics.fx);
      EXPECT_EQ(judged.camera.cam_from_world.translation, plain.camera.cam_from_world.translation);
      EXPECT_EQ(judged.determination.max_sigma_px, plain.determination.max_sigma_px);
      EXPECT_NE(judged.determination.summary.find("and the object points"), std::string::npos);
      ++compared;
    }
  }
  EXPECT_GE(compared, 15) << "too few answered scenes to compare";
}

TEST(FitAutoTest, TheScreenToleranceLiesBetweenOneAndTheGates) {
  for (const double tolerance : {0.9, 1.6, double(NAN)}) {
    AutoFitOptions options;  // noise_tolerance 1.5
    options.screen_noise_tolerance = tolerance;
    try {
      options.Check();
      ADD_FAILURE() << "screen_noise_tolerance " << tolerance << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("screen_noise_tolerance"), std::string::npos)
          << e.what();
    }
  }
  AutoFitOptions bounds;
  for (const double tolerance : {1.0, 1.5}) {
    bounds.screen_noise_tolerance = tolerance;
    EXPECT_NO_THROW(bounds.Check());
  }
}

TEST(FitAutoTest, ObjectPointsMustBeFinite) {
  AutoFitOptions options;
  options.object_points_in_world = {Eigen::Vector3d(0, 0, 1),
                                    Eigen::Vector3d(0, NAN, 1)};
  try {
    options.Check();
    ADD_FAILURE() << "a NaN object point was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("object_points_in_world[1]"), std::string::npos)
        << e.what();
  }
}

// A plane and its mirror image are the same plane moved (a reflection within it is a half turn
// out of it), so points on a plane never tell the world's handedness and are never refused for
// it: every seed, 6 to 12 points.
TEST(FitAutoTest, PlanesAreNeverRefusedAsPossiblyMirrored) {
  for (const int n : {6, 8, 12}) {
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const SynthScene scene = Clicks(seed, n, SynthObject::kPlane);
      try {
        Auto(scene.correspondences.points_in_world, scene.correspondences.pixels);
      } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()).find("flipped"), std::string::npos)
            << "n " << n << " seed " << seed << ": " << e.what();
      }
    }
  }
}

// One click among 8 moved by 60-200 px: never a camera that kept it (every seed), and it is
// named -- as the only point left out, by an answer or by a refusal whose 7 other points do not
// determine the camera (the message says to fix that point first) -- in at least 89 % of 200
// seeds: measured 189 (94.5 %), the bound 3 binomial sigmas below,
// 0.945 - 3 * sqrt(0.945 * 0.055 / 200) = 0.897. Counting also the refusals that name it among
// the 2-3 points whose removal each makes the rest consistent ("the points cannot tell which:
// among point 1 or point 8"), the issue's 95 %: measured 193 (96.5 %). The other 7 are refused
// without a name (no single point explains the residuals, or one point behind the camera).
TEST(FitAutoTest, OneMisclickAmongEightIsNamed) {
  std::mt19937_64 rng(testing::Seed(8));
  int named = 0;
  int among_candidates = 0;
  constexpr int kSeeds = 200;
  constexpr double kNotNamedAlone = 0.11;
  constexpr double kNotNamed = 0.05;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    SynthScene scene = Clicks(seed, 8);
    std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
    const int bad = static_cast<int>(seed % 8);
    Misclick(&pixels, bad, std::uniform_real_distribution<double>(60.0, 200.0)(rng), rng);
    try {
      const FitResult fit = Auto(scene.correspondences.points_in_world, pixels);
      ASSERT_TRUE(std::binary_search(fit.outliers.begin(), fit.outliers.end(), bad))
          << "seed " << seed << ": kept the mis-click, model " << fit.model << ", rms "
          << fit.rms_px;
      ASSERT_LE(fit.outliers.size(), 2u) << "seed " << seed;
      if (fit.outliers.size() != 1) continue;
      EXPECT_GT(fit.left_out[0].residual_px, 30.0);
      EXPECT_GT(fit.left_out[0].rms_with_px, 5.0 * fit.rms_px);
      ++named;
    } catch (const SceneError& e) {
      // A refusal is allowed; a wrong answer is not. It names the mis-click if it says to fix it.
      // Alone: the fix begins "Fix or drop point N (... puts it), left out ...".
      const std::string what = e.what();
      const std::string fix = e.fix();
      const std::string name = "point " + std::to_string(bad + 1);
      const size_t list_end = fix.find("), ");
      if (fix.rfind("Fix or drop " + name + " (", 0) == 0 && list_end != std::string::npos &&
          fix.compare(list_end, 11, "), left out") == 0) {
        ++named;
      }
      const size_t among = what.find("(among ");
      if (among != std::string::npos) {
        const std::string list = what.substr(among, what.find(')', among) - among);
        if ((list + ",").find(name + ",") != std::string::npos ||
            (list + " ").find(name + " ") != std::string::npos) {
          ++among_candidates;
        }
      }
    }
  }
  testing::ExpectRate("mis-clicks among 8 not named alone", kSeeds - named, kSeeds, kNotNamedAlone);
  testing::ExpectRate("mis-clicks among 8 not named, alone or among candidates",
                      kSeeds - named - among_candidates, kSeeds, kNotNamed);
}

// The least checked point (FitResult::reliability, the redundancy numbers of Baarda's internal
// reliability) says what the data can check. Its redundancy is at most the mean over every point
// and direction, (2N - p) / 2N (the least of the points' smaller redundancies cannot exceed their
// mean). And it is what it says, the first-order response of the point's residual to its own
// pixel: on noise-free clicks (where J^T J is the whole Hessian at the minimum, so the Gauss-Newton
// hat matrix is the exact linear response) the same model refitted (FitCamera) with the point
// moved by kMovePx along the reported direction moves its residual by the redundancy times that,
// within kFirstOrder of the move (the second-order term, ~1e-4 of it at 0.01 px, and the
// refits' convergence, 1e-9 px). (With noisy clicks the residuals' curvature adds to the Hessian
// where J^T J is weak: at 8 points a redundancy of 0.07 responded as 0.13.) Box clicks at 6, 8,
// 12 and 20 points, with the principal point free (the projector's) or not, 20 seeds each.
TEST(FitAutoTest, TheLeastCheckedPointKeepsWhatItsRedundancySays) {
  constexpr int kSeeds = 20;
  constexpr double kMovePx = 0.01;
  constexpr double kFirstOrder = 1e-3;
  int checked = 0;
  for (const int n : {6, 8, 12, 20}) {
    for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
      const SynthScene scene = Clicks(seed, n);
      const auto& points = scene.correspondences.points_in_world;
      std::vector<Eigen::Vector2d> pixels;
      for (const Eigen::Vector3d& x : points) pixels.push_back(*PixelFromWorld(scene.truth, x));
      FitResult fit;
      try {
        fit = Auto(points, pixels);
      } catch (const SceneError&) {
        continue;
      }
      const PointReliability& least = fit.reliability;
      SCOPED_TRACE(::testing::Message() << "n " << n << ", seed " << seed << ", " << fit.model
                                        << ": " << least.summary);
      ASSERT_TRUE(least.checked);
      ASSERT_GE(least.point, 0);
      const double p = static_cast<double>(fit.free_parameters.size());
      EXPECT_GE(least.redundancy, 0.0);
      EXPECT_LE(least.redundancy, (2.0 * n - p) / (2.0 * n) + 1e-12);
      EXPECT_NEAR(least.direction.norm(), 1.0, 1e-12);
      // The model as chosen, refitted without the selection.
      FitOptions model;
      model.focal = ParameterMode::Free();
      model.principal_point = fit.model.find("principal-point") != std::string::npos
                                  ? ParameterMode::Free()
                                  : ParameterMode::Default();
      model.aspect = fit.model.find("aspect") != std::string::npos ? ParameterMode::Free()
                                                                   : ParameterMode::Default();
      model.skew = fit.model.find("skew") != std::string::npos ? ParameterMode::Free()
                                                               : ParameterMode::Default();
      model.k1 = fit.model.find("k1") != std::string::npos ? ParameterMode::Free()
                                                           : ParameterMode::Default();
      model.k2 = fit.model.find("k2") != std::string::npos ? ParameterMode::Free()
                                                           : ParameterMode::Default();
      FitResult before, after;
      try {
        before = FitCamera(points, pixels, {1920, 1080}, model);
        pixels[least.point] += kMovePx * least.direction;
        after = FitCamera(points, pixels, {1920, 1080}, model);
      } catch (const SceneError&) {
        continue;  // from its own closed form the model's fit stops in a flat valley
      }
      ASSERT_EQ(before.model, fit.model);
      // residual = predicted - observed: moving the observation by d moves it by -(I - H) d.
      const Eigen::Vector2d change =
          after.residuals_px[least.point] - before.residuals_px[least.point];
      EXPECT_NEAR(-change.dot(least.direction) / kMovePx, least.redundancy, kFirstOrder);
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);
}

// Regression (OneMisclickAmongEightIsNamed at seed offset 1001, seed 80): seven clicks on one
// face of the box and a mis-click, 60-200 px off, that is the only point off their plane. The
// leave-one-out search judged every subset with pose + focal + principal point, which the plane
// without the mis-click cannot determine, so only the subset that kept the mis-click (and left
// out a good point) counted: answered with fx 755 px for a true 1484, exit 0. A plane subset is
// now judged with the next detection model too, its reading counts, and the scene is refused.
TEST(FitAutoTest, AMisclickOffThePlaneOfTheOthersIsNotKept) {
  const std::vector<Eigen::Vector3d> points = {
      {-0.038596128744374902, 0.038643159533135796, 0.40000000000000002},
      {0.049379596722151087, 0.29999999999999999, 0.17791905514738665},
      {-0.39349356926042944, 0.29999999999999999, -0.056270009366932432},
      {0.047253545404403186, 0.29999999999999999, 0.15699268480268957},
      {0.27341808323228411, 0.29999999999999999, 0.14580308227778324},
      {0.027116432806628454, 0.29999999999999999, 0.26757017567187952},
      {0.39500008526791508, 0.29999999999999999, 0.37849018969594639},
      {-0.47808339616399131, 0.29999999999999999, 0.36829198463541185}};
  const std::vector<Eigen::Vector2d> pixels = {
      {974.47471305449699, 966.10884043746728}, {1070, 278}, {371, 140}, {1061, 263},
      {1424, 238}, {1051, 358}, {1780, 436}, {60, 511}};
  try {
    const FitResult fit = Auto(points, pixels);
    EXPECT_TRUE(std::binary_search(fit.outliers.begin(), fit.outliers.end(), 0))
        << "kept the mis-click: " << fit.model << ", fx " << fit.camera.intrinsics.fx;
  } catch (const SceneError&) {
    // A refusal is right: the clicks alone cannot say which reading is the camera.
  }
}

// Six points and one mis-click: leaving any point out leaves too few to check the rest, so the
// scene is refused, never guessed -- unless the 9-parameter fit absorbs the mis-click within the
// noise (3 redundant equations can hide a mis-click along the directions the camera's freedom
// can follow): at least 95 % of 100 seeds refused (measured: 99), and the refusals are never
// numerical failures. Nor is the world called mirrored, unless its mirrored reading explains
// the clicks within the noise (the mis-click absorbed there): 1 of the click benchmark's 400
// held-out mis-click scenes at 6-7 points. (A mirrored reading that merely fit better than the
// orthographic camera was called a mirror in 6 and 4 of these 100 at seed offsets 0 and 1000.)
TEST(FitAutoTest, SixPointsWithAMisclickAreRefused) {
  constexpr double kMirroredMisclickRate = 1.0 / 400.0;
  std::mt19937_64 rng(testing::Seed(6));
  int answered = 0;
  int mirrored = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    SynthScene scene = Clicks(seed, 6);
    std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
    Misclick(&pixels, static_cast<int>(seed % 6), std::uniform_real_distribution<double>(60.0, 200.0)(rng), rng);
    try {
      Auto(scene.correspondences.points_in_world, pixels);
      ++answered;
    } catch (const SceneError& e) {
      EXPECT_NE(e.reason(), SceneError::Reason::kNumerical) << e.what();
      if (e.reason() == SceneError::Reason::kMirroredWorld) ++mirrored;
    }
  }
  RecordProperty("answered", answered);
  EXPECT_LE(answered, 5);
  testing::ExpectRate("right-handed worlds with a mis-click refused as mirrored", mirrored, 100,
                      kMirroredMisclickRate);
}

// 10, 30 and 50 % of 100 points replaced by random pixels: without options the outliers are
// left out and the camera predicts the true image. Bound: over the inliers, the RMS difference
// between the fit's and the truth's pixels is in expectation sqrt(p / N_in) * sigma * sqrt(2)
// (p = 9 parameters, sigma 0.7 px plus rounding 0.29 px); 3x that bounds it. Random pixels that
// land within the inlier bound of their true projection by chance may be kept (probability ~1e-4
// each), so the outlier set is checked to contain every point further than 20 px.
// Refusals are counted, not failures, per clean scene (a seed; its three fractions share its
// points and often its fate): on seeds 1-2000 of these scenes (6000 fits) 9 were refused as not
// determined (a rival such as + k1 fitting about as well, 5-10 px apart over the widened box) and
// 1 by the gate (a random pixel 4.8 px from its point's projection, not named by the re-read
// consensus), in 9 scenes; at the 99 % upper limit of that rate (9.5e-3 per scene) 3 or more of
// these 10 scenes refused has probability 1.4e-4.
TEST(FitAutoTest, OutliersAreLeftOutWithoutOptions) {
  constexpr int kScenesRefusedAllowed = 2;
  std::set<uint64_t> refused;
  for (const double fraction : {0.1, 0.3, 0.5}) {
    for (uint64_t seed = 1; seed <= 10; ++seed) {
      SynthScene scene = Clicks(seed, 100, SynthObject::kCloud);
      std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
      std::mt19937_64 rng(testing::Seed(seed));
      const int num_outliers = static_cast<int>(fraction * 100);
      for (int i = 0; i < num_outliers; ++i) {
        pixels[i] = RandomPixel(rng);
      }
      const auto& points = scene.correspondences.points_in_world;
      FitResult fit;
      try {
        fit = Auto(points, pixels);
      } catch (const SceneError& e) {
        EXPECT_TRUE(e.reason() == SceneError::Reason::kAmbiguous ||
                    e.reason() == SceneError::Reason::kDegenerate ||
                    e.reason() == SceneError::Reason::kInconsistent)
            << "fraction " << fraction << " seed " << seed << ": " << e.what();
        refused.insert(seed);
        continue;
      }
      double sum = 0.0;
      int inliers = 0;
      for (int i = 0; i < 100; ++i) {
        const Eigen::Vector2d truth = *PixelFromWorld(scene.truth, points[i]);
        const bool far = (truth - pixels[i]).norm() > 20.0;
        if (far) {
          EXPECT_TRUE(std::binary_search(fit.outliers.begin(), fit.outliers.end(), i))
              << "fraction " << fraction << " seed " << seed << " point " << i;
        }
        if (i >= num_outliers) {
          sum += (*PixelFromWorld(fit.camera, points[i]) - truth).squaredNorm();
          ++inliers;
        }
      }
      const double noise = std::hypot(0.7, 1.0 / std::sqrt(12.0));
      EXPECT_LT(std::sqrt(sum / inliers), 3.0 * std::sqrt(9.0 / inliers) * noise * std::sqrt(2.0))
          << "fraction " << fraction << " seed " << seed << " model " << fit.model;
    }
  }
  EXPECT_LE(refused.size(), kScenesRefusedAllowed);
}

// Gaussian noise of 2.5 px against the 1 px prior, no outlier: refused as noisier than assumed,
// without an outlier search (MayBeOutliers, fit/outliers.h) that would leave out the noise's
// tails, saying so and how to state the noise; with --sigma 2.5 the same points are answered
// with every point kept. Per scene, independent residuals of 100-300 points show outliers by
// chance in 0.25-0.34 % (gate_test), and the robust noise (2.5 px) falls within the gate's bound
// and its sampling margin (RobustNoiseBeyondTheBound: 2.18 px at 100 points, log sd 0.072: 1.9
// sd below 2.5 px) in 2.7 % at 100 points and never at 300; measured on the fits: 4 of 120
// scenes at seed offsets 0-500 (each searched, then refused otherwise). With the noise given, the gate's two
// tests fail clean points in about 2 alpha = 0.2 % (AutoFitOptions::significance), and
// LO-RANSAC may then leave out a point. Bound: p = 3 % per scene for either.
TEST(FitAutoTest, NoiseAboveTheAssumedIsRefusedWithoutLeavingPointsOut) {
  constexpr double kPerScene = 0.03;
  int trials = 0;
  int not_as_noise = 0;
  int given_not_kept = 0;
  for (const int n : {100, 300}) {
    for (uint64_t seed = 1; seed <= 10; ++seed) {
      SynthOptions synth;
      synth.seed = testing::Seed(seed);
      synth.num_points = n;
      synth.noise_px = 2.5;
      synth.principal_point_offset = Eigen::Vector2d(0.0, 0.4);
      const SynthScene scene = SynthesizeScene(synth);
      const auto& points = scene.correspondences.points_in_world;
      const auto& pixels = scene.correspondences.pixels;
      ++trials;
      try {
        const FitResult fit = Auto(points, pixels);
        ++not_as_noise;
        ADD_FAILURE() << "n " << n << " seed " << seed << ": answered " << fit.model << ", "
                      << fit.outliers.size() << " left out";
      } catch (const SceneError& e) {
        const std::string message = e.what();
        const bool as_noise = e.reason() == SceneError::Reason::kInconsistent &&
                              message.find("no point stands out") != std::string::npos &&
                              message.find("give --sigma") != std::string::npos;
        if (!as_noise) ++not_as_noise;
        if (!as_noise) std::printf("n %d seed %llu: %s\n", n, (unsigned long long)seed, e.what());
      }
      AutoFitOptions given;
      given.fit.pixel_sigma = 2.5;
      try {
        const FitResult fit = Auto(points, pixels, given);
        if (!fit.outliers.empty()) ++given_not_kept;
      } catch (const SceneError& e) {
        ++given_not_kept;
        std::printf("n %d seed %llu, --sigma 2.5: %s\n", n, (unsigned long long)seed, e.what());
      }
    }
  }
  testing::ExpectRate("noisier than assumed, not refused as noise", not_as_noise, trials, kPerScene);
  testing::ExpectRate("noise given, refused or points left out", given_not_kept, trials, kPerScene);
}

// A mis-click among points a little noisier than assumed (1.8 px for the 1 px prior, 40 points,
// one 12 px off): the robust noise is within the gate's bound, so the outlier stage runs
// (MayBeOutliers, fit/outliers.h) and an answer leaves the mis-click out (with it, now and then,
// a good point beyond the 1 px prior's bound) unless its residual is within the gate's outlier
// bound (the fit absorbed it: 1 of 20 at seed offset 9999); no refusal says that no point stands
// out.
// (Skipping the search on the ratio test alone refused such scenes saying so, where the search
// answers: found in a review of session 32. Answered: 9-16 of 20 at seed offsets 0-300.)
TEST(FitAutoTest, AMisclickAmongNoiseAboveTheAssumedIsStillLookedFor) {
  int answered = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.num_points = 40;
    synth.noise_px = 1.8;
    synth.object = SynthObject::kBox;
    synth.principal_point_offset = Eigen::Vector2d(0.0, 0.4);
    const SynthScene scene = SynthesizeScene(synth);
    std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
    pixels[0].x() += 12.0;
    try {
      const FitResult fit = Auto(scene.correspondences.points_in_world, pixels);
      ++answered;
      // Kept only where it does not stand out: within the gate's outlier bound.
      if (!std::binary_search(fit.outliers.begin(), fit.outliers.end(), 0)) {
        EXPECT_LE(fit.residuals_px[0].norm(), fit.consistency.max_residual_bound_px)
            << "seed " << seed << ": the mis-click kept";
      }
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).find("no point stands out"), std::string::npos)
          << "seed " << seed << ": " << e.what();
    }
  }
  std::printf("[ INFO     ] answered with the mis-click left out: %d of 20\n", answered);
  EXPECT_GE(answered, 1);
}

// A plane seen by a 1280 x 720 camera with a 50 deg vertical view (the tests below fit it as
// 1920 x 1080: an image size that is not the image's).
SynthScene PlaneShotAt1280x720(uint64_t seed, int num_points, double noise_px) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = num_points;
  synth.noise_px = noise_px;
  synth.object = SynthObject::kPlane;
  synth.image_size = {1280, 720};
  synth.fovy_deg = 50.0;
  return SynthesizeScene(synth);
}

// A plane shot at 1280 x 720 and fitted as 1920 x 1080 (its principal point assumed 320 px
// right of and 180 px below the truth): every point moves alike, and LO-RANSAC's consensus is
// part of the points, the rest left out as if outliers (data/plane: 16 of 30 points left out,
// k1 -0.25, answered before; 21 of 60 such scenes answered so, 10-19 of 30 left out). The scene
// has no outlier, so no answer may leave one out: a consensus of fewer than half the points is
// refused (RefuseAMinority), and so is a quarter or more left out nearer to the camera's pixels
// than random pixels would be (RefuseIfTheLeftOutAreNotRandom); both say to check the image
// size. Refused as a minority: 49 of 100 scenes at seed offsets 0-4000; at that rate none of
// 20 with probability 0.51^20 = 1.4e-6. Fewer left out, where the plane's homography fits every
// point, are refused too (PointsLeftOutOfAPlaneWhoseHomographyFitsThemAllAreRefused): no answer
// left a point out at seed offsets 0-150000 in steps of 1000.
TEST(FitAutoTest, AMinorityConsensusIsRefused) {
  int refused_as_minority = 0;
  int trials = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const SynthScene scene = PlaneShotAt1280x720(seed, 30, 0.5);
    const auto& points = scene.correspondences.points_in_world;
    const auto& pixels = scene.correspondences.pixels;
    ++trials;
    try {
      const FitResult fit = FitCameraAuto(points, pixels, {1920, 1080}, {});
      EXPECT_TRUE(fit.outliers.empty())
          << "seed " << seed << ": " << fit.outliers.size() << " left out, " << fit.model;
    } catch (const SceneError& e) {
      const std::string message = e.what();
      if (message.find("more than half") != std::string::npos ||
          message.find("than random pixels would") != std::string::npos) {
        EXPECT_EQ(e.reason(), SceneError::Reason::kContaminated);
        EXPECT_NE(message.find("Check the image size"), std::string::npos) << message;
      }
      if (message.find("more than half") != std::string::npos) ++refused_as_minority;
    }
  }
  std::printf("[ INFO     ] refused as a minority consensus: %d of %d\n", refused_as_minority,
              trials);
  EXPECT_GE(refused_as_minority, 1);
}

// Regression (seed offsets 44000-100000 of AMinorityConsensusIsRefused, literal seeds): planes
// shot at 1280 x 720 and fitted as 1920 x 1080 that LO-RANSAC answered with 5-7 of their 30
// points left out (below the quarter of RefuseIfTheLeftOutAreNotRandom) and k1 -0.23 to -0.84.
// Every point fits one homography of the plane within the noise, so none is an outlier: refused,
// saying so and where the principal point was assumed.
TEST(FitAutoTest, PointsLeftOutOfAPlaneWhoseHomographyFitsThemAllAreRefused) {
  int refused_by_the_rule = 0;
  for (const uint64_t literal_seed : {44018, 49002, 75009, 76004, 79012, 82004, 88009, 95013,
                                      100016, 100020}) {
    SynthOptions synth;
    synth.seed = literal_seed;
    synth.num_points = 30;
    synth.noise_px = 0.5;
    synth.object = SynthObject::kPlane;
    synth.image_size = {1280, 720};
    synth.fovy_deg = 50.0;
    const SynthScene scene = SynthesizeScene(synth);
    try {
      const FitResult fit = Auto(scene.correspondences.points_in_world, scene.correspondences.pixels);
      EXPECT_TRUE(fit.outliers.empty())
          << "seed " << literal_seed << ": " << fit.outliers.size() << " left out, " << fit.model;
    } catch (const SceneError& e) {
      const std::string message = e.what();
      if (message.find("are no outliers") == std::string::npos) continue;  // another reason
      ++refused_by_the_rule;
      EXPECT_EQ(e.reason(), SceneError::Reason::kInconsistent) << message;
      EXPECT_NE(message.find("check that the image size is the image's"), std::string::npos)
          << message;
    }
  }
  std::printf("[ INFO     ] refused as no outliers of the plane: %d of 10\n", refused_by_the_rule);
  // Measured: all 10 (each was answered before the rule).
  EXPECT_GE(refused_by_the_rule, 5);
}

// The rule above leaves a plane's real mis-click to the outlier stage: one point of 30 moved
// 30-150 px fails the homography's gate as it fails the camera's (at 0.5 px noise its drop in
// the sum of squares is hundreds of sigma^2), so the scene is answered with that point left out
// (a rate of at most 5 % otherwise over 40 seeds; a scene may still be refused for another
// reason, but never by this rule).
TEST(FitAutoTest, AMisclickOnAPlaneIsStillLeftOut) {
  std::mt19937_64 rng(testing::Seed(31));
  constexpr int kSeeds = 40;
  int named = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(600 + seed);
    synth.num_points = 30;
    synth.noise_px = 0.5;
    synth.object = SynthObject::kPlane;
    synth.image_size = {1920, 1080};
    const SynthScene scene = SynthesizeScene(synth);
    std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
    const int bad = static_cast<int>(seed % 30);
    Misclick(&pixels, bad, std::uniform_real_distribution<double>(30.0, 150.0)(rng), rng);
    AutoFitOptions options;
    options.fit.principal_point = ParameterMode::Fixed(scene.truth.intrinsics.cx,
                                                       scene.truth.intrinsics.cy);
    try {
      const FitResult fit = Auto(scene.correspondences.points_in_world, pixels, options);
      named += fit.outliers == std::vector<int>{bad};
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).find("are no outliers"), std::string::npos)
          << "seed " << seed << ": " << e.what();
    }
  }
  // Measured: 1.4 % of seeds not so answered (17 of 1240 at seed offsets 0-30000).
  testing::ExpectRate("a mis-click on a plane not left out alone", kSeeds - named, kSeeds, 0.05);
}

// Eight clicks on a plane shot at 1280 x 720, fitted as 1920 x 1080: a refusal for residuals
// no point explains says where the principal point was assumed and to check the image size
// (a plane does not show it).
TEST(FitAutoTest, APlaneRefusedForItsResidualsNamesTheAssumedPrincipalPoint) {
  int refused_for_residuals = 0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const SynthScene scene = PlaneShotAt1280x720(seed, 8, 0.7);
    const auto& points = scene.correspondences.points_in_world;
    const auto& pixels = scene.correspondences.pixels;
    try {
      FitCameraAuto(points, pixels, {1920, 1080}, {});
    } catch (const SceneError& e) {
      if (e.reason() == SceneError::Reason::kInconsistent ||
          e.reason() == SceneError::Reason::kContaminated) {
        ++refused_for_residuals;
        EXPECT_EQ(e.fix().rfind("The principal point is assumed at the image's centre (960, 540): "
                                "check that the image size is the image's",
                                0),
                  0u)
            << "seed " << seed << ": " << e.what();
      }
    }
  }
  // 9 of 10 at seed offset 0 (the 10th is answered: its clicks fit a camera with the principal
  // point at the assumed centre within the noise).
  EXPECT_GE(refused_for_residuals, 1);
}

// Purely random pixels are refused, never answered.
TEST(FitAutoTest, RandomPixelsAreRefused) {
  for (const int n : {8, 30, 200}) {
    for (uint64_t seed = 1; seed <= (n == 200 ? 3u : 10u); ++seed) {
      SynthScene scene = Clicks(seed, n, SynthObject::kCloud);
      std::mt19937_64 rng(testing::Seed(seed));
      for (auto& u : scene.correspondences.pixels) {
        u = RandomPixel(rng);
      }
      try {
        const FitResult fit = Auto(scene.correspondences.points_in_world, scene.correspondences.pixels);
        ADD_FAILURE() << "n " << n << " seed " << seed << ": answered " << fit.model << " rms "
                      << fit.rms_px;
      } catch (const SceneError& e) {
        EXPECT_NE(e.reason(), SceneError::Reason::kNumerical) << e.what();
      }
    }
  }
}

// --keep-all: the mis-click is kept and the scene refused, by the gate naming it. Least squares
// spreads a mis-click over its neighbours, so it is among the worst three named, not
// necessarily the first. 120 px on one of 10 clicks can also turn the best linear camera's view
// of some points around (refused before the gate as points behind it, as in 1 of the 20 seeds
// here); the bound below allows that in up to a quarter of the scenes.
TEST(FitAutoTest, KeepAllRefusesAContaminatedSceneNamingTheWorstPoint) {
  constexpr int kSeeds = 20;
  int named = 0;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    SynthScene scene = Clicks(seed, 10);
    std::vector<Eigen::Vector2d> pixels = scene.correspondences.pixels;
    pixels[4].x() += pixels[4].x() < 960.0 ? 120.0 : -120.0;
    AutoFitOptions options;
    options.find_outliers = false;
    options.point_names = {"a", "b", "c", "d", "e", "f", "g", "h", "i", "j"};
    try {
      const FitResult fit = Auto(scene.correspondences.points_in_world, pixels, options);
      ADD_FAILURE() << "seed " << seed << ": answered " << fit.model << ", rms " << fit.rms_px;
    } catch (const SceneError& e) {
      if (e.reason() == SceneError::Reason::kInconsistent) {
        EXPECT_NE(std::string(e.what()).find("e ("), std::string::npos) << e.what();
        ++named;
      } else {
        EXPECT_EQ(e.reason(), SceneError::Reason::kPointsBehindCamera) << e.what();
      }
    }
  }
  EXPECT_GE(named, kSeeds * 3 / 4);
}

// A non-finite point is named as the user named it (its id in the points file), or numbered from
// 1 when the points have no names.
TEST(FitAutoTest, ANonFinitePointIsNamedByItsId) {
  SynthScene scene = Clicks(3, 10);
  std::vector<Eigen::Vector3d> points = scene.correspondences.points_in_world;
  points[4].z() = std::numeric_limits<double>::infinity();
  AutoFitOptions options;
  options.point_names = {"a", "b", "c", "d", "corner-e", "f", "g", "h", "i", "j"};
  for (const bool named : {true, false}) {
    if (!named) options.point_names.clear();
    try {
      Auto(points, scene.correspondences.pixels, options);
      ADD_FAILURE() << "answered";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.reason(), SceneError::Reason::kNonFiniteInput);
      const std::string name = named ? "corner-e" : "point 5";
      EXPECT_NE(std::string(e.what()).find(name + " is not finite"), std::string::npos)
          << e.what();
    }
  }
}

// Regression (FitAutoStress at seed offsets 3, 11 and 123: its scene 1588, large-offset): ten
// clean points 8.7e7 scene sizes from the origin, where double precision moves their pixels by
// 1.1e-5 px, above CheckOffset's 1e-5. The screen refused them for it, and the outlier stage then
// left out the point with the farthest pixel, which brought the nine others under the bound: an
// answer (with an outlier named) where the unmoved points chose another model. Refused now, as
// FitCamera refuses the same points, with the advice to subtract an offset.
TEST(FitAutoTest, AnOffsetRefusalIsNotDodgedByLeavingAPointOut) {
  const std::vector<Row> clicks = {
      {-653103252.04248524, 86840183.229456231, -4106829.1865851865, 2515.2792510444538, 77.107326662076872},
      {-653103249.62477517, 86840186.141006917, -4106836.6821978404, 2821.2446322368387, 150.798103806065},
      {-653103253.17063367, 86840183.133369207, -4106826.4694404989, 3543.9175338121731, 8.9446882149736169},
      {-653103248.61427081, 86840185.256845236, -4106836.3129637456, 2638.6649330149071, 361.17035222159728},
      {-653103246.9800483, 86840187.13000828, -4106843.4682646953, 1781.0307698608731, 250.66352538702785},
      {-653103249.01540756, 86840185.608023301, -4106840.1157158897, 267.91319776525046, 4.5503900668943356},
      {-653103252.99162185, 86840182.733280584, -4106826.5410229275, 3114.9360730801095, 29.449321163388465},
      {-653103245.50328338, 86840187.388502926, -4106848.315631703, 138.67176834568426, 250.80533122173355},
      {-653103247.89642882, 86840186.013990775, -4106841.1152344588, 1188.0678328549648, 215.71220996614909},
      {-653103248.66237187, 86840185.175537959, -4106838.3340947931, 1288.8849180358357, 237.82516694269418},
  };
  const EmbeddedScene scene = Embed(clicks, {});
  const ImageSize size{3592, 425};
  try {
    FitCamera(scene.points, scene.pixels, size);
    ADD_FAILURE() << "FitCamera answered";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kNonFiniteInput) << e.what();
  }
  try {
    const FitResult fit = FitCameraAuto(scene.points, scene.pixels, size);
    ADD_FAILURE() << "answered " << fit.model << " leaving out " << fit.outliers.size()
                  << " point(s)";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.reason(), SceneError::Reason::kNonFiniteInput) << e.what();
    EXPECT_NE(std::string(e.what()).find("Subtract a common offset"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace camproj

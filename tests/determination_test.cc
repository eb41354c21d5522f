// The determination check's uncertainty (lib/src/fit/determination.h): exact on the fitted
// points (the hat matrix's trace), and calibrated against the scatter of repeated fits.
#include "fit/determination.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "camproj/synth.h"
#include "fit/candidate.h"
#include "fit/selection.h"
#include "seeds.h"
#include "test_scenes.h"

namespace camproj {
namespace {

SynthScene Scene(uint64_t seed, double noise_px) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = 12;
  synth.noise_px = noise_px;
  synth.principal_point_offset = Eigen::Vector2d(0.0, 0.3);
  return SynthesizeScene(synth);
}

FitOptions Model(bool principal_point, bool k1) {
  FitOptions model;
  model.aspect = ParameterMode::Default();
  model.principal_point = principal_point ? ParameterMode::Free() : ParameterMode::Default();
  model.k1 = k1 ? ParameterMode::Free() : ParameterMode::Default();
  return model;
}

// The pixels of `camera` as a function of 13 numbers: a rotation vector applied on the world's
// side (R exp([w]x)), the translation, and fx, fy, cx, cy, skew, k1, k2 -- a parameterization
// other than the library's (camera axes, eye, focal scale, aspect), with the same span for the
// full model, so the same sigmas.
Eigen::Vector2d PixelOf(const Camera& camera, const Eigen::Matrix<double, 13, 1>& delta,
                        const Eigen::Vector3d& x) {
  Camera moved = camera;
  const Eigen::Vector3d w = delta.head<3>();
  const Eigen::Matrix3d turn =
      w.norm() > 0.0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
  moved.cam_from_world.rotation = camera.cam_from_world.rotation * turn;
  moved.cam_from_world.translation += delta.segment<3>(3);
  Intrinsics& k = moved.intrinsics;
  k.fx += delta(6);
  k.fy += delta(7);
  k.cx += delta(8);
  k.cy += delta(9);
  k.skew += delta(10);
  k.k1 += delta(11);
  k.k2 += delta(12);
  return *PixelFromWorld(moved, x);
}

// The analytic Jacobian of the check against central differences in another parameterization:
// the full model's sigmas (focal, aspect, principal point, skew, k1, k2 free) at the box's
// corners and the fitted points. Steps 1e-5 of each number's scale: truncation ~1e-10, rounding
// ~1e-16 / 1e-5 = 1e-11 relative per entry, amplified by the normal equations' condition
// (asserted below 1e7 after Jacobi scaling; 1.06e6 at seed offset 42): 1e-4
// relative at worst; measured 2.4e-9 (a 5 % error in the k2 term of the distortion's derivative
// fails 87 of the 400 comparisons).
TEST(DeterminationTest, AnalyticJacobianMatchesCentralDifferences) {
  constexpr double kTolerance = 1e-4;
  FitOptions full;
  full.skew = full.k1 = full.k2 = ParameterMode::Free();
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    SynthScene scene = Scene(seed, 0.0);
    Camera& camera = scene.truth;
    camera.intrinsics.fy *= 1.02;
    camera.intrinsics.skew = 3.0;
    camera.intrinsics.k1 = seed % 2 ? -0.12 : 0.08;
    camera.intrinsics.k2 = 0.01;
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    std::vector<Eigen::Vector3d> test = internal::SceneTestPoints(camera, points);
    test.insert(test.end(), points.begin(), points.end());
    Eigen::Matrix<double, 13, 1> scale;
    const double t = camera.cam_from_world.translation.norm();
    const double f = camera.intrinsics.fx;
    scale << 1, 1, 1, t, t, t, f, f, f, f, f, 1, 1;
    auto jacobian_at = [&](const Eigen::Vector3d& x) {
      Eigen::Matrix<double, 2, 13> j;
      for (int c = 0; c < 13; ++c) {
        Eigen::Matrix<double, 13, 1> step = Eigen::Matrix<double, 13, 1>::Zero();
        step(c) = 1e-5 * scale(c);
        j.col(c) = (PixelOf(camera, step, x) - PixelOf(camera, -step, x)) / (2.0 * step(c));
      }
      return j;
    };
    Eigen::MatrixXd jacobian(2 * points.size(), 13);
    for (size_t i = 0; i < points.size(); ++i) jacobian.middleRows<2>(2 * i) = jacobian_at(points[i]);
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd d = normal.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd scaled = d.asDiagonal() * normal * d.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
    ASSERT_LT(eigen.eigenvalues().maxCoeff() / eigen.eigenvalues().minCoeff(), 1e7) << "seed " << seed;
    const Eigen::MatrixXd inverse = d.asDiagonal() * scaled.inverse() * d.asDiagonal();
    const std::vector<double> sigmas = internal::ReprojectionSigmaPx(camera, full, points, 1.0, test);
    for (size_t i = 0; i < test.size(); ++i) {
      const Eigen::Matrix<double, 2, 13> j = jacobian_at(test[i]);
      const double expected = std::sqrt((j * inverse * j.transpose()).trace());
      EXPECT_NEAR(sigmas[i], expected, kTolerance * expected) << "seed " << seed << ", point " << i;
    }
  }
}

// A clean cloud of n points, sigma 0.5 px, seen by a centred camera (odd seeds: a projector with
// lens shift), for the tests of a fit's kept normal equations.
SynthScene CleanCloud(uint64_t seed, int n) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = n;
  synth.noise_px = 0.5;
  synth.principal_point_offset = Eigen::Vector2d(0.0, seed % 2 ? 0.5 : 0.0);
  return SynthesizeScene(synth);
}

// The fitted points and the box's test points around them (`camera`'s view).
std::vector<Eigen::Vector3d> FittedAndTestPoints(const Camera& camera,
                                                 const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> test = points;
  for (const Eigen::Vector3d& x : internal::SceneTestPoints(camera, points, 0.5)) test.push_back(x);
  return test;
}

// Expects `from_fit` within `tolerance` (relative) of `from_pass` wherever the pass has a sigma;
// returns the largest relative difference.
double ExpectSameSigmas(const std::vector<double>& from_fit, const std::vector<double>& from_pass,
                        double tolerance, const std::string& context) {
  EXPECT_EQ(from_fit.size(), from_pass.size()) << context;
  double worst = 0.0;
  for (size_t i = 0; i < std::min(from_fit.size(), from_pass.size()); ++i) {
    if (!std::isfinite(from_pass[i])) continue;
    EXPECT_NEAR(from_fit[i], from_pass[i], tolerance * from_pass[i]) << context << ", point " << i;
    worst = std::max(worst, std::abs(from_fit[i] - from_pass[i]) / from_pass[i]);
  }
  return worst;
}

// A fitted rival's sigmas read from its fit's normal equations (the candidate's, as the model
// selection keeps them) equal those of a pass over the points at its camera: the same quantity
// in another parameterization, linearized up to one step apart. Where that step was within the
// polish's convergence test (under 1e-3 of the residuals' sigma; least_squares.cc) the sigmas
// agree to 1e-3 (measured over seed offsets 0-99000 in steps of 1000: up to 3.3e-4 at 20 points,
// 6.4e-5 at 100; at least 30 and 21 of the 60 fits compared). Where the polish took its last step on a prediction (up to 1e-2 of the
// sigma; ChartLinearization::predicted_step_back) they moved by up to 2.4e-3: the determination
// check then reads the rival's sigmas by a pass over the points (fit/determination.cc), and
// here they are counted, not compared.
TEST(DeterminationTest, SigmasFromTheFitsNormalEquationsAreThoseOfAPassOverThePoints) {
  constexpr double kSameLinearization = 1e-3;
  for (const int n : {20, 100}) {
    double worst = 0.0;
    int predicted = 0;
    int compared = 0;
    for (uint64_t seed = 1; seed <= 30; ++seed) {
      const SynthScene scene = CleanCloud(500 + seed, n);
      const Correspondences& c = scene.correspondences;
      for (const bool k1 : {false, true}) {
        const FitOptions model = Model(true, k1);
        internal::ChartLinearization linearization;
        internal::CandidateReuse reuse;
        reuse.linearization = &linearization;
        const FitResult fit = internal::FitCandidate(c.points_in_world, c.pixels,
                                                     scene.truth.image_size, model, 0.5, reuse);
        ASSERT_GT(linearization.jtj.size(), 0) << "seed " << seed;
        if (linearization.predicted_step_back) {
          ++predicted;
          continue;
        }
        ++compared;
        const std::vector<Eigen::Vector3d> test = FittedAndTestPoints(fit.camera, c.points_in_world);
        worst = std::max(
            worst, ExpectSameSigmas(
                       internal::ReprojectionSigmaFromFitPx(linearization, c.points_in_world, 1.0,
                                                            test),
                       internal::ReprojectionSigmaPx(fit.camera, model, c.points_in_world, 1.0,
                                                     test),
                       kSameLinearization,
                       std::to_string(n) + " points, seed " + std::to_string(seed) +
                           (k1 ? ", k1 free" : "")));
      }
    }
    std::printf("[ INFO     ] %d points: largest relative difference %.3g over %d fits (%d a "
                "predicted step back, not compared)\n",
                n, worst, compared, predicted);
    EXPECT_GE(compared, 10) << n << " points";
  }
}

// The chosen model's normal equations as the selection keeps them (Selection::linearization:
// from kLinearizationFromPoints points on, a perspective answer's; none below) give the sigmas of
// a pass over the points at the returned camera. The refit settles (its last step under 1e-9 px)
// and its normal equations are those one step back, where J differs by at most ~1e-9 relative
// (measured: up to 1e-12; the rounding of the two inverses, condition below 1e4 here, is
// ~1e-12).
TEST(DeterminationTest, TheChosenFitsNormalEquationsGiveItsSigmas) {
  constexpr double kSameLinearization = 1e-9;
  for (const int n : {12, 20, 100}) {
    double worst = 0.0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
      const SynthScene scene = CleanCloud(700 + seed, n);
      const Correspondences& c = scene.correspondences;
      internal::Selection selection;
      try {
        selection = internal::SelectModel(c.points_in_world, c.pixels, scene.truth.image_size,
                                          AutoFitOptions());
      } catch (const SceneError&) {
        continue;  // a refusal keeps no normal equations
      }
      if (static_cast<size_t>(n) < internal::kLinearizationFromPoints) {
        EXPECT_EQ(selection.linearization, nullptr) << n << " points, seed " << seed;
        continue;
      }
      ASSERT_NE(selection.linearization, nullptr) << n << " points, seed " << seed;
      const std::vector<Eigen::Vector3d> test =
          FittedAndTestPoints(selection.fit.camera, c.points_in_world);
      worst = std::max(
          worst,
          ExpectSameSigmas(internal::ReprojectionSigmaFromFitPx(*selection.linearization,
                                                                c.points_in_world, 1.0, test),
                           internal::ReprojectionSigmaPx(selection.fit.camera, selection.options,
                                                         c.points_in_world, 1.0, test),
                           kSameLinearization,
                           std::to_string(n) + " points, seed " + std::to_string(seed) + ", " +
                               selection.fit.model));
    }
    std::printf("[ INFO     ] %d points: largest relative difference %.3g\n", n, worst);
  }
}

// At the fitted points with sigma = 1, sum_i trace(J_i (J^T J)^-1 J_i^T) = trace of the hat
// matrix = the number of parameters, whatever the camera: the rounding of J^T J's inverse,
// amplified by the scaled normal equations' condition (below 1e4 here), well inside 1e-6
// relative.
TEST(DeterminationTest, FittedPointsSumToTheNumberOfParameters) {
  constexpr double kTolerance = 1e-6;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const SynthScene scene = Scene(seed, 0.0);
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    for (const auto& [model, num_params] :
         {std::pair{Model(false, false), 7}, {Model(true, false), 9}, {Model(true, true), 10}}) {
      const std::vector<double> sigmas =
          internal::ReprojectionSigmaPx(scene.truth, model, points, 1.0, points);
      double sum = 0.0;
      for (const double s : sigmas) sum += s * s;
      EXPECT_NEAR(sum, num_params, kTolerance * num_params) << "seed " << seed;
    }
  }
}

// An orthographic camera is judged with its perspective strength free as well (it answers only
// where the points show the perspective is gone): the hat matrix's trace is its 6 parameters
// (rotation, two eye axes, scale) plus one. Same tolerance as above.
TEST(DeterminationTest, OrthographicCountsItsPerspectiveStrength) {
  constexpr double kTolerance = 1e-6;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const SynthScene scene = Scene(seed, 0.0);
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    Camera orthographic = scene.truth;  // the same pose, a parallel view: a valid camera
    orthographic.projection = Projection::kOrthographic;
    orthographic.intrinsics.fx = orthographic.intrinsics.fy = 100.0;
    FitOptions model;
    model.projection = Projection::kOrthographic;
    model.aspect = ParameterMode::Default();
    model.principal_point = ParameterMode::Default();  // it trades with the eye in a parallel view
    const std::vector<double> sigmas =
        internal::ReprojectionSigmaPx(orthographic, model, points, 1.0, points);
    double sum = 0.0;
    for (const double s : sigmas) sum += s * s;
    EXPECT_NEAR(sum, 7.0, kTolerance * 7.0) << "seed " << seed;
  }
}

// The perspective test on the orthographic fit of the click benchmark's clean 6-point scene 55
// (fit_auto_test.cc, TheSixClicksOfScene55AreRefusedWhateverTheRounding: a projector 12.6 m from
// clicked corners 1 m deep): freeing the perspective strength removes most of the orthographic
// camera's squared residuals (12.9 of 14.7 px^2 when measured), far above chi2_1(99.9 %) = 10.83
// in units of the noise with it free. On the pixels that orthographic camera makes itself (the
// depth spread shows nothing) it removes nothing: zero to rounding. The noise is given (1 px), so
// the statistic is the removed sum itself.
TEST(DeterminationTest, PerspectiveTestSeesWhatTheOrthographicCameraLeavesOut) {
  const std::vector<Eigen::Vector3d> points = {
      {0.6558947640258102, 0.28275227060358277, 1.0109840491878523},
      {0.18648979631228613, 0.2535160403830361, 1.0109840491878523},
      {0.6558947640258102, 0.28275227060358277, 0},
      {0.6558947640258102, -0.28275227060358277, 1.0109840491878523},
      {0.18648979631228613, -0.265321251757319, 1.0109840491878523},
      {-0.4947159328370735, -0.265321251757319, 1.0109840491878523},
  };
  const std::vector<Eigen::Vector2d> clicks = {{1050, 710}, {1015, 704}, {1049, 907},
                                               {944, 713},  {921, 707},  {886, 696}};
  const ImageSize size{1920, 1080};
  FitOptions model;
  model.projection = Projection::kOrthographic;
  model.aspect = ParameterMode::Default();
  model.principal_point = ParameterMode::Default();
  AutoFitOptions options;
  options.fit.pixel_sigma = 1.0;
  internal::Selection selection;
  selection.fit = FitCamera(points, clicks, size, model);
  selection.options = model;
  const internal::PerspectiveTest shown =
      internal::TestPerspectiveStrength(selection, points, options);
  ASSERT_TRUE(shown.checked);
  EXPECT_TRUE(shown.observable) << shown.statistic;
  EXPECT_GT(shown.statistic, 10.83);
  EXPECT_NEAR(shown.statistic, shown.removed_px2, 1e-12 * shown.removed_px2);

  std::vector<Eigen::Vector2d> parallel;
  for (const Eigen::Vector3d& x : points) parallel.push_back(*PixelFromWorld(selection.fit.camera, x));
  internal::Selection exact;
  exact.fit = FitCamera(points, parallel, size, model);
  exact.options = model;
  const internal::PerspectiveTest none = internal::TestPerspectiveStrength(exact, points, options);
  ASSERT_TRUE(none.checked);
  EXPECT_FALSE(none.observable) << none.statistic;
  EXPECT_LT(none.statistic, 1e-6);
}

// Calibration: fit 400 noisy copies of one scene with the true model; the mean of
// |pixel(fit) - pixel(truth)|^2 / sigma_predicted^2 at a box corner is 1 up to linearization
// (noise 0.3 px: negligible). |d|^2 / sigma^2 has variance at most 2 (two correlated unit
// Gaussians), so the mean of 400 has a standard error of at most sqrt(2 / 400) = 0.071:
// 4 standard errors, 0.28.
TEST(DeterminationTest, PredictsTheScatterOfRepeatedFits) {
  constexpr int kTrials = 400;
  constexpr double kNoisePx = 0.3;
  const FitOptions model = Model(true, false);
  const SynthScene reference = Scene(7, 0.0);
  const std::vector<Eigen::Vector3d>& points = reference.correspondences.points_in_world;
  const std::vector<Eigen::Vector3d> test = internal::SceneTestPoints(reference.truth, points);
  ASSERT_FALSE(test.empty());
  const std::vector<double> predicted =
      internal::ReprojectionSigmaPx(reference.truth, model, points, kNoisePx, test);
  std::mt19937_64 rng(testing::Seed(3));
  std::normal_distribution<double> normal(0.0, kNoisePx);
  std::vector<double> mean_ratio(test.size(), 0.0);
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<Eigen::Vector2d> pixels = reference.correspondences.pixels;
    for (Eigen::Vector2d& u : pixels) u += testing::DrawVector2([&] { return normal(rng); });
    FitOptions options = model;
    options.compute_uncertainty = false;
    const FitResult fit = FitCamera(points, pixels, reference.truth.image_size, options);
    for (size_t i = 0; i < test.size(); ++i) {
      const Eigen::Vector2d d =
          *PixelFromWorld(fit.camera, test[i]) - *PixelFromWorld(reference.truth, test[i]);
      mean_ratio[i] += d.squaredNorm() / (predicted[i] * predicted[i]) / kTrials;
    }
  }
  for (size_t i = 0; i < test.size(); ++i) EXPECT_NEAR(mean_ratio[i], 1.0, 0.28) << "point " << i;
}

// The bound behind skipping a nested rival within its noise (determination.cc,
// NestedRivalWithinItsNoise): where a rival that frees one parameter more lowers the sum of
// squares by at most sigma^2, it moves no test point by more than its own sigma there,
// linearized (Cauchy-Schwarz); the check would count a shift only beyond 3 of them. Over 100
// seeds of 20-100 noisy points (sigma 0.5 px, lens shift), pose + focal + principal point
// against + aspect, + skew and + k1, at the rivals' test points (the box widened to a quarter of
// its longest side, and the points): every rival the rule would skip stays within 3 of its sigmas
// everywhere (measured at most 0.88 at seed offsets 0, 7 and 1000), and the rule skips
// most of the rivals (a drop below sigma^2 is chi-square with one degree of freedom below 1:
// 68 %; 200-214 of 300 at those offsets; asserted at least half).
TEST(DeterminationTest, NestedRivalWithinItsNoiseMovesNoPointBeyondThreeOfItsSigmas) {
  constexpr double kNoisePx = 0.5;
  constexpr double kRivalSigmas = 3.0;  // determination.cc's
  constexpr double kRivalBoxThickness = 0.25;  // determination.cc's
  FitOptions chosen = Model(true, false);
  chosen.compute_uncertainty = false;
  std::vector<FitOptions> rivals(3, chosen);
  rivals[0].aspect = ParameterMode::Free();
  rivals[1].skew = ParameterMode::Free();
  rivals[2].k1 = ParameterMode::Free();
  int judged = 0;
  int skipped = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    SynthOptions synth;
    synth.seed = testing::Seed(seed);
    synth.num_points = 20 + static_cast<int>(seed % 5) * 20;
    synth.noise_px = kNoisePx;
    synth.principal_point_offset = Eigen::Vector2d(0.0, 0.3);
    const SynthScene scene = SynthesizeScene(synth);
    const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
    const std::vector<Eigen::Vector2d>& pixels = scene.correspondences.pixels;
    const FitResult ours = FitCamera(points, pixels, scene.truth.image_size, chosen);
    const double ours_sum = points.size() * ours.rms_px * ours.rms_px;
    const std::vector<Eigen::Vector3d> test =
        internal::SceneTestPoints(ours.camera, points, kRivalBoxThickness);
    for (const FitOptions& model : rivals) {
      const FitResult rival = FitCamera(points, pixels, scene.truth.image_size, model);
      const double drop = ours_sum - points.size() * rival.rms_px * rival.rms_px;
      ++judged;
      if (!(drop >= 0.0 && drop <= kNoisePx * kNoisePx)) continue;
      ++skipped;
      const std::vector<double> sigmas =
          internal::ReprojectionSigmaPx(rival.camera, model, points, kNoisePx, test);
      for (size_t i = 0; i < test.size(); ++i) {
        const double shift =
            (*PixelFromWorld(rival.camera, test[i]) - *PixelFromWorld(ours.camera, test[i])).norm();
        EXPECT_LE(shift, kRivalSigmas * sigmas[i]) << "seed " << seed << ", point " << i;
      }
    }
  }
  EXPECT_GE(2 * skipped, judged) << skipped << " of " << judged;
}

// The check works in the points' centred, unit-RMS world, so the same scene in other units or
// far from the origin is judged the same. Times 2^k everything is exact: the same numbers bit
// for bit. Moved by 1e7 scene sizes, the points and the camera are rounded by ~1e-9 of the
// scene (u * 1e7), which moves the sigmas by ~1e-9 relative times the normal equations'
// condition (below 1e3 here): 1e-6 relative. (Before, central differences in world units: at
// 2^-600 the squared distances underflowed to an infinite sigma, at 2^600 they overflowed to
// std::invalid_argument, and at 1e7 the steps, 1e-6 of the distance, met the rounding: 1e-3.)
TEST(DeterminationTest, TheSameInAnyUnitsAndFarFromTheOrigin) {
  constexpr double kMovedRelative = 1e-6;
  const SynthScene scene = Scene(5, 0.5);
  const std::vector<Eigen::Vector3d>& points = scene.correspondences.points_in_world;
  const FitOptions model = Model(true, false);
  internal::Selection selection;
  selection.fit = FitCamera(points, scene.correspondences.pixels, scene.truth.image_size, model);
  selection.options = model;
  selection.options.pixel_sigma = 0.5;
  selection.sigma_px = 0.5;
  const AutoFitOptions options;
  const DeterminationCheck reference = internal::CheckDetermination(selection, points, options);
  ASSERT_TRUE(std::isfinite(reference.max_sigma_px));

  for (const int k : {-600, 600}) {
    const double unit = std::ldexp(1.0, k);
    std::vector<Eigen::Vector3d> scaled = points;
    for (auto& x : scaled) x *= unit;
    internal::Selection moved = selection;
    Camera& camera = moved.fit.camera;
    camera.cam_from_world.translation *= unit;
    camera.z_near *= unit;
    camera.z_far *= unit;
    const DeterminationCheck check = internal::CheckDetermination(moved, scaled, options);
    EXPECT_EQ(check.max_sigma_px, reference.max_sigma_px) << k;
    EXPECT_EQ(check.worst_pixel, reference.worst_pixel) << k;
  }

  const Eigen::Vector3d offset = 1e7 * Eigen::Vector3d(0.6, -0.48, 0.64);  // scene size ~1
  std::vector<Eigen::Vector3d> far = points;
  for (auto& x : far) x += offset;
  internal::Selection moved = selection;
  Rigid3& cam_from_world = moved.fit.camera.cam_from_world;
  cam_from_world.translation -= cam_from_world.rotation * offset;
  const DeterminationCheck check = internal::CheckDetermination(moved, far, options);
  EXPECT_NEAR(check.max_sigma_px, reference.max_sigma_px, kMovedRelative * reference.max_sigma_px);
}

}  // namespace
}  // namespace camproj

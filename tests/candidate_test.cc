// The model selection's candidate fit (lib/src/fit/candidate.h) warm-started from the nested
// model's camera (fit/start.h, WarmStart): where the scene has one minimum, the same optimum as
// the closed-form start reaches (to the polish's convergence test, which a scored candidate
// stops at).
#include "fit/candidate.h"

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "camproj/model_select.h"
#include "camproj/pose.h"
#include "camproj/synth.h"
#include "fit/common.h"
#include "fit/normal_equations.h"
#include "fit/selection.h"
#include "fit/start.h"
#include "seeds.h"

namespace camproj {
namespace {

// A candidate is only scored: its polish stops at the convergence test (least_squares.h,
// PolishUntil::kConverged), the last step moving the residual vector by at most 1e-3 of the
// noise, |J d| <= 1e-3 sigma. Each parameter is then within 1e-3 of its own sigma of the minimum
// (|d_i| <= sqrt((J^T J)^-1_ii) |J d|), so two runs that end at the same minimum agree within
// twice that. (Two settled fits with k1 free, as the chosen model's refit against FitCamera, also
// stop within a small fraction of the flat focal-distance-k1 direction's sigma: the same bound as
// FitTest.CeresRefinerFindsTheSameOptimum's, for that reason.)
constexpr double kSameOptimumSigmas = 2e-3;
// LM started at the minimum: its first step is rejected or negligible and it stops.
constexpr int kIterationsAtTheOptimum = 1;
// Px per axis at which a candidate may skip its restarts: the scenes' noise.
constexpr double kNoisePx = 0.5;

// The bench's clean scenes: n points in a cloud seen at 1920x1080, fovy 45 degrees, sigma
// kNoisePx, by a centred camera (offset_y 0) or a projector with lens shift (0.4).
SynthScene CloudScene(uint64_t seed, int n, double offset_y) {
  SynthOptions synth;
  synth.seed = testing::Seed(seed);
  synth.num_points = n;
  synth.object = SynthObject::kCloud;
  synth.image_size = ImageSize{1920, 1080};
  synth.fovy_deg = 45.0;
  synth.principal_point_offset = Eigen::Vector2d(0.0, offset_y);
  synth.noise_px = kNoisePx;
  return SynthesizeScene(synth);
}

// Pose + focal: FitOptions' default frees the aspect and the principal point too.
FitOptions PoseAndFocal() {
  FitOptions focal;
  focal.aspect = ParameterMode::Default();
  focal.principal_point = ParameterMode::Default();
  return focal;
}

// `sigmas`: a full fit's (FitCamera) of `model`; a candidate computes none.
void ExpectSameOptimum(const FitResult& a, const FitResult& b, const FitOptions& model,
                       const std::vector<ParameterSigma>& sigmas,
                       double bound_sigmas = kSameOptimumSigmas) {
  const Intrinsics& ka = a.camera.intrinsics;
  const Intrinsics& kb = b.camera.intrinsics;
  const Eigen::Vector3d eye_a = CameraCenterInWorld(a.camera.cam_from_world);
  const Eigen::Vector3d eye_b = CameraCenterInWorld(b.camera.cam_from_world);
  // Every free parameter these models have (fy only with the aspect free, k1 only with itself).
  const std::map<std::string, std::pair<double, double>> values = {
      {"fx", {ka.fx, kb.fx}},       {"fy", {ka.fy, kb.fy}},       {"cx", {ka.cx, kb.cx}},
      {"cy", {ka.cy, kb.cy}},       {"k1", {ka.k1, kb.k1}},       {"eye_x", {eye_a.x(), eye_b.x()}},
      {"eye_y", {eye_a.y(), eye_b.y()}}, {"eye_z", {eye_a.z(), eye_b.z()}}};
  int checked = 0;
  for (const ParameterSigma& s : sigmas) {
    const auto it = values.find(s.name);
    if (it == values.end()) continue;
    EXPECT_LE(std::abs(it->second.second - it->second.first), bound_sigmas * s.sigma) << s.name;
    ++checked;
  }
  // The focal length, the principal point and the eye, and fy and k1 where the model frees them.
  EXPECT_EQ(checked, 6 + model.aspect.IsFree() + model.k1.IsFree());
}

// Each step of the ladder (pose + focal -> + principal point -> + aspect, and -> + k1) fitted
// from the closed form and from the previous step's camera, on clouds of 20-1000 points seen by
// a centred camera and by a projector with lens shift (σ 0.5 px): the same optimum, every time.
TEST(CandidateTest, WarmStartFromTheNestedModelReachesTheClosedFormsOptimum) {
  int compared = 0;
  for (const int n : {20, 100, 1000}) {
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      for (const double offset_y : {0.0, 0.4}) {
        const SynthScene scene = CloudScene(seed, n, offset_y);
        const auto& points = scene.correspondences.points_in_world;
        const auto& pixels = scene.correspondences.pixels;
        const FitOptions focal = PoseAndFocal();
        FitOptions principal_point = focal;
        principal_point.principal_point = ParameterMode::Free();
        FitOptions aspect = principal_point;
        aspect.aspect = ParameterMode::Free();
        FitOptions k1 = principal_point;
        k1.k1 = ParameterMode::Free();
        struct Step {
          const FitOptions* nested;
          const FitOptions* model;
        };
        for (const Step& step : {Step{&focal, &principal_point}, Step{&principal_point, &aspect},
                                 Step{&principal_point, &k1}}) {
          SCOPED_TRACE(::testing::Message() << "N " << n << " seed " << seed << " offset "
                                            << offset_y << " free " << step.model->aspect.IsFree()
                                            << step.model->k1.IsFree());
          const FitResult nested = internal::FitCandidate(points, pixels, scene.truth.image_size,
                                                          *step.nested, kNoisePx);
          const FitResult cold =
              internal::FitCandidate(points, pixels, scene.truth.image_size, *step.model, kNoisePx);
          const FitResult warm = internal::FitCandidate(points, pixels, scene.truth.image_size,
                                                        *step.model, kNoisePx, {&nested.camera});
          EXPECT_EQ(warm.start_method, "warm");
          EXPECT_NE(cold.start_method, "warm");
          const std::vector<ParameterSigma> sigmas =
              FitCamera(points, pixels, scene.truth.image_size, *step.model).sigmas;
          ExpectSameOptimum(cold, warm, *step.model, sigmas);
          // Started at its own optimum, a model stays there: the start is the camera given
          // (pose and intrinsics in the scene's normalized frame), not merely near it.
          const FitResult again = internal::FitCandidate(points, pixels, scene.truth.image_size,
                                                         *step.model, kNoisePx, {&cold.camera});
          EXPECT_LE(again.iterations, kIterationsAtTheOptimum);
          ExpectSameOptimum(cold, again, *step.model, sigmas);
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 3 * 8 * 2 * 3);
}

// What stopping at the convergence test gives up (PolishUntil::kConverged): a candidate with
// its restarts (the same minimum as FitCamera's) against FitCamera, whose polish settles under
// 1e-9 px, on the bench's clouds at 6-100 points for OpenCV's model and, from 20 points, with k1.
// The candidate's last step moved the residual vector by |J d| <= 1e-3 of the noise estimate
// s = sqrt(J / (2N - p)), or the steps so far predicted the next within that (least_squares.cc:
// the next step this^2 / before, while they contract), so its sum of squares exceeds the
// minimum's by at most ~(1e-3 s)^2, and never falls below it by more than rounding; each
// parameter is within 1e-3 of its sigma (FitCamera's, from the same s). Rounding: each residual is rounded
// to ~16 ulp of its pixel's magnitude (least_squares.cc's cost allowance), so a sum of squares S
// is off by at most 2 sqrt(S) 16 u |pixels| (Cauchy-Schwarz), and the two fits' by twice that.
TEST(CandidateTest, AScoredFitStopsWithinItsConvergenceTestOfTheSettledMinimum) {
  constexpr double kConvergedFraction = 1e-3;  // least_squares.cc's convergence test
  constexpr double kResidualUlps = 16.0;
  int compared = 0;
  for (const int n : {6, 8, 20, 100}) {
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      for (const double offset_y : {0.0, 0.4}) {
        const SynthScene scene = CloudScene(seed, n, offset_y);
        const auto& points = scene.correspondences.points_in_world;
        const auto& pixels = scene.correspondences.pixels;
        FitOptions opencv = PoseAndFocal();
        opencv.principal_point = ParameterMode::Free();
        FitOptions k1 = opencv;
        k1.k1 = ParameterMode::Free();
        for (const FitOptions* model : {&opencv, &k1}) {
          if (model == &k1 && n < 20) continue;
          SCOPED_TRACE(::testing::Message() << "N " << n << " seed " << seed << " offset "
                                            << offset_y << " k1 " << (model == &k1));
          FitResult settled;
          try {
            settled = FitCamera(points, pixels, scene.truth.image_size, *model);
          } catch (const SceneError&) {
            continue;  // not determined (a few 6-point scenes): nothing to compare
          }
          const FitResult scored = internal::FitCandidate(points, pixels, scene.truth.image_size,
                                                          *model, std::nullopt);
          auto sum_of_squares = [](const FitResult& fit) {
            double sum = 0.0;
            for (const Eigen::Vector2d& r : fit.residuals_px) sum += r.squaredNorm();
            return sum;
          };
          const double minimum = sum_of_squares(settled);
          const double dof = 2.0 * n - static_cast<double>(settled.free_parameters.size());
          double pixel_norm2 = 0.0;
          for (const Eigen::Vector2d& u : pixels) pixel_norm2 += u.squaredNorm();
          const double rounding = 2.0 * 2.0 * kResidualUlps *
                                  std::numeric_limits<double>::epsilon() * std::sqrt(minimum) *
                                  std::sqrt(pixel_norm2);
          const double excess = sum_of_squares(scored) - minimum;
          EXPECT_LE(excess,
                    kConvergedFraction * kConvergedFraction * minimum / dof + rounding);
          EXPECT_GE(excess, -rounding);
          EXPECT_EQ(scored.model, settled.model);
          ExpectSameOptimum(settled, scored, *model, settled.sigmas, kConvergedFraction);
          ++compared;
        }
      }
    }
  }
  // Every scene at 8 points and more, and most at 6.
  EXPECT_GE(compared, 2 * 8 * (1 + 2 + 2) + 8);
}

// The chosen model refitted from the ladder's camera (FitReusing, what FitCameraAuto does from 20
// points on) is FitCamera's fit from scratch: the same optimum, sigmas, views and linearity
// check; and FitCameraAuto names the closed form its selection began at, never "warm".
TEST(CandidateTest, ChosenModelRefittedFromTheLadderIsTheFitFromScratch) {
  int compared = 0;
  for (const int n : {20, 100, 1000}) {
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      for (const double offset_y : {0.0, 0.4}) {
        const SynthScene scene = CloudScene(100 + seed, n, offset_y);
        const auto& points = scene.correspondences.points_in_world;
        const auto& pixels = scene.correspondences.pixels;
        SCOPED_TRACE(::testing::Message() << "N " << n << " seed " << seed << " offset "
                                          << offset_y);
        FitOptions nested;  // pose + focal + principal point, the ladder's step before k1
        nested.aspect = ParameterMode::Default();
        FitOptions model = nested;
        model.k1 = ParameterMode::Free();
        model.pixel_sigma = kNoisePx;
        const FitResult before =
            internal::FitCandidate(points, pixels, scene.truth.image_size, nested, kNoisePx);
        const FitResult ladder = internal::FitCandidate(points, pixels, scene.truth.image_size, model,
                                                        kNoisePx, {&before.camera});
        const FitResult scratch = FitCamera(points, pixels, scene.truth.image_size, model);
        const FitResult chosen =
            internal::FitReusing(points, pixels, scene.truth.image_size, model, {&ladder.camera});
        EXPECT_EQ(chosen.start_method, "warm");
        ExpectSameOptimum(scratch, chosen, model, scratch.sigmas);
        EXPECT_EQ(chosen.sigmas.size(), scratch.sigmas.size());
        EXPECT_TRUE(chosen.views.clip_from_gl_eye.allFinite());
        EXPECT_EQ(chosen.linearity.checked, scratch.linearity.checked);
        // (A clean scene may be refused as not determined: at seed offset 77777, N 20, pose +
        // focal + k1 + k2 and pose + focal + principal point fit about as well and part by 8 px.)
        try {
          const FitResult automatic = FitCameraAuto(points, pixels, scene.truth.image_size);
          EXPECT_NE(automatic.start_method, "warm");
          EXPECT_FALSE(automatic.start_method.empty());
        } catch (const SceneError& e) {
          EXPECT_TRUE(e.reason() == SceneError::Reason::kAmbiguous ||
                      e.reason() == SceneError::Reason::kDegenerate)
              << e.what();
        }
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 3 * 8 * 2);
}

// The reason and message of `fit`'s refusal, or "answered".
template <typename Fit>
std::string Refusal(Fit fit) {
  try {
    fit();
  } catch (const SceneError& error) {
    return std::to_string(static_cast<int>(error.reason())) + ": " + error.what();
  }
  return "answered";
}

// The points prepared once for every candidate (fit/scene.h, PrepareScene) give each model the
// refusal, with the same message, that preparing them for that model alone gives: too few
// (distinct) points, coordinates too large, collinear points, an offset beyond double precision,
// a plane asked for too many intrinsics -- and scenes where several of these hold at once.
TEST(CandidateTest, PreparedPointsRefuseAsTheirOwnScene) {
  const SynthScene base = [] {
    SynthOptions synth;
    synth.seed = testing::Seed(3);
    synth.num_points = 8;
    synth.noise_px = kNoisePx;
    return SynthesizeScene(synth);
  }();
  const ImageSize size = base.truth.image_size;
  struct Case {
    const char* name;
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
  };
  std::vector<Case> cases;
  const auto& points = base.correspondences.points_in_world;
  const auto& pixels = base.correspondences.pixels;
  cases.push_back({"well-formed", points, pixels});
  cases.push_back({"five points", {points.begin(), points.begin() + 5},
                   {pixels.begin(), pixels.begin() + 5}});
  {
    Case c{"three points repeated", {}, {}};
    for (int i = 0; i < 8; ++i) {
      c.points.push_back(points[i % 3]);
      c.pixels.push_back(pixels[i]);
    }
    cases.push_back(c);
  }
  {
    Case c{"collinear", {}, pixels};
    for (int i = 0; i < 8; ++i) c.points.push_back(Eigen::Vector3d(i, 2.0 * i, 0.5 * i));
    cases.push_back(c);
  }
  {
    Case c{"coplanar", {}, pixels};
    for (const Eigen::Vector3d& x : points) c.points.push_back(Eigen::Vector3d(x.x(), x.y(), 0.0));
    cases.push_back(c);
  }
  {
    Case c{"offset 1e12", points, pixels};
    for (Eigen::Vector3d& x : c.points) x += Eigen::Vector3d(1e12, 0.0, 0.0);
    cases.push_back(c);
  }
  {
    // The spread is finite, the extents of the cloud are not: once refused or not depending
    // on the stack's contents (Eigen's SVD left its singular values unset).
    Case c{"coordinates near the largest double", points, pixels};
    for (int i = 0; i < 4; ++i) c.points[i].x() = i % 2 ? 1.7e308 : -1.7e308;  // spread: inf
    cases.push_back(c);
  }
  FitOptions focal = PoseAndFocal();
  FitOptions full = focal;  // focal, aspect, principal point, skew: 4 linear intrinsics
  full.aspect = ParameterMode::Free();
  full.principal_point = ParameterMode::Free();
  full.skew = ParameterMode::Free();
  for (const Case& c : cases) {
    const internal::SceneGeometry geometry =
        internal::PrepareScene(c.points, c.pixels, size, focal.pixel_origin);
    for (const FitOptions* model : {&focal, &full}) {
      SCOPED_TRACE(::testing::Message() << c.name << (model == &full ? ", full model" : ""));
      const std::string own = Refusal([&] {
        internal::FitCandidate(c.points, c.pixels, size, *model, kNoisePx);
      });
      const std::string shared = Refusal([&] {
        internal::FitCandidate(c.points, c.pixels, size, *model, kNoisePx, {nullptr, &geometry});
      });
      EXPECT_EQ(shared, own);
      if (std::string(c.name) == "coordinates near the largest double") {
        EXPECT_EQ(own.rfind(std::to_string(static_cast<int>(SceneError::Reason::kNonFiniteInput)) +
                                ": the 3D points' coordinates are too large",
                            0),
                  0u)
            << own;
      }
    }
  }
}

// The DLT is read once for the prepared points (fit/start.h, DltStartOf) and every model fitted
// to them starts from it: each model's fit from the shared preparation is bit for bit the fit
// from its own (the same arithmetic on the same numbers), its DLT read only once, at 6-12
// points of both kinds of scene; and a DLT that refuses (no camera with every point in front)
// refuses every model with the message the model's own DLT gives.
TEST(CandidateTest, ModelsFittedToPreparedPointsShareOneDlt) {
  constexpr int kSeeds = 20;
  FitOptions focal = PoseAndFocal();
  FitOptions off_axis = focal;
  off_axis.principal_point = ParameterMode::Free();
  FitOptions full = off_axis;
  full.aspect = ParameterMode::Free();
  full.skew = ParameterMode::Free();
  int fitted = 0;
  for (const int n : {6, 8, 12}) {
    for (const double offset_y : {0.0, 0.4}) {
      for (int seed = 1; seed <= kSeeds; ++seed) {
        const SynthScene scene = CloudScene(seed, n, offset_y);
        const auto& points = scene.correspondences.points_in_world;
        const auto& pixels = scene.correspondences.pixels;
        const ImageSize size = scene.truth.image_size;
        const internal::SceneGeometry geometry =
            internal::PrepareScene(points, pixels, size, focal.pixel_origin);
        ASSERT_NE(geometry.scene.dlt, nullptr);
        for (const FitOptions* model : {&focal, &off_axis, &full}) {
          SCOPED_TRACE(::testing::Message() << "n " << n << ", offset " << offset_y << ", seed "
                                            << seed << ", " << internal::NumParameters(*model)
                                            << " parameters");
          if (2 * n - internal::NumParameters(*model) < 1) continue;
          FitResult own, shared;
          const std::string own_refusal = Refusal([&] {
            own = internal::FitReusing(points, pixels, size, *model, {});
          });
          const std::string shared_refusal = Refusal([&] {
            shared = internal::FitReusing(points, pixels, size, *model, {nullptr, &geometry});
          });
          ASSERT_EQ(shared_refusal, own_refusal);
          if (own_refusal != "answered") continue;
          ++fitted;
          EXPECT_TRUE(geometry.scene.dlt->camera.has_value());
          EXPECT_EQ(shared.camera.intrinsics.fx, own.camera.intrinsics.fx);
          EXPECT_EQ(shared.camera.intrinsics.cy, own.camera.intrinsics.cy);
          EXPECT_EQ(shared.camera.cam_from_world.rotation, own.camera.cam_from_world.rotation);
          EXPECT_EQ(shared.camera.cam_from_world.translation,
                    own.camera.cam_from_world.translation);
          EXPECT_EQ(shared.rms_px, own.rms_px);
        }
      }
    }
  }
  EXPECT_GE(fitted, 3 * 2 * kSeeds * 2);  // most scenes determine the models

  // Four points and their reflections through the camera centre, each pixel the camera matrix's
  // (the reflection has the same ray, at negative depth): the DLT recovers that camera exactly,
  // with four points behind it.
  const SynthScene scene = CloudScene(1, 4, 0.0);
  const Camera& truth = scene.truth;
  const Eigen::Vector3d eye = CameraCenterInWorld(truth.cam_from_world);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (const Eigen::Vector3d& x : scene.correspondences.points_in_world) {
    for (const Eigen::Vector3d& point : {x, Eigen::Vector3d(2.0 * eye - x)}) {
      const Eigen::Vector3d p = truth.cam_from_world * point;
      const Intrinsics& k = truth.intrinsics;
      points.push_back(point);
      pixels.emplace_back(k.fx * p.x() / p.z() + k.skew * p.y() / p.z() + k.cx,
                          k.fy * p.y() / p.z() + k.cy);
    }
  }
  const ImageSize size = truth.image_size;
  const internal::SceneGeometry geometry =
      internal::PrepareScene(points, pixels, size, focal.pixel_origin);
  for (const FitOptions* model : {&focal, &off_axis}) {
    const std::string own = Refusal([&] { internal::FitReusing(points, pixels, size, *model, {}); });
    const std::string shared = Refusal(
        [&] { internal::FitReusing(points, pixels, size, *model, {nullptr, &geometry}); });
    EXPECT_EQ(shared, own);
    EXPECT_EQ(own.rfind(std::to_string(
                            static_cast<int>(SceneError::Reason::kPointsBehindCamera)) + ":", 0),
              0u)
        << own;
  }
  EXPECT_TRUE(geometry.scene.dlt->refusal.has_value());
}

// A candidate's fit refuses on the reciprocal condition of its Jacobi-scaled J^T J, and where a
// Cholesky bound clears the refusal it computes no eigenvalues (fit/common.h,
// ReciprocalConditionLowerBound): the bound is below the eigenvalues' rcond, by at most p^2
// (trace S = p against the largest eigenvalue, trace S^-1 against the smallest's reciprocal), on
// random normal equations of 6-13 parameters, rcond down to ~1e-11; and a singular one (a
// column repeated, a column of zeros) bounds to 0 or to rounding (1e-16 times p^2). The inverse
// Cholesky factor it reads (InverseCholeskyOfScaled), which the determination check whitens
// with, inverts the scaled J^T J.
TEST(CandidateTest, ReciprocalConditionBoundIsBelowTheEigenvalues) {
  constexpr double kRounding = 1e-9;  // relative, the eigenvalues' own at rcond 1e-13 and above
  std::mt19937_64 rng(testing::Seed(31));
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const int p = 6 + i % 8;
    Eigen::MatrixXd j(2 * p + 4, p);
    for (int r = 0; r < j.rows(); ++r) {
      for (int c = 0; c < p; ++c) j(r, c) = uniform(rng);
    }
    // Columns of very different units, and one nearly a combination of the others.
    const double near = std::pow(10.0, -2.5 * (i % 3));  // 1, 3e-3, 1e-5: rcond to ~1e-11
    j.col(p - 1) = j.col(0) + j.col(1) + near * j.col(p - 1);
    for (int c = 0; c < p; ++c) j.col(c) *= std::pow(10.0, 3.0 * uniform(rng));
    const internal::ParamMatrix jtj = j.transpose() * j;
    const double bound = internal::ReciprocalConditionLowerBound(jtj);
    const double rcond = internal::JacobiScaledNormal<internal::ParamMatrix>(jtj).rcond;
    SCOPED_TRACE(::testing::Message() << "case " << i << ", p " << p << ", rcond " << rcond);
    if (rcond < 1e-13) continue;  // below the eigenvalues' own rounding
    ++checked;
    EXPECT_LE(bound, rcond * (1.0 + kRounding));
    EXPECT_GE(bound, rcond / (p * p) * (1.0 - kRounding));
    // Its X = L^-1 inverts the scaled S = D J^T J D as X^T X (so J^T J as W W^T, W = D X^T) to
    // the Cholesky's rounding: p eps times S's condition 1 / rcond (16 p eps / rcond allowed).
    const std::optional<internal::ParamMatrix> x = internal::InverseCholeskyOfScaled(jtj);
    ASSERT_TRUE(x.has_value());
    const Eigen::VectorXd d = jtj.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd scaled = d.asDiagonal() * Eigen::MatrixXd(jtj) * d.asDiagonal();
    const Eigen::MatrixXd identity = x->transpose() * *x * scaled;
    EXPECT_LE((identity - Eigen::MatrixXd::Identity(p, p)).cwiseAbs().maxCoeff(),
              16.0 * p * std::numeric_limits<double>::epsilon() / rcond);
  }
  EXPECT_GE(checked, 290);  // all but a rare draw beyond the eigenvalues' rounding
  Eigen::MatrixXd j(20, 8);
  for (int r = 0; r < j.rows(); ++r) {
    for (int c = 0; c < j.cols(); ++c) j(r, c) = uniform(rng);
  }
  j.col(7) = j.col(2);
  EXPECT_LE(internal::ReciprocalConditionLowerBound(internal::ParamMatrix(j.transpose() * j)),
            64 * 1e-16);
  j.col(7).setZero();
  EXPECT_EQ(internal::ReciprocalConditionLowerBound(internal::ParamMatrix(j.transpose() * j)),
            0.0);
}

}  // namespace
}  // namespace camproj

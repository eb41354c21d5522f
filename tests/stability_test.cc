// Stability suite: every extreme case ends in the right camera or a clear, specific refusal, never
// a wrong camera. One table of cases (fields of view, world offsets and units, lens shift, aspect,
// near-planar and planar scenes, few points, collinear points, noise, outliers, points behind the
// camera, look-at, GL export at extreme depth ranges), each with its expected outcome.
//
// With CAMPROJ_STABILITY_TABLE=path the suite writes one Markdown row per case to `path`;
// scripts/stability.sh assembles docs/stability.md from it.
//
// How "right" is judged (every tolerance below is a named constant with its reason):
// - Noise-free fits: first-order perturbation theory of least squares. The fit's error in
//   parameter j is e_j = -[(J^T J)^-1 J^T r]_j, so |e_j| <= sigma_j(1 px) |r|_2 (Cauchy-Schwarz),
//   where sigma_j(1 px) is the fit's own reported sigma at a pixel sigma of 1 and r is what
//   perturbs the data: the pixels' inconsistency with the true camera (evaluated in long double)
//   plus a bound on the fitter's own rounding when it evaluates residuals. This is the
//   "condition number x rounding" rule made per parameter: sigma_j is |column j|^-1 times the
//   Jacobian's conditioning.
// - Noisy fits: consistent with the fit's own reported uncertainty (sigma estimated from the
//   residuals). Each parameter's error in its sigmas is Student's t with 2N - p degrees of
//   freedom, the normalized estimation error squared (NEES) p F(p, 2N - p), for a linear
//   Gaussian model; both must be below their 1 - kFalseAlarm quantiles where the fit reports its
//   linearization valid (FitResult::linearity), at a rate over many noise draws.
// - RANSAC: outliers are displaced far beyond the threshold, so the outlier set must be exact.
// - GL export: each stage's float64 rounding, propagated to pixels and window depth.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "camproj/gl.h"
#include "camproj/look_at.h"
#include "camproj/model_select.h"
#include "camproj/synth.h"
#include "seeds.h"
#include "test_scenes.h"
#include "truth_condition.h"

namespace camproj {
namespace {

using Clock = std::chrono::steady_clock;
using Reason = SceneError::Reason;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;

// Unit roundoff of float64 (truth_condition.h).
using testing::kUnitRoundoff;

// --- Tolerances -----------------------------------------------------------------------------

// Noise-free fits: |e_j| <= kFirstOrderMargin sigma_j(1 px) |r|_2 plus the returned value's own
// rounding (truth_condition.h, with the rounding counts kEvalRoundings and kOutputRoundings).
using testing::kEvalRoundings;
using testing::kFirstOrderMargin;
using testing::kOutputRoundings;

// fit.h: a fit whose scaled Jacobian has a condition number above testing::kFitterConditionLimit
// is refused as undetermined (SceneError kDegenerate). The suite computes the condition number at
// the true camera independently (ConditionAtTruth) and expects a camera below it, that refusal
// above it.
using testing::kFitterConditionLimit;

// Noisy fits and RANSAC: each case's statistical check fails by chance with at most this
// probability: NEES below its 99.99 % quantile, and every parameter within the two-sided
// 1 - kFalseAlarm / p quantile of Student's t (Bonferroni over the p parameters).
constexpr double kFalseAlarm = 1e-4;

// Noisy fits: the checks rest on the first-order covariance, i.e. on the model being linear over
// the noise's reach. The fit says where it is not (FitResult::linearity, checked along the
// covariance's principal directions at the edge of its 99.99 % region); there its covariance
// claims nothing and is not checked. Each noisy case runs kNoisyDraws noise draws and asserts a
// rate: refusals count as failures, and the checks' failures among the draws reported linear
// are bounded by NoisyFalseAlarm, the false-alarm rate the linearity bound allows.
constexpr int kNoisyDraws = 20;

// RANSAC: an outlier is moved at least this far from its true pixel. The fitted camera predicts
// an inlier's pixel to within a few sigma sqrt(p / N) << 1 px (0.5 px noise, N >= 40), so a point
// displaced by 20 px is at least 15 px from the prediction, far outside the 4 px threshold; an
// inlier with 0.5 px noise is outside 4 px with probability exp(-4^2 / (2 0.5^2)) = exp(-32).
constexpr double kFarOutlierPx = 20.0;

// GL export: testing::kGlRoundings unit roundoffs per term (test_scenes.h), applied to the
// magnitudes each stage handles (RunGl).
using testing::kGlRoundings;

// Look-at: the roll comes from up x w, whose relative error is (rounding of up and of the gaze
// direction) / sin(angle(up, gaze)). Rounding of up: 1 unit roundoff; of the gaze
// target - eye: 2 (|eye| + |target|) / |gaze|; normalizations and the cross product: ~4. 8 covers.
constexpr double kLookAtRoundings = 8.0;

// --- The table -----------------------------------------------------------------------------

struct Row {
  std::string label;
  std::string expected;
  std::string outcome;
  std::string error;
  std::string condition = "-";
  std::string time_ms = "-";
  bool pass = true;
};

std::vector<Row>& Rows() {
  static std::vector<Row> rows;
  return rows;
}

std::string Escape(std::string text) {
  std::string out;
  for (const char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

// Writes the rows when CAMPROJ_STABILITY_TABLE names a file (scripts/stability.sh).
class TableWriter : public ::testing::Environment {
 public:
  void TearDown() override {
    const char* path = std::getenv("CAMPROJ_STABILITY_TABLE");
    if (path == nullptr || *path == '\0') return;
    std::ofstream out(path);
    out << "| # | case | expected | outcome | error | Jacobian condition | time (ms) | check |\n"
        << "|---|------|----------|---------|-------|-------------------:|----------:|-------|\n";
    int index = 0;
    for (const Row& row : Rows()) {
      out << "| " << ++index << " | " << Escape(row.label) << " | " << Escape(row.expected) << " | "
          << Escape(row.outcome) << " | " << Escape(row.error) << " | " << row.condition << " | "
          << row.time_ms << " | " << (row.pass ? "pass" : "**FAIL**") << " |\n";
    }
  }
};

[[maybe_unused]] ::testing::Environment* const kTableWriter =
    ::testing::AddGlobalTestEnvironment(new TableWriter);

std::string Sci(double value, int digits = 2) {
  std::ostringstream s;
  s << std::setprecision(digits) << value;
  return s.str();
}

std::string Fixed(double value, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

const char* ReasonName(Reason reason) {
  switch (reason) {
    case Reason::kTooFewPoints:
      return "kTooFewPoints";
    case Reason::kCollinearPoints:
      return "kCollinearPoints";
    case Reason::kPlanarUnderdetermined:
      return "kPlanarUnderdetermined";
    case Reason::kNonFiniteInput:
      return "kNonFiniteInput";
    case Reason::kPointsBehindCamera:
      return "kPointsBehindCamera";
    case Reason::kMirroredWorld:
      return "kMirroredWorld";
    case Reason::kDegenerate:
      return "kDegenerate";
    case Reason::kContaminated:
      return "kContaminated";
    case Reason::kInconsistent:
      return "kInconsistent";
    case Reason::kAmbiguous:
      return "kAmbiguous";
    case Reason::kNumerical:
      return "kNumerical";
  }
  return "?";
}

// --- Distributions ------------------------------------------------------------------------

// Continued fraction of the incomplete beta function (modified Lentz; Numerical Recipes 6.4).
double BetaContinuedFraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  const double qab = a + b;
  const double qap = a + 1.0;
  const double qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 1000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < 1e-15) break;
  }
  return h;
}

// I_x(a, b), the regularized incomplete beta function.
double RegularizedIncompleteBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * BetaContinuedFraction(a, b, x) / a;
  return 1.0 - front * BetaContinuedFraction(b, a, 1.0 - x) / b;
}

// P(F <= f) for Fisher's F with (d1, d2) degrees of freedom.
double FCdf(double f, double d1, double d2) {
  return RegularizedIncompleteBeta(0.5 * d1, 0.5 * d2, d1 * f / (d1 * f + d2));
}

// The q-quantile of F(d1, d2), by bisection (the CDF is increasing).
double FQuantile(double q, double d1, double d2) {
  double lo = 0.0;
  double hi = 1.0;
  while (FCdf(hi, d1, d2) < q) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (FCdf(mid, d1, d2) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The quantile function the statistical checks rest on, against closed forms: F(2, d2) has
// P(F <= f) = 1 - (1 + 2 f / d2)^(-d2 / 2); I_x(a, 1) = x^a; and the F quantiles' reciprocity.
TEST(StabilityHarness, FQuantileMatchesClosedForms) {
  for (const double d2 : {3.0, 10.0, 90.0, 1000.0}) {
    for (const double q : {0.5, 0.95, 0.9999}) {
      const double closed = 0.5 * d2 * (std::pow(1.0 - q, -2.0 / d2) - 1.0);
      EXPECT_NEAR(FQuantile(q, 2.0, d2), closed, 1e-9 * closed) << d2 << " " << q;
    }
  }
  for (const double a : {0.5, 3.5, 7.0}) {
    EXPECT_NEAR(RegularizedIncompleteBeta(a, 1.0, 0.3), std::pow(0.3, a), 1e-13);
  }
  EXPECT_NEAR(FQuantile(0.9999, 10, 90), 1.0 / FQuantile(1e-4, 90, 10), 1e-8);
}

// --- Cameras, scenes and errors -------------------------------------------------------------

struct Truth {
  ImageSize size;
  Intrinsics intrinsics;                                   // kCenter
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // of cam_from_world
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        // camera centre in world
};

struct Scenario {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  FitOptions options;
  Truth truth;
  bool noisy = false;         // Gaussian pixel noise: judged statistically
  std::vector<int> outliers;  // with options.ransac: indices of the displaced points, ascending
};

Truth TruthOf(const Camera& camera) {
  return {camera.image_size, camera.intrinsics, camera.cam_from_world.rotation,
          CameraCenterInWorld(camera.cam_from_world)};
}

Scenario FromSynth(const SynthOptions& synth) {
  const SynthScene scene = SynthesizeScene(synth);
  Scenario s;
  s.points = scene.correspondences.points_in_world;
  s.pixels = scene.correspondences.pixels;
  s.truth = TruthOf(scene.truth);
  s.noisy = synth.noise_px > 0.0;
  return s;
}

SynthOptions Synth(uint64_t seed, int num_points, double fovx_deg = 60.0,
                   SynthObject object = SynthObject::kCloud) {
  SynthOptions o;
  o.seed = testing::Seed(seed);
  o.num_points = num_points;
  o.object = object;
  // Horizontal field of view -> the vertical one synth.h takes (square pixels).
  o.fovy_deg =
      2.0 *
      std::atan(std::tan(0.5 * fovx_deg / kDegPerRad) * o.image_size.height / o.image_size.width) *
      kDegPerRad;
  return o;
}

// Points anywhere in the image at depths 2..4 (tests/test_scenes.h) for a camera with the given
// intrinsics, a seeded rotation and a centre within 5 units of the origin.
Scenario FromIntrinsics(const Intrinsics& k, const ImageSize& size, uint64_t seed, int num_points,
                        double noise_px, bool planar = false) {
  std::mt19937_64 rng(testing::Seed(seed));
  testing::RandomCamera camera;
  camera.size = size;
  camera.intrinsics = k;
  // The centre is drawn before the rotation (testing::DrawVector3 says why).
  const Eigen::Vector3d center = testing::UniformVector3(rng, -5, 5);
  camera.cam_from_world = CamFromWorldFromCenter(testing::RandomRotation(rng), center);
  testing::SceneOptions scene_options;
  scene_options.num_points = num_points;
  scene_options.pixel_noise = noise_px;
  scene_options.planar = planar;
  const testing::Scene scene = testing::MakeScene(rng, camera, scene_options);
  Scenario s;
  s.points = scene.points_in_world;
  s.pixels = scene.observed_pixels;
  s.truth = {size, k, camera.cam_from_world.rotation, CameraCenterInWorld(camera.cam_from_world)};
  s.noisy = noise_px > 0.0;
  return s;
}

Intrinsics MakeIntrinsics(double fx, double fy, double cx, double cy, double skew = 0.0) {
  Intrinsics k;
  k.fx = fx;
  k.fy = fy;
  k.cx = cx;
  k.cy = cy;
  k.skew = skew;
  return k;
}

FitOptions FocalOnly() {
  FitOptions o;
  o.aspect = ParameterMode::Default();
  o.principal_point = ParameterMode::Default();
  return o;
}

// The camera's pixel of a world point in long double (64-bit significand: 2^-11 of float64's
// rounding), as the reference for what the float64 pipelines compute.
using Vector3l = Eigen::Matrix<long double, 3, 1>;

Eigen::Matrix<long double, 2, 1> PixelLong(const Intrinsics& k, const Vector3l& p) {
  const long double slots[kIntrinsicsArraySize] = {k.fx,   k.fy, k.cx, k.cy, k.skew,
                                                   k.k1,   k.k2, k.p1, k.p2, k.k3};
  long double pixel[2];
  PixelFromNormalized<long double>(slots, p.x() / p.z(), p.y() / p.z(), pixel);
  return {pixel[0], pixel[1]};
}

// |r|_2 of what perturbs a noise-free fit (truth_condition.h).
double PerturbationNorm(const Scenario& s) {
  return testing::PerturbationNorm(s.points, s.pixels, s.truth.rotation, s.truth.center,
                                   s.truth.intrinsics);
}

// The condition number of the scaled Jacobian at the true camera (truth_condition.h).
double ConditionAtTruth(const Scenario& s) {
  return testing::ConditionAtTruth(s.points, s.truth.rotation, s.truth.center,
                                   s.truth.intrinsics, s.options);
}

// The fit's error in its own parameterization (truth_condition.h).
Eigen::VectorXd EstimationError(const FitResult& fit, const Truth& truth) {
  return testing::EstimationError(fit, truth.rotation, truth.center, truth.intrinsics);
}

// The errors users read: worst relative intrinsic error (principal point and skew relative to
// the focal length), rotation error (deg), camera-centre error relative to the scene distance.
struct Errors {
  double intrinsic = 0.0;
  double rotation_deg = 0.0;
  double center = 0.0;
};

Errors ErrorsOf(const FitResult& fit, const Scenario& s) {
  const Intrinsics& k = fit.camera.intrinsics;
  const Intrinsics& t = s.truth.intrinsics;
  Errors e;
  e.intrinsic = std::max({std::abs(k.fx - t.fx) / t.fx, std::abs(k.fy - t.fy) / t.fy,
                          std::abs(k.cx - t.cx) / t.fx, std::abs(k.cy - t.cy) / t.fy,
                          std::abs(k.skew - t.skew) / t.fx});
  e.rotation_deg =
      Eigen::AngleAxisd(fit.camera.cam_from_world.rotation * s.truth.rotation.transpose()).angle() *
      kDegPerRad;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& x : s.points) centroid += x;
  centroid /= static_cast<double>(s.points.size());
  e.center = (CameraCenterInWorld(fit.camera.cam_from_world) - s.truth.center).norm() /
             (centroid - s.truth.center).norm();
  return e;
}

std::string ErrorText(const Errors& e) {
  return "intrinsics " + Sci(e.intrinsic) + ", rotation " + Sci(e.rotation_deg) + " deg, centre " +
         Sci(e.center);
}

// A noisy fit against its own reported uncertainty (sigma estimated from the 2N - p residual
// degrees of freedom). Each parameter: e_j / sigma_j is Student's t with dof degrees of freedom
// (t^2 is F(1, dof)), within the two-sided 1 - kFalseAlarm / p quantile; jointly NEES / p is
// F(p, dof), within its 1 - kFalseAlarm quantile. Both rest on the linearization, which the fit
// checks itself (FitResult::linearity): where it reports the model curved within the noise's
// reach, its covariance claims nothing and neither is checked.
struct NoisyVerdict {
  bool linear = false;
  bool t_ok = true;
  bool nees_ok = true;
  double worst_z = 0.0, z_bound = 0.0, nees = 0.0, nees_bound = 0.0;
  std::string text;
};

NoisyVerdict JudgeNoisy(const Scenario& s, const FitResult& fit) {
  NoisyVerdict v;
  const Eigen::VectorXd e = EstimationError(fit, s.truth);
  const int p = static_cast<int>(e.size());
  const int n = static_cast<int>(s.points.size() - fit.outliers.size());
  const int dof = 2 * n - p;
  v.z_bound = std::sqrt(FQuantile(1.0 - kFalseAlarm / p, 1, dof));
  for (int j = 0; j < p; ++j) {
    v.worst_z = std::max(v.worst_z, std::abs(e(j)) / std::sqrt(fit.covariance(j, j)));
  }
  v.nees = e.dot(fit.covariance.ldlt().solve(e));
  v.nees_bound = p * FQuantile(1.0 - kFalseAlarm, p, dof);
  v.linear = fit.linearity.checked && fit.linearity.linear;
  if (v.linear) {
    v.t_ok = v.worst_z <= v.z_bound;
    v.nees_ok = v.nees <= v.nees_bound;
  }
  v.text = "worst " + Fixed(v.worst_z, 2) + " sigma (bound " + Fixed(v.z_bound, 2) + "), NEES " +
           Fixed(v.nees, 1) + " (bound " + Fixed(v.nees_bound, 1) + ", p = " + std::to_string(p) +
           "), linearity " + Sci(fit.linearity.worst_deviation) +
           (v.linear ? "" : " (curved: the covariance claims nothing, not checked)");
  return v;
}

// The chance that a fit with linearity deviation d fails JudgeNoisy: the checks' kFalseAlarm
// each, raised because a curved valley inflates the linearized statistics of an error on its
// floor by up to a factor 1 + d (fit.h, kMaxLinearityDeviation): the bounds then stand where the
// true statistic is 1 / (1 + d) of them.
double NoisyFalseAlarm(int p, int dof, double deviation) {
  const double shrink = 1.0 / (1.0 + deviation);
  const double z2 = FQuantile(1.0 - kFalseAlarm / p, 1, dof);
  const double f = FQuantile(1.0 - kFalseAlarm, p, dof);
  return p * (1.0 - FCdf(shrink * z2, 1, dof)) + (1.0 - FCdf(shrink * f, p, dof));
}

// Checks a noise-free camera against the truth; returns the table's error text.
std::string JudgeFit(const Scenario& s, const FitResult& fit) {
  const Errors errors = ErrorsOf(fit, s);
  std::string text = ErrorText(errors);
  EXPECT_TRUE(fit.covariance_available);
  if (!fit.covariance_available) return text;
  // Noisy and RANSAC scenes are judged over their draws (RunNoisyDraws), never once here.
  EXPECT_FALSE(s.noisy || s.options.ransac) << "a noisy case belongs in FittedNoisy";
  // Noise-free: per parameter, |e_j| <= margin sigma_j(1 px) |r|_2 + output rounding; the
  // intrinsics the fit did not estimate as given.
  const double r = PerturbationNorm(s);
  const double worst = testing::ExpectWithinFirstOrderBound(
      fit, s.points, s.pixels, s.truth.rotation, s.truth.center, s.truth.intrinsics, "");
  text += "; " + Sci(worst) + " of the rounding bound (|r|_2 = " + Sci(r) + " px)";
  return text;
}

// --- Cases ---------------------------------------------------------------------------------

struct Case;
Row RowOf(const Case& c);

struct Case {
  std::string id;        // GoogleTest name
  std::string label;     // table
  std::string expected;  // table
  std::function<Row(const Case&)> run;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

Row RowOf(const Case& c) {
  Row row;
  row.label = c.label;
  row.expected = c.expected;
  return row;
}

struct Refusal {
  std::vector<Reason> reasons;     // any of them (more than one only where each is true)
  std::vector<std::string> words;  // the message must say one of these
};

Row RunFit(const Case& c, const Scenario& s, const std::optional<Refusal>& refusal) {
  Row row = RowOf(c);
  FitOptions options = s.options;
  // Noise-free: sigma = 1 px only scales the reported covariance, making it (J^T J)^-1.
  if (!s.noisy) options.pixel_sigma = 1.0;
  // The expectation against an independent computation: a camera where the truth's condition
  // number is below the fitter's limit, an undetermined-refusal (kDegenerate) only above it.
  const bool expect_degenerate =
      refusal && std::find(refusal->reasons.begin(), refusal->reasons.end(), Reason::kDegenerate) !=
                     refusal->reasons.end();
  std::string truth_condition;
  double condition = kInfinity;
  if (!refusal || expect_degenerate) {
    condition = ConditionAtTruth(s);
    truth_condition = "condition at truth " + Sci(condition, 3);
    if (refusal) {
      EXPECT_GT(condition, kFitterConditionLimit) << "the truth is determined: no reason to refuse";
    } else {
      EXPECT_LT(condition, kFitterConditionLimit) << "the truth is undetermined: expect a refusal";
    }
  }
  const Clock::time_point start = Clock::now();
  try {
    const FitResult fit = FitCamera(s.points, s.pixels, s.truth.size, options);
    row.outcome = "fitted (" + fit.start_method + ")";
    row.condition = Sci(fit.jacobian_condition, 3);
    row.time_ms = Fixed(fit.time_ms, 2);
    if (refusal) {
      ADD_FAILURE() << c.label
                    << ": expected a refusal, got a camera: " << ErrorText(ErrorsOf(fit, s));
      row.error = ErrorText(ErrorsOf(fit, s));
    } else {
      row.error = JudgeFit(s, fit);
    }
  } catch (const SceneError& e) {
    row.time_ms = Fixed(MillisecondsSince(start), 2) + " (wall)";
    row.outcome = std::string("refused: ") + ReasonName(e.reason());
    row.error = "\"" + std::string(e.what()) + "\"";
    if (!refusal) {
      ADD_FAILURE() << c.label << ": expected a camera, refused: " << e.what();
    } else {
      EXPECT_NE(std::find(refusal->reasons.begin(), refusal->reasons.end(), e.reason()),
                refusal->reasons.end())
          << "reason " << ReasonName(e.reason()) << ": " << e.what();
      const std::string message = e.what();
      EXPECT_TRUE(std::any_of(
          refusal->words.begin(), refusal->words.end(),
          [&](const std::string& word) { return message.find(word) != std::string::npos; }))
          << "the message should say \"" << refusal->words.front() << "\": " << message;
    }
  } catch (const std::exception& e) {
    row.outcome = std::string("threw: ") + e.what();
    ADD_FAILURE() << c.label << ": unexpected exception " << e.what();
  }
  if (!truth_condition.empty()) row.error += "; " + truth_condition;
  return row;
}

Case Fitted(std::string id, std::string label, std::function<Scenario()> make,
            std::string expected) {
  Case c{std::move(id), std::move(label), std::move(expected), nullptr};
  c.run = [make](const Case& self) { return RunFit(self, make(), std::nullopt); };
  return c;
}

Case Refused(std::string id, std::string label, std::function<Scenario()> make, Refusal refusal) {
  std::string expected = "refused: ";
  for (size_t i = 0; i < refusal.reasons.size(); ++i) {
    expected += (i ? " or " : "") + std::string(ReasonName(refusal.reasons[i]));
  }
  Case c{std::move(id), std::move(label), expected, nullptr};
  c.run = [make, refusal](const Case& self) { return RunFit(self, make(), refusal); };
  return c;
}

// What a noisy case expects of its draws (RunNoisyDraws).
struct NoisyExpectation {
  // The draws the fit may report curved: 0 where the model is known linear over the noise's
  // reach (sub-pixel noise, well-conditioned), kNoisyDraws where it may go either way.
  int max_curved = kNoisyDraws;
  // The draws it must report curved (a refused draw counts with them: it makes no "linear"
  // report, and refusals have their own rate): where the noise's reach is far beyond the linear
  // regime (the truth's NEES far above its bound in every draw), a "linear" report would be wrong.
  int min_curved = 0;
  // The chance per draw of a refusal ("did not reach the minimum"), 0 unless a known weakness
  // of the refinement says otherwise (then `why`, with the measurement).
  double refusal_rate = 0.0;
  // false: the fit's "linear" reports are known to miss this case's curvature (`why`), and the
  // covariance is not checked even where it says linear.
  bool check_covariance = true;
  std::string why;
};

// A noisy case: kNoisyDraws draws of Gaussian pixel noise of `sigma` px on the noise-free scene
// `make` returns (seeds Seed(seed * 1000 + draw)). Refusals are a rate at
// `expect.refusal_rate` (the truth is determined, its condition below the fitter's limit);
// among the draws the fit reports linear, JudgeNoisy's failures are a rate bounded by
// NoisyFalseAlarm at each draw's own deviation. The draws reported curved are not a failure
// (the fit said so itself), within `expect`'s bounds on their number.
Scenario WithNoise(Scenario s, double sigma, uint64_t seed);

Row RunNoisyDraws(const Case& c, const std::function<Scenario()>& make, double sigma,
                  uint64_t seed, const NoisyExpectation& expect) {
  Row row = RowOf(c);
  const Scenario clean = make();
  const double condition = ConditionAtTruth(clean);
  EXPECT_LT(condition, kFitterConditionLimit) << "the truth is undetermined: expect a refusal";
  int refused = 0, curved = 0, linear = 0, failed = 0, wrong_outliers = 0;
  double false_alarm_sum = 0.0;
  double worst_nees_ratio = 0.0, worst_deviation = 0.0, time_ms = 0.0;
  std::string first_refusal;
  for (int draw = 0; draw < kNoisyDraws; ++draw) {
    const Scenario s = WithNoise(clean, sigma, seed * 1000 + draw);
    try {
      const FitResult fit = FitCamera(s.points, s.pixels, s.truth.size, s.options);
      time_ms += fit.time_ms;
      EXPECT_TRUE(fit.covariance_available && fit.linearity.checked) << c.label << " draw " << draw;
      if (!fit.covariance_available) continue;
      // RANSAC: the outlier set exactly (kFarOutlierPx), in every draw.
      if (s.options.ransac && fit.outliers != s.outliers) {
        ++wrong_outliers;
        ADD_FAILURE() << c.label << " draw " << draw << ": " << fit.outliers.size()
                      << " outliers found of " << s.outliers.size();
      }
      const NoisyVerdict v = JudgeNoisy(s, fit);
      worst_deviation = std::max(worst_deviation, fit.linearity.worst_deviation);
      if (!v.linear) {
        ++curved;
        continue;
      }
      ++linear;
      if (!expect.check_covariance) continue;
      const int p = static_cast<int>(fit.free_parameters.size());
      const int kept = static_cast<int>(s.points.size() - fit.outliers.size());
      false_alarm_sum += NoisyFalseAlarm(p, 2 * kept - p, fit.linearity.worst_deviation);
      worst_nees_ratio = std::max(worst_nees_ratio, v.nees / v.nees_bound);
      if (!v.t_ok || !v.nees_ok) {
        ++failed;
        std::printf("  %s draw %d: %s\n", c.id.c_str(), draw, v.text.c_str());
      }
    } catch (const SceneError& e) {
      ++refused;
      if (first_refusal.empty()) first_refusal = e.what();
    }
  }
  if (expect.refusal_rate > 0.0) {
    testing::ExpectRate(c.id + ": refused (" + expect.why + ")", refused, kNoisyDraws,
                        expect.refusal_rate);
  } else {
    EXPECT_EQ(refused, 0) << c.label << ": refused " << refused << " of " << kNoisyDraws
                          << " draws, e.g.: " << first_refusal;
  }
  EXPECT_LE(curved, expect.max_curved)
      << c.label << ": reported curved in " << curved << " of " << kNoisyDraws
      << " draws (worst deviation " << worst_deviation << ")";
  // A refused draw is no "linear" report: min_curved counts it with the curved ones (the
  // refusals have their own rate above).
  EXPECT_GE(curved + refused, expect.min_curved)
      << c.label << ": reported curved in only " << curved << " of " << kNoisyDraws
      << " draws (" << refused << " refused)";
  // The draws' failure chances differ (each its own deviation): the count of failures is
  // Poisson-binomial, whose upper tail beyond the mean is at most the binomial's with the mean
  // chance (Hoeffding 1956), so the bound uses the mean.
  const bool checked = expect.check_covariance && linear > 0;
  const double false_alarm = checked ? false_alarm_sum / linear : 0.0;
  if (checked) {
    testing::ExpectRate(c.id + ": beyond its sigmas (t or NEES) among the draws reported linear",
                        failed, linear, false_alarm);
  }
  row.outcome = "fitted " + std::to_string(kNoisyDraws - refused) + " of " +
                std::to_string(kNoisyDraws) + " draws";
  row.error = std::to_string(curved) + " reported curved (worst linearity deviation " +
              Sci(worst_deviation) + "); ";
  if (checked) {
    row.error += std::to_string(failed) + " of " + std::to_string(linear) +
                 " linear draws beyond their sigmas (allowed " +
                 std::to_string(testing::MaxFailures(linear, false_alarm)) + "), worst NEES " +
                 Fixed(worst_nees_ratio, 2) + " of its bound";
  } else if (!expect.check_covariance) {
    row.error += "covariance not checked: " + expect.why;
  }
  if (clean.options.ransac) {
    row.error += "; outlier set exact in " + std::to_string(kNoisyDraws - refused - wrong_outliers) +
                 " of " + std::to_string(kNoisyDraws - refused) + " draws";
  }
  if (refused > 0) row.error += "; " + std::to_string(refused) + " refused: " + first_refusal;
  row.error += "; condition at truth " + Sci(condition, 3);
  row.condition = Sci(condition, 3) + " (truth)";
  row.time_ms = Fixed(time_ms / kNoisyDraws, 2) + " (mean)";
  return row;
}

Case FittedNoisy(std::string id, std::string label, std::function<Scenario()> make, double sigma,
                 uint64_t seed, const NoisyExpectation& expect) {
  Case c{std::move(id), std::move(label), "", nullptr};
  c.expected = std::to_string(kNoisyDraws) + " draws: right camera within its sigmas (t, F " +
               "99.99 %) where it reports linear";
  if (expect.max_curved == 0) c.expected += ", never curved";
  if (expect.min_curved == kNoisyDraws) c.expected += ", always curved";
  c.run = [make, sigma, seed, expect](const Case& self) {
    return RunNoisyDraws(self, make, sigma, seed, expect);
  };
  return c;
}

// Automatic model selection on a view whose perspective is not observable: it must return an
// orthographic camera (pose + focal is refused as undetermined) whose image agrees with the
// truth's. With sigma px noise on N points a 6-parameter linear fit leaves an RMS prediction
// error of sqrt(6 / N) sigma sqrt(2) in expectation; 3 times that bounds it (the perspective's
// own deviation from parallel, ~1e-3 of the image at 0.1 degrees, is well inside).
Row RunAutoOrthographic(const Case& c, const Scenario& s, double sigma) {
  Row row = RowOf(c);
  Camera truth;
  truth.image_size = s.truth.size;
  truth.intrinsics = s.truth.intrinsics;
  truth.cam_from_world = CamFromWorldFromCenter(s.truth.rotation, s.truth.center);
  try {
    const FitResult fit = FitCameraAuto(s.points, s.pixels, s.truth.size);
    row.outcome = "fitted: " + fit.model;
    row.condition = Sci(fit.jacobian_condition, 3);
    row.time_ms = Fixed(fit.time_ms, 2) + " (last model)";
    double sum = 0.0;
    for (const Eigen::Vector3d& x : s.points) {
      sum += (*PixelFromWorld(fit.camera, x) - *PixelFromWorld(truth, x)).squaredNorm();
    }
    const double rms = std::sqrt(sum / s.points.size());
    const double bound = 3.0 * std::sqrt(6.0 / s.points.size()) * sigma * std::sqrt(2.0);
    row.error = "image RMS vs truth " + Sci(rms, 2) + " px (bound " + Sci(bound, 2) + ")";
    EXPECT_EQ(fit.camera.projection, Projection::kOrthographic) << c.label << ": " << fit.model;
    EXPECT_LT(rms, bound) << c.label;
  } catch (const std::exception& e) {
    row.outcome = std::string("threw: ") + e.what();
    ADD_FAILURE() << c.label << ": " << e.what();
  }
  return row;
}

// --- Scenes of the cases ------------------------------------------------------------------------

// The scene with seeded Gaussian pixel noise of `sigma` px per axis.
Scenario WithNoise(Scenario s, double sigma, uint64_t seed) {
  std::mt19937_64 rng(testing::Seed(seed));
  std::normal_distribution<double> normal;
  for (auto& pixel : s.pixels) pixel += sigma * testing::DrawVector2([&] { return normal(rng); });
  s.noisy = true;
  return s;
}

// A camera with the given horizontal field of view on a 1280 x 800 image (square pixels,
// principal point at the centre) and 40 points filling the image at depths 2..4.
Scenario FieldOfView(double fovx_deg, bool full_model, uint64_t seed) {
  const double f = 640.0 / std::tan(0.5 * fovx_deg / kDegPerRad);
  Scenario s = FromIntrinsics(MakeIntrinsics(f, f, 639.5, 399.5), {1280, 800}, seed, 40, 0.0);
  s.options = full_model ? FitOptions{} : FocalOnly();
  return s;
}

// A compact object (synth.h's cloud, 1 x 0.6 x 0.8) filling the 1920 x 1080 image: its depth
// range shrinks with the field of view (about 1e-3 of the distance at 0.1 degrees).
Scenario CompactObject(double fovx_deg) {
  Scenario s = FromSynth(Synth(11, 40, fovx_deg));
  s.options = FocalOnly();
  return s;
}

// The reference scene of the units and offset cases: 40 points, 60 degrees, full model.
Scenario Transformed(double unit, const Eigen::Vector3d& offset) {
  Scenario s = FromSynth(Synth(12, 40, 60.0));
  for (auto& x : s.points) x = unit * x + offset;
  s.truth.center = unit * s.truth.center + offset;
  return s;
}

// 60 points anywhere in a 1280 x 800 image with the principal point at (cx, cy), full model.
Scenario LensShift(double cx, double cy, double noise_px, uint64_t seed) {
  return FromIntrinsics(MakeIntrinsics(1000, 1000, cx, cy), {1280, 800}, seed, 60, noise_px);
}

// A synth plane thickened to `thickness` (of the object size, 1): offsets along the normal,
// uniform in [-thickness / 2, thickness / 2]; pixels from the true camera.
Scenario NearPlanar(double thickness, bool full_model) {
  const SynthScene scene = SynthesizeScene(Synth(14, 40, 60.0, SynthObject::kPlane));
  Scenario s;
  s.points = scene.correspondences.points_in_world;
  s.pixels = scene.correspondences.pixels;
  s.truth = TruthOf(scene.truth);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& x : s.points) centroid += x;
  centroid /= static_cast<double>(s.points.size());
  Eigen::MatrixXd centred(s.points.size(), 3);
  for (size_t i = 0; i < s.points.size(); ++i)
    centred.row(i) = (s.points[i] - centroid).transpose();
  const Eigen::Vector3d normal =
      Eigen::JacobiSVD<Eigen::MatrixXd>(centred, Eigen::ComputeThinV).matrixV().col(2);
  std::mt19937_64 rng(testing::Seed(15));
  for (size_t i = 0; i < s.points.size(); ++i) {
    if (thickness > 0.0) {
      s.points[i] += thickness * testing::Uniform(rng, -0.5, 0.5) * normal;
      s.pixels[i] = *PixelFromWorld(scene.truth, s.points[i]);
    }
  }
  s.options = full_model ? FitOptions{} : FocalOnly();
  return s;
}

// Synth cloud of `n` points (45 degrees), with a model.
Scenario FewPoints(int n, const FitOptions& options) {
  Scenario s = FromSynth(Synth(16, n, 45.0));
  s.options = options;
  return s;
}

// A projector-like scene with noise and `fraction` of the points moved far from their pixel.
Scenario Outliers(double fraction, uint64_t seed) {
  Scenario s = FromIntrinsics(MakeIntrinsics(1200, 1180, 660, 760), {1280, 800}, seed, 80, 0.0);
  std::mt19937_64 rng(testing::Seed(seed + 1));
  std::vector<int> order(s.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  const int count = static_cast<int>(std::lround(fraction * s.points.size()));
  for (int m = 0; m < count; ++m) {
    const int i = order[m];
    const Eigen::Vector2d true_pixel =
        PixelFromCam(s.truth.intrinsics, s.truth.rotation * (s.points[i] - s.truth.center));
    Eigen::Vector2d moved;
    do {
      moved = testing::RandomPixelInImage(rng, s.truth.size);
    } while ((moved - true_pixel).norm() < kFarOutlierPx);
    s.pixels[i] = moved;
    s.outliers.push_back(i);
  }
  std::sort(s.outliers.begin(), s.outliers.end());
  s.options.ransac = true;
  return s;
}

// Points all around the camera (a sphere of directions at distance 1..2), with the pixel a
// projective camera gives each (x / z, y / z, also for z < 0): no real camera sees them all.
Scenario CameraInsideCloud() {
  Scenario s = FromSynth(Synth(17, 8, 60.0));
  std::mt19937_64 rng(testing::Seed(18));
  std::normal_distribution<double> normal;
  int front = 0;
  int back = 0;
  s.points.clear();
  s.pixels.clear();
  while (front + back < 40) {
    const Eigen::Vector3d direction = testing::DrawVector3([&] { return normal(rng); }).normalized();
    const Eigen::Vector3d p = testing::Uniform(rng, 1.0, 2.0) * direction;  // in cam
    if (std::abs(p.z()) < 0.2) continue;
    const double slots[kIntrinsicsArraySize] = {s.truth.intrinsics.fx, s.truth.intrinsics.fy,
                                                s.truth.intrinsics.cx, s.truth.intrinsics.cy};
    Eigen::Vector2d pixel;
    PixelFromNormalized<double>(slots, p.x() / p.z(), p.y() / p.z(), pixel.data());
    if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > s.truth.size.width - 1 ||
        pixel.y() > s.truth.size.height - 1) {
      continue;
    }
    int& count = p.z() > 0 ? front : back;
    if (count >= 20) continue;
    ++count;
    s.points.push_back(s.truth.rotation.transpose() * p + s.truth.center);
    s.pixels.push_back(pixel);
  }
  return s;
}

// --- Look-at -------------------------------------------------------------------------------

Row RunLookAtRefusal(const Case& c, const LookAt& look_at, const std::string& word) {
  Row row = RowOf(c);
  const Clock::time_point start = Clock::now();
  try {
    CamFromWorldFromLookAt(look_at);
    row.outcome = "returned a pose";
    ADD_FAILURE() << c.label << ": expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    row.outcome = "refused: std::invalid_argument";
    row.error = "\"" + std::string(e.what()) + "\"";
    EXPECT_NE(std::string(e.what()).find(word), std::string::npos)
        << "the message should say \"" << word << "\": " << e.what();
  }
  row.time_ms = Fixed(MillisecondsSince(start), 3) + " (wall)";
  return row;
}

// A look-at built from a known pose, with up tilted towards the gaze until
// sin(angle(up, gaze)) = sin_up_gaze and the gaze scaled to `gaze_length`.
Row RunLookAtPose(const Case& c, double sin_up_gaze, double gaze_length,
                  const Eigen::Vector3d& eye) {
  Row row = RowOf(c);
  std::mt19937_64 rng(testing::Seed(19));
  const Eigen::Matrix3d rotation = testing::RandomRotation(rng);
  const Eigen::Vector3d gaze = rotation.row(2).transpose();
  const Eigen::Vector3d up = -rotation.row(1).transpose();
  LookAt look_at;
  look_at.eye = eye;
  look_at.target = eye + gaze_length * gaze;
  look_at.up = std::sqrt(1.0 - sin_up_gaze * sin_up_gaze) * gaze + sin_up_gaze * up;
  const Clock::time_point start = Clock::now();
  try {
    const Rigid3 pose = CamFromWorldFromLookAt(look_at);
    row.time_ms = Fixed(MillisecondsSince(start), 3) + " (wall)";
    const double angle = Eigen::AngleAxisd(pose.rotation * rotation.transpose()).angle();
    const double bound = kLookAtRoundings * kUnitRoundoff *
                         (1.0 + (look_at.eye.norm() + look_at.target.norm()) / gaze_length) /
                         sin_up_gaze;
    // The same rounding leaves u off orthogonal to w by up to `bound`, so R^T R differs from I by
    // up to 2 bound, and the eye comes back through C = -R^T (-R eye) = R^T R eye.
    const double orthonormality =
        (pose.rotation.transpose() * pose.rotation - Eigen::Matrix3d::Identity())
            .cwiseAbs()
            .maxCoeff();
    const double eye_error = (CameraCenterInWorld(pose) - eye).norm();
    const double eye_bound = (2.0 * bound + kLookAtRoundings * kUnitRoundoff) * eye.norm();
    row.outcome = "pose";
    row.error = "rotation " + Sci(angle * kDegPerRad) + " deg (" + Fixed(angle / bound, 3) +
                " of the rounding bound), |R^T R - I| " + Sci(orthonormality) + ", eye " +
                Sci(eye_error);
    EXPECT_LE(angle, bound);
    EXPECT_LE(orthonormality, 2.0 * bound);
    EXPECT_LE(eye_error, eye_bound);
  } catch (const std::exception& e) {
    row.outcome = std::string("threw: ") + e.what();
    ADD_FAILURE() << c.label << ": " << e.what();
  }
  return row;
}

// --- GL export -----------------------------------------------------------------------------

// Window depth at cam depth z, exactly (docs/conventions.md section 6), in long double.
long double ExactWindowDepth(long double z, long double n, double f, bool reversed) {
  if (std::isinf(f)) return reversed ? n / z : 1.0L - n / z;
  const long double fl = f;
  return reversed ? n * (fl - z) / ((fl - n) * z) : fl * (z - n) / ((fl - n) * z);
}

Row RunGl(const Case& c, const GlDepth& depth, double z_far) {
  Row row = RowOf(c);
  const Clock::time_point start = Clock::now();
  // An extreme projector: lens shift (principal point half an image below), fx != fy, skew.
  Camera camera;
  camera.image_size = {1280, 800};
  camera.intrinsics = MakeIntrinsics(1000, 1100, 700.25, 1200.0, 50.0);
  std::mt19937_64 rng(testing::Seed(20));
  camera.cam_from_world =
      CamFromWorldFromCenter(testing::RandomRotation(rng), Eigen::Vector3d(3.0, -2.0, 5.0));
  camera.z_near = 1e-6;
  camera.z_far = z_far;
  const Truth truth = TruthOf(camera);
  const Intrinsics& k = camera.intrinsics;
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  try {
    const CameraViews views = ViewsOfCamera(camera, 1.0, depth);
    const double a = views.clip_from_gl_eye(2, 2);
    const double b = views.clip_from_gl_eye(2, 3);
    std::vector<double> depths;
    for (double z = 1e-6; z <= 1.0001e9; z *= std::sqrt(10.0)) depths.push_back(z);
    if (std::isinf(z_far)) {
      for (const double z : {1e12, 1e16, 1e20, 1e50, 1e100, 1e300}) depths.push_back(z);
    }
    const std::vector<Eigen::Vector2d> pixels = {{-0.5, -0.5},
                                                 {w - 0.5, h - 0.5},
                                                 {0.5 * (w - 1), 0.5 * (h - 1)},
                                                 {0.0, h - 1.0},
                                                 {w - 1.0, 0.0}};
    double worst_pixel = 0.0;
    double worst_depth = 0.0;
    double worst_pixel_px = 0.0;
    int ordered = 0;
    int resolvable = 0;
    int checked = 0;
    double near_window_depth = 0.0;  // of the first pixel's points at depth 1e-6 and 1e9
    double far_window_depth = 0.0;
    for (const Eigen::Vector2d& pixel : pixels) {
      const Eigen::Vector3d ray = CamRayFromPixel(k, pixel);
      long double previous_exact = 0.0L;
      double previous_depth = 0.0;
      double previous_tolerance = 0.0;
      for (size_t d = 0; d < depths.size(); ++d) {
        const Eigen::Vector3d x = truth.center + truth.rotation.transpose() * (depths[d] * ray);
        // The exact pinhole projection of this Camera (R x + t, as it stores them).
        const Vector3l p =
            camera.cam_from_world.rotation.cast<long double>() * x.cast<long double>() +
            camera.cam_from_world.translation.cast<long double>();
        const Eigen::Matrix<long double, 2, 1> exact = PixelLong(k, p);
        const GlPixel gl = GlPixelFromWorld(views.clip_from_gl_eye, views.gl_eye_from_world, x,
                                            camera.image_size, depth.clip_depth);
        const std::optional<Eigen::Vector2d> cv = PixelFromWorld(camera, x);
        ++checked;
        const bool finite = gl.pixel.allFinite() && std::isfinite(gl.window_depth) &&
                            cv.has_value() && cv->allFinite();
        EXPECT_TRUE(finite) << "depth " << depths[d];
        if (!finite) continue;
        // Rounding propagated to pixels (testing::PixelRoundingBound).
        const double z = static_cast<double>(p.z());
        const double u = static_cast<double>(exact.x());
        const double v = static_cast<double>(exact.y());
        const double world_to_cam =
            (x.lpNorm<1>() + camera.cam_from_world.translation.lpNorm<1>()) / z;
        const Eigen::Vector2d exact_pixel(u, v);
        const double pixel_tolerance = testing::PixelRoundingBound(
            k, camera.image_size, camera.cam_from_world, x, exact_pixel,
            (k.fx + k.fy + std::abs(k.skew) + std::abs(u - k.cx) + std::abs(v - k.cy)) / z);
        const double gl_error = (gl.pixel - exact_pixel).norm();
        const double cv_error = (*cv - exact_pixel).norm();
        EXPECT_LE(gl_error, pixel_tolerance) << "GL pixel at depth " << depths[d];
        EXPECT_LE(cv_error, pixel_tolerance) << "pinhole pixel at depth " << depths[d];
        worst_pixel =
            std::max({worst_pixel, gl_error / pixel_tolerance, cv_error / pixel_tolerance});
        worst_pixel_px = std::max(worst_pixel_px, gl_error);
        // Window depth: clip.z = A z_eye + B and the divide err by ~kGlRoundings u of |A| and of
        // |B| / z (amplified by the cam depth's own error), the viewport by ~u of 1.
        const long double exact_depth =
            ExactWindowDepth(p.z(), camera.z_near, z_far, depth.reversed_z);
        const double depth_tolerance = kGlRoundings * kUnitRoundoff *
                                       (std::abs(a) + std::abs(b) / z * (1.0 + world_to_cam) + 1.0);
        const double depth_error = std::abs(gl.window_depth - static_cast<double>(exact_depth));
        EXPECT_LE(depth_error, depth_tolerance) << "window depth at depth " << depths[d];
        if (&pixel == &pixels.front() && d == 0) near_window_depth = gl.window_depth;
        if (&pixel == &pixels.front() && std::abs(depths[d] / 1e9 - 1.0) < 1e-9)
          far_window_depth = gl.window_depth;
        worst_depth = std::max(worst_depth, depth_error / depth_tolerance);
        // Monotone: wherever two exact depths are further apart than their tolerances, the
        // computed ones must be ordered the same way (and they are never out of order by more).
        if (d > 0) {
          const long double step =
              depth.reversed_z ? previous_exact - exact_depth : exact_depth - previous_exact;
          const double computed = depth.reversed_z ? previous_depth - gl.window_depth
                                                   : gl.window_depth - previous_depth;
          if (step > previous_tolerance + depth_tolerance) {
            ++resolvable;
            EXPECT_GT(computed, 0.0)
                << "depth order between " << depths[d - 1] << " and " << depths[d];
            if (computed > 0.0) ++ordered;
          }
          EXPECT_GE(computed, -(previous_tolerance + depth_tolerance));
        }
        previous_exact = exact_depth;
        previous_depth = gl.window_depth;
        previous_tolerance = depth_tolerance;
      }
    }
    row.outcome = "finite, " + std::to_string(checked) + " points at depths 1e-6.." +
                  Sci(depths.back(), 1) + "; window depth " + Sci(near_window_depth, 3) +
                  " at the near plane, " + Sci(far_window_depth, 3) + " at 1e9";
    row.error = "pixel " + Sci(worst_pixel_px) + " px (" + Fixed(worst_pixel, 3) +
                " of the rounding bound), window depth " + Fixed(worst_depth, 3) +
                " of its bound; ordered " + std::to_string(ordered) + " of " +
                std::to_string(resolvable) + " resolvable depth steps";
  } catch (const std::exception& e) {
    row.outcome = std::string("threw: ") + e.what();
    ADD_FAILURE() << c.label << ": " << e.what();
  }
  row.time_ms = Fixed(MillisecondsSince(start), 2) + " (wall)";
  return row;
}

// --- The table of cases ---------------------------------------------------------------------

std::vector<Case> AllCases() {
  const std::string exact = "right camera (rounding bound)";
  std::vector<Case> cases;

  // Fields of view (horizontal): points filling the image at depths 2..4, noise-free.
  const std::pair<const char*, double> fovs[] = {{"0p1", 0.1}, {"1", 1.0},     {"5", 5.0},
                                                 {"90", 90.0}, {"150", 150.0}, {"170", 170.0}};
  for (const auto& [id, fov] : fovs) {
    cases.push_back(Fitted(
        std::string("Fov") + id + "DegFocalFree",
        "FoV " + Sci(fov, 3) + " deg, depths 2..4, focal free",
        [fov = fov] { return FieldOfView(fov, false, 31); }, exact));
  }
  for (const auto& [id, fov] : fovs) {
    if (fov < 1.0) continue;  // 0.1 degrees: refused, next
    cases.push_back(Fitted(
        std::string("Fov") + id + "DegFullModel",
        "FoV " + Sci(fov, 3) + " deg, depths 2..4, full model",
        [fov = fov] { return FieldOfView(fov, true, 32); }, exact));
  }
  // At 0.1 degrees a principal-point shift d and a rotation by d / fx differ in the image only by
  // ~d x^2 with |x| <= tan(0.05 deg) = 8.7e-4: the scaled Jacobian's smallest singular value is
  // ~x^2 = 7.6e-7 of its largest, a condition number above the fitter's limit of 1e6.
  cases.push_back(Refused("Fov0p1DegFullModel", "FoV 0.1 deg, depths 2..4, full model",
                          [] { return FieldOfView(0.1, true, 33); },
                          {{Reason::kDegenerate}, {"determine"}}));
  // A compact object far away: focal length and distance trade off ever more closely as the
  // field of view narrows (condition number ~1/fov^2).
  cases.push_back(Fitted(
      "CompactObjectFov1Deg", "FoV 1 deg, compact object, focal free",
      [] { return CompactObject(1.0); }, exact));
  cases.push_back(Refused("CompactObjectFov0p1Deg", "FoV 0.1 deg, compact object, focal free",
                          [] { return CompactObject(0.1); },
                          {{Reason::kDegenerate}, {"determine"}}));

  // The same object with automatic model selection and 0.5 px noise: orthographic.
  {
    Case c{"CompactObjectFov0p1DegAuto", "FoV 0.1 deg, compact object, --model auto, 0.5 px noise",
           "orthographic camera, image within 3 sqrt(6/N) sigma sqrt 2 of the truth's", nullptr};
    c.run = [](const Case& self) {
      return RunAutoOrthographic(self, WithNoise(CompactObject(0.1), 0.5, 43), 0.5);
    };
    cases.push_back(c);
  }

  // Noise on the hardest-conditioned scenes that still fit.
  cases.push_back(FittedNoisy(
      "Fov1DegFullModelNoisy", "FoV 1 deg, full model, 0.5 px noise",
      [] { return FieldOfView(1.0, true, 32); }, 0.5, 41,
      [] {
        NoisyExpectation e;
        // Measured at seed offsets 0-40 (820 draws): 41 refused as short of the minimum (LM
        // stops on its cost tolerance in the curved valley while the polish sees it short);
        // 20 reported linear, 17 of them with NEES far above its bound: around the estimate
        // the check probes a straight stretch of the valley, and the truth lies beyond it.
        e.refusal_rate = 0.1;
        e.check_covariance = false;
        e.why = "a 1-degree view with the full model: the linearity check probes 6 sigmas around "
                "the estimate, the truth lies further along the curved valley (17 of 20 draws "
                "reported linear failed NEES, seed offsets 0-40); 41 of 820 refused short of "
                "the minimum";
        return e;
      }()));
  cases.push_back(FittedNoisy(
      "CompactObjectFov1DegNoisy", "FoV 1 deg, compact object, focal free, 0.5 px noise",
      [] { return CompactObject(1.0); }, 0.5, 42,
      [] {
        NoisyExpectation e;
        e.min_curved = kNoisyDraws - 2;  // 819 of 819 fitted draws curved at offsets 0-40
        // Per draw; the draws of one seed offset share its object (Synth(11) shifts with the
        // offset), and some objects refuse more: at offsets 0-400, 55 of 8020 draws, 28 offsets
        // with any, at most 5 of 20 at one (offset 123), within the bound at this rate.
        e.refusal_rate = 0.01;
        e.why = "55 of 8020 draws refused short of the minimum at seed offsets 0-400";
        return e;
      }()));
  cases.push_back(FittedNoisy(
      "AspectTenNoisy", "fx / fy = 10, 2 px noise",
      [] {
        return FromIntrinsics(MakeIntrinsics(2000, 200, 639.5, 399.5), {1280, 800}, 25, 60, 0.0);
      },
      2.0, 43, NoisyExpectation{0, 0, 0.0, true, ""}));
  cases.push_back(FittedNoisy(
      "NearPlanar1em3FocalFreeNoisy", "near-planar, thickness 0.001, focal free, 1 px noise",
      [] { return NearPlanar(1e-3, false); }, 1.0, 44, NoisyExpectation{0, 0, 0.0, true, ""}));
  cases.push_back(FittedNoisy(
      "NearPlanar1em2FullModelNoisy", "near-planar, thickness 0.01, full model, 0.5 px noise",
      [] { return NearPlanar(1e-2, true); }, 0.5, 45,
      [] {
        // Curved in 1619 of 1620 draws at seed offsets 0-80; the one reported linear sat on a
        // straight stretch of the valley with the truth beyond the probe (NEES above its bound).
        NoisyExpectation e{kNoisyDraws, kNoisyDraws - 2, 0.0, true, ""};
        // Refused short of the minimum (LM stops on its cost tolerance in the flat, curved
        // valley after ~110 iterations) in 2 of 6000 draws at seed offsets 0, 20, ..., 5980,
        // and at offset 2048: p 1e-3 is above the measured rate's 99 % upper limit (1.4e-3 is
        // its 99.9 %); ExpectRate allows 3 of 20 at level 1e-6.
        e.refusal_rate = 1e-3;
        e.why = "2 of 6000 draws refused short of the minimum at seed offsets 0-5980";
        return e;
      }()));
  cases.push_back(FittedNoisy(
      "LensShiftTwoWidthsLeftNoisy10", "pp two widths left, 10 px noise",
      [] { return LensShift(-2560.5, 399.5, 0.0, 22); }, 10.0, 46,
      NoisyExpectation{kNoisyDraws, kNoisyDraws, 0.0, true, ""}));

  // World offsets and units: the same scene (60 deg, 40 points, full model) moved and scaled.
  cases.push_back(Fitted(
      "WorldOffset1e7", "world offset by (1e7, -1e7, 1e7)",
      [] { return Transformed(1.0, Eigen::Vector3d(1e7, -1e7, 1e7)); }, exact));
  for (const auto& [id, unit] :
       {std::pair<const char*, double>{"1em6", 1e-6}, {"1em3", 1e-3}, {"1e3", 1e3}, {"1e6", 1e6}}) {
    cases.push_back(Fitted(
        std::string("Units") + id, "world units x " + Sci(unit, 1),
        [unit = unit] { return Transformed(unit, Eigen::Vector3d::Zero()); }, exact));
  }
  cases.push_back(Fitted(
      "Units1e6Offset1e7", "world units x 1e6 and offset by 1e7",
      [] { return Transformed(1e6, Eigen::Vector3d(1e7, 1e7, -1e7)); }, exact));

  // Lens shift: 60 points, full model, 1280 x 800, fx = fy = 1000.
  cases.push_back(Fitted(
      "LensShiftHalfImageBelow", "pp half an image below (cy = 1199.5)",
      [] { return LensShift(639.5, 1199.5, 0.0, 21); }, exact));
  cases.push_back(Fitted(
      "LensShiftTwoWidthsLeft", "pp two widths left (cx = -2560.5)",
      [] { return LensShift(-2560.5, 399.5, 0.0, 22); }, exact));
  cases.push_back(Fitted(
      "LensShiftTwoWidthsRightTwoHeightsUp",
      "pp two widths right, two heights up (3839.5, -1600.5)",
      [] { return LensShift(3839.5, -1600.5, 0.0, 23); }, exact));
  cases.push_back(FittedNoisy(
      "LensShiftTwoWidthsLeftNoisy", "pp two widths left, 1 px noise",
      [] { return LensShift(-2560.5, 399.5, 0.0, 24); }, 1.0, 24, NoisyExpectation{}));

  // Aspect: fx / fy = 10 and 1 / 10, 60 points, full model.
  cases.push_back(Fitted(
      "AspectTen", "fx / fy = 10 (2000 / 200)",
      [] {
        return FromIntrinsics(MakeIntrinsics(2000, 200, 639.5, 399.5), {1280, 800}, 25, 60, 0.0);
      },
      exact));
  cases.push_back(Fitted(
      "AspectTenth", "fx / fy = 0.1 (200 / 2000)",
      [] {
        return FromIntrinsics(MakeIntrinsics(200, 2000, 639.5, 399.5), {1280, 800}, 26, 60, 0.0);
      },
      exact));

  // Near-planar: a plane thickened to 1e-3, 1e-6, 1e-9 of its size.
  for (const auto& [id, t] :
       {std::pair<const char*, double>{"1em3", 1e-3}, {"1em6", 1e-6}, {"1em9", 1e-9}}) {
    cases.push_back(Fitted(
        std::string("NearPlanar") + id + "FocalFree",
        "near-planar, thickness " + Sci(t) + ", focal free",
        [t = t] { return NearPlanar(t, false); }, exact));
  }
  // Near-planar (thickness 1e-3, condition 5e4 at the truth), full model, noise-free: LM's
  // stopping rules once left it crawling along the valley at RMS 0.002 px, 2.7 % off in fx (6 of
  // its own sigmas); the fitter now resumes LM until the Gauss-Newton step is negligible against
  // the noise, or refuses.
  cases.push_back(Fitted(
      "NearPlanar1em3FullModel", "near-planar, thickness 0.001, full model",
      [] { return NearPlanar(1e-3, true); }, exact));
  cases.push_back(Fitted(
      "NearPlanar1em4FullModel", "near-planar, thickness 0.0001, full model",
      [] { return NearPlanar(1e-4, true); }, exact));
  // The off-plane information that pins the intrinsics a plane cannot determine shrinks with the
  // thickness t (the condition number grows ~1/t, 5e4 at t = 1e-3): at 1e-6 it is ~5e7.
  cases.push_back(Refused("NearPlanar1em6FullModel", "near-planar, thickness 1e-06, full model",
                          [] { return NearPlanar(1e-6, true); },
                          {{Reason::kDegenerate}, {"determine"}}));
  cases.push_back(Refused("NearPlanar1em9FullModel", "near-planar, thickness 1e-09, full model",
                          [] { return NearPlanar(1e-9, true); },
                          {{Reason::kPlanarUnderdetermined, Reason::kDegenerate}, {"determine"}}));

  // Exact planes.
  cases.push_back(Fitted(
      "PlaneFocalFree", "plane, focal free (pp, aspect default)",
      [] { return NearPlanar(0.0, false); }, exact));
  cases.push_back(Fitted(
      "PlaneFocalAspectFree", "plane (tilt about an oblique axis), focal and aspect free, pp given",
      [] {
        Scenario s = FromIntrinsics(MakeIntrinsics(1500, 1530, 700.5, 420.5), {1280, 800}, 34, 40,
                                    0.0, true);
        s.options.aspect = ParameterMode::Free();
        s.options.principal_point =
            ParameterMode::Fixed(s.truth.intrinsics.cx, s.truth.intrinsics.cy);
        return s;
      },
      exact));
  // synth.h tilts its plane about a horizontal axis and the camera has no roll: the plane's
  // vanishing line is parallel to the image rows, so the homography's two constraints on the
  // image of the absolute conic say nothing about fx apart from fy (Sturm and Maybank 1999).
  cases.push_back(Refused("PlaneTiltedAboutImageXFocalAspectFree",
                          "plane tilted about the image x axis, focal and aspect free",
                          [] {
                            Scenario s = NearPlanar(0.0, false);
                            s.options.aspect = ParameterMode::Free();
                            s.options.principal_point =
                                ParameterMode::Fixed(s.truth.intrinsics.cx, s.truth.intrinsics.cy);
                            return s;
                          },
                          {{Reason::kDegenerate}, {"determine"}}));
  // The refusal's advice must name an intrinsic (the user cannot fix a pose): the undetermined
  // direction is mostly rotation_x and the eye, with fx, fy along.
  cases.push_back(Refused("PlaneTiltedAboutImageXMessageNamesAnIntrinsic",
                          "plane tilted about the image x axis: message names focal or aspect",
                          [] {
                            Scenario s = NearPlanar(0.0, false);
                            s.options.aspect = ParameterMode::Free();
                            s.options.principal_point =
                                ParameterMode::Fixed(s.truth.intrinsics.cx, s.truth.intrinsics.cy);
                            return s;
                          },
                          {{Reason::kDegenerate}, {"fx", "fy", "focal", "aspect"}}));
  cases.push_back(Refused("PlaneFullModel", "plane, focal, aspect, pp free",
                          [] { return NearPlanar(0.0, true); },
                          {{Reason::kPlanarUnderdetermined}, {"Fix the principal point"}}));
  cases.push_back(Refused("PlaneHeadOn", "plane seen head-on, focal free",
                          [] {
                            Scenario s;
                            s.truth.size = {1280, 800};
                            s.truth.intrinsics = MakeIntrinsics(1000, 1000, 639.5, 399.5);
                            for (int i = 0; i < 5; ++i) {
                              for (int j = 0; j < 4; ++j) {
                                const Eigen::Vector3d point_in_cam(-0.8 + 0.4 * i, -0.6 + 0.4 * j,
                                                                   3.0);
                                s.points.push_back(point_in_cam);
                                s.pixels.push_back(PixelFromCam(s.truth.intrinsics, point_in_cam));
                              }
                            }
                            s.options = FocalOnly();
                            return s;
                          },
                          {{Reason::kDegenerate}, {"fx"}}));

  // Few points, with the model they can support, and one fewer.
  FitOptions all_but_focal_given = FocalOnly();
  cases.push_back(Fitted(
      "FourPointsFocalFree", "4 points, focal free",
      [=] { return FewPoints(4, all_but_focal_given); }, exact));
  cases.push_back(Fitted(
      "FivePointsFocalFree", "5 points, focal free",
      [=] { return FewPoints(5, all_but_focal_given); }, exact));
  cases.push_back(Fitted(
      "SixPointsFullModel", "6 points, full model", [] { return FewPoints(6, {}); }, exact));
  cases.push_back(Fitted(
      "SevenPointsFullModel", "7 points, full model", [] { return FewPoints(7, {}); }, exact));
  cases.push_back(Refused("FourPointsFullModel", "4 points, full model",
                          [] { return FewPoints(4, {}); },
                          {{Reason::kTooFewPoints}, {"10 unknowns"}}));
  cases.push_back(Refused("FivePointsFullModel", "5 points, full model",
                          [] { return FewPoints(5, {}); },
                          {{Reason::kTooFewPoints}, {"6 non-coplanar"}}));
  cases.push_back(Refused("FivePointsFocalAspectFree", "5 points, focal and aspect free",
                          [] {
                            FitOptions o = FocalOnly();
                            o.aspect = ParameterMode::Free();
                            return FewPoints(5, o);
                          },
                          {{Reason::kTooFewPoints}, {"6 non-coplanar"}}));
  cases.push_back(Refused("ThreePointsKnownIntrinsics", "3 points, intrinsics known",
                          [] {
                            Scenario s = FewPoints(3, {});
                            s.options.known_intrinsics = s.truth.intrinsics;
                            return s;
                          },
                          {{Reason::kTooFewPoints}, {"4 points"}}));

  // Collinear and coincident points.
  cases.push_back(Refused("CollinearPoints", "10 collinear points",
                          [] {
                            Scenario s = FewPoints(6, {});
                            const Eigen::Vector3d a = s.points[0];
                            const Eigen::Vector3d d = s.points[1] - s.points[0];
                            s.points.clear();
                            s.pixels.clear();
                            for (int i = 0; i < 10; ++i) {
                              s.points.push_back(a + (i / 9.0) * d);
                              const Camera camera{
                                  s.truth.size, s.truth.intrinsics,
                                  CamFromWorldFromCenter(s.truth.rotation, s.truth.center)};
                              s.pixels.push_back(*PixelFromWorld(camera, s.points.back()));
                            }
                            return s;
                          },
                          {{Reason::kCollinearPoints}, {"collinear"}}));
  cases.push_back(Refused("CoincidentPoints", "10 copies of one point",
                          [] {
                            Scenario s = FewPoints(6, {});
                            s.points.assign(10, s.points[0]);
                            s.pixels.assign(10, s.pixels[0]);
                            return s;
                          },
                          {{Reason::kCollinearPoints}, {"coincide"}}));

  // Pixel noise: 50 points, 60 degrees, full model.
  cases.push_back(Fitted(
      "Noise0px", "noise 0 px",
      [] {
        Scenario s = FromSynth(Synth(27, 50, 60.0));
        return s;
      },
      exact));
  for (const auto& [id, sigma] :
       {std::pair<const char*, double>{"0p5", 0.5}, {"2", 2.0}, {"10", 10.0}}) {
    // Either way: the scene changes with the seed offset, and its curvature with it (measured
    // at offsets 0-40: some scenes curved in every draw at 0.5 px, some linear in half the
    // draws at 10 px; the deviation grows as sigma^2).
    const NoisyExpectation expectation;
    cases.push_back(FittedNoisy(std::string("Noise") + id + "px", "noise " + Sci(sigma) + " px",
                                [] { return FromSynth(Synth(27, 50, 60.0)); }, sigma, 27,
                                expectation));
  }

  // Outliers with RANSAC: 80 points, 0.5 px noise.
  for (const auto& [id, fraction] :
       {std::pair<const char*, double>{"10", 0.1}, {"30", 0.3}, {"50", 0.5}}) {
    cases.push_back(FittedNoisy(
        std::string("Outliers") + id + "Percent",
        "RANSAC, " + std::string(id) + " % outliers (>= 20 px off), 0.5 px noise",
        [fraction = fraction] { return Outliers(fraction, 28); }, 0.5, 28, NoisyExpectation{}));
  }

  // Points behind the camera; the camera inside the cloud; a mirrored world.
  cases.push_back(Refused("HalfThePointsBehind", "half the points reflected behind the camera",
                          [] {
                            Scenario s = FromSynth(Synth(29, 20, 60.0));
                            for (size_t i = 0; i < s.points.size(); i += 2)
                              s.points[i] = 2.0 * s.truth.center - s.points[i];
                            return s;
                          },
                          {{Reason::kPointsBehindCamera}, {"behind"}}));
  cases.push_back(Refused("CameraInsideCloud", "camera inside the cloud (points all around)",
                          CameraInsideCloud, {{Reason::kPointsBehindCamera}, {"behind"}}));
  cases.push_back(Refused("MirroredWorld", "left-handed world (z negated)",
                          [] {
                            Scenario s = FromSynth(Synth(30, 20, 60.0));
                            for (auto& x : s.points) x.z() = -x.z();
                            return s;
                          },
                          {{Reason::kMirroredWorld}, {"left-handed"}}));

  // Look-at.
  const Eigen::Vector3d eye(5.0, -3.0, 2.0);
  auto look_at_refusal = [&](std::string id, std::string label, LookAt look_at, std::string word) {
    Case c{std::move(id), std::move(label), "refused: std::invalid_argument", nullptr};
    c.run = [look_at, word](const Case& self) { return RunLookAtRefusal(self, look_at, word); };
    cases.push_back(c);
  };
  look_at_refusal("LookAtUpAlongGaze", "look-at, up parallel to the gaze",
                  {eye, eye + Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(2, 4, 6)}, "parallel");
  look_at_refusal("LookAtUpAgainstGaze", "look-at, up antiparallel to the gaze",
                  {eye, eye + Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-1, -2, -3)}, "parallel");
  look_at_refusal("LookAtUpWithin1em7", "look-at, sin(up, gaze) = 1e-7 (< 1e-6)",
                  {eye, eye + Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1e-7, 0, 1)}, "parallel");
  look_at_refusal("LookAtEyeIsTarget", "look-at, eye == target",
                  {eye, eye, Eigen::Vector3d::UnitY()}, "eye equals target");
  look_at_refusal("LookAtUpZero", "look-at, up = 0",
                  {eye, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, "zero");
  auto look_at_pose = [&](std::string id, std::string label, double sin_up_gaze, double gaze_length,
                          Eigen::Vector3d at) {
    Case c{std::move(id), std::move(label), "right pose (rounding / sin bound)", nullptr};
    c.run = [=](const Case& self) { return RunLookAtPose(self, sin_up_gaze, gaze_length, at); };
    cases.push_back(c);
  };
  look_at_pose("LookAtUpWithin1em5", "look-at, sin(up, gaze) = 1e-5", 1e-5, 1.0, eye);
  look_at_pose("LookAtGaze1em300", "look-at, |target - eye| = 1e-300 at the origin", 1.0, 1e-300,
               Eigen::Vector3d::Zero());

  // GL export at near 1e-6 with far 1e9 and infinite, in the four depth conventions.
  const std::pair<const char*, GlDepth> conventions[] = {
      {"No", {ClipDepth::kNegativeOneToOne, false}},
      {"Zo", {ClipDepth::kZeroToOne, false}},
      {"NoReversed", {ClipDepth::kNegativeOneToOne, true}},
      {"ZoReversed", {ClipDepth::kZeroToOne, true}}};
  for (const auto& [id, depth] : conventions) {
    for (const double far : {1e9, kInfinity}) {
      const std::string name =
          std::string(depth.clip_depth == ClipDepth::kZeroToOne ? "ZO" : "NO") +
          (depth.reversed_z ? " reversed-Z" : "");
      Case c{std::string("Gl") + id + (std::isinf(far) ? "InfiniteFar" : "Far1e9"),
             "GL " + name + ", near 1e-6, far " + (std::isinf(far) ? "infinite" : "1e9"),
             "finite; pixel and depth within rounding; depth monotone", nullptr};
      c.run = [depth = depth, far](const Case& self) { return RunGl(self, depth, far); };
      cases.push_back(c);
    }
  }
  return cases;
}

class StabilityTest : public ::testing::TestWithParam<Case> {};

TEST_P(StabilityTest, RightCameraOrSpecificRefusal) {
  const Case& c = GetParam();
  Row row = c.run(c);
  row.pass = !HasFailure();
  Rows().push_back(row);
}

INSTANTIATE_TEST_SUITE_P(Cases, StabilityTest, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.id; });

}  // namespace
}  // namespace camproj

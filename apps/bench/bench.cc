// bench: error against run time per fitting method, on the same seeded synthetic scenes for
// every method, in one process. What is measured and why: docs/bench/README.md.
//
//   bench [--quick] [--out DIR] [--scenes-scale X] [--mapamok-literal-focal]
//   bench --clicks [--quick] [--out DIR] [--scenes N]     (the click benchmark: clicks.h)
//   bench --stage-cost [--n N,N,...] [--seeds K]          (the default path's cost: stage_cost.h)
//   bench --memory [--n N,N,...] [--out DIR]              (memory per point: memory.h)
//   bench --calibrate [--views N,...] [--sets K] [--out DIR] (many views vs calibrateCamera)
//
// Writes DIR/results.csv, DIR/results.json and DIR/table.md. Single-threaded (OpenCV is set to
// one thread, Ceres runs with one), so 1 / median time is fits per second per core.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <regex>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/version.hpp>

#include "camproj/camera.h"
#include "camproj/model_select.h"
#include "camproj/fit.h"
#include "camproj/synth.h"
#include "common.h"
#include "clicks.h"
#include "calibrate_bench.h"
#include "memory.h"
#include "stage_cost.h"

#ifndef CAMPROJ_CERES_VERSION
#define CAMPROJ_CERES_VERSION "unknown"
#endif
#ifndef CAMPROJ_BUILD_TYPE
#define CAMPROJ_BUILD_TYPE "unknown"
#endif

namespace camproj {
namespace bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

// An answer further than this many Cramér–Rao standard deviations from the truth is a failure.
constexpr double kFailureSigmas = 10.0;
// With noise-free pixels the bound is 0; measure "10 sigma" against this noise instead, far
// above float32 rounding of OpenCV's inputs (~1e-5 px) and far below any real error.
constexpr double kZeroNoiseFloorPx = 0.01;
// The noise-free fit that yields the bound must land on the truth; beyond this relative focal
// error it did not, and the bound for that scene is dropped (and reported).
constexpr double kCrbFitTolerance = 1e-6;
// A clamped principal-point guess moved by less than this is not reported (rounding at σ = 0).
constexpr double kNegligibleMovePx = 1e-6;

// ---------------------------------------------------------------------------------------------
// Options

struct BenchOptions {
  bool quick = false;
  std::string out_dir = "bench-results";
  double scenes_scale = 1.0;
  bool mapamok_literal_focal = false;
  std::string command;
};

const char* kUsage =
    "bench: error against run time per camera-fitting method (camproj and OpenCV 4).\n"
    "\n"
    "Usage: bench [--quick] [--out DIR] [--scenes-scale X] [--mapamok-literal-focal]\n"
    "\n"
    "Fits the same seeded synthetic scenes (camproj::SynthesizeScene: 1920x1080, fovy 45 deg;\n"
    "N in {6,10,20,30,100,1000,10000} points, noise 0, 0.5, 2 px; a point cloud and a plane; a\n"
    "centred camera and a projector with its principal point at the bottom edge) with every\n"
    "method, and writes per method and cell the median and 90th-percentile wall time per fit,\n"
    "median RMS, focal, rotation and camera-centre errors, failure rate and the ratio of the\n"
    "error to the Cramer-Rao bound. Single-threaded. See docs/bench/README.md.\n"
    "\n"
    "  --quick                  3 scenes per cell for N <= 100, 1 for N = 1000 (a smoke test)\n"
    "  --out DIR                output directory (default bench-results): results.csv,\n"
    "                           results.json, table.md\n"
    "  --scenes-scale X         multiply the number of scenes per cell by X (> 0)\n"
    "  --mapamok-literal-focal  start the 80-degree OpenCV method at mapamok's literal\n"
    "                           f = width * 80 * pi / 180 instead of the 80-degree field of view\n"
    "\n"
    "Exit codes: 0 ok; 1 usage; 2 error; 3 a camproj method failed on a noise-free scene (the\n"
    "results are still written).\n"
    "\n"
    "bench --clicks [...] runs the click benchmark of the default fitting path instead\n"
    "(bench --clicks --help); bench --stage-cost [...] what the default path costs on clean\n"
    "scenes (bench --stage-cost --help); bench --memory [...] the fit's memory per point\n"
    "(bench --memory --help); bench --calibrate [...] many-view calibration against\n"
    "cv::calibrateCamera (bench --calibrate --help).\n"
    "\n"
    "Example:\n"
    "  bench --out docs/bench        (what scripts/bench.sh runs)\n";

// The numbers of the grid.
const std::vector<int> kNumPoints = {6, 10, 20, 30, 100, 1000, 10000};
const std::vector<double> kSigmas = {0.0, 0.5, 2.0};
constexpr double kFovyDeg = 45.0;
const ImageSize kImageSize{1920, 1080};

int ScenesPerCell(int n, const BenchOptions& options) {
  int scenes = n <= 100 ? 200 : n <= 1000 ? 100 : 30;
  if (options.quick) scenes = n <= 100 ? 3 : n <= 1000 ? 1 : 0;  // < 20 s even with sanitizers
  return scenes == 0 ? 0 : std::max(1, static_cast<int>(std::lround(scenes * options.scenes_scale)));
}

// ---------------------------------------------------------------------------------------------
// Cells and methods

enum class Object { kCloud, kPlane };
enum class Lens { kCentred, kProjector };

const char* Name(Object o) { return o == Object::kCloud ? "cloud" : "plane"; }
const char* Name(Lens l) { return l == Lens::kCentred ? "centred" : "projector"; }

// Which parameter set the method estimates (and so which Cramér–Rao bound applies).
enum class Model {
  kShared,   // focal + principal point (non-planar) or focal alone, principal point fixed at the
             // truth (planar); aspect 1, no skew, no distortion; + pose
  kDefault,  // camproj fit's defaults (focal, aspect, principal point) on non-planar; kShared on
             // planar (the default refuses a plane with 3 free intrinsics)
  kPose,     // true intrinsics given, pose only
};

enum class MethodId {
  kOursStart,
  kOursRefine,
  kOursRefineCeres,
  kOursDefault,
  kOursAuto,
  kCvCalib80,
  kCvCalibOurStart,
  kCvSqpnp,
  kCvIterative,
};

struct Method {
  MethodId id;
  const char* name;
  const char* label;
  Model model;
};

const std::vector<Method> kMethods = {
    {MethodId::kOursStart, "ours-start", "camproj closed-form start only (refine = false)",
     Model::kShared},
    {MethodId::kOursRefine, "ours-refine",
     "camproj start + the own LM and polish (compute_uncertainty = false)", Model::kShared},
    {MethodId::kOursRefineCeres, "ours-refine-ceres",
     "the same with ceres::Solver for LM (FitOptions::refiner = kCeres)", Model::kShared},
    {MethodId::kOursDefault, "ours-default",
     "camproj default FitOptions (10 parameters, covariance included)", Model::kDefault},
    {MethodId::kOursAuto, "ours-auto",
     "camproj automatic model selection (what `camproj fit` runs; CRB of the shared model)",
     Model::kShared},
    {MethodId::kCvCalib80, "cv-calib-80deg",
     "OpenCV calibrateCamera from an 80 deg guess (mapamok / camSchnappr style)", Model::kShared},
    {MethodId::kCvCalibOurStart, "cv-calib-ourstart",
     "OpenCV calibrateCamera from camproj's closed-form start (time includes the start)",
     Model::kShared},
    {MethodId::kCvSqpnp, "cv-sqpnp", "OpenCV solvePnP SQPNP, true intrinsics (pose only)",
     Model::kPose},
    {MethodId::kCvIterative, "cv-iterative",
     "OpenCV solvePnP ITERATIVE, true intrinsics (pose only)", Model::kPose},
};

// One scene's inputs in every form the methods take, prepared outside the timed region.
struct SceneInput {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<std::vector<cv::Point3f>> cv_points_f;  // calibrateCamera takes float32, one view
  std::vector<std::vector<cv::Point2f>> cv_pixels_f;
  std::vector<cv::Point3d> cv_points_d;
  std::vector<cv::Point2d> cv_pixels_d;
  bool planar = false;
  Intrinsics truth;  // for the methods given the truth (fixed principal point, pose only)
};

SceneInput MakeInput(const SynthScene& scene, bool planar) {
  SceneInput in;
  in.points = scene.correspondences.points_in_world;
  in.pixels = scene.correspondences.pixels;
  in.cv_points_f.resize(1);
  in.cv_pixels_f.resize(1);
  for (size_t i = 0; i < in.points.size(); ++i) {
    const Eigen::Vector3d& x = in.points[i];
    const Eigen::Vector2d& u = in.pixels[i];
    in.cv_points_f[0].emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()),
                                   static_cast<float>(x.z()));
    in.cv_pixels_f[0].emplace_back(static_cast<float>(u.x()), static_cast<float>(u.y()));
    in.cv_points_d.emplace_back(x.x(), x.y(), x.z());
    in.cv_pixels_d.emplace_back(u.x(), u.y());
  }
  in.planar = planar;
  in.truth = scene.truth.intrinsics;
  return in;
}

FitOptions OptionsFor(Model model, const SceneInput& in) {
  FitOptions options;
  if (model == Model::kPose) {
    options.known_intrinsics = in.truth;
  } else if (model == Model::kShared || in.planar) {
    options.aspect = ParameterMode::Default();
    options.principal_point =
        in.planar ? ParameterMode::Fixed(in.truth.cx, in.truth.cy) : ParameterMode::Free();
  }
  return options;
}

struct Estimate {
  Intrinsics intrinsics;
  Rigid3 cam_from_world;
};

struct Outcome {
  bool refused = false;
  std::string error;
  std::string note;  // something the method's caller had to adapt, counted per cell
  Estimate estimate;
  double time_us = 0.0;
};

// A refusal message with its numbers replaced by '#', so equal causes count together.
std::string ErrorKind(const std::string& message) {
  static const std::regex number(R"(-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  return std::regex_replace(message, number, "#").substr(0, 100);
}

double MicrosecondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

// calibrateCamera on the one view: aspect fixed at the guess's (1), no distortion, principal
// point free unless `fix_principal_point`. Returns the estimate.
Estimate CvCalibrate(const SceneInput& in, double focal, double cx, double cy,
                     bool fix_principal_point) {
  cv::Mat k = (cv::Mat_<double>(3, 3) << focal, 0, cx, 0, focal, cy, 0, 0, 1);
  cv::Mat distortion = cv::Mat::zeros(5, 1, CV_64F);
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  int flags = cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_ASPECT_RATIO |
              cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3;
  if (fix_principal_point) flags |= cv::CALIB_FIX_PRINCIPAL_POINT;
  cv::calibrateCamera(in.cv_points_f, in.cv_pixels_f, cv::Size(kImageSize.width, kImageSize.height),
                      k, distortion, rvecs, tvecs, flags);
  return {IntrinsicsFromCv(k), RigidFromCv(rvecs.at(0), tvecs.at(0))};
}

Estimate CvSolvePnp(const SceneInput& in, int flag) {
  const cv::Mat k = (cv::Mat_<double>(3, 3) << in.truth.fx, in.truth.skew, in.truth.cx, 0,
                     in.truth.fy, in.truth.cy, 0, 0, 1);
  cv::Mat rvec;
  cv::Mat tvec;
  if (!cv::solvePnP(in.cv_points_d, in.cv_pixels_d, k, cv::noArray(), rvec, tvec, false, flag)) {
    throw std::runtime_error("solvePnP returned false");
  }
  return {in.truth, RigidFromCv(rvec, tvec)};
}

Estimate FromFit(const FitResult& fit) { return {fit.camera.intrinsics, fit.camera.cam_from_world}; }

struct MethodConfig {
  double calib80_focal = 0.0;  // the 80-degree method's starting focal length, px
};

// Runs one method on one scene; the clock covers the library calls only.
Outcome Run(const Method& method, const SceneInput& in, const MethodConfig& config) {
  Outcome outcome;
  const double centre_x = 0.5 * (kImageSize.width - 1);
  const double centre_y = 0.5 * (kImageSize.height - 1);
  FitOptions options = OptionsFor(method.model, in);
  if (method.id == MethodId::kOursStart || method.id == MethodId::kCvCalibOurStart) {
    options.refine = false;
    options.compute_uncertainty = false;
  } else if (method.id == MethodId::kOursRefine || method.id == MethodId::kOursRefineCeres) {
    options.compute_uncertainty = false;
    if (method.id == MethodId::kOursRefineCeres) options.refiner = Refiner::kCeres;
  }
  const Clock::time_point start = Clock::now();
  try {
    switch (method.id) {
      case MethodId::kOursStart:
      case MethodId::kOursRefine:
      case MethodId::kOursRefineCeres:
      case MethodId::kOursDefault:
        outcome.estimate = FromFit(FitCamera(in.points, in.pixels, kImageSize, options));
        break;
      case MethodId::kOursAuto: {
        // A plane cannot determine the principal point: given, as to every planar method.
        AutoFitOptions auto_options;
        // This benchmark measures the estimate against the Cramer-Rao bound in every cell (6
        // noise-free points included); the refusal of loosely determined cameras is the click
        // benchmark's subject (bench --clicks), so it is off here.
        auto_options.max_uncertainty_px = std::numeric_limits<double>::infinity();
        if (in.planar) auto_options.fit.principal_point = ParameterMode::Fixed(in.truth.cx, in.truth.cy);
        outcome.estimate = FromFit(FitCameraAuto(in.points, in.pixels, kImageSize, auto_options));
        break;
      }
      case MethodId::kCvCalib80:
        outcome.estimate =
            CvCalibrate(in, config.calib80_focal, in.planar ? in.truth.cx : centre_x,
                        in.planar ? in.truth.cy : centre_y, in.planar);
        break;
      case MethodId::kCvCalibOurStart: {
        const Intrinsics guess = FitCamera(in.points, in.pixels, kImageSize, options).camera.intrinsics;
        // calibrateCamera refuses a guessed principal point outside [0, W) x [0, H) ("Principal
        // point must be within the image"); a projector's lens shift puts it at or beyond the
        // edge, so move the guess to the image's outer edge (W - 0.5, H - 0.5 in OpenCV's
        // pixel convention), as a caller of OpenCV has to.
        const double cx = std::clamp(guess.cx, 0.0, kImageSize.width - 0.5);
        const double cy = std::clamp(guess.cy, 0.0, kImageSize.height - 0.5);
        if (std::abs(cx - guess.cx) + std::abs(cy - guess.cy) > kNegligibleMovePx) {
          outcome.note = "principal point guess moved onto the image edge";
        }
        outcome.estimate = CvCalibrate(in, guess.fx, cx, cy, in.planar);
        break;
      }
      case MethodId::kCvSqpnp:
        outcome.estimate = CvSolvePnp(in, cv::SOLVEPNP_SQPNP);
        break;
      case MethodId::kCvIterative:
        outcome.estimate = CvSolvePnp(in, cv::SOLVEPNP_ITERATIVE);
        break;
    }
  } catch (const std::exception& e) {
    outcome.refused = true;
    outcome.error = ErrorKind(e.what());
  }
  outcome.time_us = MicrosecondsBetween(start, Clock::now());
  return outcome;
}

// ---------------------------------------------------------------------------------------------
// Errors and the Cramér–Rao bound

// Variances at pixel noise 1 px (they scale with sigma^2): focal fx (px^2), eye position summed
// over x, y, z (world^2), rotation summed over the three axes (deg^2).
struct Bound {
  bool available = false;
  double var_focal = 0.0;
  double var_eye = 0.0;
  double var_rotation = 0.0;
};

// The bound for `model` at the true camera: camproj's covariance of a fit to the noise-free
// pixels (which lands on the truth) with pixel_sigma = 1, i.e. (J^T J)^-1 with J the Jacobian of
// all pixel residuals with respect to the model's free parameters at the truth.
Bound BoundFor(Model model, const SceneInput& noise_free, const Camera& truth, std::string* warning) {
  Bound bound;
  FitOptions options = OptionsFor(model, noise_free);
  options.pixel_sigma = 1.0;
  try {
    const FitResult fit = FitCamera(noise_free.points, noise_free.pixels, kImageSize, options);
    const double focal_error = std::abs(fit.camera.intrinsics.fx / truth.intrinsics.fx - 1.0);
    if (!fit.covariance_available || !(focal_error < kCrbFitTolerance)) {
      *warning = "noise-free fit did not land on the truth (focal error " +
                 std::to_string(focal_error) + ")";
      return bound;
    }
    for (size_t j = 0; j < fit.free_parameters.size(); ++j) {
      const std::string& name = fit.free_parameters[j];
      const double v = fit.covariance(j, j);
      if (name == "fx") bound.var_focal = v;
      if (name.rfind("eye_", 0) == 0) bound.var_eye += v;
      if (name.rfind("rotation_", 0) == 0) bound.var_rotation += v;
    }
    bound.available = true;
  } catch (const std::exception& e) {
    *warning = std::string("noise-free fit refused: ") + e.what();
  }
  return bound;
}

struct Errors {
  bool valid = false;  // every point in front of the estimated camera
  double rms_px = 0.0;
  double focal_px = 0.0;  // signed fx - true fx
  double rotation_deg = 0.0;
  double centre = 0.0;    // |C - C_true|, world
};

Errors ErrorsOf(const Estimate& estimate, const SceneInput& in, const Camera& truth) {
  Errors errors;
  if (!estimate.intrinsics.K().allFinite() || !(estimate.intrinsics.fx > 0.0) ||
      !(estimate.intrinsics.fy > 0.0) || !estimate.cam_from_world.rotation.allFinite() ||
      !estimate.cam_from_world.translation.allFinite()) {
    return errors;
  }
  double sum = 0.0;
  for (size_t i = 0; i < in.points.size(); ++i) {
    const Eigen::Vector3d p = estimate.cam_from_world * in.points[i];
    if (!(p.z() > 0.0)) return errors;
    sum += (PixelFromCam(estimate.intrinsics, p) - in.pixels[i]).squaredNorm();
  }
  errors.valid = true;
  errors.rms_px = std::sqrt(sum / static_cast<double>(in.points.size()));
  errors.focal_px = estimate.intrinsics.fx - truth.intrinsics.fx;
  const Eigen::Matrix3d delta =
      estimate.cam_from_world.rotation * truth.cam_from_world.rotation.transpose();
  errors.rotation_deg = Eigen::AngleAxisd(delta).angle() * 180.0 / kPi;
  errors.centre = (CameraCenterInWorld(estimate.cam_from_world) -
                   CameraCenterInWorld(truth.cam_from_world))
                      .norm();
  return errors;
}

// ---------------------------------------------------------------------------------------------
// Statistics per cell and method

struct Samples {
  int total = 0;
  int refused = 0;
  int outliers = 0;  // answered, but > kFailureSigmas from the truth (or points behind it)
  std::vector<double> time_us;  // every call, refusals included
  std::vector<double> rms_px, focal_pct, rotation_deg, centre_rel;  // answered calls
  // Sums over the non-failed fits for the bound ratios (squared errors and bound variances).
  int bound_count = 0;
  double sum_focal2 = 0.0, sum_var_focal = 0.0;
  double sum_eye2 = 0.0, sum_var_eye = 0.0;
  double sum_rotation2 = 0.0, sum_var_rotation = 0.0;
  std::map<std::string, int> errors;  // refusal message (truncated) -> count
  std::map<std::string, int> notes;   // Outcome::note -> count
};

struct CellKey {
  int n;
  double sigma;
  Object object;
  Lens lens;
  bool operator<(const CellKey& o) const {
    return std::tie(n, sigma, object, lens) < std::tie(o.n, o.sigma, o.object, o.lens);
  }
};

struct Row {
  CellKey cell;
  const Method* method;
  int num_params = 0;
  int scenes = 0;
  int refused = 0;
  int outliers = 0;
  double failure_rate = NAN;
  double time_median_us = NAN;
  double time_p90_us = NAN;
  double rms_median_px = NAN;
  double focal_err_median_pct = NAN;
  double rotation_err_median_deg = NAN;
  double centre_err_median_rel = NAN;
  double crb_ratio_focal = NAN;  // NaN: not applicable (sigma 0, or focal not estimated)
  double crb_ratio_eye = NAN;
  double crb_ratio_rotation = NAN;
  std::map<std::string, int> errors;
  std::map<std::string, int> notes;
};

int NumParams(Model model, bool planar) {
  if (model == Model::kPose) return 6;
  if (planar) return 7;
  return model == Model::kDefault ? 10 : 9;
}

Row Summarize(const CellKey& cell, const Method& method, const Samples& s) {
  Row row;
  row.cell = cell;
  row.method = &method;
  row.num_params = NumParams(method.model, cell.object == Object::kPlane);
  row.scenes = s.total;
  row.refused = s.refused;
  row.outliers = s.outliers;
  row.failure_rate = s.total ? static_cast<double>(s.refused + s.outliers) / s.total : NAN;
  row.time_median_us = Median(s.time_us);
  row.time_p90_us = Percentile90(s.time_us);
  row.rms_median_px = Median(s.rms_px);
  row.focal_err_median_pct = method.model == Model::kPose ? NAN : Median(s.focal_pct);
  row.rotation_err_median_deg = Median(s.rotation_deg);
  row.centre_err_median_rel = Median(s.centre_rel);
  if (cell.sigma > 0.0 && s.bound_count > 0) {
    if (method.model != Model::kPose && s.sum_var_focal > 0.0) {
      row.crb_ratio_focal = std::sqrt(s.sum_focal2 / s.sum_var_focal);
    }
    if (s.sum_var_eye > 0.0) row.crb_ratio_eye = std::sqrt(s.sum_eye2 / s.sum_var_eye);
    if (s.sum_var_rotation > 0.0) {
      row.crb_ratio_rotation = std::sqrt(s.sum_rotation2 / s.sum_var_rotation);
    }
  }
  row.errors = s.errors;
  row.notes = s.notes;
  return row;
}

// Least-squares slope of log(median time) against log N over the rows with n >= min_n.
double Slope(const std::vector<std::pair<int, double>>& points, int min_n) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (const auto& [n, t] : points) {
    if (n < min_n || !(t > 0.0)) continue;
    const double x = std::log(n);
    const double y = std::log(t);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++count;
  }
  if (count < 2) return NAN;
  const double denominator = count * sxx - sx * sx;
  return denominator > 0.0 ? (count * sxy - sx * sy) / denominator : NAN;
}

// ---------------------------------------------------------------------------------------------
// Output

std::string FormatTime(double us) {
  if (std::isnan(us)) return "-";
  if (us < 1000.0) return Format(us, "%.3g") + " µs";
  if (us < 1e6) return Format(us / 1000.0, "%.3g") + " ms";
  return Format(us / 1e6, "%.3g") + " s";
}

std::string FormatPercent(double fraction) {
  if (std::isnan(fraction)) return "-";
  return fraction == 0.0 ? "0 %" : Format(100.0 * fraction, "%.1f") + " %";
}

nlohmann::json JsonNumber(double v) { return std::isnan(v) ? nlohmann::json() : nlohmann::json(v); }

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buffer;
}

void WriteCsv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "n,sigma_px,object,camera,method,params,scenes,refused,outliers,failure_rate,"
         "time_median_us,time_p90_us,fits_per_s_per_core,rms_median_px,focal_err_median_pct,"
         "rotation_err_median_deg,centre_err_median_rel,crb_ratio_focal,crb_ratio_eye,"
         "crb_ratio_rotation\n";
  auto num = [](double v) { return std::isnan(v) ? std::string() : Format(v, "%.6g"); };
  for (const Row& r : rows) {
    out << r.cell.n << ',' << r.cell.sigma << ',' << Name(r.cell.object) << ',' << Name(r.cell.lens)
        << ',' << r.method->name << ',' << r.num_params << ',' << r.scenes << ',' << r.refused << ','
        << r.outliers << ',' << num(r.failure_rate) << ',' << num(r.time_median_us) << ','
        << num(r.time_p90_us) << ',' << num(1e6 / r.time_median_us) << ','
        << num(r.rms_median_px) << ',' << num(r.focal_err_median_pct) << ','
        << num(r.rotation_err_median_deg) << ',' << num(r.centre_err_median_rel) << ','
        << num(r.crb_ratio_focal) << ',' << num(r.crb_ratio_eye) << ','
        << num(r.crb_ratio_rotation) << '\n';
  }
}

struct SlopeRow {
  const Method* method;
  Object object;
  Lens lens;
  double sigma;
  double slope_100;   // N >= 100
  double slope_1000;  // N >= 1000
};

std::vector<SlopeRow> Slopes(const std::vector<Row>& rows) {
  std::vector<SlopeRow> slopes;
  for (const Method& method : kMethods) {
    for (Object object : {Object::kCloud, Object::kPlane}) {
      for (Lens lens : {Lens::kCentred, Lens::kProjector}) {
        for (double sigma : kSigmas) {
          std::vector<std::pair<int, double>> points;
          for (const Row& r : rows) {
            if (r.method == &method && r.cell.object == object && r.cell.lens == lens &&
                r.cell.sigma == sigma) {
              points.emplace_back(r.cell.n, r.time_median_us);
            }
          }
          if (points.empty()) continue;
          slopes.push_back({&method, object, lens, sigma, Slope(points, 100), Slope(points, 1000)});
        }
      }
    }
  }
  return slopes;
}

void WriteJson(const std::string& path, const std::vector<Row>& rows,
               const std::vector<SlopeRow>& slopes, const BenchOptions& options,
               const MethodConfig& config, double total_seconds,
               const std::map<std::string, int>& bound_warnings) {
  nlohmann::json json;
  json["meta"] = {
      {"command", options.command},
      {"date_utc", UtcNow()},
      {"quick", options.quick},
      {"scenes_scale", options.scenes_scale},
      {"opencv_version", CV_VERSION},
      {"ceres_version", CAMPROJ_CERES_VERSION},
      {"compiler", __VERSION__},
      {"build_type", CAMPROJ_BUILD_TYPE},
      {"threads", 1},
      {"image_size", {kImageSize.width, kImageSize.height}},
      {"fovy_deg", kFovyDeg},
      {"calib80_start_focal_px", config.calib80_focal},
      {"failure_sigmas", kFailureSigmas},
      {"zero_noise_floor_px", kZeroNoiseFloorPx},
      {"total_seconds", total_seconds},
  };
  nlohmann::json methods = nlohmann::json::array();
  for (const Method& m : kMethods) methods.push_back({{"name", m.name}, {"label", m.label}});
  json["methods"] = methods;
  nlohmann::json cells = nlohmann::json::array();
  for (const Row& r : rows) {
    nlohmann::json errors = nlohmann::json::object();
    for (const auto& [message, count] : r.errors) errors[message] = count;
    nlohmann::json notes = nlohmann::json::object();
    for (const auto& [message, count] : r.notes) notes[message] = count;
    cells.push_back({
        {"n", r.cell.n},
        {"sigma_px", r.cell.sigma},
        {"object", Name(r.cell.object)},
        {"camera", Name(r.cell.lens)},
        {"method", r.method->name},
        {"params", r.num_params},
        {"scenes", r.scenes},
        {"refused", r.refused},
        {"outliers", r.outliers},
        {"failure_rate", JsonNumber(r.failure_rate)},
        {"time_median_us", JsonNumber(r.time_median_us)},
        {"time_p90_us", JsonNumber(r.time_p90_us)},
        {"fits_per_s_per_core", JsonNumber(1e6 / r.time_median_us)},
        {"rms_median_px", JsonNumber(r.rms_median_px)},
        {"focal_err_median_pct", JsonNumber(r.focal_err_median_pct)},
        {"rotation_err_median_deg", JsonNumber(r.rotation_err_median_deg)},
        {"centre_err_median_rel", JsonNumber(r.centre_err_median_rel)},
        {"crb_ratio_focal", JsonNumber(r.crb_ratio_focal)},
        {"crb_ratio_eye", JsonNumber(r.crb_ratio_eye)},
        {"crb_ratio_rotation", JsonNumber(r.crb_ratio_rotation)},
        {"errors", errors},
        {"notes", notes},
    });
  }
  json["cells"] = cells;
  nlohmann::json slope_json = nlohmann::json::array();
  for (const SlopeRow& s : slopes) {
    slope_json.push_back({{"method", s.method->name},
                          {"object", Name(s.object)},
                          {"camera", Name(s.lens)},
                          {"sigma_px", s.sigma},
                          {"slope_n_ge_100", JsonNumber(s.slope_100)},
                          {"slope_n_ge_1000", JsonNumber(s.slope_1000)}});
  }
  json["time_slopes"] = slope_json;
  nlohmann::json warnings = nlohmann::json::object();
  for (const auto& [message, count] : bound_warnings) warnings[message] = count;
  json["bound_warnings"] = warnings;
  std::ofstream(path) << json.dump(1) << '\n';
}

const Row* Find(const std::vector<Row>& rows, const CellKey& cell, MethodId id) {
  for (const Row& r : rows) {
    if (r.method->id == id && r.cell.n == cell.n && r.cell.sigma == cell.sigma &&
        r.cell.object == cell.object && r.cell.lens == cell.lens) {
      return &r;
    }
  }
  return nullptr;
}

void WriteTableRow(std::ostream& out, const Row& r, bool with_cell, const Row* calib80) {
  if (with_cell) out << "| " << r.cell.n << " | " << Format(r.cell.sigma, "%g") << " ";
  out << "| " << r.method->name << " | " << FormatTime(r.time_median_us) << " | "
      << FormatTime(r.time_p90_us) << " | " << Format(1e6 / r.time_median_us, "%.0f") << " | "
      << Format(r.rms_median_px) << " | " << Format(r.focal_err_median_pct) << " | "
      << Format(r.rotation_err_median_deg) << " | " << Format(r.centre_err_median_rel) << " | "
      << FormatPercent(r.failure_rate) << " | " << Format(r.crb_ratio_focal, "%.2f") << " | "
      << Format(r.crb_ratio_eye, "%.2f") << " |";
  if (calib80 != nullptr) out << ' ' << Format(calib80->time_median_us / r.time_median_us, "%.2f") << " |";
  out << '\n';
}

const char* kColumns =
    "| method | median time | p90 time | fits/s/core | median RMS (px) | focal err (%) | "
    "rotation err (°) | centre err (rel.) | failures | CRB ratio f | CRB ratio eye |";

void WriteTable(const std::string& path, const std::vector<Row>& rows,
                const std::vector<SlopeRow>& slopes, const BenchOptions& options,
                const MethodConfig& config, double total_seconds) {
  std::ofstream out(path);
  out << "# camproj benchmark: error against run time\n\n"
      << "Generated by `apps/bench` (" << options.command << ") on " << UtcNow() << " in "
      << Format(total_seconds, "%.0f")
      << " s; the machine and the exact command are in machine.md, the method and model choices "
         "in README.md. Do not edit by hand: rerun `bash scripts/bench.sh`.\n\n"
      << "Times are wall time per fit call on one core (fits/s/core = 1 / median time). Errors "
         "are medians over the answered fits: focal |f̂/f − 1|, rotation angle of R̂ Rᵀ, camera "
         "centre |Ĉ − C| / |C − scene centre|. Failures: refused (exception) or answered more "
         "than "
      << Format(kFailureSigmas, "%g")
      << " Cramér–Rao standard deviations from the truth (focal, eye or rotation). CRB ratio: "
         "sqrt(mean squared error) / sqrt(mean CRB variance) over the non-failed fits, in the "
         "method's own parameterization (1 = efficient; '-' at σ = 0 and for the focal length "
         "of the pose-only methods). The 80° method starts at f = "
      << Format(config.calib80_focal, "%.1f") << " px.\n\n";

  out << "## Headline: σ = 0.5 px, non-planar points, projector (principal point at the bottom "
         "edge)\n\n"
      << "Last column: the median time of OpenCV's calibrateCamera from an 80° guess (how mapamok "
         "and camSchnappr fit projectors) divided by this method's.\n\n";
  for (int n : {100, 1000}) {
    const CellKey cell{n, 0.5, Object::kCloud, Lens::kProjector};
    const Row* calib80 = Find(rows, cell, MethodId::kCvCalib80);
    if (calib80 == nullptr) continue;
    out << "### N = " << n << " (" << calib80->scenes << " scenes)\n\n"
        << kColumns << " 80° calib time ÷ this |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const Method& m : kMethods) {
      if (const Row* r = Find(rows, cell, m.id)) WriteTableRow(out, *r, false, calib80);
    }
    out << '\n';
  }

  out << "## Scaling: slope of log(median time) against log N\n\n"
      << "Least-squares slope over N ∈ {100, 1000, 10000}, and in brackets from N = 1000 to "
         "10000 alone (closer to the asymptote: the fixed cost per fit weighs less); 1 = linear "
         "in the number of points.\n\n"
      << "| method |";
  std::vector<std::pair<Object, Lens>> configs = {{Object::kCloud, Lens::kCentred},
                                                  {Object::kCloud, Lens::kProjector},
                                                  {Object::kPlane, Lens::kCentred},
                                                  {Object::kPlane, Lens::kProjector}};
  for (const auto& [object, lens] : configs) out << ' ' << Name(object) << ", " << Name(lens) << " |";
  out << "\n|---|---:|---:|---:|---:|\n";
  for (const Method& m : kMethods) {
    out << "| " << m.name << " |";
    for (const auto& [object, lens] : configs) {
      std::string cell = "-";
      for (const SlopeRow& s : slopes) {
        if (s.method == &m && s.object == object && s.lens == lens && s.sigma == 0.5) {
          cell = Format(s.slope_100, "%.2f") + " (" + Format(s.slope_1000, "%.2f") + ")";
        }
      }
      out << ' ' << cell << " |";
    }
    out << '\n';
  }
  out << "\nσ = 0.5 px; the other noise levels are in results.json (`time_slopes`).\n\n";

  out << "## Methods\n\n| method | what | parameters (non-planar / planar) |\n|---|---|---|\n";
  for (const Method& m : kMethods) {
    out << "| " << m.name << " | " << m.label << " | " << NumParams(m.model, false) << " / "
        << NumParams(m.model, true) << " |\n";
  }
  out << '\n';

  out << "## All cells\n\n";
  for (Object object : {Object::kCloud, Object::kPlane}) {
    for (Lens lens : {Lens::kCentred, Lens::kProjector}) {
      out << "### " << (object == Object::kCloud ? "Non-planar (cloud)" : "Planar") << ", "
          << (lens == Lens::kCentred ? "centred camera" : "projector (principal point at the bottom edge)")
          << "\n\n| N | σ (px) " << kColumns << "\n"
          << "|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
      for (const Row& r : rows) {
        if (r.cell.object == object && r.cell.lens == lens) WriteTableRow(out, r, true, nullptr);
      }
      out << '\n';
    }
  }

  bool any_note = false;
  for (const Row& r : rows) any_note = any_note || !r.notes.empty();
  if (any_note) {
    out << "## Adapted inputs\n\n| N | σ | object | camera | method | count | what |\n"
           "|---:|---:|---|---|---|---:|---|\n";
    for (const Row& r : rows) {
      for (const auto& [message, count] : r.notes) {
        out << "| " << r.cell.n << " | " << Format(r.cell.sigma, "%g") << " | "
            << Name(r.cell.object) << " | " << Name(r.cell.lens) << " | " << r.method->name
            << " | " << count << " of " << r.scenes << " | " << message << " |\n";
      }
    }
    out << '\n';
  }

  bool any_error = false;
  for (const Row& r : rows) any_error = any_error || !r.errors.empty();
  if (any_error) {
    out << "## Refusals, exceptions and invalid answers\n\nNumbers in the messages are replaced "
           "by '#'.\n\n| N | σ | object | camera | method | count | message (first 100 "
           "characters) |\n|---:|---:|---|---|---|---:|---|\n";
    for (const Row& r : rows) {
      for (const auto& [message, count] : r.errors) {
        std::string text = message;
        std::replace(text.begin(), text.end(), '|', '/');
        std::replace(text.begin(), text.end(), '\n', ' ');
        out << "| " << r.cell.n << " | " << Format(r.cell.sigma, "%g") << " | "
            << Name(r.cell.object) << " | " << Name(r.cell.lens) << " | " << r.method->name
            << " | " << count << " | " << text << " |\n";
      }
    }
    out << '\n';
  }
}

// ---------------------------------------------------------------------------------------------

// One method's outcome on a scene, added to its cell's samples: the time, a refusal, or the
// errors and, within kFailureSigmas of `bound` (where available), their share of the bound.
void Accumulate(const Outcome& outcome, const Method& method, const SceneInput& in,
                const Camera& truth, double distance, double sigma, const Bound& bound,
                Samples* s) {
  ++s->total;
  s->time_us.push_back(outcome.time_us);
  if (!outcome.note.empty()) ++s->notes[outcome.note];
  if (outcome.refused) {
    ++s->refused;
    ++s->errors[outcome.error];
    return;
  }
  const Errors e = ErrorsOf(outcome.estimate, in, truth);
  if (!e.valid) {
    ++s->outliers;
    ++s->errors["answer has points behind the camera or non-finite values"];
    return;
  }
  s->rms_px.push_back(e.rms_px);
  s->focal_pct.push_back(100.0 * std::abs(e.focal_px) / truth.intrinsics.fx);
  s->rotation_deg.push_back(e.rotation_deg);
  s->centre_rel.push_back(e.centre / distance);
  if (!bound.available) return;
  const double sigma_for_failure = std::max(sigma, kZeroNoiseFloorPx);
  const double limit2 = kFailureSigmas * kFailureSigmas * sigma_for_failure * sigma_for_failure;
  const bool focal_out =
      method.model != Model::kPose && e.focal_px * e.focal_px > limit2 * bound.var_focal;
  const bool eye_out = e.centre * e.centre > limit2 * bound.var_eye;
  const bool rotation_out = e.rotation_deg * e.rotation_deg > limit2 * bound.var_rotation;
  if (focal_out || eye_out || rotation_out) {
    ++s->outliers;
    return;
  }
  ++s->bound_count;
  const double sigma2 = sigma * sigma;
  s->sum_focal2 += e.focal_px * e.focal_px;
  s->sum_var_focal += sigma2 * bound.var_focal;
  s->sum_eye2 += e.centre * e.centre;
  s->sum_var_eye += sigma2 * bound.var_eye;
  s->sum_rotation2 += e.rotation_deg * e.rotation_deg;
  s->sum_var_rotation += sigma2 * bound.var_rotation;
}

using SampleMap = std::map<std::pair<CellKey, int>, Samples>;  // (cell, method index)

// Scene `index` of N = n points, `object` and `lens` at every noise level, every method: its
// outcomes into `samples`, a Cramér–Rao bound that could not be computed into `bound_warnings`.
void MeasureScene(int n, Object object, Lens lens, int index, const MethodConfig& config,
                  SampleMap* samples, std::map<std::string, int>* bound_warnings) {
  SynthOptions synth;
  synth.seed = static_cast<uint64_t>(index) + 1;
  synth.num_points = n;
  synth.object = object == Object::kCloud ? SynthObject::kCloud : SynthObject::kPlane;
  synth.image_size = kImageSize;
  synth.fovy_deg = kFovyDeg;
  synth.principal_point_offset =
      lens == Lens::kCentred ? Eigen::Vector2d(0, 0) : Eigen::Vector2d(0, 0.5);
  const bool planar = object == Object::kPlane;
  // The noise is drawn after the geometry: the same seed gives the same points and camera at
  // every noise level, and noise 0 gives the true pixels.
  synth.noise_px = 0.0;
  const SynthScene truth_scene = SynthesizeScene(synth);
  const Camera& truth = truth_scene.truth;
  const SceneInput noise_free = MakeInput(truth_scene, planar);
  std::map<Model, Bound> bounds;
  for (Model model : {Model::kShared, Model::kDefault, Model::kPose}) {
    std::string warning;
    bounds[model] = BoundFor(model, noise_free, truth, &warning);
    if (!warning.empty()) ++(*bound_warnings)[ErrorKind(warning)];
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& x : noise_free.points) centroid += x;
  centroid /= static_cast<double>(n);
  const double distance = (CameraCenterInWorld(truth.cam_from_world) - centroid).norm();

  for (double sigma : kSigmas) {
    synth.noise_px = sigma;
    const SynthScene scene = SynthesizeScene(synth);
    const SceneInput in = MakeInput(scene, planar);
    const CellKey cell{n, sigma, object, lens};
    for (size_t m = 0; m < kMethods.size(); ++m) {
      const Method& method = kMethods[m];
      Accumulate(Run(method, in, config), method, in, truth, distance, sigma,
                 bounds[method.model], &(*samples)[{cell, static_cast<int>(m)}]);
    }
  }
}

// The self-check that makes --quick a smoke test: on noise-free pixels camproj must answer every
// scene at the truth. OpenCV's failures are results, not errors (calibrateCamera from the 80
// degree guess can settle in a local minimum even without noise). The number of rows that fail.
int NoiseFreeFailures(const std::vector<Row>& rows) {
  int broken = 0;
  for (const Row& r : rows) {
    const bool ours = std::string(r.method->name).rfind("ours-", 0) == 0;
    if (ours && r.cell.sigma == 0.0 && r.refused + r.outliers > 0) {
      std::cerr << "bench: check failed: " << r.method->name << " failed " << r.refused + r.outliers
                << " of " << r.scenes << " noise-free scenes (N = " << r.cell.n << ", "
                << Name(r.cell.object) << ", " << Name(r.cell.lens) << ")\n";
      ++broken;
    }
  }
  return broken;
}

int Main(const BenchOptions& options) {
  cv::setNumThreads(1);
  std::filesystem::create_directories(options.out_dir);
  MethodConfig config;
  config.calib80_focal = options.mapamok_literal_focal
                             ? kImageSize.width * 80.0 * kPi / 180.0
                             : 0.5 * kImageSize.width / std::tan(0.5 * 80.0 * kPi / 180.0);
#ifndef NDEBUG
  std::cerr << "bench: warning: assertions are on (not a Release build); times are not "
               "representative\n";
#endif
  const Clock::time_point begin = Clock::now();

  // Warm-up: every method once, untimed (page faults, lazy initialization, caches).
  {
    SynthOptions synth;
    synth.seed = 12345;
    synth.num_points = 100;
    synth.noise_px = 0.5;
    synth.fovy_deg = kFovyDeg;
    const SceneInput in = MakeInput(SynthesizeScene(synth), false);
    for (const Method& m : kMethods) Run(m, in, config);
  }

  SampleMap samples;
  std::map<std::string, int> bound_warnings;
  for (int n : kNumPoints) {
    const int scenes = ScenesPerCell(n, options);
    if (scenes == 0) continue;
    const Clock::time_point n_begin = Clock::now();
    for (Object object : {Object::kCloud, Object::kPlane}) {
      for (Lens lens : {Lens::kCentred, Lens::kProjector}) {
        for (int index = 0; index < scenes; ++index) {
          MeasureScene(n, object, lens, index, config, &samples, &bound_warnings);
        }
      }
    }
    std::cerr << "bench: N = " << n << ": " << scenes << " scenes per cell, "
              << Format(MicrosecondsBetween(n_begin, Clock::now()) / 1e6, "%.1f") << " s\n";
  }

  std::vector<Row> rows;
  for (const auto& [key, s] : samples) rows.push_back(Summarize(key.first, kMethods[key.second], s));
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    const auto ka = std::make_tuple(a.cell.object, a.cell.lens, a.cell.n, a.cell.sigma, a.method->id);
    const auto kb = std::make_tuple(b.cell.object, b.cell.lens, b.cell.n, b.cell.sigma, b.method->id);
    return ka < kb;
  });
  const std::vector<SlopeRow> slopes = Slopes(rows);
  const double total_seconds = MicrosecondsBetween(begin, Clock::now()) / 1e6;
  const std::filesystem::path dir(options.out_dir);
  WriteCsv((dir / "results.csv").string(), rows);
  WriteJson((dir / "results.json").string(), rows, slopes, options, config, total_seconds,
            bound_warnings);
  WriteTable((dir / "table.md").string(), rows, slopes, options, config, total_seconds);
  for (const auto& [message, count] : bound_warnings) {
    std::cerr << "bench: warning: Cramér–Rao bound unavailable for " << count
              << " scene(s): " << message << '\n';
  }
  std::cerr << "bench: " << rows.size() << " rows in " << Format(total_seconds, "%.1f")
            << " s -> " << options.out_dir << "/{results.csv,results.json,table.md}\n";
  return NoiseFreeFailures(rows) == 0 ? 0 : 3;
}

}  // namespace
}  // namespace bench
}  // namespace camproj

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--clicks") return camproj::bench::ClicksMain(argc, argv);
    if (std::string(argv[i]) == "--stage-cost") return camproj::bench::StageCostMain(argc, argv);
    if (std::string(argv[i]) == "--memory") return camproj::bench::MemoryMain(argc, argv);
    if (std::string(argv[i]) == "--calibrate") return camproj::bench::CalibrateMain(argc, argv);
  }
  camproj::bench::BenchOptions options;
  options.command = "bench";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    options.command += " " + arg;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench: " << arg << " needs a value\n" << camproj::bench::kUsage;
        std::exit(1);
      }
      options.command += std::string(" ") + argv[i + 1];
      return argv[++i];
    };
    if (arg == "-h" || arg == "--help") {
      std::cout << camproj::bench::kUsage;
      return 0;
    } else if (arg == "--quick") {
      options.quick = true;
    } else if (arg == "--out") {
      options.out_dir = value();
    } else if (arg == "--scenes-scale") {
      const std::string text = value();
      char* end = nullptr;
      options.scenes_scale = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !(options.scenes_scale > 0.0)) {
        std::cerr << "bench: --scenes-scale must be a positive number, got \"" << text << "\"\n";
        return 1;
      }
    } else if (arg == "--mapamok-literal-focal") {
      options.mapamok_literal_focal = true;
    } else {
      std::cerr << "bench: unknown argument \"" << arg << "\"\n" << camproj::bench::kUsage;
      return 1;
    }
  }
  try {
    return camproj::bench::Main(options);
  } catch (const std::exception& e) {
    std::cerr << "bench: error: " << e.what() << '\n';
    return 2;
  }
}

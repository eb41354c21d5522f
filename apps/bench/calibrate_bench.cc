// bench --calibrate (calibrate_bench.h).
#include "calibrate_bench.h"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camproj/calibrate.h"
#include "camproj/synth.h"
#include "common.h"

namespace camproj {
namespace bench {
namespace {

const char* kUsage =
    "bench --calibrate: Calibrate against cv::calibrateCamera on the same board sets.\n"
    "\n"
    "Usage: bench --calibrate [--views N,N,...] [--sets K] [--out DIR]\n"
    "\n"
    "  --views N,...  views per set (default 5,13,50), each 54 corners of a 9 x 6 board\n"
    "  --sets K       sets per view count (default 20; seeds 1..K)\n"
    "  --out DIR      also write DIR/calibrate.md\n"
    "\n"
    "Example:\n"
    "  bench --calibrate --out docs/bench\n";

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

Intrinsics TrueCamera() {
  Intrinsics k;
  k.fx = 820.0;
  k.fy = 826.0;
  k.cx = 331.5;
  k.cy = 247.0;
  k.k1 = -0.21;
  k.k2 = 0.07;
  return k;
}

struct Row {
  std::vector<double> ours_s, ours_full_s, opencv_s, ours_rms, opencv_rms, ours_focal_error,
      opencv_focal_error, apart_sigmas, ours_iterations;
  int opencv_failed = 0;
};

struct CalibrateBenchArgs {
  std::vector<int> view_counts = {5, 13, 50};
  int sets = 20;
  std::string out_dir;
  std::string command = "bench --calibrate";
};

// The arguments, or the exit code when there is nothing to run (--help: 0, an error: 1, said on
// the stream).
std::optional<int> ParseArgs(int argc, char** argv, CalibrateBenchArgs* args) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench: " << arg << " needs a value\n" << kUsage;
        std::exit(1);
      }
      args->command += " " + arg + " " + argv[i + 1];
      return argv[++i];
    };
    if (arg == "--calibrate") continue;
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (arg == "--views") {
      args->view_counts.clear();
      std::stringstream list(value());
      std::string item;
      while (std::getline(list, item, ',')) {
        const int n = std::atoi(item.c_str());
        if (n < 3) {
          std::cerr << "bench: --views takes counts >= 3, got \"" << item << "\"\n";
          return 1;
        }
        args->view_counts.push_back(n);
      }
    } else if (arg == "--sets") {
      args->sets = std::atoi(value().c_str());
      if (args->sets < 1) {
        std::cerr << "bench: --sets must be >= 1\n";
        return 1;
      }
    } else if (arg == "--out") {
      args->out_dir = value();
    } else {
      std::cerr << "bench: unknown argument " << arg << "\n" << kUsage;
      return 1;
    }
  }
  return std::nullopt;
}

// Set `set` of `num_views` views: ours (without, then with the covariance and cross-validation)
// and cv::calibrateCamera, timed and compared, into `row`.
void MeasureSet(int num_views, int set, const Intrinsics& truth, Row* row) {
  CalibrationSynthOptions synth;
  synth.seed = static_cast<uint64_t>(set);
  synth.num_views = num_views;
  synth.noise_px = 0.5;
  synth.intrinsics = truth;
  const std::vector<CalibrationView> views = SynthesizeCalibrationViews(synth);

  CalibrateOptions options;
  options.image_size = synth.image_size;
  options.compute_uncertainty = false;
  options.cross_validate = false;
  auto start = Clock::now();
  const Calibration ours = Calibrate(views, options);
  row->ours_s.push_back(Seconds(start));
  row->ours_iterations.push_back(ours.iterations);
  options.compute_uncertainty = true;
  options.cross_validate = true;
  start = Clock::now();
  const Calibration full = Calibrate(views, options);
  row->ours_full_s.push_back(Seconds(start));

  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (const auto& view : views) {
    object_points.emplace_back();
    image_points.emplace_back();
    for (const auto& p : view.points_in_world) object_points.back().emplace_back(p.x(), p.y(), p.z());
    for (const auto& p : view.pixels) image_points.back().emplace_back(p.x(), p.y());
  }
  cv::Mat k, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  double cv_rms = NAN;
  start = Clock::now();
  try {
    cv_rms = cv::calibrateCamera(object_points, image_points,
                                 cv::Size(synth.image_size.width, synth.image_size.height), k,
                                 distortion, rvecs, tvecs,
                                 cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3);
  } catch (const cv::Exception&) {
    ++row->opencv_failed;
    return;
  }
  row->opencv_s.push_back(Seconds(start));
  row->ours_rms.push_back(ours.rms_px);
  row->opencv_rms.push_back(cv_rms);
  row->ours_focal_error.push_back(100.0 * std::abs(ours.intrinsics.fx / truth.fx - 1.0));
  row->opencv_focal_error.push_back(100.0 * std::abs(k.at<double>(0, 0) / truth.fx - 1.0));
  const double theirs[] = {k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2),
                           k.at<double>(1, 2), distortion.at<double>(0), distortion.at<double>(1)};
  double apart = 0.0;
  for (int i = 0; i < 6 && i < static_cast<int>(full.intrinsics_sigma.size()); ++i) {
    const ParameterSigma& p = full.intrinsics_sigma[i];
    apart = std::max(apart, std::abs(p.value - theirs[i]) / p.sigma);
  }
  row->apart_sigmas.push_back(apart);
}

// The table's row for `num_views` views over `sets` sets.
std::string TableRow(int num_views, int sets, const Row& row) {
  const double ours_t = Median(row.ours_s), cv_t = Median(row.opencv_s);
  std::ostringstream out;
  out << "| " << num_views << " | " << sets << " | " << Format(1e3 * ours_t, "%.3g") << " ms | "
      << Format(1e3 * Median(row.ours_full_s), "%.3g") << " ms | " << Format(1e3 * cv_t, "%.3g")
      << " ms" << (row.opencv_failed ? " (" + std::to_string(row.opencv_failed) + " failed)" : "")
      << " | " << Format(cv_t / ours_t, "%.1f") << " | "
      << Format(Median(row.ours_iterations), "%.0f") << " | " << Format(Median(row.ours_rms), "%.4f")
      << " / " << Format(Median(row.opencv_rms), "%.4f") << " | "
      << Format(Median(row.ours_focal_error), "%.3f") << " / "
      << Format(Median(row.opencv_focal_error), "%.3f") << " | "
      << Format(*std::max_element(row.apart_sigmas.begin(), row.apart_sigmas.end()), "%.2g")
      << " |\n";
  return out.str();
}

// calibrate.md: the command, the machine's state, the method and the table.
std::string ReportText(const std::string& command, const std::string& table) {
  std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  std::ostringstream report;
  report << "# Calibration from many views against cv::calibrateCamera\n\n"
         << "Generated by `" << command << "` (apps/bench/calibrate_bench.cc). Do not edit by hand.\n\n"
         << "| | |\n|---|---|\n"
         << "| command | `" << command << "` |\n"
         << "| git | " << GitDescription() << " |\n"
         << "| date | " << date << " |\n"
         << "| load average | " << LoadAverage() << " at the end (1, 5, 15 min) |\n\n"
         << "Sets: `SynthesizeCalibrationViews` (9 x 6 board, 640 x 480, fx 820, fy 826, cx 331.5, "
            "cy 247, k1 -0.21, k2 0.07, sigma 0.5 px), seeds 1..K. Both fit fx, fy, cx, cy, k1, k2 "
            "(OpenCV: CALIB_ZERO_TANGENT_DIST | CALIB_FIX_K3, its default termination: 30 "
            "iterations or a relative change below DBL_EPSILON). Wall time per calibration, one "
            "thread; \"ours\" is `Calibrate` without the covariance and the cross-validation, the "
            "next column with both (the default of `camproj calibrate`). Optima apart: the largest "
            "|ours - OpenCV| over the six intrinsics in units of our sigma, over the sets.\n\n"
         << table;
  return report.str();
}

}  // namespace

int CalibrateMain(int argc, char** argv) {
  CalibrateBenchArgs args;
  if (const std::optional<int> code = ParseArgs(argc, argv, &args)) return *code;
#ifndef NDEBUG
  std::cerr << "bench --calibrate: warning: assertions are on (not a Release build)\n";
#endif
  const Intrinsics truth = TrueCamera();
  std::string table =
      "| views | sets | ours: calibrate (median) | ours: + covariance + cross-validation | "
      "cv::calibrateCamera | OpenCV ÷ ours | iterations (ours, median) | RMS px (ours / OpenCV) | "
      "fx error % (ours / OpenCV) | optima apart (max over fx..k2, in our sigmas) |\n"
      "|---:|---:|---:|---:|---:|---:|---:|---|---|---:|\n";
  for (const int num_views : args.view_counts) {
    Row row;
    for (int set = 1; set <= args.sets; ++set) MeasureSet(num_views, set, truth, &row);
    table += TableRow(num_views, args.sets, row);
    std::cout << "views " << num_views << ": done\n";
  }
  const std::string report = ReportText(args.command, table);
  std::cout << report;
  if (!args.out_dir.empty()) {
    std::filesystem::create_directories(args.out_dir);
    std::ofstream(args.out_dir + "/calibrate.md") << report;
  }
  return 0;
}

}  // namespace bench
}  // namespace camproj

// Helpers the benchmarks (bench.cc: error against run time; clicks.cc: the default path on
// clicked scenes; memory.cc: memory per point) use: table numbers, order statistics, OpenCV's
// camera -> camproj's, and the machine's state for a report's header.
#ifndef CAMPROJ_APPS_BENCH_COMMON_H_
#define CAMPROJ_APPS_BENCH_COMMON_H_

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "camproj/intrinsics.h"
#include "camproj/pose.h"

namespace camproj {
namespace bench {

// A number in a table: printf `format`, "-" for NaN (no value), "inf" / "-inf" as printf writes
// them.
inline std::string Format(double v, const char* format = "%.3g") {
  if (std::isnan(v)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

// NaN for no values.
inline double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t mid = v.size() / 2;
  return v.size() % 2 ? v[mid] : 0.5 * (v[mid - 1] + v[mid]);
}

// Nearest-rank 90th percentile; NaN for no values.
inline double Percentile90(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(0.9 * static_cast<double>(v.size())));
  return v[std::max<size_t>(rank, 1) - 1];
}

// cam_from_world from OpenCV's rvec (Rodrigues) and tvec.
inline Rigid3 RigidFromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Rigid3 rigid;
  for (int i = 0; i < 3; ++i) {
    rigid.translation(i) = tvec.at<double>(i);
    for (int j = 0; j < 3; ++j) rigid.rotation(i, j) = r.at<double>(i, j);
  }
  return rigid;
}

// Intrinsics (kCenter, OpenCV's convention) from OpenCV's 3 x 3 camera matrix.
inline Intrinsics IntrinsicsFromCv(const cv::Mat& k) {
  Intrinsics intrinsics;
  intrinsics.fx = k.at<double>(0, 0);
  intrinsics.fy = k.at<double>(1, 1);
  intrinsics.cx = k.at<double>(0, 2);
  intrinsics.cy = k.at<double>(1, 2);
  intrinsics.skew = k.at<double>(0, 1);
  return intrinsics;
}

// First line of a shell command's output, "" on failure.
inline std::string ShellLine(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return "";
  char buffer[256];
  std::string line;
  if (std::fgets(buffer, sizeof buffer, pipe) != nullptr) line = buffer;
  pclose(pipe);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  return line;
}

// "1.23 0.98 0.50" from /proc/loadavg, "unknown" elsewhere.
inline std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(in >> one >> five >> fifteen)) return "unknown";
  return one + " " + five + " " + fifteen;
}

// The source's commit, marked when lib/ or apps/ differ from it.
inline std::string GitDescription() {
  const std::string dir = CAMPROJ_SOURCE_DIR;
  const std::string git = "git -C '" + dir + "' ";
  std::string commit = ShellLine(git + "rev-parse --short HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  if (!ShellLine(git + "status --porcelain -- lib apps 2>/dev/null").empty()) {
    commit += " (with uncommitted changes in lib/ or apps/)";
  }
  return commit;
}

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_COMMON_H_

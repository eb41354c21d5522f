// Helpers both benchmarks (bench.cc: error against run time; clicks.cc: the default path on
// clicked scenes) use: table numbers, order statistics and OpenCV's camera -> camproj's.
#ifndef CAMPROJ_APPS_BENCH_COMMON_H_
#define CAMPROJ_APPS_BENCH_COMMON_H_

#include <algorithm>
#include <cmath>
#include <cstdio>
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

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_COMMON_H_

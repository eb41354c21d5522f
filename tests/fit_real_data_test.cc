// The fitter on real third-party correspondences (data/real/README.md): cameras nobody on this
// project made, compared with each data set's own reference at the level of its RMS.
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "camproj/fit.h"
#include "camproj/points_file.h"

namespace camproj {
namespace {

const std::string kRealData = CAMPROJ_DATA_DIR "/real";

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Bundler's model is exactly ours with square pixels, the principal point at the image centre and
// k1, k2: the same model must reach the reference RMS (within 5 %: the references were computed in
// a bundle adjustment over all cameras, ours is the best single-camera fit) and its focal length
// (within 1 %).
TEST(FitRealDataTest, BalbianelloMatchesBundlerWithItsModel) {
  const nlohmann::json cameras = ReadJson(kRealData + "/balbianello/cameras.json")["cameras"];
  for (const auto& [csv, reference] : cameras.items()) {
    const Correspondences data = ReadCorrespondencesFile(kRealData + "/balbianello/" + csv);
    const ImageSize size{reference["image_size"][0].get<int>(), reference["image_size"][1].get<int>()};
    const double reference_focal = reference["K"][0][0].get<double>();
    const double reference_rms = reference["reference_rms_px"].get<double>();
    FitOptions options;
    options.aspect = ParameterMode::Default();
    options.principal_point = ParameterMode::Default();
    options.k1 = ParameterMode::Free();
    options.k2 = ParameterMode::Free();
    const FitResult fit = FitCamera(data.points_in_world, data.pixels, size, options);
    EXPECT_LE(fit.rms_px, 1.05 * reference_rms) << csv;
    EXPECT_NEAR(fit.camera.intrinsics.fx, reference_focal, 0.01 * reference_focal) << csv;
    RecordProperty(csv + "_rms_px", std::to_string(fit.rms_px));
    RecordProperty(csv + "_reference_rms_px", std::to_string(reference_rms));
    RecordProperty(csv + "_focal_error_percent",
                   std::to_string(100.0 * (fit.camera.intrinsics.fx / reference_focal - 1.0)));

    // Without distortion a pinhole cannot reach the data. (The data's README quotes 2.5-4.2 px
    // for the reference camera with its distortion dropped; refitting focal and pose absorbs part
    // of it: 1.11-1.66 px, which OpenCV's calibrateCamera with the same model reproduces to the
    // last digit. So the check is that dropping distortion at least doubles the RMS.)
    FitOptions pinhole = options;
    pinhole.k1 = ParameterMode::Default();
    pinhole.k2 = ParameterMode::Default();
    const FitResult undistorted = FitCamera(data.points_in_world, data.pixels, size, pinhole);
    EXPECT_GE(undistorted.rms_px, 2.0 * fit.rms_px) << csv;
    RecordProperty(csv + "_pinhole_rms_px", std::to_string(undistorted.rms_px));
  }
}

// One planar view of a chessboard determines the focal length (and k1) only with the rest
// fixed: square pixels and the principal point at the image centre, 22 px from the reference's.
// That model error dominates. Bounds: focal within 6 % of the all-view reference (OpenCV's
// calibrateCamera with the same flags reaches 5.3 %), and the RMS no worse than that
// calibrateCamera's on the same view. The RMS is not bounded by 2.5x the reference's RMS on the
// view: on left05 calibrateCamera itself lands at 2.58x (0.411 px against 0.159 px), and so do we.
TEST(FitRealDataTest, ChessboardSingleViewsWithFocalAndK1) {
  const nlohmann::json document = ReadJson(kRealData + "/opencv_chessboard/cameras.json");
  int views = 0;
  double worst_focal_error = 0.0;
  double worst_rms_ratio = 0.0;
  for (const auto& [side, camera] : document["cameras"].items()) {
    const ImageSize size{camera["image_size"][0].get<int>(), camera["image_size"][1].get<int>()};
    cv::Mat k = cv::Mat::eye(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) k.at<double>(r, c) = camera["K"][r][c].get<double>();
    }
    const std::vector<double> distortion = camera["dist_k1_k2_p1_p2_k3"].get<std::vector<double>>();
    const double reference_focal = k.at<double>(0, 0);
    for (const auto& [name, view] : camera["views"].items()) {
      const Correspondences data =
          ReadCorrespondencesFile(kRealData + "/opencv_chessboard/" + view["csv"].get<std::string>());
      // The reference camera's RMS on this view, with its full Brown-Conrady model.
      std::vector<cv::Point3d> object;
      for (const auto& x : data.points_in_world) object.emplace_back(x.x(), x.y(), x.z());
      std::vector<cv::Point2d> projected;
      cv::projectPoints(object, view["rvec"].get<std::vector<double>>(), view["t"].get<std::vector<double>>(),
                        k, distortion, projected);
      double sum = 0.0;
      for (size_t i = 0; i < projected.size(); ++i) {
        sum += std::pow(projected[i].x - data.pixels[i].x(), 2) + std::pow(projected[i].y - data.pixels[i].y(), 2);
      }
      const double reference_rms = std::sqrt(sum / projected.size());

      // OpenCV with the same model on this view alone, from a neutral guess.
      std::vector<cv::Point3f> object_f;
      std::vector<cv::Point2f> image_f;
      for (size_t i = 0; i < object.size(); ++i) {
        object_f.emplace_back(object[i].x, object[i].y, object[i].z);
        image_f.emplace_back(data.pixels[i].x(), data.pixels[i].y());
      }
      cv::Mat opencv_k = (cv::Mat_<double>(3, 3) << 500, 0, 0.5 * (size.width - 1), 0, 500,
                          0.5 * (size.height - 1), 0, 0, 1);
      cv::Mat opencv_distortion = cv::Mat::zeros(5, 1, CV_64F);
      std::vector<cv::Mat> rvecs;
      std::vector<cv::Mat> tvecs;
      const double opencv_rms = cv::calibrateCamera(
          std::vector<std::vector<cv::Point3f>>{object_f}, std::vector<std::vector<cv::Point2f>>{image_f},
          cv::Size(size.width, size.height), opencv_k, opencv_distortion, rvecs, tvecs,
          cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_PRINCIPAL_POINT | cv::CALIB_FIX_ASPECT_RATIO |
              cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3);

      FitOptions options;
      options.aspect = ParameterMode::Default();
      options.principal_point = ParameterMode::Default();
      options.k1 = ParameterMode::Free();
      const FitResult fit = FitCamera(data.points_in_world, data.pixels, size, options);
      EXPECT_TRUE(fit.planar) << name;
      const double focal_error = std::abs(fit.camera.intrinsics.fx / reference_focal - 1.0);
      EXPECT_LE(focal_error, 0.06) << name << " fx " << fit.camera.intrinsics.fx;
      // Both reach the same least-squares optimum; OpenCV stops at DBL_EPSILON relative change
      // or 30 iterations, so allow it a hair of slack the other way.
      EXPECT_LE(fit.rms_px, opencv_rms * (1.0 + 1e-6)) << name << " OpenCV " << opencv_rms;
      worst_focal_error = std::max(worst_focal_error, focal_error);
      worst_rms_ratio = std::max(worst_rms_ratio, fit.rms_px / reference_rms);
      // The reported focal sigma comes from pixel noise alone (sigma estimated from these
      // residuals); it does not cover the fixed principal point's model error. Record both.
      for (const ParameterSigma& s : fit.sigmas) {
        if (s.name == "fx") {
          RecordProperty(name + "_fx_sigma_px", std::to_string(s.sigma));
          RecordProperty(name + "_fx_error_px",
                         std::to_string(fit.camera.intrinsics.fx - reference_focal));
        }
      }
      ++views;
    }
  }
  EXPECT_EQ(views, 26);
  RecordProperty("worst_focal_error_percent", std::to_string(100.0 * worst_focal_error));
  RecordProperty("worst_rms_ratio", std::to_string(worst_rms_ratio));
}

}  // namespace
}  // namespace camproj

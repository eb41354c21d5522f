#include "camproj/calibration_file.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "camproj/look_at.h"
#include "camproj/number_text.h"
#include "camproj/points_file.h"

namespace camproj {

std::string CalibrationToJsonText(const Calibration& calibration,
                                  const CameraFileOptions& options) {
  options.Check();
  const Intrinsics k =
      ConvertPixelOrigin(calibration.intrinsics, PixelOrigin::kCenter, options.pixel_origin);
  nlohmann::ordered_json file;
  file["calibration"] = "camproj calibrate: intrinsics shared by every view, a pose per view";
  file["image_size"] = {calibration.image_size.width, calibration.image_size.height};
  file["pixel_origin"] = ToString(options.pixel_origin);
  file["intrinsics"] = {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy},
                        {"skew", k.skew}, {"k1", k.k1}, {"k2", k.k2}};
  if (k.HasBeyondTwoRadial()) {
    file["intrinsics"]["p1"] = k.p1;
    file["intrinsics"]["p2"] = k.p2;
    file["intrinsics"]["k3"] = k.k3;
  }
  nlohmann::ordered_json sigma = nlohmann::ordered_json::object();
  for (const ParameterSigma& p : calibration.intrinsics_sigma) sigma[p.name] = p.sigma;
  file["sigma"] = sigma;
  if (!calibration.model_choice.empty()) {
    nlohmann::ordered_json model = nlohmann::ordered_json::object();
    for (const CalibrationModelChoice& c : calibration.model_choice) {
      model[c.group] = {{"free", c.free}, {"reason", c.reason}};
    }
    file["model"] = {{"selection", "BIC from the focal length up (docs/calibration.md)"},
                     {"sigma_px", calibration.selection_sigma_px},
                     {"sigma_given", calibration.selection_sigma_given},
                     {"groups", model}};
  }
  file["rms_px"] = calibration.rms_px;
  file["projection_sigma_px"] = {{"center", calibration.projection_sigma_center_px},
                                 {"worst_corner", calibration.projection_sigma_corner_px}};
  file["num_points"] = calibration.num_points;
  file["num_parameters"] = calibration.num_parameters;
  const CrossValidation& cv = calibration.cross_validation;
  if (cv.done) {
    file["cross_validation"] = {{"views_a", cv.views_a}, {"views_b", cv.views_b},
                                {"rms_px", cv.rms_px}, {"max_px", cv.max_px},
                                {"predicted_rms_px", cv.predicted_rms_px}};
  } else {
    file["cross_validation"] = {{"not_done", cv.why_not}};
  }
  file["solver"] = {{"iterations", calibration.iterations},
                    {"termination", calibration.termination}};
  nlohmann::ordered_json views = nlohmann::ordered_json::array();
  for (const CalibratedView& view : calibration.views) {
    views.push_back({{"name", view.name},
                     {"num_points", view.num_points},
                     {"rms_px", view.rms_px},
                     {"camera", nlohmann::ordered_json::parse(CameraToJsonText(view.camera, options))}});
  }
  file["views"] = views;
  nlohmann::ordered_json refused = nlohmann::ordered_json::array();
  for (const RefusedView& view : calibration.refused_views) {
    if (!view.reason.empty()) {
      refused.push_back({{"name", view.name}, {"num_points", view.num_points},
                         {"reason", view.reason}});
      continue;
    }
    refused.push_back({{"name", view.name}, {"num_points", view.num_points},
                       {"rms_px", view.rms_px}, {"others_rms_px", view.others_rms_px},
                       {"chi_square", view.statistic}, {"bound", view.bound}});
  }
  file["refused_views"] = refused;
  nlohmann::ordered_json outliers = nlohmann::ordered_json::array();
  for (const OutlierPoint& point : calibration.outliers) {
    outliers.push_back({{"view", point.view}, {"id", point.id},
                        {"residual_px", point.residual_px}, {"bound_px", point.bound_px}});
  }
  file["outliers"] = outliers;
  return file.dump(2) + "\n";
}

std::string CalibrationPosesCsvText(const Calibration& calibration,
                                    const CameraFileOptions& options) {
  options.Check();
  std::ostringstream out;
  out << "view,eye_x,eye_y,eye_z,target_x,target_y,target_z,up_x,up_y,up_z,"
         "r00,r01,r02,r10,r11,r12,r20,r21,r22,t_x,t_y,t_z\n";
  for (const CalibratedView& view : calibration.views) {
    const Rigid3& pose = view.camera.cam_from_world;
    const LookAt look_at = LookAtFromCamFromWorld(pose, options.target_distance);
    out << CsvField(view.name);
    for (const Eigen::Vector3d* v : {&look_at.eye, &look_at.target, &look_at.up}) {
      for (int i = 0; i < 3; ++i) out << ',' << ShortestDouble((*v)(i));
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out << ',' << ShortestDouble(pose.rotation(r, c));
    for (int i = 0; i < 3; ++i) out << ',' << ShortestDouble(pose.translation(i));
    out << '\n';
  }
  return out.str();
}

}  // namespace camproj

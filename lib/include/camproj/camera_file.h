// The camera file: JSON, documented key by key in docs/camera-file.md. Reading needs
// image_size, intrinsics, a pose (cam_from_world, or look_at when cam_from_world is absent) and
// frustum.near / frustum.far; every other key is derived and rewritten on output.
#ifndef CAMPROJ_CAMERA_FILE_H_
#define CAMPROJ_CAMERA_FILE_H_

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camproj/camera.h"
#include "camproj/fit.h"  // LinearityCheck
#include "camproj/conventions.h"
#include "camproj/gl.h"

namespace camproj {

struct CameraFileOptions {
  PixelOrigin pixel_origin = PixelOrigin::kCenter;  // convention of cx, cy written to the file
  double target_distance = 1.0;                     // look_at.target distance along the gaze
  GlDepth depth;                                    // gl.projection's depth convention
  void Check() const;
};

// The camera file's "fit" object: how the camera was fitted (docs/camera-file.md).
struct FitRecord {
  double rms_px = 0.0;     // sqrt(mean(du^2 + dv^2))
  double median_px = 0.0;  // median |residual|
  double max_px = 0.0;
  int num_points = 0;       // points used (without RANSAC's outliers)
  std::vector<int> outliers;  // 0-based indices of the points left out of the fit
  std::string outlier_method;  // how they were found: ransac | leave-one-out | leave-two-out | lo-ransac
  struct OutlierPoint {
    int index = 0;             // 0-based, as `outliers`
    double residual_px = 0.0;  // against this camera
    double rms_with_px = 0.0;  // the same model fitted with the point put back (0: not computed)
  };
  std::vector<OutlierPoint> outlier_points;
  std::string consistency;  // the consistency gate's verdict in words (automatic fit only)
  std::string determination;  // the determination check's verdict in words (automatic fit only)
  std::string reliability;  // the least checked point in words (automatic fit only)
  std::string start;        // closed-form start: dlt | homography | pnp | pnp-focal-sweep
  std::string model;        // "pose+focal+principal-point": the free intrinsics
  // Automatic model selection (empty otherwise): criterion, the noise it used, every model tried.
  struct Candidate {
    std::string name;
    int num_params = 0;     // 0 when refused
    double rms_px = 0.0;
    double criterion = 0.0;
    std::string verdict;
  };
  std::string criterion;    // "AIC" | "BIC"
  double selection_sigma_px = 0.0;
  std::vector<Candidate> candidates;
  std::vector<std::string> free;                                 // estimated parameters
  std::vector<std::pair<std::string, std::string>> fixed;        // name, "value (why)"
  std::vector<std::pair<std::string, std::string>> left_out;     // name, why
  std::vector<std::pair<std::string, double>> sigma;             // name, standard deviation
  double pixel_sigma = 0.0;            // px per axis, used for the sigmas
  bool pixel_sigma_estimated = true;   // from the residuals (else given)
  int iterations = 0;
  double jacobian_condition = 0.0;     // of the column-scaled Jacobian at the solution
  LinearityCheck linearity;            // written when checked (fit.h)
  double time_ms = 0.0;
};

// Parses camera-file text. `source` names the text in messages ("camera.json"). Throws
// InputError naming the source, the line and column of a JSON syntax error, or the key path
// ("intrinsics.fx") of a missing or invalid value. Arrays and objects nested deeper than 32
// levels are refused before parsing (no recursion grows with the input), and messages describe a
// wrong value by its type and size, never by quoting it.
Camera CameraFromJsonText(const std::string& text, const std::string& source);

// ReadWholeFile + CameraFromJsonText.
Camera ReadCameraFile(const std::string& path);

// The camera of one view of a calibration file (calibration_file.h, docs/calibration.md): the
// `camera` of the entry of `views` whose `name` is `view`, read as CameraFromJsonText reads a
// camera file, with messages naming "SOURCE, view NAME: KEY: ...". Throws InputError naming the
// source when the text is not a calibration file (a `views` array and no pose at the top level),
// when that view was refused (`refused_views`), or when no view has that name (the message lists
// the first ten names). CameraFromJsonText refuses a calibration file, pointing here.
Camera CalibrationViewFromJsonText(const std::string& text, const std::string& source,
                                   const std::string& view);

// ReadWholeFile + CalibrationViewFromJsonText.
Camera ReadCalibrationView(const std::string& path, const std::string& view);

// The convention a camera file states its cx, cy in: its "pixel_origin", or (`view` not empty)
// that of the calibration file's view `view`; kCenter where absent. The camera the readers above
// return is in kCenter either way: this is what tells a command which convention its user works
// in. Throws InputError as those readers do for text they refuse.
PixelOrigin CameraFilePixelOrigin(const std::string& text, const std::string& source,
                                  const std::string& view = "");

// The intrinsics of a camera file, or of any JSON object with "intrinsics" {fx, fy, cx, cy[,
// skew, k1, k2]} and optionally "pixel_origin" (a calibration file too): returned in kCenter.
// `image_size`, if given, gets the object's "image_size" (the image the intrinsics are for),
// or nullopt where it has none. Throws InputError, also for an orthographic camera's file (its
// fx, fy are px per world unit, not a pinhole's). ReadIntrinsicsFile and ReadCalibrationView
// refuse a file over 16 MiB (a calibration of ~5800 views), ReadCameraFile one over 1 MiB.
Intrinsics IntrinsicsFromJsonText(const std::string& text, const std::string& source,
                                  std::optional<ImageSize>* image_size = nullptr);
Intrinsics ReadIntrinsicsFile(const std::string& path,
                              std::optional<ImageSize>* image_size = nullptr);

// The `fit.outliers` of camera-file text (0-based indices of the points the fit left out), empty
// when there is no fit record or no outliers. Throws InputError naming `source` and the key when
// fit.outliers is not an array of non-negative integers.
std::vector<int> OutlierIndicesFromJsonText(const std::string& text, const std::string& source);

// The camera file text: all keys of docs/camera-file.md, `fit` only when given, doubles at full
// precision (they round-trip exactly).
std::string CameraToJsonText(const Camera& camera, const CameraFileOptions& options = {},
                             const FitRecord* fit = nullptr);

}  // namespace camproj

#endif  // CAMPROJ_CAMERA_FILE_H_

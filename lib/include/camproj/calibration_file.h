// The calibration file that `camproj calibrate` writes (docs/camera-file.md, "Calibration
// files"): JSON with the shared intrinsics at the top level — so every reader of intrinsics takes
// it as it is (`camproj fit --intrinsics CALIB.json` fits poses against it) — their sigmas, the
// RMS, and per view a complete camera file under views[i].camera.
#ifndef CAMPROJ_CALIBRATION_FILE_H_
#define CAMPROJ_CALIBRATION_FILE_H_

#include <string>

#include "camproj/calibrate.h"
#include "camproj/camera_file.h"

namespace camproj {

// The file text; doubles at full precision. cx, cy (top level and in each view's camera) in
// options.pixel_origin. Throws std::invalid_argument if a view's camera is invalid.
std::string CalibrationToJsonText(const Calibration& calibration,
                                  const CameraFileOptions& options = {});

// The poses table: a header line, then per view: view, eye (3), target (3, at
// options.target_distance along the gaze), up (3), cam_from_world rotation (9, row-major) and
// translation (3). Comma-separated (RFC 4180: a view name with a comma, a quote or a line break
// is quoted), doubles at full precision.
std::string CalibrationPosesCsvText(const Calibration& calibration,
                                    const CameraFileOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_CALIBRATION_FILE_H_

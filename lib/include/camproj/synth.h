// Reproducible synthetic scenes with their true camera: for examples, tests and benchmarks.
#ifndef CAMPROJ_SYNTH_H_
#define CAMPROJ_SYNTH_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/calibrate.h"
#include "camproj/camera.h"
#include "camproj/points_file.h"

namespace camproj {

enum class SynthObject {
  kCloud,  // points filling a box volume (non-planar)
  kBox,    // points on the faces of a box the eye sees, each at more than 0.1 cosine from the
           // face's normal at its centre (projection mapping)
  kPlane,  // points on one plane, tilted against the view
};

struct SynthOptions {
  uint64_t seed = 1;
  int num_points = 20;
  double noise_px = 0.0;   // Gaussian sigma per axis, px
  SynthObject object = SynthObject::kCloud;
  ImageSize image_size{1920, 1080};
  double fovy_deg = 40.0;  // vertical field of view of the true camera, (0, 180)
  // Principal point offset from the image centre as a fraction of the image size: (0, 0.5)
  // puts it at the bottom edge, as a projector with lens shift.
  Eigen::Vector2d principal_point_offset = Eigen::Vector2d::Zero();
  double aspect = 1.0;     // fy / fx of the true camera
  double object_size = 1.0;  // world units: the object's largest extent
  void Check() const;      // throws std::invalid_argument naming the field
};

struct SynthScene {
  Camera truth;                     // z_near, z_far tight around the points (10 % margin)
  Correspondences correspondences;  // pixels in kCenter, with noise; ids "1".."N"
};

// The camera looks at the object's centre through the image centre from a seeded direction, at
// the distance that keeps every point inside the image. Same options, same scene, on any machine
// with IEEE doubles (std::mt19937_64 and this file's own distributions).
SynthScene SynthesizeScene(const SynthOptions& options);

// Views of a calibration target for Calibrate (calibrate.h): a 9 x 6 board's corners (unit
// squares, Z = 0) or a 4 x 4 x 3 grid rig (spacing 2), each from a seeded pose — 13 to 20 units
// from the target's centre, tilted up to 0.6 rad about x and y and turned up to 0.3 rad about the
// axis — redrawn until every point is inside the image; Gaussian pixel noise. Reproducible as
// SynthesizeScene. Names "view1", "view2", ...
struct CalibrationSynthOptions {
  uint64_t seed = 1;
  int num_views = 5;
  bool planar = true;
  double noise_px = 0.0;  // Gaussian sigma per axis, px
  ImageSize image_size{640, 480};
  Intrinsics intrinsics;  // the true camera (kCenter), distortion included
  void Check() const;     // throws std::invalid_argument naming the field
};
std::vector<CalibrationView> SynthesizeCalibrationViews(const CalibrationSynthOptions& options);

// "cloud" | "box" | "plane"; throws std::invalid_argument otherwise.
SynthObject SynthObjectFromString(const std::string& text);

}  // namespace camproj

#endif  // CAMPROJ_SYNTH_H_

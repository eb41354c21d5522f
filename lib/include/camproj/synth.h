// Reproducible synthetic scenes with their true camera: for examples, tests and benchmarks.
#ifndef CAMPROJ_SYNTH_H_
#define CAMPROJ_SYNTH_H_

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/points_file.h"

namespace camproj {

enum class SynthObject {
  kCloud,  // points filling a box volume (non-planar)
  kBox,    // points on the three faces of a box that face the camera (projection mapping)
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

// "cloud" | "box" | "plane"; throws std::invalid_argument otherwise.
SynthObject SynthObjectFromString(const std::string& text);

}  // namespace camproj

#endif  // CAMPROJ_SYNTH_H_

// A picture of a fit: observed points, reprojected points and the residual vectors, drawn on the
// camera's image (or a blank canvas of its size).
#ifndef CAMPROJ_OVERLAY_H_
#define CAMPROJ_OVERLAY_H_

#include <string>

#include "camproj/camera.h"
#include "camproj/points_file.h"

namespace camproj {

struct OverlayOptions {
  double magnify = 10.0;  // residual vectors are drawn this many times their length, > 0
  std::string background_path;  // image to draw on (any format OpenCV reads); empty: blank
  void Check() const;
};

struct OverlayStats {
  int drawn = 0;   // points drawn
  int behind = 0;  // points behind the camera (listed in the legend, not drawn)
};

// Draws and writes a PNG to `output_path` atomically. Pixels of `correspondences` are in kCenter.
// Throws InputError if the background cannot be read or its size differs from the camera's
// image size, or the output cannot be written.
OverlayStats WriteOverlayPng(const Camera& camera, const Correspondences& correspondences,
                             const OverlayOptions& options, const std::string& output_path);

}  // namespace camproj

#endif  // CAMPROJ_OVERLAY_H_

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
  std::string background_path;  // image to draw on, PNG or JPEG; empty: blank
  void Check() const;
};

struct OverlayStats {
  int drawn = 0;   // points drawn
  int behind = 0;  // points behind the camera (listed in the legend, not drawn)
};

// Draws and writes the picture to `output_path` atomically, as PNG or JPEG by its extension
// (ImageFormatOfPath). Pixels of `correspondences` are in kCenter.
// Throws std::invalid_argument if the extension is neither or the camera's image size is beyond
// kMaxImagePixels (before allocating anything); InputError if the background is not a PNG or JPEG,
// its header states another size than the camera's (checked before decoding), it cannot be
// decoded, or the output cannot be written.
OverlayStats WriteOverlayImage(const Camera& camera, const Correspondences& correspondences,
                               const OverlayOptions& options, const std::string& output_path);

}  // namespace camproj

#endif  // CAMPROJ_OVERLAY_H_

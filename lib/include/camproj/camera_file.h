// The camera file: JSON, documented key by key in docs/camera-file.md. Reading needs
// image_size, intrinsics, a pose (cam_from_world, or look_at when cam_from_world is absent) and
// frustum.near / frustum.far; every other key is derived and rewritten on output.
#ifndef CAMPROJ_CAMERA_FILE_H_
#define CAMPROJ_CAMERA_FILE_H_

#include <string>

#include "camproj/camera.h"
#include "camproj/conventions.h"
#include "camproj/gl.h"

namespace camproj {

struct CameraFileOptions {
  PixelOrigin pixel_origin = PixelOrigin::kCenter;  // convention of cx, cy written to the file
  double target_distance = 1.0;                     // look_at.target distance along the gaze
  GlDepth depth;                                    // gl.projection's depth convention
  void Check() const;
};

// Parses camera-file text. `source` names the text in messages ("camera.json"). Throws
// InputError naming the source, the line and column of a JSON syntax error, or the key path
// ("intrinsics.fx") of a missing or invalid value.
Camera CameraFromJsonText(const std::string& text, const std::string& source);

// ReadWholeFile + CameraFromJsonText.
Camera ReadCameraFile(const std::string& path);

// The camera file text: all keys of docs/camera-file.md except `fit`, doubles at full precision
// (they round-trip exactly).
std::string CameraToJsonText(const Camera& camera, const CameraFileOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_CAMERA_FILE_H_

// Text exports of a camera for other tools. Conventions: docs/conventions.md.
#ifndef CAMPROJ_EXPORT_H_
#define CAMPROJ_EXPORT_H_

#include <string>

#include "camproj/camera.h"
#include "camproj/gl.h"

namespace camproj {

struct GlExportOptions {
  GlDepth depth;
  bool row_major = false;  // print rows instead of GL's column-major order
};

// "projection" and "view" lines of 16 numbers each (column-major unless row_major, 17 significant
// digits), preceded by comment lines ('#') naming the conventions used. The projection is the
// pinhole part: a comment says so when the camera has distortion.
std::string ExportGl(const Camera& camera, const GlExportOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_EXPORT_H_

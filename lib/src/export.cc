#include "camproj/export.h"

#include <iomanip>
#include <limits>
#include <sstream>

namespace camproj {

namespace {

void PrintMatrix(std::ostream& out, const char* name, const Eigen::Matrix4d& m, bool row_major) {
  out << name;
  for (int i = 0; i < 16; ++i) {
    const int major = i / 4;
    const int minor = i % 4;
    out << ' ' << (row_major ? m(major, minor) : m(minor, major));
  }
  out << '\n';
}

}  // namespace

std::string ExportGl(const Camera& camera, const GlExportOptions& options) {
  const CameraViews views = ViewsOfCamera(camera, 1.0, options.depth);
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  out << "# camproj GL export: projection = clip_from_gl_eye, view = gl_eye_from_world\n"
      << "# " << (options.row_major ? "row-major (transpose before a GL_FALSE upload)"
                                    : "column-major: upload with transpose = GL_FALSE")
      << "; depth " << ToString(options.depth.clip_depth)
      << (options.depth.clip_depth == ClipDepth::kZeroToOne ? " (glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE))" : " ([-1,1], GL default)")
      << (options.depth.reversed_z ? ", reversed-Z (glDepthFunc(GL_GREATER), clear depth 0)" : "")
      << "; near " << camera.z_near << ", far " << camera.z_far << "; viewport 0 0 "
      << camera.image_size.width << ' ' << camera.image_size.height << '\n';
  if (camera.intrinsics.HasDistortion()) {
    out << "# note: k1 = " << camera.intrinsics.k1 << ", k2 = " << camera.intrinsics.k2
        << " are not in the projection matrix (GL projection is linear)\n";
  }
  PrintMatrix(out, "projection", views.clip_from_gl_eye, options.row_major);
  PrintMatrix(out, "view", views.gl_eye_from_world, options.row_major);
  return out.str();
}

}  // namespace camproj

#include "camproj/export.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>

#include "camproj/camera_file.h"
#include "camproj/lens_gl.h"
#include "camproj/number_text.h"
#include "camproj/world_origin.h"
#include "check.h"
#include "exact_stream.h"

namespace camproj {

namespace {

using ordered_json = nlohmann::ordered_json;

constexpr double kRadToDeg = 57.295779513082320876798154814105;

struct FormatName {
  ExportFormat format;
  const char* name;
};

constexpr FormatName kFormatNames[] = {
    {ExportFormat::kGl, "gl"},
    {ExportFormat::kGlm, "glm"},
    {ExportFormat::kOpenCvYaml, "opencv-yaml"},
    {ExportFormat::kColmap, "colmap"},
    {ExportFormat::kThree, "three"},
    {ExportFormat::kJson, "json"},
    {ExportFormat::kGlsl, "glsl"},
    {ExportFormat::kDistortionMesh, "distortion-mesh"},
};

using internal::ExactStream;

// The GL state a matrix built with `depth` needs, as one comment line per call.
std::string DepthState(const GlDepth& depth, const std::string& prefix) {
  std::string text = prefix + "glDepthRange(0.0, 1.0);";
  if (depth.clip_depth == ClipDepth::kZeroToOne) {
    text += " glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);";
  }
  text += depth.reversed_z ? " glDepthFunc(GL_GREATER); glClearDepth(0.0);"
                           : " glDepthFunc(GL_LESS); glClearDepth(1.0);";
  return text + "\n";
}

std::string DepthSummary(const GlDepth& depth) {
  std::string text = ToString(depth.clip_depth);
  text += depth.clip_depth == ClipDepth::kZeroToOne ? " ([0, 1])" : " ([-1, 1], GL's default)";
  if (depth.reversed_z) {
    text += depth.clip_depth == ClipDepth::kZeroToOne ? ", reversed-Z (near -> 1, far -> 0)"
                                                      : ", reversed-Z (near -> 1, far -> -1)";
  }
  return text;
}

std::string DistortionNote(const Camera& camera) {
  auto out = ExactStream();
  out << DistortionText(camera.intrinsics) << " are not in the projection matrix (GL projection is linear): it puts points up to "
      << std::setprecision(3) << PinholeErrorAtWorstCornerPx(camera)
      << " px (worst image corner) from where the lens images them; "
      << (camera.intrinsics.HasBeyondTwoRadial()
              ? "the GL lens exports (glsl, distortion-mesh, stmap) render k1, k2 only: use "
                "opencv-yaml or colmap for this lens"
              : "to render the lens: export glsl (per vertex), distortion-mesh or stmap "
                "(post-process warp)");
  return out.str();
}

// The pixel convention of GL window coordinates against camproj's pixels, one sentence.
std::string GlPixelNote(const Camera& camera) {
  return internal::Concat("pixels: GL window x = u + 0.5, y = ", camera.image_size.height,
                          " - (v + 0.5) for camproj's kCenter pixel (u, v) (docs/conventions.md, "
                          "section 2)");
}

void PrintMatrix(std::ostream& out, const char* name, const Eigen::Matrix4d& m, bool row_major) {
  out << name;
  for (int i = 0; i < 16; ++i) {
    const int major = i / 4;
    const int minor = i % 4;
    out << ' ' << (row_major ? m(major, minor) : m(minor, major));
  }
  out << '\n';
}

std::string ExportGlText(const Camera& camera, const ExportOptions& options) {
  const CameraViews views = ViewsOfCamera(camera, 1.0, options.depth);
  auto out = ExactStream();
  out << "# camproj GL export: projection = clip_from_gl_eye, view = "
      << (camera.world_origin ? "gl_eye_from_origin_world" : "gl_eye_from_world") << "\n"
      << "# "
      << (options.row_major ? "row-major (transpose before a GL_FALSE upload)"
                            : "column-major: upload with transpose = GL_FALSE")
      << "; depth " << ToString(options.depth.clip_depth)
      << (options.depth.clip_depth == ClipDepth::kZeroToOne
              ? " (glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE))"
              : " ([-1,1], GL default)")
      << (options.depth.reversed_z ? ", reversed-Z (glDepthFunc(GL_GREATER), clear depth 0)" : "")
      << (camera.projection == Projection::kOrthographic ? "; orthographic" : "")
      << "; near " << camera.z_near << ", far " << camera.z_far << "; viewport 0 0 "
      << camera.image_size.width << ' ' << camera.image_size.height << '\n';
  out << "# " << GlPixelNote(camera) << '\n';
  if (camera.intrinsics.HasDistortion()) {
    out << "# note: " << DistortionNote(camera) << '\n';
  } else {
    out << "# distortion: none (k1, k2, p1, p2, k3 are 0): the matrices are the whole camera\n";
  }
  out << "# " << WorldOriginNote(camera) << '\n';
  PrintMatrix(out, "projection", views.clip_from_gl_eye, options.row_major);
  PrintMatrix(out, "view", views.gl_eye_from_origin_world, options.row_major);
  return out.str();
}

// A C++ double literal that reads back bit for bit ("0.0", not "0", which glm would take as int).
std::string CppDouble(double value) {
  auto out = ExactStream();
  out << value;
  std::string text = out.str();
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

void PrintGlmMatrix(std::ostream& out, const char* name, const Eigen::Matrix4d& m) {
  out << "const glm::dmat4 " << name << "(\n";
  for (int col = 0; col < 4; ++col) {
    out << "    ";
    for (int row = 0; row < 4; ++row) {
      out << CppDouble(m(row, col)) << (row < 3 ? ", " : "");
    }
    out << (col < 3 ? ",  // column " : ");  // column ") << col << '\n';
  }
}

std::string ExportGlmText(const Camera& camera, const ExportOptions& options) {
  const CameraViews views = ViewsOfCamera(camera, 1.0, options.depth);
  auto out = ExactStream();
  out << "// camproj glm export: projection = clip_from_gl_eye, view = "
      << (camera.world_origin ? "gl_eye_from_origin_world" : "gl_eye_from_world") << ".\n"
      << "// #include <glm/glm.hpp> and <glm/gtc/type_ptr.hpp>. glm is column-major: the\n"
      << "// 16-number glm::dmat4 constructor takes column 0 first, the order GL uploads.\n"
      << (camera.projection == Projection::kOrthographic
              ? "// Orthographic (glOrtho form when skew is 0; fx, fy in px per world unit).\n"
              : "")
      << "// Depth " << DepthSummary(options.depth) << "; near " << camera.z_near << ", far "
      << camera.z_far << ".\n"
      << "// GL state: glViewport(0, 0, " << camera.image_size.width << ", "
      << camera.image_size.height << ");\n"
      << DepthState(options.depth, "//   ") << "// Upload to a mat4 uniform (float):\n"
      << "//   const glm::mat4 projection_f(projection), view_f(view);\n"
      << "//   glUniformMatrix4fv(projection_location, 1, GL_FALSE, "
         "glm::value_ptr(projection_f));\n"
      << "//   glUniformMatrix4fv(view_location, 1, GL_FALSE, glm::value_ptr(view_f));\n"
      << "// or to a dmat4 uniform (GL 4.0): glUniformMatrix4dv(location, 1, GL_FALSE, "
         "glm::value_ptr(projection)).\n";
  out << "// " << GlPixelNote(camera) << ".\n";
  if (camera.intrinsics.HasDistortion()) {
    out << "// Note: " << DistortionNote(camera) << ".\n";
  } else {
    out << "// Distortion: none (k1, k2, p1, p2, k3 are 0): the matrices are the whole camera.\n";
  }
  out << "// " << WorldOriginNote(camera) << ".\n";
  if (camera.world_origin) {
    const Eigen::Vector3d& o = *camera.world_origin;
    out << "// Vertices: glm::vec3(glm::dvec3(point_in_world) - world_origin).\n"
        << "const glm::dvec3 world_origin(" << CppDouble(o.x()) << ", " << CppDouble(o.y()) << ", "
        << CppDouble(o.z()) << ");\n";
  }
  PrintGlmMatrix(out, "projection", views.clip_from_gl_eye);
  PrintGlmMatrix(out, "view", views.gl_eye_from_origin_world);
  return out.str();
}

// The unit quaternion of a rotation with w >= 0 (COLMAP's QW QX QY QZ), and its Rodrigues vector
// (angle * axis). Eigen's matrix -> quaternion -> angle-axis path stays accurate at angles near 0
// and pi, where cv::Rodrigues' acos-based formula loses digits.
Eigen::Quaterniond QuaternionOf(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

Eigen::Vector3d RodriguesOf(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd angle_axis(QuaternionOf(rotation));
  return angle_axis.angle() * angle_axis.axis();
}

cv::Mat CvMatrix(const Eigen::MatrixXd& m) {
  cv::Mat result(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) result.at<double>(r, c) = m(r, c);
  }
  return result;
}

void RequireNoSkew(const Camera& camera, const char* format, const char* why) {
  internal::Require(camera.intrinsics.skew == 0.0, format, " cannot represent this camera: ", why,
                    ", but skew = ", camera.intrinsics.skew,
                    " px (fit with skew fixed at 0, or export to gl, glm, three or json)");
}

void RequirePerspective(const Camera& camera, const char* format) {
  internal::Require(camera.projection == Projection::kPerspective, format,
                    " has no orthographic camera model: export to gl, glm, three or json");
}

std::string ExportOpenCvYamlText(const Camera& camera) {
  RequirePerspective(camera, "opencv-yaml");
  camera.Check();
  RequireNoSkew(camera, "opencv-yaml",
                "OpenCV's camera model has no skew (cv::projectPoints ignores camera_matrix(0,1))");
  const Intrinsics& k = camera.intrinsics;
  Eigen::Matrix<double, 1, 5> distortion;
  distortion << k.k1, k.k2, k.p1, k.p2, k.k3;
  cv::FileStorage storage(
      "", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  storage.writeComment(
      "camproj OpenCV export: read with cv::FileStorage(path, cv::FileStorage::READ).");
  storage.writeComment("Pixel origin: OpenCV's, (0, 0) = centre of the top-left pixel.");
  storage.writeComment(
      "rvec, tvec: cam_from_world (x_cam = R x_world + t, as cv::solvePnP returns it); "
      "R = cv::Rodrigues(rvec), also written as R.");
  storage.writeComment("distortion_coefficients: k1 k2 p1 p2 k3 (cv::projectPoints' order).");
  storage << "image_width" << camera.image_size.width;
  storage << "image_height" << camera.image_size.height;
  storage << "camera_matrix" << CvMatrix(k.K());
  storage << "distortion_coefficients" << CvMatrix(distortion);
  storage << "rvec" << CvMatrix(RodriguesOf(camera.cam_from_world.rotation));
  storage << "tvec" << CvMatrix(camera.cam_from_world.translation);
  storage << "R" << CvMatrix(camera.cam_from_world.rotation);
  return storage.releaseAndGetString();
}

// -0 printed as "0" (-0 + 0 = +0): COLMAP's files never hold a negative zero.
double WithoutNegativeZero(double value) { return value + 0.0; }

std::string ExportColmapText(const Camera& camera) {
  RequirePerspective(camera, "colmap");
  camera.Check();
  RequireNoSkew(camera, "colmap", "no COLMAP camera model (PINHOLE, OPENCV, ...) has skew");
  const Intrinsics k =
      ConvertPixelOrigin(camera.intrinsics, PixelOrigin::kCenter, PixelOrigin::kCorner);
  const Eigen::Quaterniond q = QuaternionOf(camera.cam_from_world.rotation);
  const Eigen::Vector3d& t = camera.cam_from_world.translation;
  auto out = ExactStream();
  out << "# camproj COLMAP export: a text model. Save each section below as its own file in one\n"
      << "# folder (docs/exports.md). Pixel origin: COLMAP's, (0.5, 0.5) = centre of the top-left\n"
      << "# pixel. QW QX QY QZ, TX TY TZ: cam_from_world (x_cam = R x_world + t).\n"
      << "# ==> cameras.txt <==\n"
      << "# Camera list with one line of data per camera:\n"
      << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      << "# Number of cameras: 1\n"
      << "1 " << (k.k3 != 0.0 ? "FULL_OPENCV" : k.HasDistortion() ? "OPENCV" : "PINHOLE") << ' '
      << camera.image_size.width << ' ' << camera.image_size.height << ' ' << k.fx << ' ' << k.fy
      << ' ' << k.cx << ' ' << k.cy;
  // OPENCV: k1 k2 p1 p2; FULL_OPENCV: k1 k2 p1 p2 k3 k4 k5 k6 (k4..k6 the rational model's
  // denominator, 0 here).
  if (k.HasDistortion()) out << ' ' << k.k1 << ' ' << k.k2 << ' ' << k.p1 << ' ' << k.p2;
  if (k.k3 != 0.0) out << ' ' << k.k3 << " 0 0 0";
  out << '\n'
      << "# ==> images.txt <==\n"
      << "# Image list with two lines of data per image:\n"
      << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      << "# Number of images: 1, mean observations per image: 0\n"
      << "1 " << WithoutNegativeZero(q.w()) << ' ' << WithoutNegativeZero(q.x()) << ' '
      << WithoutNegativeZero(q.y()) << ' ' << WithoutNegativeZero(q.z()) << ' '
      << WithoutNegativeZero(t.x()) << ' ' << WithoutNegativeZero(t.y()) << ' '
      << WithoutNegativeZero(t.z()) << " 1 image\n"
      << '\n'
      << "# ==> points3D.txt <==\n"
      << "# 3D point list with one line of data per point:\n"
      << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      << "# Number of points: 0, mean track length: 0\n";
  return out.str();
}

ordered_json Matrix4Json(const Eigen::Matrix4d& m) {
  ordered_json numbers = ordered_json::array();
  for (int i = 0; i < 16; ++i) numbers.push_back(m.data()[i]);  // column-major
  return numbers;
}

// Why three's updateProjectionMatrix() cannot rebuild projectionMatrix ("" if it can: each
// reason " ...;"), and the note's sentence on an off-centre principal point.
struct ThreeRebuild {
  std::string no_rebuild;
  std::string off_axis;
};

// `type` and the fields three rebuilds projectionMatrix from: the glOrtho box, or fov, aspect and
// (off-centre) the view offset.
ThreeRebuild SetThreeProjectionFields(const Camera& camera, const CameraViews& views,
                                      ordered_json* document) {
  ThreeRebuild rebuild;
  if (camera.projection == Projection::kOrthographic) {
    // THREE.OrthographicCamera(left, right, top, bottom, near, far): the glOrtho box.
    (*document)["type"] = "OrthographicCamera";
    if (views.ortho) {
      (*document)["left"] = views.ortho->left;
      (*document)["right"] = views.ortho->right;
      (*document)["top"] = views.ortho->top;
      (*document)["bottom"] = views.ortho->bottom;
    } else {
      rebuild.no_rebuild += " skew != 0 (no left, right, top, bottom form);";
    }
    return rebuild;
  }
  (*document)["type"] = "PerspectiveCamera";
  if (!views.frustum) {
    rebuild.no_rebuild += " skew != 0 (no fov, aspect or view form);";
    return rebuild;
  }
  // Enlarge the frustum to one centred on the gaze and show the image as a window of it, in
  // units of s = W / (r - l) per near-plane unit on both axes, so that fullWidth / fullHeight
  // is the full view's aspect (setViewOffset sets aspect to it). Exactly centred: no window.
  const Frustum& f = *views.frustum;
  const double half_width = std::max(-f.left, f.right);
  const double half_height = std::max(f.top, -f.bottom);
  const double s = camera.image_size.width / (f.right - f.left);
  (*document)["fov"] = 2.0 * std::atan(half_height / f.z_near) * kRadToDeg;
  (*document)["aspect"] = half_width / half_height;
  if (f.left != -f.right || f.bottom != -f.top) {
    (*document)["view"] = {{"enabled", true},
                           {"fullWidth", 2.0 * half_width * s},
                           {"fullHeight", 2.0 * half_height * s},
                           {"offsetX", (f.left + half_width) * s},
                           {"offsetY", (half_height - f.top) * s},
                           {"width", (f.right - f.left) * s},
                           {"height", (f.top - f.bottom) * s}};
    rebuild.off_axis =
        " The principal point is off-centre: fov and aspect are those of an enlarged view "
        "centred on the gaze, and view is the image's window in it, as "
        "camera.setViewOffset(fullWidth, fullHeight, offsetX, offsetY, width, height) sets it.";
  }
  return rebuild;
}

// The export's `note`: how to load the matrices into three, whether updateProjectionMatrix may
// run, the renderer the depth convention needs, pixels, distortion, matrixWorld and the origin.
std::string ThreeNote(const Camera& camera, const GlDepth& depth, ThreeRebuild rebuild) {
  std::string note =
      "projectionMatrix is exact: camera.projectionMatrix.fromArray(projectionMatrix); "
      "camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert(). "
      "camera.updateProjectionMatrix() (which resize handlers call, and the renderer too when "
      "reversedDepthBuffer is on) rebuilds it from " +
      std::string(camera.projection == Projection::kOrthographic
                      ? "left, right, top, bottom, near, far and zoom: "
                      : "fov, aspect, near, far, zoom and view: ");
  std::string& no_rebuild = rebuild.no_rebuild;
  if (depth.clip_depth == ClipDepth::kNegativeOneToOne && depth.reversed_z) {
    no_rebuild += " three has no [-1, 1] reversed-Z depth;";
  }
  if (no_rebuild.empty()) {
    note += "set those too, and it rebuilds projectionMatrix to rounding.";
  } else {
    no_rebuild.pop_back();
    note += "here it cannot (" + no_rebuild.substr(1) + "), so never let it run.";
  }
  note += rebuild.off_axis;
  note += depth.reversed_z
              ? (depth.clip_depth == ClipDepth::kZeroToOne
                     ? " Depth zo reversed-Z: a renderer made with reversedDepthBuffer: true; "
                       "set camera._reversedDepth = true (three r187) after loading "
                       "projectionMatrix, or that renderer rebuilds it on its first render."
                     : "")
              : (depth.clip_depth == ClipDepth::kZeroToOne ? " Depth zo: WebGPURenderer."
                                                           : " Depth no: WebGLRenderer.");
  note +=
      " Pixels: three's canvas pixels (Vector3.project mapped by x = (ndc.x + 1) / 2 * W, y = "
      "(1 - ndc.y) / 2 * H) are corner-origin: camproj's kCenter pixel + 0.5 (docs/conventions.md, "
      "section 2).";
  note += camera.intrinsics.HasDistortion()
              ? " " + DistortionNote(camera) + "."
              : std::string(" Distortion: none (k1, k2, p1, p2, k3 are 0): projectionMatrix is the whole camera.");
  note += std::string(" matrixWorld = ") +
          (camera.world_origin ? "world_from_gl_eye in the origin-relative world" : "world_from_gl_eye") +
          " (three's camera looks down -z with y up); for a camera "
          "without a parent set camera.position.fromArray(position) and "
          "camera.quaternion.fromArray(quaternion), which the renderer turns into this matrixWorld.";
  note += " " + WorldOriginNote(camera) +
          (camera.world_origin
               ? ": positions in this three world are point_in_world - world_origin (objects' "
                 "positions and geometry vertices alike; three multiplies the object and camera "
                 "matrices in double, so vertices small around their object's position are "
                 "precise either way)."
               : ".");
  return note;
}

std::string ExportThreeText(const Camera& camera, const ExportOptions& options) {
  const CameraViews views = ViewsOfCamera(camera, 1.0, options.depth);
  // With a world origin three's world is the origin-relative one: the scene's positions are
  // point_in_world - world_origin (three's numbers are doubles until they reach the GPU).
  const Rigid3 world_from_gl_eye = Inverse(Rigid3FromMatrix(views.gl_eye_from_origin_world));
  const Eigen::Quaterniond q(world_from_gl_eye.rotation);
  const Eigen::Vector3d& position = world_from_gl_eye.translation;
  const GlDepth& depth = options.depth;

  ordered_json document;
  document["projectionMatrix"] = Matrix4Json(views.clip_from_gl_eye);
  document["matrixWorld"] = Matrix4Json(world_from_gl_eye.ToMatrix());
  document["position"] = {position.x(), position.y(), position.z()};
  document["quaternion"] = {q.x(), q.y(), q.z(), q.w()};  // three's Quaternion.fromArray order
  ThreeRebuild rebuild = SetThreeProjectionFields(camera, views, &document);
  document["near"] = camera.z_near;
  if (std::isfinite(camera.z_far)) {
    document["far"] = camera.z_far;
  } else {
    document["far"] = nullptr;
    rebuild.no_rebuild += " the far plane is infinite (far = Infinity gives NaN);";
  }
  document["zoom"] = 1.0;
  document["filmOffset"] = 0.0;
  document["depth"] = ToString(depth.clip_depth);
  document["reversed_z"] = depth.reversed_z;
  document["image_size"] = {camera.image_size.width, camera.image_size.height};
  if (camera.world_origin) {
    document["world_origin"] = {camera.world_origin->x(), camera.world_origin->y(),
                                camera.world_origin->z()};
  } else {
    document["world_origin"] = nullptr;
  }
  document["note"] = ThreeNote(camera, depth, std::move(rebuild));
  return document.dump(2) + "\n";
}

}  // namespace

double PinholeErrorAtWorstCornerPx(const Camera& camera) {
  camera.Check();
  if (!camera.intrinsics.HasDistortion()) return 0.0;
  const Intrinsics pinhole = camera.intrinsics.Pinhole();
  const double w = camera.image_size.width;
  const double h = camera.image_size.height;
  double worst = 0.0;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
                                        Eigen::Vector2d(-0.5, h - 0.5), Eigen::Vector2d(w - 0.5, h - 0.5)}) {
    const Eigen::Vector3d ray = CamRayFromPixel(pinhole, corner);
    worst = std::max(worst, (PixelFromCam(camera.intrinsics, ray) - corner).norm());
  }
  return worst;
}

const char* ToString(ExportFormat format) {
  for (const FormatName& entry : kFormatNames) {
    if (entry.format == format) return entry.name;
  }
  return "unknown";
}

ExportFormat ExportFormatFromString(const std::string& text) {
  std::string choices;
  for (const FormatName& entry : kFormatNames) {
    if (text == entry.name) return entry.format;
    choices += std::string(choices.empty() ? "" : ", ") + "\"" + entry.name + "\"";
  }
  throw std::invalid_argument("export format must be one of " + choices + ", got \"" + text + "\"");
}

std::string ExportCamera(const Camera& camera, ExportFormat format, const ExportOptions& options) {
  RequireFiniteViews(camera, options.depth);
  switch (format) {
    case ExportFormat::kGl:
      return ExportGlText(camera, options);
    case ExportFormat::kGlm:
      return ExportGlmText(camera, options);
    case ExportFormat::kOpenCvYaml:
      return ExportOpenCvYamlText(camera);
    case ExportFormat::kColmap:
      return ExportColmapText(camera);
    case ExportFormat::kThree:
      return ExportThreeText(camera, options);
    case ExportFormat::kJson:
      return CameraToJsonText(camera, CameraFileOptions{options.pixel_origin, 1.0, options.depth});
    case ExportFormat::kGlsl:
      return LensGlslText(camera, options.depth);
    case ExportFormat::kDistortionMesh:
      return LensDistortionMeshJson(camera, options.mesh_step_px, options.depth);
  }
  throw std::invalid_argument(internal::Concat("unknown export format ", static_cast<int>(format)));
}

}  // namespace camproj

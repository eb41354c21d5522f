// Text exports of a camera for other tools: `camproj export CAMERA.json --to FORMAT`.
// Conventions: docs/conventions.md; each format, with how to load it: docs/exports.md.
//
// Every number is printed so that it reads back bit for bit (17 significant digits, or the
// shortest form that round-trips). What each format holds:
//   gl           `projection` (clip_from_gl_eye) and `view` (gl_eye_from_world) lines of 16
//                numbers, column-major unless row_major, after '#' comment lines.
//   glm          a C++ snippet defining `const glm::dmat4 projection(...)` and `view(...)` with the
//                same numbers (glm's 16-scalar constructor takes column 0 first), with the upload
//                call and the depth state (glClipControl, glDepthFunc) in comments.
//   opencv-yaml  a cv::FileStorage YAML file: image_width, image_height, camera_matrix (3x3),
//                distortion_coefficients (1x5: k1 k2 p1 p2 k3), rvec and tvec (3x1: cam_from_world
//                as cv::solvePnP returns it, rvec = Rodrigues vector of R) and R (3x3). cx, cy in
//                OpenCV's kCenter origin.
//   colmap       the lines of a COLMAP text model: cameras.txt (PINHOLE; OPENCV when k1, k2, p1 or p2
//                is set; FULL_OPENCV when k3 is; cx, cy in COLMAP's kCorner origin), images.txt (QW QX QY QZ TX TY TZ of
//                cam_from_world, then the empty POINTS2D line) and an empty points3D.txt, each
//                section opened by a "# ==> FILE <==" line.
//   three        a JSON object for a three.js PerspectiveCamera: projectionMatrix and matrixWorld
//                (world_from_gl_eye, the inverse of the view matrix) as Matrix4.fromArray takes
//                them (column-major), position, quaternion (x, y, z, w), fov / aspect / near /
//                far and, for an off-axis principal point, the setViewOffset `view` that makes
//                three's own updateProjectionMatrix() rebuild the same matrix; a `note` says when
//                that is impossible (skew, infinite far, reversed-Z).
//   json         the camera file (docs/camera-file.md), as CameraToJsonText writes it.
//   glsl         GLSL rendering the lens per vertex (lens_gl.h LensGlslText): the pinhole
//                projection and view as const mat4 and camproj_lens(), distorting gl_eye positions.
//   distortion-mesh  JSON triangle mesh warping a pinhole render target onto the image
//                (lens_gl.h LensDistortionMeshJson, ExportOptions::mesh_step_px).
// gl, glm and three hold the pinhole part only: a comment or note says when k1, k2 are dropped
// (a projection matrix is linear) and names the exports that render the lens (glsl,
// distortion-mesh, and the STMap files of `camproj export --to stmap`, lens_gl.h). With
// Camera::world_origin set, their view matrix is
// gl_eye_from_origin_world (vertices given as point_in_world - world_origin; world_origin.h),
// glm also defines `const glm::dvec3 world_origin`, three's matrixWorld and position are in the
// origin-relative world and its `world_origin` key holds it (null without); their header states
// the origin (or "world origin: none") and Float32PixelError at the near plane with and without
// it. json writes world_origin; opencv-yaml and colmap stay absolute.
#ifndef CAMPROJ_EXPORT_H_
#define CAMPROJ_EXPORT_H_

#include <string>

#include "camproj/camera.h"
#include "camproj/conventions.h"
#include "camproj/gl.h"

namespace camproj {

enum class ExportFormat { kGl, kGlm, kOpenCvYaml, kColmap, kThree, kJson, kGlsl, kDistortionMesh };

// "gl" | "glm" | "opencv-yaml" | "colmap" | "three" | "json" | "glsl" | "distortion-mesh".
const char* ToString(ExportFormat format);

// The inverse of ToString; throws std::invalid_argument naming the text and listing the choices.
ExportFormat ExportFormatFromString(const std::string& text);

struct ExportOptions {
  // gl, glm, three, json: depth convention of the projection matrix. An infinite far plane is
  // the Camera's z_far = kInfinity.
  GlDepth depth;
  // gl: print each matrix row by row instead of GL's column-major order.
  bool row_major = false;
  // json: pixel origin of the cx, cy written (the other formats use their tool's own origin).
  PixelOrigin pixel_origin = PixelOrigin::kCenter;
  // distortion-mesh: grid step in px of the camera's image (>= 1), or 0: the largest power of 2
  // up to 64 keeping the mesh's interpolation error <= kLensMeshErrorPx (lens_gl.h).
  int mesh_step_px = 0;
};

// How far (px) the pinhole projection matrix of the gl, glm and three exports puts a point from
// where the lens (k1, k2) images it, worst over the image's 4 outer corners (kCenter (-0.5, -0.5),
// (W - 0.5, -0.5), (-0.5, H - 0.5), (W - 0.5, H - 0.5)): for the ray the matrix sends to a corner
// c, |PixelFromCam(intrinsics, ray) - c|. 0 without distortion. Throws on an invalid camera.
double PinholeErrorAtWorstCornerPx(const Camera& camera);

// The text of `camera` in `format` (see the file comment), ending in a newline. The gl, glm and
// three headers (comments; three's `note`) state the pixel convention and, with k1 or k2 != 0,
// that the matrix drops the distortion and PinholeErrorAtWorstCornerPx.
// Throws std::invalid_argument on an invalid camera, on one whose derived numbers overflow
// (RequireFiniteViews: every format alike, nothing non-finite is ever written), or when the format
// cannot represent it, saying why: opencv-yaml and colmap refuse skew != 0 (OpenCV's projectPoints ignores
// camera_matrix(0,1), and no COLMAP camera model has skew); glsl and distortion-mesh refuse an
// orthographic camera and a lens whose first fold lies inside the image (RequireLensCoversImage).
std::string ExportCamera(const Camera& camera, ExportFormat format,
                         const ExportOptions& options = {});

}  // namespace camproj

#endif  // CAMPROJ_EXPORT_H_

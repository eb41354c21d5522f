// A complete camera: image size, intrinsics, pose and the depth range a GL export uses, with the
// derived views users ask for (look-at, frustum, perspective, GL matrices). Conventions:
// docs/conventions.md.
#ifndef CAMPROJ_CAMERA_H_
#define CAMPROJ_CAMERA_H_

#include <optional>

#include <Eigen/Core>

#include "camproj/conventions.h"
#include "camproj/frustum.h"
#include "camproj/gl.h"
#include "camproj/intrinsics.h"
#include "camproj/look_at.h"
#include "camproj/pose.h"

namespace camproj {

// kPerspective: a pinhole, pixel = K (x/z, y/z) (docs/conventions.md). kOrthographic: parallel
// projection, pixel = (fx x + skew y + cx, fy y + cy) of the point in cam, fx, fy and skew in
// px per world unit, no distortion; depth only orders points (the eye may sit anywhere on the
// axis: a fit places it in front of every point).
enum class Projection { kPerspective, kOrthographic };

struct Camera {
  ImageSize image_size;
  Intrinsics intrinsics;  // cx, cy in kCenter
  Rigid3 cam_from_world;
  double z_near = 0.1;    // depth range of the GL export, > 0
  double z_far = 100.0;   // > z_near, or kInfinity (perspective only)
  Projection projection = Projection::kPerspective;

  // Throws std::invalid_argument naming the field on any invalid part.
  void Check() const;
};

// Everything derived from a Camera, in the units and frames of docs/conventions.md.
struct CameraViews {
  LookAt look_at;                          // target at target_distance along the gaze
  std::optional<Frustum> frustum;          // absent when skew != 0 (no glFrustum form)
  std::optional<Perspective> perspective;  // only when the frustum is symmetric
  std::optional<Ortho> ortho;              // orthographic camera without skew: the glOrtho box
  Eigen::Matrix4d clip_from_gl_eye;        // projection matrix (pinhole part, skew included)
  Eigen::Matrix4d gl_eye_from_world;       // view matrix
};

// Derives the views; the projection uses intrinsics.Pinhole() (a GL matrix is linear: distortion
// is dropped, which callers that export must say). Throws on an invalid camera.
CameraViews ViewsOfCamera(const Camera& camera, double target_distance = 1.0,
                          const GlDepth& depth = {});

// Throws std::invalid_argument, naming what overflowed, unless every number ViewsOfCamera derives
// is finite (a far plane at kInfinity excepted): the projection and view matrices, the frustum or
// ortho box, the look-at. A valid camera with extreme values (fx = 1e308, cx = 1e308) overflows
// them; the camera-file reader and every exporter refuse it alike.
void RequireFiniteViews(const Camera& camera, const GlDepth& depth = {});

// The pixel (kCenter) of a world point, distortion included; std::nullopt if the point is not in
// front of the camera (z_cam <= 0), for either projection.
std::optional<Eigen::Vector2d> PixelFromWorld(const Camera& camera,
                                              const Eigen::Vector3d& point_in_world);

}  // namespace camproj

#endif  // CAMPROJ_CAMERA_H_

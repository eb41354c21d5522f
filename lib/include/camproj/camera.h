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
  // Camera-relative rendering for large coordinates (docs/conventions.md, section 11): when set,
  // GL-facing exports give the view matrix gl_eye_from_origin_world, which takes
  // point_in_world - *world_origin (subtracted in double by the user), so that float32 vertices
  // and matrices hold small numbers. Absent: vertices in world coordinates as they are. Does not
  // change the camera: cam_from_world, PixelFromWorld and `camproj project` stay absolute.
  std::optional<Eigen::Vector3d> world_origin = std::nullopt;

  // Throws std::invalid_argument naming the field on any invalid part.
  void Check() const;
};

// Everything derived from a Camera, in the units and frames of docs/conventions.md.
struct CameraViews {
  LookAt look_at;                          // target at target_distance along the gaze
  std::optional<Frustum> frustum;          // absent when skew != 0 (no glFrustum form)
  std::optional<Perspective> perspective;  // only where HasPerspectiveForm(*frustum)
  std::optional<Ortho> ortho;              // orthographic camera without skew: the glOrtho box
  Eigen::Matrix4d clip_from_gl_eye;        // projection matrix (pinhole part, skew included)
  Eigen::Matrix4d gl_eye_from_world;       // view matrix
  // The view matrix for vertices given relative to camera.world_origin (point_in_world - origin):
  // GlEyeFromOriginWorld; equals gl_eye_from_world when the camera has no world origin.
  Eigen::Matrix4d gl_eye_from_origin_world;
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
// front of the camera (z_cam <= 0), or if its cam coordinates or its pixel are beyond a double
// (t = 1e308 and X = 1e308, a ray ~1e300 times farther off the axis than along it, or a lens
// polynomial that overflows), for either projection.
std::optional<Eigen::Vector2d> PixelFromWorld(const Camera& camera,
                                              const Eigen::Vector3d& point_in_world);

// An axis-aligned box in world units, e.g. a model's bounding box: min_in_world <= max_in_world on
// each axis.
struct BoxInWorld {
  Eigen::Vector3d min_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_in_world = Eigen::Vector3d::Zero();

  // Throws std::invalid_argument unless every coordinate is finite and min <= max on each axis.
  void Check() const;
  // The 8 corners; bit 0 of the index picks x from max (else min), bit 1 y, bit 2 z.
  Eigen::Vector3d Corner(int index) const;
};

// The depth range (along the view axis, z in cam) that covers a box: its 8 corners' depths,
// widened like FitOptions' default: z_near = min depth / (1 + depth_margin), z_far = max depth *
// (1 + depth_margin).
struct DepthRangeOfBox {
  double min_depth = 0.0;  // of the 8 corners (may be <= 0: the box reaches behind the camera)
  double max_depth = 0.0;
  int nearest_corner = 0;  // BoxInWorld::Corner index of min_depth
  // Absent when a corner is not in front of the camera (min_depth <= 0): the box then crosses
  // the camera's plane, and points of it in front come arbitrarily close, so no near plane covers
  // it (give one: the part nearer than it is clipped).
  std::optional<double> z_near;
  double z_far = 0.0;
};

// The range for `box` seen by a camera at `cam_from_world`. Throws std::invalid_argument when the
// whole box is behind the camera (max depth <= 0), naming the depth, for an invalid pose, box or
// depth_margin < 0, or when a depth or the range is beyond a double (a margin of 1e308).
DepthRangeOfBox DepthRangeCoveringBox(const Rigid3& cam_from_world, const BoxInWorld& box,
                                      double depth_margin = 0.1);

}  // namespace camproj

#endif  // CAMPROJ_CAMERA_H_

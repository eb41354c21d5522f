#include "camproj/camera.h"

#include <cmath>

#include "camproj/world_origin.h"
#include "check.h"

namespace camproj {

void Camera::Check() const {
  image_size.Check();
  intrinsics.Check();
  cam_from_world.Check();
  Frustum{-1.0, 1.0, -1.0, 1.0, z_near, z_far}.Check();
  if (projection == Projection::kOrthographic) {
    if (intrinsics.HasDistortion()) {
      internal::ThrowInvalidArgument("an orthographic camera has no distortion, got ",
                                     DistortionText(intrinsics));
    }
    internal::Require(std::isfinite(z_far), "an orthographic camera needs a finite far plane");
  }
  if (world_origin) internal::RequireFiniteAll(*world_origin, "world origin");
}

CameraViews ViewsOfCamera(const Camera& camera, double target_distance, const GlDepth& depth) {
  camera.Check();
  CameraViews views;
  views.look_at = LookAtFromCamFromWorld(camera.cam_from_world, target_distance);
  views.gl_eye_from_world = GlEyeFromWorld(camera.cam_from_world);
  views.gl_eye_from_origin_world =
      camera.world_origin ? GlEyeFromOriginWorld(camera.cam_from_world, *camera.world_origin)
                          : views.gl_eye_from_world;
  if (camera.projection == Projection::kOrthographic) {
    const Intrinsics& k = camera.intrinsics;
    if (k.skew == 0.0) {
      views.ortho = OrthoFromOrthographic(k, camera.image_size, camera.z_near, camera.z_far);
    }
    views.clip_from_gl_eye =
        ClipFromGlEyeOrthographic(k, camera.image_size, camera.z_near, camera.z_far, depth);
    return views;
  }
  const Intrinsics pinhole = camera.intrinsics.Pinhole();
  if (pinhole.skew == 0.0) {
    views.frustum =
        FrustumFromIntrinsics(pinhole, camera.image_size, camera.z_near, camera.z_far);
    if (HasPerspectiveForm(*views.frustum)) {
      views.perspective = PerspectiveFromFrustum(*views.frustum);
    }
  }
  views.clip_from_gl_eye =
      ClipFromGlEye(pinhole, camera.image_size, camera.z_near, camera.z_far, depth);
  return views;
}

void RequireFiniteViews(const Camera& camera, const GlDepth& depth) {
  const CameraViews views = ViewsOfCamera(camera, 1.0, depth);
  const char* what = "the values are too large for a double";
  internal::Require(views.clip_from_gl_eye.allFinite(), "the projection matrix is not finite: ", what);
  internal::Require(views.gl_eye_from_world.allFinite(), "the view matrix is not finite: ", what);
  internal::Require(views.gl_eye_from_origin_world.allFinite(),
                    "the view matrix relative to the world origin is not finite: ", what);
  internal::Require(views.look_at.eye.allFinite() && views.look_at.target.allFinite() &&
                        views.look_at.up.allFinite(),
                    "the look-at is not finite: ", what);
  if (views.frustum) {
    const Frustum& f = *views.frustum;
    internal::Require(std::isfinite(f.left) && std::isfinite(f.right) && std::isfinite(f.bottom) &&
                          std::isfinite(f.top),
                      "the frustum is not finite: ", what);
  }
  if (views.ortho) {
    const Ortho& o = *views.ortho;
    internal::Require(std::isfinite(o.left) && std::isfinite(o.right) && std::isfinite(o.bottom) &&
                          std::isfinite(o.top),
                      "the ortho box is not finite: ", what);
  }
  if (views.perspective) {
    internal::Require(std::isfinite(views.perspective->fovy_deg) && std::isfinite(views.perspective->aspect),
                      "the perspective is not finite: ", what);
  }
}

std::optional<Eigen::Vector2d> PixelFromWorld(const Camera& camera,
                                              const Eigen::Vector3d& point_in_world) {
  const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
  if (!(point_in_cam.z() > 0.0)) return std::nullopt;
  // A finite point whose cam coordinates overflow (t = 1e308, X = 1e308) has no pixel either.
  if (!point_in_cam.allFinite()) return std::nullopt;
  if (camera.projection == Projection::kOrthographic) {
    const Intrinsics& k = camera.intrinsics;
    const Eigen::Vector2d pixel(k.fx * point_in_cam.x() + k.skew * point_in_cam.y() + k.cx,
                                k.fy * point_in_cam.y() + k.cy);
    if (!pixel.allFinite()) return std::nullopt;
    return pixel;
  }
  const Eigen::Vector2d pixel = PixelFromCam(camera.intrinsics, point_in_cam);
  if (!pixel.allFinite()) return std::nullopt;
  return pixel;
}

void BoxInWorld::Check() const {
  for (int axis = 0; axis < 3; ++axis) {
    internal::Require(std::isfinite(min_in_world[axis]) && std::isfinite(max_in_world[axis]),
                      "box coordinates must be finite, got min ", min_in_world.transpose(),
                      ", max ", max_in_world.transpose());
    internal::Require(min_in_world[axis] <= max_in_world[axis], "box min must be <= max on each axis, got ",
                      "min ", min_in_world.transpose(), ", max ", max_in_world.transpose());
  }
}

Eigen::Vector3d BoxInWorld::Corner(int index) const {
  return {(index & 1) ? max_in_world.x() : min_in_world.x(),
          (index & 2) ? max_in_world.y() : min_in_world.y(),
          (index & 4) ? max_in_world.z() : min_in_world.z()};
}

DepthRangeOfBox DepthRangeCoveringBox(const Rigid3& cam_from_world, const BoxInWorld& box,
                                      double depth_margin) {
  cam_from_world.Check();
  box.Check();
  internal::Require(std::isfinite(depth_margin) && depth_margin >= 0.0,
                    "depth margin must be >= 0, got ", depth_margin);
  DepthRangeOfBox range;
  for (int i = 0; i < 8; ++i) {
    const double depth = (cam_from_world * box.Corner(i)).z();
    internal::Require(std::isfinite(depth), "the depth of the box's corner (",
                      box.Corner(i).transpose(), ") cannot be represented in a double (", depth,
                      ")");
    if (i == 0 || depth < range.min_depth) {
      range.min_depth = depth;
      range.nearest_corner = i;
    }
    if (i == 0 || depth > range.max_depth) range.max_depth = depth;
  }
  internal::Require(range.max_depth > 0.0, "the box (min ", box.min_in_world.transpose(), ", max ",
                    box.max_in_world.transpose(),
                    ") is entirely behind the camera (its farthest corner at depth ",
                    range.max_depth, ")");
  if (range.min_depth > 0.0) range.z_near = range.min_depth / (1.0 + depth_margin);
  range.z_far = range.max_depth * (1.0 + depth_margin);
  // A margin of 1e308 overflows far and can underflow near to 0: no plane pair to give.
  internal::Require(std::isfinite(range.z_far) && (!range.z_near || *range.z_near > 0.0),
                    "the depth range covering the box cannot be represented in a double (depths ",
                    range.min_depth, " to ", range.max_depth, ", margin ", depth_margin,
                    ": near ", range.z_near.value_or(0.0), ", far ", range.z_far, ")");
  return range;
}

}  // namespace camproj

#include "camproj/camera.h"

#include <cmath>

#include "check.h"

namespace camproj {

void Camera::Check() const {
  image_size.Check();
  intrinsics.Check();
  cam_from_world.Check();
  Frustum{-1.0, 1.0, -1.0, 1.0, z_near, z_far}.Check();
  if (projection == Projection::kOrthographic) {
    internal::Require(!intrinsics.HasDistortion(), "an orthographic camera has no distortion, got k1 = ",
                      intrinsics.k1, ", k2 = ", intrinsics.k2);
    internal::Require(std::isfinite(z_far), "an orthographic camera needs a finite far plane");
  }
}

CameraViews ViewsOfCamera(const Camera& camera, double target_distance, const GlDepth& depth) {
  camera.Check();
  CameraViews views;
  views.look_at = LookAtFromCamFromWorld(camera.cam_from_world, target_distance);
  views.gl_eye_from_world = GlEyeFromWorld(camera.cam_from_world);
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
    if (IsSymmetric(*views.frustum)) views.perspective = PerspectiveFromFrustum(*views.frustum);
  }
  views.clip_from_gl_eye =
      ClipFromGlEye(pinhole, camera.image_size, camera.z_near, camera.z_far, depth);
  return views;
}

std::optional<Eigen::Vector2d> PixelFromWorld(const Camera& camera,
                                              const Eigen::Vector3d& point_in_world) {
  const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
  if (!(point_in_cam.z() > 0.0)) return std::nullopt;
  if (camera.projection == Projection::kOrthographic) {
    const Intrinsics& k = camera.intrinsics;
    return Eigen::Vector2d(k.fx * point_in_cam.x() + k.skew * point_in_cam.y() + k.cx,
                           k.fy * point_in_cam.y() + k.cy);
  }
  return PixelFromCam(camera.intrinsics, point_in_cam);
}

}  // namespace camproj

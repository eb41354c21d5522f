#include "camproj/camera.h"

#include "check.h"

namespace camproj {

void Camera::Check() const {
  image_size.Check();
  intrinsics.Check();
  cam_from_world.Check();
  Frustum{-1.0, 1.0, -1.0, 1.0, z_near, z_far}.Check();
}

CameraViews ViewsOfCamera(const Camera& camera, double target_distance, const GlDepth& depth) {
  camera.Check();
  CameraViews views;
  views.look_at = LookAtFromCamFromWorld(camera.cam_from_world, target_distance);
  const Intrinsics pinhole = camera.intrinsics.Pinhole();
  if (pinhole.skew == 0.0) {
    views.frustum =
        FrustumFromIntrinsics(pinhole, camera.image_size, camera.z_near, camera.z_far);
    if (IsSymmetric(*views.frustum)) views.perspective = PerspectiveFromFrustum(*views.frustum);
  }
  views.clip_from_gl_eye =
      ClipFromGlEye(pinhole, camera.image_size, camera.z_near, camera.z_far, depth);
  views.gl_eye_from_world = GlEyeFromWorld(camera.cam_from_world);
  return views;
}

std::optional<Eigen::Vector2d> PixelFromWorld(const Camera& camera,
                                              const Eigen::Vector3d& point_in_world) {
  const Eigen::Vector3d point_in_cam = camera.cam_from_world * point_in_world;
  if (!(point_in_cam.z() > 0.0)) return std::nullopt;
  return PixelFromCam(camera.intrinsics, point_in_cam);
}

}  // namespace camproj

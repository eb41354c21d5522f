#include "camproj/look_at.h"

#include <Eigen/Geometry>

#include "check.h"

namespace camproj {

using internal::Require;
using internal::RequireFiniteAll;

Rigid3 CamFromWorldFromLookAt(const LookAt& look_at) {
  RequireFiniteAll(look_at.eye, "look-at eye");
  RequireFiniteAll(look_at.target, "look-at target");
  RequireFiniteAll(look_at.up, "look-at up");
  const Eigen::Vector3d gaze = look_at.target - look_at.eye;
  RequireFiniteAll(gaze, "look-at target - eye");
  // stableNorm/stableNormalized: no underflow for a gaze of 1e-200, no overflow for 1e200.
  Require(gaze.stableNorm() > 0.0, "look-at eye equals target (", look_at.eye.transpose(),
          "): the gaze direction is undefined");
  Require(look_at.up.stableNorm() > 0.0, "look-at up is the zero vector");
  const Eigen::Vector3d w = -gaze.stableNormalized();
  const Eigen::Vector3d up_cross_w = look_at.up.stableNormalized().cross(w);
  const double sin_angle = up_cross_w.norm();
  Require(sin_angle >= kLookAtMinSinUpGaze, "look-at up (", look_at.up.transpose(),
          ") is parallel to the gaze (sin of the angle ", sin_angle, " < ",
          kLookAtMinSinUpGaze, "): the roll is undefined; choose another up");
  const Eigen::Vector3d u = up_cross_w.normalized();
  const Eigen::Vector3d v = w.cross(u);

  // gl_eye_from_world has rows (u, v, w); cam = diag(1, -1, -1) gl_eye flips the last two.
  Eigen::Matrix3d cam_from_world_rotation;
  cam_from_world_rotation.row(0) = u;
  cam_from_world_rotation.row(1) = -v;
  cam_from_world_rotation.row(2) = -w;
  return CamFromWorldFromCenter(cam_from_world_rotation, look_at.eye);
}

LookAt LookAtFromCamFromWorld(const Rigid3& cam_from_world, double target_distance) {
  cam_from_world.Check();
  Require(std::isfinite(target_distance) && target_distance > 0.0,
          "look-at target distance must be finite and positive, got ", target_distance);
  LookAt look_at;
  look_at.eye = CameraCenterInWorld(cam_from_world);
  const Eigen::Vector3d gaze = cam_from_world.rotation.row(2).transpose();
  look_at.target = look_at.eye + target_distance * gaze;
  look_at.up = -cam_from_world.rotation.row(1).transpose();
  // A finite translation of 1e308 can put the eye, or the target beyond it, past a double.
  internal::RequireFiniteResult(look_at.eye, "the look-at eye of the pose");
  internal::RequireFiniteResult(look_at.target, "the look-at target at distance ",
                                target_distance);
  return look_at;
}

}  // namespace camproj

// Look-at (eye, target, up) <-> pose, exactly as gluLookAt builds its view matrix:
//   g = target - eye, w = -g/|g|, u = up x w / |up x w|, v = w x u;
//   gl_eye_from_world has rotation rows (u, v, w) and translation -R eye.
// cam_from_world = gl_eye_from_cam^-1 * gl_eye_from_world (docs/conventions.md).
#ifndef CAMPROJ_LOOK_AT_H_
#define CAMPROJ_LOOK_AT_H_

#include <Eigen/Core>

#include "camproj/pose.h"

namespace camproj {

struct LookAt {
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();     // camera centre, world
  Eigen::Vector3d target = -Eigen::Vector3d::UnitZ();  // a point on the gaze, world
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();     // any vector not parallel to the gaze, world
};

// Below this sine of the angle between `up` and the gaze, look-at is refused: the roll would be
// set by rounding (the cross product's relative error is ~1e-16 / sin).
inline constexpr double kLookAtMinSinUpGaze = 1e-6;

// The pose gluLookAt(eye, target, up) describes. Throws std::invalid_argument naming the problem
// for non-finite input, eye == target, zero up, or up parallel to the gaze (where glm's lookAt
// returns NaN).
Rigid3 CamFromWorldFromLookAt(const LookAt& look_at);

// eye = camera centre; up = the camera's true up (-y of cam in world: a unit vector orthogonal to
// the gaze); target = eye + target_distance * gaze (unit gaze = +z of cam in world).
// Throws unless the pose passes Rigid3::Check() and target_distance is finite and positive.
// CamFromWorldFromLookAt(LookAtFromCamFromWorld(p, d)) == p to rounding.
LookAt LookAtFromCamFromWorld(const Rigid3& cam_from_world, double target_distance = 1.0);

}  // namespace camproj

#endif  // CAMPROJ_LOOK_AT_H_

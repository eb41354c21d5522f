// Rigid transforms named by frames (docs/conventions.md): `Rigid3 cam_from_world` maps
// point_in_world to point_in_cam = rotation * point_in_world + translation.
#ifndef CAMPROJ_POSE_H_
#define CAMPROJ_POSE_H_

#include <Eigen/Core>

namespace camproj {

struct Rigid3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // Throws std::invalid_argument unless every entry is finite and `rotation` is a proper rotation:
  // |R^T R - I| <= kRotationTolerance entrywise and det(R) > 0.
  void Check() const;

  // The 4x4 homogeneous matrix [R t; 0 1] (column-major, as GL uploads it).
  Eigen::Matrix4d ToMatrix() const;

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
};

// Orthonormality a rotation read from a file (17 significant digits) or built in double passes.
inline constexpr double kRotationTolerance = 1e-9;

// b_from_a -> a_from_b.
Rigid3 Inverse(const Rigid3& b_from_a);

// c_from_b * b_from_a = c_from_a.
Rigid3 operator*(const Rigid3& c_from_b, const Rigid3& b_from_a);

// The camera centre C in world: cam_from_world * C = 0, i.e. C = -R^T t.
Eigen::Vector3d CameraCenterInWorld(const Rigid3& cam_from_world);

// cam_from_world with rotation R and camera centre C: t = -R C.
Rigid3 CamFromWorldFromCenter(const Eigen::Matrix3d& cam_from_world_rotation,
                              const Eigen::Vector3d& center_in_world);

// Rigid3 from a 4x4 [R t; 0 1]; throws unless the bottom row is (0,0,0,1) and R is a rotation.
Rigid3 Rigid3FromMatrix(const Eigen::Matrix4d& matrix);

}  // namespace camproj

#endif  // CAMPROJ_POSE_H_

#include "camproj/pose.h"

#include <cmath>

#include <Eigen/LU>

#include "check.h"

namespace camproj {

using internal::Require;
using internal::RequireFiniteAll;

void Rigid3::Check() const {
  RequireFiniteAll(rotation, "rotation");
  RequireFiniteAll(translation, "translation");
  const double off = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity())
                         .cwiseAbs()
                         .maxCoeff();
  Require(off <= kRotationTolerance, "rotation is not orthonormal: max |R^T R - I| = ", off,
          " > ", kRotationTolerance);
  const double det = rotation.determinant();
  Require(det > 0.0, "rotation has det ", det,
          " < 0: a reflection, i.e. a left-handed (mirrored) frame; flip one world axis");
}

Eigen::Matrix4d Rigid3::ToMatrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation;
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Rigid3 Inverse(const Rigid3& b_from_a) {
  Rigid3 a_from_b;
  a_from_b.rotation = b_from_a.rotation.transpose();
  a_from_b.translation = -(a_from_b.rotation * b_from_a.translation);
  return a_from_b;
}

Rigid3 operator*(const Rigid3& c_from_b, const Rigid3& b_from_a) {
  Rigid3 c_from_a;
  c_from_a.rotation = c_from_b.rotation * b_from_a.rotation;
  c_from_a.translation = c_from_b.rotation * b_from_a.translation + c_from_b.translation;
  return c_from_a;
}

Eigen::Vector3d CameraCenterInWorld(const Rigid3& cam_from_world) {
  return -(cam_from_world.rotation.transpose() * cam_from_world.translation);
}

Rigid3 CamFromWorldFromCenter(const Eigen::Matrix3d& cam_from_world_rotation,
                              const Eigen::Vector3d& center_in_world) {
  Rigid3 cam_from_world;
  cam_from_world.rotation = cam_from_world_rotation;
  cam_from_world.translation = -(cam_from_world_rotation * center_in_world);
  return cam_from_world;
}

Rigid3 Rigid3FromMatrix(const Eigen::Matrix4d& matrix) {
  RequireFiniteAll(matrix, "rigid matrix");
  Require(matrix(3, 0) == 0.0 && matrix(3, 1) == 0.0 && matrix(3, 2) == 0.0 && matrix(3, 3) == 1.0,
          "a rigid 4x4 matrix must have bottom row (0, 0, 0, 1), got (", matrix(3, 0), ", ",
          matrix(3, 1), ", ", matrix(3, 2), ", ", matrix(3, 3), ")");
  Rigid3 rigid;
  rigid.rotation = matrix.topLeftCorner<3, 3>();
  rigid.translation = matrix.topRightCorner<3, 1>();
  rigid.Check();
  return rigid;
}

}  // namespace camproj

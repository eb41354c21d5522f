// Helpers to compare camproj's Eigen matrices with glm's (column-major, m[column][row]).
#ifndef CAMPROJ_TESTS_GLM_COMPARE_H_
#define CAMPROJ_TESTS_GLM_COMPARE_H_

#include <algorithm>

#include <Eigen/Core>
#include <glm/glm.hpp>

namespace camproj {
namespace testing {

inline Eigen::Matrix4d FromGlm(const glm::dmat4& m) {
  Eigen::Matrix4d e;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) e(row, col) = m[col][row];
  }
  return e;
}

inline glm::dvec3 ToGlm(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// max |a - b| over entries divided by max |b| (1 if b is zero).
inline double RelativeDifference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const double scale = std::max(1e-300, b.cwiseAbs().maxCoeff());
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

}  // namespace testing
}  // namespace camproj

#endif  // CAMPROJ_TESTS_GLM_COMPARE_H_

// Zhang's closed form (private; calibrate.cc): a camera's K from the homographies of several
// views of planes (Z. Zhang, "A flexible new technique for camera calibration", PAMI 2000).
#ifndef CAMPROJ_SRC_FIT_ZHANG_H_
#define CAMPROJ_SRC_FIT_ZHANG_H_

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/conventions.h"
#include "camproj/intrinsics.h"

namespace camproj {
namespace internal {

// Which entries of K the closed form solves for; the others hold: skew 0, fy = fx, the principal
// point at the image centre.
struct ZhangModel {
  bool aspect_free = true;
  bool principal_point_free = true;
  bool skew_free = false;
};

// The number of unknowns of B = K^-T K^-1 up to scale under `model` (5 with everything free).
int ZhangUnknowns(const ZhangModel& model);

// K from the homographies (plane coordinates -> kCenter pixels, scale arbitrary) of >= 1 views:
// each gives the two constraints h1^T B h2 = 0 and h1^T B h1 = h2^T B h2 on B = K^-T K^-1,
// solved in pixels scaled by the image size, B the null vector of the stacked constraints.
// std::nullopt when the views give fewer constraints than B has unknowns less one, or B is not
// positive definite (the views do not determine K: e.g. parallel boards, or noise swamping
// nearly fronto-parallel views).
std::optional<Intrinsics> ZhangIntrinsics(const std::vector<Eigen::Matrix3d>& homographies,
                                          const ImageSize& image_size, const ZhangModel& model);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_ZHANG_H_

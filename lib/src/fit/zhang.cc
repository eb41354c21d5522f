#include "fit/zhang.h"

#include <cmath>

#include <Eigen/Dense>

namespace camproj {
namespace internal {

namespace {

// b = (B11, B12, B22, B13, B23, B33) of the symmetric B; the reduced unknowns are groups of its
// entries that share one value (B11 = B22 when fy = fx and skew = 0) or that vanish (B12 with
// zero skew; B13, B23 with the principal point at the origin of the scaled pixels).
std::vector<std::vector<int>> UnknownGroups(const ZhangModel& model) {
  std::vector<std::vector<int>> groups;
  if (!model.aspect_free && !model.skew_free) {
    groups.push_back({0, 2});
  } else {
    groups.push_back({0});
    groups.push_back({2});
  }
  if (model.skew_free) groups.push_back({1});
  if (model.principal_point_free) {
    groups.push_back({3});
    groups.push_back({4});
  }
  groups.push_back({5});
  return groups;
}

// Zhang's v_ij: h_i^T B h_j = v_ij^T b for the columns h_i, h_j of H.
Eigen::Matrix<double, 1, 6> V(const Eigen::Matrix3d& h, int i, int j) {
  Eigen::Matrix<double, 1, 6> v;
  v << h(0, i) * h(0, j), h(0, i) * h(1, j) + h(1, i) * h(0, j), h(1, i) * h(1, j),
      h(2, i) * h(0, j) + h(0, i) * h(2, j), h(2, i) * h(1, j) + h(1, i) * h(2, j),
      h(2, i) * h(2, j);
  return v;
}

}  // namespace

int ZhangUnknowns(const ZhangModel& model) {
  return static_cast<int>(UnknownGroups(model).size());
}

std::optional<Intrinsics> ZhangIntrinsics(const std::vector<Eigen::Matrix3d>& homographies,
                                          const ImageSize& image_size, const ZhangModel& model) {
  const std::vector<std::vector<int>> groups = UnknownGroups(model);
  const int unknowns = static_cast<int>(groups.size());
  const int rows = 2 * static_cast<int>(homographies.size());
  // B is defined up to scale: unknowns - 1 degrees of freedom.
  if (rows < unknowns - 1) return std::nullopt;

  // Pixels scaled to about [-1, 1] around the image centre: the constraints' columns are then of
  // comparable size (in raw pixels B33 and B11 differ by ~1e6), and the centre is the origin.
  const double scale = 0.5 * (image_size.width + image_size.height);
  Eigen::Matrix3d scaled_from_pixel = Eigen::Matrix3d::Identity();
  scaled_from_pixel(0, 0) = scaled_from_pixel(1, 1) = 1.0 / scale;
  scaled_from_pixel(0, 2) = -0.5 * (image_size.width - 1) / scale;
  scaled_from_pixel(1, 2) = -0.5 * (image_size.height - 1) / scale;

  Eigen::MatrixXd a(rows, unknowns);
  for (size_t view = 0; view < homographies.size(); ++view) {
    Eigen::Matrix3d h = scaled_from_pixel * homographies[view];
    h /= h.norm();
    const Eigen::Matrix<double, 1, 6> v12 = V(h, 0, 1);
    const Eigen::Matrix<double, 1, 6> v11_minus_v22 = V(h, 0, 0) - V(h, 1, 1);
    for (int g = 0; g < unknowns; ++g) {
      double first = 0.0, second = 0.0;
      for (int entry : groups[g]) {
        first += v12(entry);
        second += v11_minus_v22(entry);
      }
      a(2 * static_cast<int>(view), g) = first;
      a(2 * static_cast<int>(view) + 1, g) = second;
    }
  }
  // The null vector: the right singular vector of the smallest singular value (a square system,
  // rows == unknowns - 1, gets one from the full V).
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd c = svd.matrixV().col(unknowns - 1);
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  for (int g = 0; g < unknowns; ++g) {
    for (int entry : groups[g]) b(entry) = c(g);
  }
  Eigen::Matrix3d big_b;
  big_b << b(0), b(1), b(3), b(1), b(2), b(4), b(3), b(4), b(5);
  if (big_b(0, 0) < 0.0) big_b = -big_b;

  // B = K^-T K^-1 = L L^T (Cholesky): K^-1 = L^T up to a positive scale.
  const Eigen::LLT<Eigen::Matrix3d> llt(big_b);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix3d k_inverse = llt.matrixL().transpose();
  Eigen::Matrix3d k_scaled = k_inverse.inverse();
  if (!k_scaled.allFinite() || k_scaled(2, 2) == 0.0) return std::nullopt;
  k_scaled /= k_scaled(2, 2);
  const Eigen::Matrix3d k = scaled_from_pixel.inverse() * k_scaled;
  Intrinsics intrinsics;
  intrinsics.fx = k(0, 0);
  intrinsics.fy = k(1, 1);
  intrinsics.skew = model.skew_free ? k(0, 1) : 0.0;
  intrinsics.cx = k(0, 2);
  intrinsics.cy = k(1, 2);
  if (!(intrinsics.fx > 0.0) || !(intrinsics.fy > 0.0) || !k.allFinite()) return std::nullopt;
  return intrinsics;
}

}  // namespace internal
}  // namespace camproj

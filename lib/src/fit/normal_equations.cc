#include "fit/normal_equations.h"

#include <vector>

#include <Eigen/Core>

#include "fit/reprojection_error.h"

namespace camproj {
namespace internal {

namespace {

// LocalNormalEquations (normal_equations.h). kNumGeneral (the general columns) and
// kPrincipalPoint (whether it is free) are template parameters so that the accumulation below is
// unrolled; kRadialOnly (ResidualOfCamPoint) where p1 = p2 = k3 = 0 and none of them is free.
template <int kNumGeneral, bool kPrincipalPoint, bool kRadialOnly>
bool AccumulateLocalNormalEquations(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                                    const IntrinsicValues& intrinsics,
                                    const JacobianColumns& columns, NormalEquations* out) {
  // Each column's two entries (one per residual) side by side in an Array2d, so that one SIMD
  // product and sum serve both residuals; the two halves are added at the end. J^T J: the upper
  // triangle of the general columns' products, and each general column's sum (its products with
  // the principal point's columns (1, 0) and (0, 1)).
  constexpr int kTriangle = kNumGeneral * (kNumGeneral + 1) / 2;
  Eigen::Array2d jtj[kTriangle];
  Eigen::Array2d jtr[kNumGeneral];
  Eigen::Array2d column_sums[kNumGeneral];
  for (auto& e : jtj) e.setZero();
  for (auto& e : jtr) e.setZero();
  for (auto& e : column_sums) e.setZero();
  Eigen::Array2d residual_sum = Eigen::Array2d::Zero();
  Eigen::Array2d cost = Eigen::Array2d::Zero();
  bool all_in_front = true;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = rotation * (points[i] - center);
    // Checked after the loop: with an exit here GCC stores every sum twice per point (~15 % more
    // instructions). A point behind makes infinities or NaNs, never a trap, and is refused below.
    all_in_front &= p.z() > 0.0;
    Eigen::Array2d r;
    double jk[2 * kFitIntrinsicsSize];  // row-major 2 x kFitIntrinsicsSize
    double jp[6];                                 // row-major 2 x 3: d residual / d p
    ResidualOfCamPoint<kRadialOnly>(intrinsics.data(), p, pixels[i], r.data(), jk, jp);
    Eigen::Array2d j[kNumGeneral];
    const Eigen::Array2d ax(jp[0], jp[3]);
    const Eigen::Array2d ay(jp[1], jp[4]);
    const Eigen::Array2d az(jp[2], jp[5]);
    // d residual / d theta = -a^T [p]x = (p x a)^T; d residual / d c = -a^T.
    j[0] = p.y() * az - p.z() * ay;
    j[1] = p.z() * ax - p.x() * az;
    j[2] = p.x() * ay - p.y() * ax;
    j[3] = -ax;
    j[4] = -ay;
    j[5] = -az;
    for (int g = 6; g < kNumGeneral; ++g) {
      const int slot = columns.general_slots[g - 6];
      j[g] = Eigen::Array2d(jk[slot], jk[kFitIntrinsicsSize + slot]);
    }
    // GCC does not unroll the triangular loops by itself; unrolled, they take ~30 % fewer
    // instructions per point (callgrind, 10 parameters).
    int k = 0;
#pragma GCC unroll 16
    for (int a = 0; a < kNumGeneral; ++a) {
#pragma GCC unroll 16
      for (int b = a; b < kNumGeneral; ++b) jtj[k++] += j[a] * j[b];
      jtr[a] += j[a] * r;
      if (kPrincipalPoint) column_sums[a] += j[a];
    }
    residual_sum += r;
    cost += r * r;
  }
  if (!all_in_front) return false;

  // In parameter order.
  out->jtj.setZero(columns.num_params, columns.num_params);
  out->jtr.resize(columns.num_params);
  int k = 0;
  for (int a = 0; a < kNumGeneral; ++a) {
    const int row = columns.general_parameter[a];
    for (int b = a; b < kNumGeneral; ++b, ++k) {
      const int column = columns.general_parameter[b];
      out->jtj(row, column) = out->jtj(column, row) = jtj[k].sum();
    }
    out->jtr(row) = jtr[a].sum();
    if (kPrincipalPoint) {
      out->jtj(row, columns.cx_parameter) = out->jtj(columns.cx_parameter, row) = column_sums[a](0);
      out->jtj(row, columns.cy_parameter) = out->jtj(columns.cy_parameter, row) = column_sums[a](1);
    }
  }
  if (kPrincipalPoint) {
    out->jtj(columns.cx_parameter, columns.cx_parameter) = static_cast<double>(points.size());
    out->jtj(columns.cy_parameter, columns.cy_parameter) = static_cast<double>(points.size());
    out->jtr(columns.cx_parameter) = residual_sum(0);
    out->jtr(columns.cy_parameter) = residual_sum(1);
  }
  out->cost = cost.sum();
  return true;
}

template <bool kPrincipalPoint, bool kRadialOnly>
bool AccumulateLocalNormalEquations(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Eigen::Vector2d>& pixels,
                                    const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                                    const IntrinsicValues& intrinsics,
                                    const JacobianColumns& columns, NormalEquations* out) {
  // 6 (pose) + up to 5 general slots: focal, aspect, skew, k1, k2.
  switch (columns.num_general) {
#define CAMPROJ_ACCUMULATE_CASE(n)                                                            \
  case n:                                                                                     \
    return AccumulateLocalNormalEquations<n, kPrincipalPoint, kRadialOnly>(                   \
        points, pixels, rotation, center, intrinsics, columns, out);
    CAMPROJ_ACCUMULATE_CASE(6)
    CAMPROJ_ACCUMULATE_CASE(7)
    CAMPROJ_ACCUMULATE_CASE(8)
    CAMPROJ_ACCUMULATE_CASE(9)
    CAMPROJ_ACCUMULATE_CASE(10)
#undef CAMPROJ_ACCUMULATE_CASE
    default:
      return AccumulateLocalNormalEquations<11, kPrincipalPoint, kRadialOnly>(
          points, pixels, rotation, center, intrinsics, columns, out);
  }
}

}  // namespace

bool LocalNormalEquations(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& pixels,
                          const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                          const IntrinsicValues& intrinsics, const JacobianColumns& columns,
                          NormalEquations* out) {
  bool radial_only = RadialOnly(intrinsics.data());
  for (int g = 0; g < columns.num_general - 6; ++g) {
    radial_only &= columns.general_slots[g] < 7;  // p1, p2, k3 fixed
  }
  const bool pp = columns.cx_parameter >= 0;
  return pp ? (radial_only ? AccumulateLocalNormalEquations<true, true>(
                                 points, pixels, rotation, center, intrinsics, columns, out)
                           : AccumulateLocalNormalEquations<true, false>(
                                 points, pixels, rotation, center, intrinsics, columns, out))
            : (radial_only ? AccumulateLocalNormalEquations<false, true>(
                                 points, pixels, rotation, center, intrinsics, columns, out)
                           : AccumulateLocalNormalEquations<false, false>(
                                 points, pixels, rotation, center, intrinsics, columns, out));
}

void ToChart(const Eigen::Matrix3d& d_theta_d_omega, const Eigen::Matrix3d& rotation,
             NormalEquations* normal) {
  const int num_intrinsics = static_cast<int>(normal->jtr.size()) - 6;
  Eigen::Matrix<double, 6, 6> t = Eigen::Matrix<double, 6, 6>::Zero();
  t.topLeftCorner<3, 3>() = d_theta_d_omega;
  t.bottomRightCorner<3, 3>() = rotation;
  const Eigen::Matrix<double, 6, 6> pose_block = normal->jtj.topLeftCorner<6, 6>();
  normal->jtj.topLeftCorner<6, 6>() = t.transpose() * pose_block * t;
  const Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kFitIntrinsicsSize> cross_block =
      t.transpose() * normal->jtj.topRightCorner(6, num_intrinsics);
  normal->jtj.topRightCorner(6, num_intrinsics) = cross_block;
  normal->jtj.bottomLeftCorner(num_intrinsics, 6) = cross_block.transpose();
  const Eigen::Matrix<double, 6, 1> pose_gradient = normal->jtr.head<6>();
  normal->jtr.head<6>() = t.transpose() * pose_gradient;
}

bool ComputeNormalEquations(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                            const IntrinsicValues& intrinsics, const JacobianColumns& columns,
                            NormalEquations* out) {
  if (!LocalNormalEquations(points, pixels, rotation, center, intrinsics, columns, out)) {
    return false;
  }
  ToChart(Eigen::Matrix3d::Identity(), rotation, out);
  return true;
}

bool ComputeNormalEquations(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                            const Model& model, NormalEquations* out) {
  return ComputeNormalEquations(points, pixels, rotation, center, model.value,
                                JacobianColumns(model), out);
}

}  // namespace internal
}  // namespace camproj

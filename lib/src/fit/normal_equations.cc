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
  // T = diag(A, R) is block diagonal: T^T P T by its 3 x 3 blocks, a third of the dense 6 x 6
  // products' multiplications (it runs once per pass over the points).
  const Eigen::Matrix3d& a = d_theta_d_omega;
  const Eigen::Matrix3d& r = rotation;
  ParamMatrix& jtj = normal->jtj;
  const int num_intrinsics = static_cast<int>(normal->jtr.size()) - 6;
  const Eigen::Matrix3d rotation_block = a.transpose() * jtj.block<3, 3>(0, 0) * a;
  const Eigen::Matrix3d mixed_block = a.transpose() * jtj.block<3, 3>(0, 3) * r;
  const Eigen::Matrix3d center_block = r.transpose() * jtj.block<3, 3>(3, 3) * r;
  jtj.block<3, 3>(0, 0) = rotation_block;
  jtj.block<3, 3>(0, 3) = mixed_block;
  jtj.block<3, 3>(3, 0) = mixed_block.transpose();
  jtj.block<3, 3>(3, 3) = center_block;
  for (int j = 6; j < 6 + num_intrinsics; ++j) {
    const Eigen::Vector3d rotation_column = a.transpose() * jtj.block<3, 1>(0, j);
    const Eigen::Vector3d center_column = r.transpose() * jtj.block<3, 1>(3, j);
    jtj.block<3, 1>(0, j) = rotation_column;
    jtj.block<3, 1>(3, j) = center_column;
    jtj.block<1, 3>(j, 0) = rotation_column.transpose();
    jtj.block<1, 3>(j, 3) = center_column.transpose();
  }
  normal->jtr.head<3>() = (a.transpose() * normal->jtr.head<3>()).eval();
  normal->jtr.segment<3>(3) = (r.transpose() * normal->jtr.segment<3>(3)).eval();
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

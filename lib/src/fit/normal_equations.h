// Gauss-Newton normal equations of the reprojection residuals (private): J^T J, J^T r and r^T r
// over all points for a camera in the scene's normalized world (point_in_cam = rotation *
// (point - center)) and a Model's intrinsics, accumulated point by point so that no 2N x p matrix
// is formed. The parameters are the pose's six, then the free intrinsic slots in slot order; how
// the pose is parameterized is said where the equations are made (LocalNormalEquations, ToChart,
// ComputeNormalEquations). The refinement solves with them; the assessment inverts them.
#ifndef CAMPROJ_SRC_FIT_NORMAL_EQUATIONS_H_
#define CAMPROJ_SRC_FIT_NORMAL_EQUATIONS_H_

#include <array>
#include <vector>

#include <Eigen/Core>

#include "fit/model.h"
#include "fit/reprojection_error.h"

namespace camproj {
namespace internal {

// The pose's 6 parameters and every intrinsic slot.
inline constexpr int kMaxParams = 6 + kFitIntrinsicsSize;
// At most kMaxParams entries, sized at run time: on the stack, never allocated.
using ParamVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxParams, 1>;
using ParamMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxParams, kMaxParams>;

struct NormalEquations {
  ParamMatrix jtj;
  ParamVector jtr;
  double cost = 0.0;  // sum of squared residuals
};

// Every intrinsic slot's value, free or fixed (Model::value's layout).
using IntrinsicValues = std::array<double, kFitIntrinsicsSize>;

// A fit's J^T J at its answer (or one settling step before it) in ComputeNormalEquations' chart
// -- turns about the camera's axes, the centre in the scene's normalized world, then the model's
// free slots in slot order -- with the answer there and the world's normalization
// (point_in_world = centroid + scale * point). A point's reprojection sigma does not depend on
// the parameterization, so the determination check reads a fitted rival's from this instead of
// linearizing its camera over every point again (fit/determination.cc).
struct ChartLinearization {
  ParamMatrix jtj;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // point_in_cam = rotation * (x - center)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Model model;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // jtj is one step back from the camera, a step the polish took on a prediction (up to 1e-2 of
  // the residuals' sigma: LeastSquaresOutcome::normal_predicted_step_back); otherwise at most a
  // step within its convergence test back.
  bool predicted_step_back = false;
};

// The columns of the Jacobian in the camera's local frame (see LocalNormalEquations), split by
// how they are summed: the principal point's two columns are the same for every point
// (d residual / d (cx, cy) = I), so their rows of J^T J are sums of the other columns and need
// no products; every other column ("general": the pose and the other free slots) varies.
struct JacobianColumns {
  explicit JacobianColumns(const Model& model) {
    int parameter = 6;
    for (int slot = 0; slot < kFitIntrinsicsSize; ++slot) {
      if (!model.free[slot]) continue;
      if (slot == 2) {
        cx_parameter = parameter;
      } else if (slot == 3) {
        cy_parameter = parameter;
      } else {
        general_slots[num_general - 6] = slot;
        general_parameter[num_general] = parameter;
        ++num_general;
      }
      ++parameter;
    }
    num_params = parameter;
  }
  int num_params = 0;
  int num_general = 6;  // the pose's 6, then the general free slots
  int general_slots[kFitIntrinsicsSize] = {};  // slot of general column 6 + i
  int general_parameter[kMaxParams] = {0, 1, 2, 3, 4, 5};  // parameter index of general column
  int cx_parameter = -1;  // parameter indices of the principal point, -1 when it is fixed
  int cy_parameter = -1;
};

// The normal equations in the camera's local frame at (rotation, center): parameters [theta (3),
// c (3), free intrinsic slots] with R -> exp(theta) R and C -> C + R^T c, so that a point in the
// camera frame moves by dp = -[p]x dtheta - dc. This is the cheapest Jacobian to form per point;
// ToChart maps the sums to the solver's parameters once per pass instead. `columns` is
// JacobianColumns of the model whose slot values `intrinsics` holds. Returns false, leaving
// `out` untouched, if a point is not in front of the camera.
bool LocalNormalEquations(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& pixels,
                          const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                          const IntrinsicValues& intrinsics, const JacobianColumns& columns,
                          NormalEquations* out);

// Maps local normal equations to parameters whose first six are [omega, center] with
// dtheta = d_theta_d_omega domega and dc = rotation dC: J = J_local T with
// T = diag(d_theta_d_omega, rotation, I), so J^T J -> T^T J^T J T and J^T r -> T^T J^T r (only
// the first six rows and columns change).
void ToChart(const Eigen::Matrix3d& d_theta_d_omega, const Eigen::Matrix3d& rotation,
             NormalEquations* normal);

// The normal equations in the user parameterization u = [omega (3, rad, R = exp(omega) R_hat),
// center (3, normalized world), free intrinsic slots] at omega = 0: dp/domega = -[p]x and
// dp/dC = -R_hat. Returns false, leaving `out` untouched, if a point is not in front.
bool ComputeNormalEquations(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                            const IntrinsicValues& intrinsics, const JacobianColumns& columns,
                            NormalEquations* out);

// The same at the model's values.
bool ComputeNormalEquations(const std::vector<Eigen::Vector3d>& points,
                            const std::vector<Eigen::Vector2d>& pixels,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& center,
                            const Model& model, NormalEquations* out);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_NORMAL_EQUATIONS_H_

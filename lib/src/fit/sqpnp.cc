#include "fit/sqpnp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

namespace camproj {
namespace internal {

Eigen::Matrix3d NearestRotationSvd(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * svd.matrixV().transpose();
}

namespace {

using Vector9 = Eigen::Matrix<double, 9, 1>;
using Matrix9 = Eigen::Matrix<double, 9, 9>;
using Matrix39 = Eigen::Matrix<double, 3, 9>;
using Matrix93 = Eigen::Matrix<double, 9, 3>;
using Matrix96 = Eigen::Matrix<double, 9, 6>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using RowMajorMatrix3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// OpenCV's thresholds (calib3d/src/sqpnp.cpp, 4.6): each decides which minimum is found or
// where SQP stops, so they are kept as OpenCV has them for the two to return the same pose.
// Eigenvalues of Omega below this span its null space (absolute, as OpenCV's).
constexpr double kRankTolerance = 1e-7;
// An eigenvector times sqrt(3) with ||E E^T - I||_F^2 below this is taken as the rotation itself
// (its sign fixed by its determinant), without SQP.
constexpr double kOrthogonalitySquaredError = 1e-8;
// SQP stops when a step's squared norm is at most this, or after kSqpMaxSteps steps.
constexpr double kSqpSquaredStep = 1e-10;
constexpr int kSqpMaxSteps = 15;
// SQP's result is projected on the rotations only if its determinant exceeds this; otherwise it
// is kept as is (its cost and translation computed from it, its rotation orthogonalized at the
// end as cv::Rodrigues does).
constexpr double kSqpDeterminant = 1.001;
// The tangent step is skipped where det(N^T Omega N) (N orthonormal) is below this: OpenCV's
// symmetric 3 x 3 inverse refuses there and leaves the step's tangent part zero.
constexpr double kTangentDeterminant = 1e-8;
// OpenCV's nearest rotation uses FOAM where |det| of the matrix is at least this, and FOAM as
// OpenCV starts it (its Newton iteration from -(||m||^2 + 3) / 2 where det < 0, converging to
// the quartic's smallest root) returns the nearest rotation of the sign of the matrix with
// det > 0, so both of OpenCV's runs from +-e start there; below it, an SVD's nearest rotation
// of each sign.
constexpr double kFoamDeterminant = 1e-4;
// OpenCV refuses (CV_Assert) an image spread (the variance of x plus that of y) below this...
constexpr double kMinImageVariance = 1e-5;
// ...an Omega whose largest eigenvalue is below this...
constexpr double kMinLargestEigenvalue = 1e-7;
// ...and more than this many eigenvalues below kRankTolerance: 3 points leave 6.
constexpr int kMaxNullSpace = 6;

// Ours.
// Collinear points leave the rotation about their line free: refused where the centred scatter
// matrix's second eigenvalue is below this fraction of its first (measured by its 2 x 2 minors
// against its trace squared, which bound the ratio within a factor 9): the points then deviate
// from a line by less than ~1e-6 of their extent.
constexpr double kCollinear = 1e-12;
// Coincident points: their spread (the scatter's trace) below this fraction of their squared
// magnitudes, i.e. the coordinates agree to 12 digits.
constexpr double kCoincident = 1e-24;
// Planar points: the scatter's smallest eigenvalue below this fraction of its largest (the
// points within ~1e-5 of their extent from a plane). Omega then has the 3-dimensional null space
// {a n^T} (n the normal: a n^T X_i = a (n.X_i) is absorbed by t) whose vectors are no rotations:
// the search runs on the other 6 eigenvectors (SearchPlanar). Only the starts depend on it.
constexpr double kPlanar = 1e-10;
// FOAM's closed form divides by 2 (s1 + s2)(s1 + s3)(s2 + s3) (s the singular values); where
// that is below this fraction of ||m||^3 the nearest rotation is ill-conditioned and an SVD
// computes it instead. Above it FOAM loses at most ~1e-10 relative.
constexpr double kFoamMinDenominator = 1e-6;
// FOAM's rotation is checked: max |R^T R - I| above this and the SVD computes it instead.
// Rounding leaves ~1e-15 where FOAM converged; seen above it: 3e-3 to 0.98 at a 0.01 deg view
// (FitAutoStress, wild-intrinsics), where the Newton iteration stopped short of the root.
constexpr double kFoamOrthonormal = 1e-12;
// FOAM's Newton iteration for its quartic's largest root (monotone from the upper bound it
// starts at): at most this many steps, stopping at a relative change of kFoamRelativeStep.
constexpr int kFoamMaxSteps = 15;
constexpr double kFoamRelativeStep = 1e-12;
// Where a start is not one OpenCV also makes (an arbitrary basis of a null space of dimension
// >= 2, an SVD's choice among nearest rotations, the planar search, the algebraic start), SQP's
// stopping rule leaves the pose off its minimum by an amount that depends on the path (up to
// ~1e-7 in planar scenes, where SQP converges linearly at ~1e-2 per step: its Hessian leaves out
// the multipliers' curvature). The winner is then polished by Newton-SQP steps to a squared step
// of this (|step| 1e-10: the pose that of the minimum to ~1e-12), at most kPolishMaxSteps.
constexpr double kPolishSquaredStep = 1e-20;
constexpr int kPolishMaxSteps = 8;
// Our SQP's tangent step is skipped only where det(W) < this times trace(W)^3 (W's eigenvalues
// spread by more than ~1e12: singular to rounding), not at OpenCV's absolute 1e-8.
constexpr double kTangentRcond = 1e-36;

// The rounding of a cost r^T Omega r (|r|^2 = 3): ~9 unit roundoffs of |r|^T |Omega| |r| <=
// 3 ||Omega||_F, times 32 for a margin; costs are small differences of Omega's large entries.
constexpr double kCostRoundoffs = 3.0 * 32.0;

// FactorLdlt's pivot floor, relative to the largest diagonal entry: 1e-13 leaves ~3 digits
// beyond rounding for a pivot to carry its sign.
constexpr double kPivotFloor = 1e-13;
// Inverse iteration for the smallest eigenvector (SmallestEigenvector): it converges by the ratio
// of the two smallest eigenvalues per step (~1e-3 for noisy 6-point scenes); stopping at an
// infinity-norm change of 1e-14, the vector is OpenCV's SVD's to ~1e-13, so SQP starts where
// OpenCV's starts. Past kInverseIterations (a ratio above ~0.15) the full decomposition decides.
constexpr int kInverseIterations = 16;
constexpr double kInverseIterationChange = 1e-14;
// ...on Omega + this I: below the smallest eigenvalue (>= 0 up to rounding), so that one is
// nearest the shift; 1e-3 of kRankTolerance, so the ratio stays that of the eigenvalues where
// the second is above kRankTolerance (with the shift at kRankTolerance itself, a second
// eigenvalue just above it would win: seen, 1.07e-7 against 1e-15), and a positive pivot where
// the smallest is 0 (noise-free data).
constexpr double kInverseIterationShift = 1e-3 * kRankTolerance;

constexpr double kInverseSqrt2 = 0.70710678118654752440;

// r, the 9-vector of a 3 x 3 matrix's rows (the paper's and OpenCV's layout).
Eigen::Matrix3d AsMatrix(const Vector9& r) { return Eigen::Map<const RowMajorMatrix3>(r.data()); }

Vector9 AsVector(const Eigen::Matrix3d& m) {
  Vector9 r;
  Eigen::Map<RowMajorMatrix3>(r.data()) = m;
  return r;
}

double Determinant(const Vector9& r) {
  return r(0) * (r(4) * r(8) - r(5) * r(7)) - r(1) * (r(3) * r(8) - r(5) * r(6)) +
         r(2) * (r(3) * r(7) - r(4) * r(6));
}

// The cofactor matrix det(m) m^-T: its rows are the cross products of m's rows.
Eigen::Matrix3d Cofactors(const Eigen::Matrix3d& m) {
  Eigen::Matrix3d c;
  c.row(0) = m.row(1).cross(m.row(2));
  c.row(1) = m.row(2).cross(m.row(0));
  c.row(2) = m.row(0).cross(m.row(1));
  return c;
}

// ||E E^T - I||_F^2 for E = AsMatrix(e).
double OrthogonalityError(const Vector9& e) {
  const Eigen::Matrix3d m = AsMatrix(e);
  return (m * m.transpose() - Eigen::Matrix3d::Identity()).squaredNorm();
}

// The proper rotation nearest to m (det(m) > 0 expected; else the SVD's) by FOAM: F. L. Markley,
// "Attitude Determination Using Vector Observations: A Fast Optimal Matrix Algorithm", J.
// Astronaut. Sci. 41(2), 1993, as used for the nearest rotation by M. Lourakis, "An Efficient
// Solution to Absolute Orientation", ICPR 2016. With s1 >= s2 >= s3 > 0 m's singular values,
// lambda = s1 + s2 + s3 = max tr(R^T m) is the largest root of
//   p(l) = (l^2 - ||m||^2)^2 - 8 l det(m) - 4 ||cof(m)||^2
// (its roots are +-s1 +-s2 +-s3 with an even number of minus signs), and
//   R = ((l^2 + ||m||^2) m + 2 l cof(m) - 2 m m^T m) / (l (l^2 - ||m||^2) - 2 det(m)),
// as both sides are diagonal in m's singular bases (the denominator is 2 (s1+s2)(s1+s3)(s2+s3)).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const double det = m.determinant();
  if (!(det > 0.0)) return NearestRotationSvd(m);
  const Eigen::Matrix3d cof = Cofactors(m);
  const double m_sq = m.squaredNorm();
  const double cof_sq = cof.squaredNorm();
  // sum s_i <= sum (s_i^2 + 1) / 2: an upper bound above which p is increasing and convex (p''
  // > 0 beyond sqrt(||m||^2 / 3) <= lambda), so Newton descends monotonically onto lambda.
  double l = 0.5 * (m_sq + 3.0);
  for (int step = 0; step < kFoamMaxSteps; ++step) {
    const double a = l * l - m_sq;
    const double p = a * a - 8.0 * l * det - 4.0 * cof_sq;
    const double dp = 4.0 * l * a - 8.0 * det;
    const double next = l - p / dp;
    const bool done = std::abs(next - l) <= kFoamRelativeStep * std::abs(l);
    l = next;
    if (done) break;
  }
  const double denominator = l * (l * l - m_sq) - 2.0 * det;
  if (!(denominator > kFoamMinDenominator * m_sq * std::sqrt(m_sq))) {
    return NearestRotationSvd(m);
  }
  const Eigen::Matrix3d r =
      ((l * l + m_sq) * m + 2.0 * l * cof - 2.0 * m * m.transpose() * m) / denominator;
  if (!((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <=
        kFoamOrthonormal)) {
    return NearestRotationSvd(m);
  }
  return r;
}

// How an SQP step treats the tangent space (SqpStep).
enum class StepKind {
  // OpenCV's: the tangent part skipped where det(W) in an orthonormal basis is below
  // kTangentDeterminant (an absolute threshold: for a scene of small extent or a narrow field of
  // view OpenCV's SQP then only restores the constraints).
  kOpenCv,
  // Skipped only where W is singular relative to its own scale (kTangentRcond).
  kFull,
  // kFull with the Lagrangian's full Hessian, Omega - M (x) I (M the constraints' multipliers,
  // estimated from Omega r = M R at a stationary point), where that is positive definite on the
  // tangent space: quadratic convergence near a minimum, where SQPnP's Omega alone converges
  // linearly at a rate set by the multipliers (seen, 0.65 per step in a 98-degree planar scene).
  kNewton,
};

// One SQP step from r (the paper's eq. 14-16): the step delta minimizing (r + delta)^T omega
// (r + delta) subject to the linearized constraints of R R^T = I, i.e. R Delta^T + Delta R^T =
// I - R R^T. Its solutions are Delta_p + S R^-T (S skew): Delta_p = (I - R R^T) R^-T / 2 is one
// (R^-T R^T = I and the right side is symmetric), and S R^-T spans the constraints' null space
// (the tangent space). The minimizer over the tangent part solves the 3 x 3 system W y = -N^T
// omega (r + delta_p), W = N^T omega N. The step is basis-independent: it equals OpenCV's,
// which takes delta_p in the constraint Jacobian's row space and N from its null-space
// projector (6 x 6 and 9 x 9 work replaced by closed forms).
Vector9 SqpStep(const Matrix9& omega, const Vector9& r, StepKind kind) {
  const Eigen::Matrix3d rotation = AsMatrix(r);
  const Eigen::Matrix3d cof = Cofactors(rotation);
  const double det = rotation.row(0).dot(cof.row(0));
  const Eigen::Matrix3d inverse_transpose = cof / det;
  const Eigen::Matrix3d violation =
      Eigen::Matrix3d::Identity() - rotation * rotation.transpose();
  const Vector9 delta_p = AsVector(0.5 * violation * inverse_transpose);
  // N's columns: [e_k]_x R^-T / sqrt(2), orthonormal where R is a rotation. [e_k]_x M puts M's
  // other two rows, signed, in its rows.
  const Eigen::RowVector3d m0 = inverse_transpose.row(0) * kInverseSqrt2;
  const Eigen::RowVector3d m1 = inverse_transpose.row(1) * kInverseSqrt2;
  const Eigen::RowVector3d m2 = inverse_transpose.row(2) * kInverseSqrt2;
  Matrix93 n = Matrix93::Zero();
  n.block<3, 1>(3, 0) = -m2.transpose();
  n.block<3, 1>(6, 0) = m1.transpose();
  n.block<3, 1>(0, 1) = m2.transpose();
  n.block<3, 1>(6, 1) = -m0.transpose();
  n.block<3, 1>(0, 2) = -m1.transpose();
  n.block<3, 1>(3, 2) = m0.transpose();
  const Matrix93 omega_n = omega.lazyProduct(n);
  Eigen::Matrix3d w = n.transpose() * omega_n;
  Eigen::Vector3d rhs = omega_n.transpose() * (r + delta_p);
  if (kind == StepKind::kNewton) {
    Eigen::Matrix3d multipliers = AsMatrix(omega * r) * inverse_transpose.transpose();
    multipliers = 0.5 * (multipliers + multipliers.transpose()).eval();
    // (M (x) I) vec(X) = vec(M X) in the rows' layout.
    Matrix93 m_n;
    for (int k = 0; k < 3; ++k) m_n.col(k) = AsVector(multipliers * AsMatrix(n.col(k)));
    const Eigen::Matrix3d newton = w - n.transpose() * m_n;
    const Eigen::LLT<Eigen::Matrix3d> positive(newton);
    if (positive.info() == Eigen::Success) {
      return delta_p - n * positive.solve(rhs - m_n.transpose() * delta_p);
    }
  }
  const double w_det = w.determinant();
  double floor = 0.0;
  if (kind == StepKind::kOpenCv) {
    // det of W in an orthonormal basis of the same space: det(W) / det(N^T N).
    floor = kTangentDeterminant * (n.transpose() * n).determinant();
  } else {
    const double scale = w.trace();
    floor = kTangentRcond * scale * scale * scale;
  }
  Vector9 delta = delta_p;
  if (std::abs(w_det) >= floor && w_det != 0.0) delta.noalias() -= n * (w.inverse() * rhs);
  return delta;
}

// SQP from the rotation r0 to a local minimum (`kind`: SqpStep's); then, as OpenCV:
// the sign with det > 0, projected on the rotations only if det > kSqpDeterminant. `converged`:
// it stopped by its tolerance.
Vector9 RunSqp(const Matrix9& omega, const Vector9& r0, StepKind kind, bool* converged) {
  Vector9 r = r0;
  double step_squared = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kSqpMaxSteps && step_squared > kSqpSquaredStep; ++step) {
    const Vector9 delta = SqpStep(omega, r, kind);
    r += delta;
    step_squared = delta.squaredNorm();
  }
  *converged = step_squared <= kSqpSquaredStep;
  double det = Determinant(r);
  if (det < 0.0) {
    r = -r;
    det = -det;
  }
  if (det > kSqpDeterminant) return AsVector(NearestRotation(AsMatrix(r)));
  return r;
}

// The problem after the O(N) pass: E(r) = r^T omega r over rotations r, t = p r, the points
// centred on their centroid (the cost as a function of r does not change with the world's
// origin, t absorbs it; centring spares Omega's sums the cancellation of large coordinates).
struct Problem {
  Matrix9 omega;
  Matrix39 p;
  Eigen::Vector3d centroid;
  const std::vector<Eigen::Vector3d>* points = nullptr;
};

// A local minimum: r_hat as OpenCV keeps it (a rotation up to SQP's tolerance) and its cost.
struct Candidate {
  Vector9 r_hat;
  double cost = std::numeric_limits<double>::infinity();
  bool from_sqp = false;   // else an eigenvector taken as a rotation
  bool converged = true;   // SQP stopped by its tolerance, not its step limit
};

class Search {
 public:
  explicit Search(const Problem& problem)
      : problem_(problem),
        cost_rounding_(kCostRoundoffs * std::numeric_limits<double>::epsilon() *
                       problem.omega.norm()) {}

  // The candidate r_hat: kept if the points are in front (the centroid, else the majority, as
  // OpenCV), the best so far if its cost is lower; min_cost tracks the lowest cost of any kept
  // candidate (OpenCV's rule for the further eigenvectors). Costs within cost_rounding_ are
  // equal: exact solutions (3 points have up to 4) differ only by rounding there, and then one
  // with every point in front is preferred, then by Kind (an r_hat off the rotations, an
  // eigenvector or where SQP stopped unconverged, can cost less than the rotation it stands
  // for), then the lower cost.
  // `flip`: whether a planar scene seen from behind may be considered flipped (once: the flip of
  // a flip is not tried again, which rounding could otherwise repeat without end -- seen: a stack
  // overflow at FitAutoStress seed offset 424242).
  void Consider(const Vector9& r_hat, bool from_sqp, bool converged, bool flip = true) {
    if (!r_hat.allFinite()) return;
    const Eigen::Vector3d t = problem_.p * r_hat;
    if (flip && planar_normal_ != nullptr && t.z() < 0.0) {
      // A plane's points (centred: n.X = 0) seen behind the camera by (R, t) are seen in front,
      // on the same rays, by (-R (I - 2 n n^T), -t): a proper rotation with r^T Omega r the same
      // (the two differ by a null vector of Omega).
      const Eigen::Vector3d& n = *planar_normal_;
      const Eigen::Matrix3d flipped =
          -AsMatrix(r_hat) * (Eigen::Matrix3d::Identity() - 2.0 * n * n.transpose());
      Consider(AsVector(flipped), from_sqp, converged, /*flip=*/false);
    }
    if (!(t.z() > 0.0) && 2 * InFront(r_hat, t) < Count()) return;
    const double cost = r_hat.dot(problem_.omega * r_hat);
    if (!std::isfinite(cost)) return;
    if (cost < min_cost_) min_cost_ = cost;
    bool better = cost < best_.cost - cost_rounding_;
    if (!better && cost <= best_.cost + cost_rounding_) {
      const bool all_in_front = InFront(r_hat, t) == Count();
      const bool best_all_in_front = InFront(best_.r_hat, problem_.p * best_.r_hat) == Count();
      const int kind = Kind(from_sqp, converged);
      const int best_kind = Kind(best_.from_sqp, best_.converged);
      better = all_in_front != best_all_in_front ? all_in_front
               : kind != best_kind               ? kind > best_kind
                                                 : cost < best_.cost;
    }
    if (better) {
      best_.r_hat = r_hat;
      best_.cost = cost;
      best_.from_sqp = from_sqp;
      best_.converged = converged;
    }
  }

  // SQP from the nearest rotation of +-e: one run where FOAM's (OpenCV's) nearest rotation
  // starts both signs at the same rotation, two otherwise.
  void StartFrom(const Vector9& e) {
    const double det = Determinant(e);
    if (std::abs(det) >= kFoamDeterminant) {
      SqpFrom(NearestRotation(AsMatrix(det > 0.0 ? e : -e)));
    } else {
      arbitrary_ = true;
      SqpFrom(NearestRotationSvd(AsMatrix(e)));
      SqpFrom(NearestRotationSvd(AsMatrix(-e)));
    }
  }

  void SqpFrom(const Eigen::Matrix3d& start) {
    bool converged = false;
    const Vector9 r_hat = RunSqp(problem_.omega, AsVector(start),
                                 arbitrary_ ? StepKind::kFull : StepKind::kOpenCv, &converged);
    Consider(r_hat, true, converged);
  }

  // SQPnP's search over the eigenpairs (values ascending, vectors unit columns) of Omega or of
  // its restriction: from each eigenvector with |eigenvalue| < kRankTolerance (at least the
  // first, `searched` of them), then from the next ones (Further). OpenCV's order: its singular
  // values descend, so it takes the null vectors last first.
  template <int kSize>
  void SearchNullSpace(const Eigen::Matrix<double, 9, kSize>& vectors, int searched) {
    for (int j = searched - 1; j >= 0; --j) {
      const Vector9 e = std::sqrt(3.0) * vectors.col(j);
      if (OrthogonalityError(e) < kOrthogonalitySquaredError) {
        Consider(Determinant(e) * e, false, true);
      } else {
        StartFrom(e);
      }
    }
  }

  // From eigenvector `from` on while the best cost exceeds `norm_squared` (|r|^2 of a rotation
  // in that space: no minimum lies near an eigenvector of eigenvalue above cost / |r|^2) times
  // its eigenvalue; never the last, as OpenCV. Returns the first eigenvector not tried.
  template <int kSize>
  int Further(const Eigen::Matrix<double, 9, kSize>& vectors,
              const Eigen::Matrix<double, kSize, 1>& values, int from, double norm_squared) {
    int j = from;
    for (; j < kSize - 1 && min_cost_ > norm_squared * std::abs(values(j)); ++j) {
      StartFrom(vectors.col(j));
    }
    return j;
  }

  template <int kSize>
  int Run(const Eigen::Matrix<double, 9, kSize>& vectors,
          const Eigen::Matrix<double, kSize, 1>& values, int null_space, double norm_squared) {
    const int searched = null_space > 0 ? null_space : 1;
    SearchNullSpace<kSize>(vectors, searched);
    return Further<kSize>(vectors, values, searched, norm_squared);
  }

  double min_cost() const { return min_cost_; }
  bool best_all_in_front() const {
    return std::isfinite(best_.cost) && InFront(best_.r_hat, problem_.p * best_.r_hat) == Count();
  }

  // Ours: where the best pose has a point behind the camera (OpenCV accepts the centroid's or
  // the majority's depth; e.g. a 3-point solution of exact cost with one point behind), SQP
  // from the eigenvectors the cost rule skipped as well (never the last, as OpenCV).
  template <int kSize>
  void Complete(const Eigen::Matrix<double, 9, kSize>& vectors, int next) {
    if (!std::isfinite(best_.cost) || best_all_in_front()) return;
    arbitrary_ = true;
    for (int j = next; j < kSize - 1; ++j) StartFrom(vectors.col(j));
  }

  // From here on the search is ours, not OpenCV's path: SQP takes its tangent steps wherever W
  // is regular (OpenCV's absolute det(W) >= 1e-8 stalls it for narrow fields of view: seen, a
  // 5-degree planar scene's "minimum" the start's nearest rotation), and the winner is polished.
  void MarkArbitrary() { arbitrary_ = true; }
  void SetPlanarNormal(const Eigen::Vector3d* normal) { planar_normal_ = normal; }
  bool arbitrary() const { return arbitrary_; }
  double cost_rounding() const { return cost_rounding_; }
  const Candidate& best() const { return best_; }

 private:
  int Count() const { return static_cast<int>(problem_.points->size()); }

  // A rotation where SQP converged, over an eigenvector taken as one (a rotation to ~1e-4), over
  // SQP's result where it stopped at its step limit.
  static int Kind(bool from_sqp, bool converged) { return !from_sqp ? 1 : converged ? 2 : 0; }

  // How many points have a positive depth under (r, t) (t for the centred points).
  int InFront(const Vector9& r, const Eigen::Vector3d& t) const {
    int in_front = 0;
    const Eigen::Vector3d row2(r(6), r(7), r(8));
    for (const Eigen::Vector3d& x : *problem_.points) {
      if (row2.dot(x - problem_.centroid) + t.z() > 0.0) ++in_front;
    }
    return in_front;
  }

  const Problem& problem_;
  const double cost_rounding_;
  Candidate best_;
  double min_cost_ = std::numeric_limits<double>::max();
  bool arbitrary_ = false;
  const Eigen::Vector3d* planar_normal_ = nullptr;
};

// Eigenvalues of magnitude below kRankTolerance, counted from the smallest (ascending values).
template <int kSize>
int NullSpaceDimension(const Eigen::Matrix<double, kSize, 1>& values) {
  int count = 0;
  while (count < kSize && std::abs(values(count)) < kRankTolerance) ++count;
  return count;
}

// Where Omega's null space has dimension k = 2..4 (4 points: 4, 5 points: 2), its basis is
// arbitrary and a rotation in it (the pose, for noise-free data) may lie between the basis
// vectors, far from the nearest rotation of each: both OpenCV and the basis starts then miss it
// in ~3 % of noise-free 4-point scenes. The rotations R = sum c_i E_i in the span satisfy
// R R^T ~ I and R^T R ~ I: 10 equations linear in the k (k + 1) / 2 products c_i c_j, whose
// least-squares solution is c c^T; c is its leading eigenvector. A start of SQP's, the nearest
// rotation of sum c_i E_i.
// Sized at run time (k = 2..4): the path is rare (4-5 points), and one dynamic instantiation of
// Eigen's eigensolver compiles far faster than one per k and per product count (fixed sizes 2-4
// and 3-10 took this file from 50 s to 85 s with GCC 12 -O3).
Vector9 AlgebraicStart(const Eigen::Matrix<double, 9, Eigen::Dynamic>& basis) {
  const int dim = static_cast<int>(basis.cols());
  Eigen::MatrixXd equations(10, dim * (dim + 1) / 2);
  int column = 0;
  for (int i = 0; i < dim; ++i) {
    const Eigen::Matrix3d e_i = AsMatrix(basis.col(i));
    for (int j = i; j < dim; ++j) {
      const Eigen::Matrix3d e_j = AsMatrix(basis.col(j));
      Eigen::Matrix3d g = e_i * e_j.transpose();
      Eigen::Matrix3d h = e_i.transpose() * e_j;
      if (j != i) {
        g += g.transpose().eval();
        h += h.transpose().eval();
      }
      // The traceless parts of the symmetric g and h: zero for an orthogonal matrix's products.
      equations.col(column++) << g(0, 1), g(0, 2), g(1, 2), g(0, 0) - g(1, 1), g(1, 1) - g(2, 2),
          h(0, 1), h(0, 2), h(1, 2), h(0, 0) - h(1, 1), h(1, 1) - h(2, 2);
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> products(equations.transpose() *
                                                                equations);
  const Eigen::VectorXd m = products.eigenvectors().col(0);
  Eigen::MatrixXd outer(dim, dim);
  column = 0;
  for (int i = 0; i < dim; ++i) {
    for (int j = i; j < dim; ++j) outer(i, j) = outer(j, i) = m(column++);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> factor(outer);
  // m has either sign: c c^T is the eigenvalue of largest magnitude's.
  const int lead = std::abs(factor.eigenvalues()(0)) > std::abs(factor.eigenvalues()(dim - 1))
                       ? 0
                       : dim - 1;
  const Vector9 r = basis * factor.eigenvectors().col(lead);
  return std::sqrt(3.0) * r / r.norm();
}

// LDL^T of the symmetric m (its lower triangle read) without pivoting. False where a pivot is not
// finite or has magnitude below kPivotFloor times m's largest diagonal entry: the factorization
// is then no reliable witness of m's inertia (the signs of d count m's negative eigenvalues,
// Sylvester's law) nor a reliable solver.
bool FactorLdlt(const Matrix9& m, Matrix9* l, Vector9* d) {
  const double floor = kPivotFloor * m.diagonal().cwiseAbs().maxCoeff();
  l->setIdentity();
  for (int j = 0; j < 9; ++j) {
    double pivot = m(j, j);
    for (int k = 0; k < j; ++k) pivot -= (*l)(j, k) * (*l)(j, k) * (*d)(k);
    if (!std::isfinite(pivot) || !(std::abs(pivot) > floor)) return false;
    (*d)(j) = pivot;
    const double inverse = 1.0 / pivot;
    for (int i = j + 1; i < 9; ++i) {
      double sum = m(i, j);
      for (int k = 0; k < j; ++k) sum -= (*l)(i, k) * (*l)(j, k) * (*d)(k);
      (*l)(i, j) = sum * inverse;
    }
  }
  return true;
}

// x <- (L D L^T)^-1 x.
void SolveLdlt(const Matrix9& l, const Vector9& d, Vector9* x) {
  for (int i = 1; i < 9; ++i) {
    for (int k = 0; k < i; ++k) (*x)(i) -= l(i, k) * (*x)(k);
  }
  x->array() /= d.array();
  for (int i = 7; i >= 0; --i) {
    for (int k = i + 1; k < 9; ++k) (*x)(i) -= l(k, i) * (*x)(k);
  }
}

// The number of eigenvalues of omega below `shift`, or -1 where the factorization is unreliable.
int CountBelow(const Matrix9& omega, double shift) {
  Matrix9 l;
  Vector9 d;
  if (!FactorLdlt(omega - shift * Matrix9::Identity(), &l, &d)) return -1;
  return static_cast<int>((d.array() < 0.0).count());
}

// The cost-relevant shortcut for the common case: at most one eigenvalue of Omega below
// kRankTolerance (OpenCV's null space empty or the smallest eigenvector alone, which OpenCV's
// search treats alike: noisy or noise-free data, >= 6 points in general position), counted by
// the negative pivots of an LDL^T of Omega - kRankTolerance I. The smallest eigenvector then by
// inverse iteration on Omega + kInverseIterationShift I (positive definite): two factorizations
// and a few triangular solves, where the full 9 x 9 eigendecomposition costs ~10 times that.
// False where Omega has two or more such eigenvalues, a factorization is unreliable or the
// iteration does not settle (then the full decomposition decides).
bool SmallestEigenvector(const Matrix9& omega, Vector9* vector) {
  Matrix9 l;
  Vector9 d;
  if (!FactorLdlt(omega - kRankTolerance * Matrix9::Identity(), &l, &d)) return false;
  if ((d.array() < 0.0).count() > 1) return false;
  if (!FactorLdlt(omega + kInverseIterationShift * Matrix9::Identity(), &l, &d)) return false;
  Vector9 x;
  x << 1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2;
  x.normalize();
  for (int step = 0; step < kInverseIterations; ++step) {
    Vector9 y = x;
    SolveLdlt(l, d, &y);
    y.normalize();
    if (y.dot(x) < 0.0) y = -y;
    const double change = (y - x).lpNorm<Eigen::Infinity>();
    x = y;
    if (!x.allFinite()) return false;
    if (change <= kInverseIterationChange) {
      *vector = x;
      return true;
    }
  }
  return false;
}

// The O(N) pass: Omega, P and the centroid into `problem`, the centred points' scatter matrix
// into `scatter`. False on the degenerate configurations SolveSqPnp refuses.
//
// Omega = sum A_i^T Q_i A_i - (sum Q_i A_i)^T (sum Q_i)^-1 (sum Q_i A_i), A_i r = R X_i,
// Q_i = B_i^T B_i = [1 0 -x; 0 1 -y; -x -y x^2+y^2]: A_i^T Q_i A_i = Q_i (x) X X^T (Kronecker),
// so four weighted scatter matrices (weights 1, x, y, s = x^2 + y^2) and the weighted sums of X
// and of the weights make it: per point the outer product of (X X^T's 6 distinct entries, X, 1)
// with the weights, 40 multiply-adds.
bool BuildProblem(const std::vector<Eigen::Vector3d>& points_in_world,
                  const std::vector<Eigen::Vector2d>& normalized, Problem* problem,
                  Eigen::Matrix3d* scatter) {
  const size_t count = points_in_world.size();
  if (count < 3 || normalized.size() != count) return false;
  problem->points = &points_in_world;
  problem->centroid.setZero();
  for (size_t i = 0; i < count; ++i) {
    if (!points_in_world[i].allFinite() || !normalized[i].allFinite()) return false;
    problem->centroid += points_in_world[i];
  }
  const double n = static_cast<double>(count);
  problem->centroid /= n;
  Eigen::Matrix<double, 10, 4> sums = Eigen::Matrix<double, 10, 4>::Zero();
  double sum_magnitude = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d point = points_in_world[i] - problem->centroid;
    const double x = normalized[i].x();
    const double y = normalized[i].y();
    Eigen::Matrix<double, 10, 1> products;
    products << point.x() * point.x(), point.x() * point.y(), point.x() * point.z(),
        point.y() * point.y(), point.y() * point.z(), point.z() * point.z(), point, 1.0;
    const Eigen::RowVector4d weights(1.0, x, y, x * x + y * y);
    sums.noalias() += products * weights;
    sum_magnitude += points_in_world[i].squaredNorm();
  }
  // Column k of `sums`: weight k's sums; rows 0-5 X X^T's upper triangle, 6-8 X, 9 the weight.
  auto scatter_of = [&](int k) {
    Eigen::Matrix3d m;
    m << sums(0, k), sums(1, k), sums(2, k),  //
        sums(1, k), sums(3, k), sums(4, k),   //
        sums(2, k), sums(4, k), sums(5, k);
    return m;
  };
  *scatter = scatter_of(0);
  const double sum_x = sums(9, 1);
  const double sum_y = sums(9, 2);
  const double sum_s = sums(9, 3);

  const Eigen::Matrix3d& c = *scatter;
  const double spread = c.trace();
  if (!(spread > kCoincident * sum_magnitude)) return false;
  const double minors = c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1) + c(0, 0) * c(2, 2) -
                        c(0, 2) * c(0, 2) + c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
  if (!(minors > kCollinear * spread * spread)) return false;
  const double image_variance = (n * sum_s - sum_x * sum_x - sum_y * sum_y) / (n * n);
  if (!(image_variance >= kMinImageVariance)) return false;

  // sum Q_i A_i with the centred points (sum X = 0): rows [X^T, 0, -x X^T], [0, X^T, -y X^T],
  // [-x X^T, -y X^T, s X^T] summed.
  Matrix39 qa = Matrix39::Zero();
  qa.block<1, 3>(0, 6) = -sums.block<3, 1>(6, 1).transpose();
  qa.block<1, 3>(1, 6) = -sums.block<3, 1>(6, 2).transpose();
  qa.block<1, 3>(2, 0) = -sums.block<3, 1>(6, 1).transpose();
  qa.block<1, 3>(2, 3) = -sums.block<3, 1>(6, 2).transpose();
  qa.block<1, 3>(2, 6) = sums.block<3, 1>(6, 3).transpose();
  Eigen::Matrix3d q;
  q << n, 0.0, -sum_x, 0.0, n, -sum_y, -sum_x, -sum_y, sum_s;
  // det(Q) = n^3 image_variance >= 27e-5: invertible.
  problem->p.noalias() = -q.inverse() * qa;
  Matrix9& omega = problem->omega;
  omega.setZero();
  omega.block<3, 3>(0, 0) = c;
  omega.block<3, 3>(3, 3) = c;
  omega.block<3, 3>(0, 6) = -scatter_of(1);
  omega.block<3, 3>(6, 0) = -scatter_of(1);
  omega.block<3, 3>(3, 6) = -scatter_of(2);
  omega.block<3, 3>(6, 3) = -scatter_of(2);
  omega.block<3, 3>(6, 6) = scatter_of(3);
  omega.noalias() += qa.transpose().lazyProduct(problem->p);
  return omega.allFinite() && problem->p.allFinite();
}

// Planar points (normal n): Omega annihilates {a n^T} and, being symmetric, maps its complement,
// the matrices C B^T (B the plane's in-plane axes), to itself, so its other 6 eigenpairs are
// those of B3^T Omega B3, B3 = diag(B, B, B) (9 x 6, orthonormal). A rotation's part there has
// |r|^2 = 2 (its part R n n^T in the null space has 1), and the nearest rotation of C B^T (rank
// 2) is unique: the search starts where the pose is, not at the arbitrary rotations R with R n = a
// that OpenCV's null vectors a n^T give (which miss the pose in ~2 % of noise-free 4-point
// planar scenes). False on OpenCV's refusals, which it applies to these 6 eigenvalues and 3 zeros.
bool SearchPlanar(const Problem& problem, const Eigen::Vector3d& normal, Search* search) {
  Eigen::Matrix<double, 3, 2> in_plane;
  in_plane.col(0) = normal.unitOrthogonal();
  in_plane.col(1) = normal.cross(in_plane.col(0));
  Matrix96 complement = Matrix96::Zero();
  for (int k = 0; k < 3; ++k) complement.block<3, 2>(3 * k, 2 * k) = in_plane;
  const Eigen::SelfAdjointEigenSolver<Matrix6> eigen(complement.transpose() * problem.omega *
                                                     complement);
  if (eigen.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 6, 1>& values = eigen.eigenvalues();
  if (!(values(5) >= kMinLargestEigenvalue)) return false;
  const int null_space = NullSpaceDimension<6>(values);
  if (3 + null_space > kMaxNullSpace) return false;
  const Matrix96 vectors = complement * eigen.eigenvectors();
  search->MarkArbitrary();
  search->SetPlanarNormal(&normal);
  const int next = search->Run<6>(vectors, values, null_space, 2.0);
  // A plane seen from afar has two poses of nearly equal cost, mirror images in depth about the
  // plane's centroid, and SQP from the eigenvectors finds one (in ~1 % of noisy 6-point scenes
  // the worse): SQP also from the best's mirror image, (I - 2 v v^T) R (I - 2 n n^T) (v the
  // centroid's viewing direction; the two reflections make it proper, and it maps the plane's
  // points to the same viewing directions where the depth range is small).
  const auto mirror_best = [&] {
    const Candidate& found = search->best();
    if (!std::isfinite(found.cost)) return;
    const Eigen::Vector3d view = (problem.p * found.r_hat).normalized();
    search->SqpFrom((Eigen::Matrix3d::Identity() - 2.0 * view * view.transpose()) *
                    NearestRotation(AsMatrix(found.r_hat)) *
                    (Eigen::Matrix3d::Identity() - 2.0 * normal * normal.transpose()));
  };
  mirror_best();
  search->Complete<6>(vectors, next);
  mirror_best();
  return true;
}

// Non-planar points: OpenCV's search on Omega's eigenvectors. The fast path (see
// SmallestEigenvector) where OpenCV's largest-eigenvalue refusal cannot apply (trace >= 9
// kMinLargestEigenvalue), the null space has at most 1 dimension, and after the smallest
// eigenvector's SQP (OpenCV's first step) no further eigenvector is wanted: fewer than 2
// eigenvalues below min_cost / 3 (with `extent` kFirstMinimum: whatever they are), and the best
// pose has every point in front. Otherwise the full decomposition. False on OpenCV's refusals.
bool SearchGeneral(const Problem& problem, SqPnpSearch extent, Search* search) {
  const Matrix9& omega = problem.omega;
  Vector9 smallest;
  bool started = false;
  if (omega.trace() >= 9.0 * kMinLargestEigenvalue && SmallestEigenvector(omega, &smallest)) {
    search->SearchNullSpace<1>(smallest, 1);
    started = true;
    if (search->best_all_in_front()) {
      if (extent == SqPnpSearch::kFirstMinimum) return true;
      const int below = CountBelow(omega, search->min_cost() / 3.0);
      if (below >= 0 && below <= 1) return true;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Matrix9> eigen(omega);
  if (eigen.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 9, 1>& values = eigen.eigenvalues();
  if (!(std::max(std::abs(values(0)), std::abs(values(8))) >= kMinLargestEigenvalue)) {
    return false;
  }
  const int null_space = NullSpaceDimension<9>(values);
  if (null_space > kMaxNullSpace) return false;
  const Matrix9& vectors = eigen.eigenvectors();
  if (null_space >= 2) search->MarkArbitrary();
  // Where the fast path took the smallest eigenvector already, OpenCV's search goes on from the
  // next.
  const int next = started && null_space <= 1 ? search->Further<9>(vectors, values, 1, 3.0)
                                              : search->Run<9>(vectors, values, null_space, 3.0);
  if (null_space >= 2 && null_space <= 4) {
    search->StartFrom(AlgebraicStart(vectors.leftCols(null_space)));
  }
  search->Complete<9>(vectors, next);
  return true;
}

// The winner's r_hat, polished where the search was ours (its start not OpenCV's: SQP's stopping
// rule left it off its minimum by an amount that depends on the path) or where it is an
// eigenvector taken as the rotation (OpenCV's shortcut) whose cost is zero to rounding
// (noise-free data: it is then the pose up to rounding amplified by Omega's conditioning, seen
// 1e-7 at 6 points where the second eigenvalue is 1e-7). Newton-SQP steps; the result is kept
// only where they converged and it is no worse: where Omega's null space is large (4 coplanar
// points) SQP can wander without converging.
Vector9 Polished(const Problem& problem, const Search& search) {
  const Candidate& best = search.best();
  const bool exact_eigenvector = !best.from_sqp && std::abs(best.cost) <= search.cost_rounding();
  if (!(best.from_sqp && search.arbitrary()) && !exact_eigenvector) return best.r_hat;
  Vector9 polished = best.r_hat;
  double step_squared = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kPolishMaxSteps && step_squared > kPolishSquaredStep; ++step) {
    const Vector9 delta = SqpStep(problem.omega, polished, StepKind::kNewton);
    polished += delta;
    step_squared = delta.squaredNorm();
  }
  if (!(step_squared <= kSqpSquaredStep) || !polished.allFinite()) return best.r_hat;
  // Compared as rotations (an r_hat off the rotations by SQP's tolerance can cost less), up to
  // the costs' rounding.
  const Vector9 before = AsVector(NearestRotation(AsMatrix(best.r_hat)));
  const Vector9 after = AsVector(NearestRotation(AsMatrix(polished)));
  return after.dot(problem.omega * after) <= before.dot(problem.omega * before) +
                                                 search.cost_rounding()
             ? polished
             : best.r_hat;
}

}  // namespace

bool SolveSqPnp(const std::vector<Eigen::Vector3d>& points_in_world,
                const std::vector<Eigen::Vector2d>& normalized, Eigen::Matrix3d* rotation,
                Eigen::Vector3d* translation, SqPnpSearch extent) {
  Problem problem;
  Eigen::Matrix3d scatter;
  if (!BuildProblem(points_in_world, normalized, &problem, &scatter)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> shape;
  shape.computeDirect(scatter);
  const Eigen::Vector3d normal = shape.eigenvectors().col(0);
  const bool planar = shape.eigenvalues()(0) <= kPlanar * shape.eigenvalues()(2);
  Search search(problem);
  if (!(planar ? SearchPlanar(problem, normal, &search)
               : SearchGeneral(problem, extent, &search))) {
    return false;
  }
  if (!std::isfinite(search.best().cost)) return false;
  const Vector9 r_best = Polished(problem, search);
  const Eigen::Matrix3d r_hat = AsMatrix(r_best);
  // cv::Rodrigues orthogonalizes OpenCV's r_hat the same way; t is computed from r_hat itself.
  const Eigen::Matrix3d r = NearestRotation(r_hat);
  const Eigen::Vector3d t = problem.p * r_best - r_hat * problem.centroid;
  if (!r.allFinite() || !t.allFinite()) return false;
  *rotation = r;
  *translation = t;
  return true;
}

}  // namespace internal
}  // namespace camproj

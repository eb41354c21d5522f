// SQPnP (private): the pose of a calibrated camera from N >= 3 points and their normalized image
// coordinates, after G. Terzakis and M. Lourakis, "A Consistently Fast and Globally Optimal
// Solution to the Perspective-n-Point Problem", ECCV 2020. It stands in for OpenCV 4.6's
// cv::solvePnP(..., cv::SOLVEPNP_SQPNP) with K = I in the closed-form starts (closed_form.cc):
// the same pose where OpenCV's search is well defined, at a tenth of its instructions
// (scripts/bench_sqpnp_cost.sh).
#ifndef CAMPROJ_SRC_FIT_SQPNP_H_
#define CAMPROJ_SRC_FIT_SQPNP_H_

#include <vector>

#include <Eigen/Core>

namespace camproj {
namespace internal {

// The pose cam_from_world (point_in_cam = rotation * point_in_world + translation) minimizing
// SQPnP's squared error over proper rotations R and translations t,
//
//   E(R, t) = sum_i || B_i (R X_i + t) ||^2,   B_i = [1 0 -x_i; 0 1 -y_i]   (2 x 3),
//
// X_i = points_in_world[i], (x_i, y_i) = normalized[i] = (X/Z, Y/Z) of the camera point. Term i
// is z_i^2 |(x_i, y_i) - (X/Z, Y/Z)|^2, the image error weighted by the squared depth: zero
// exactly where R X_i + t is on the ray v_i = (x_i, y_i, 1), as is the orthogonal-projector
// form || (I - v_i v_i^T / v_i^T v_i) (R X_i + t) ||^2; Q_i = B_i^T B_i = [I, -u; -u^T, |u|^2]
// is what OpenCV's and the authors' implementations minimize, and hence this function.
//
// The minimum is global in SQPnP's sense. With r the 9-vector of R's rows and t(r) = P r the
// best translation, E = r^T Omega r (Omega 9 x 9 and P 3 x 9 accumulated in O(N)); SQP on the
// rotations runs from the nearest rotation of each eigenvector of Omega with eigenvalue below
// 1e-7 (at least the smallest), then of the next eigenvectors while the best cost exceeds 3
// times their eigenvalue (a rotation has |r|^2 = 3: no lower minimum can lie near one above
// that); of the local minima with the points in front (the centroid's depth > 0, else the
// majority's) the lowest E is returned. Every threshold that decides which minimum OpenCV finds
// is OpenCV's (sqpnp.cc lists them), and where its search is well defined -- non-planar points
// whose Omega has at most one eigenvalue below 1e-7 (noisy data at N >= 6 in general position,
// noise-free data) -- ours takes the same SQP steps from the same starts: the same pose to
// rounding (1e-12; 1e-9 to 1e-5 at fields of view of a few degrees, where rounding is amplified).
// Differences, all of which give a lower or equal E:
//  - OpenCV keeps the first-found of minima whose E differ by less than its absolute 1e-6; ours
//    the lowest (and among those equal to rounding, one with every point in front, e.g. among 3
//    points' exact poses).
//  - Planar points (Omega's null space then holds {a n^T}, n the normal, no rotation): ours
//    searches Omega's other 6 eigenvectors, whose nearest rotations are unique, and the mirror
//    image in depth of the best, where OpenCV starts at arbitrary rotations R n = a; OpenCV's
//    planar pose is its minimum only to its SQP's stopping error (1e-9 to 1e-5).
//  - A null space of dimension 2 to 4 (4 or 5 non-planar points): its basis is arbitrary, and
//    ours also starts at the rotation nearest to it (a least-squares solve of R R^T = R^T R = I
//    in its span), which OpenCV misses in ~3 % of noise-free 4-point scenes.
//  - Where a start is ours, SQP's tangent step is taken wherever it is regular (OpenCV skips it
//    below an absolute det 1e-8, which stalls its SQP for narrow fields of view), and the
//    winner is polished to its minimum by Newton-SQP steps (~1e-12).
//  - An eigenvector taken as the rotation without SQP (OpenCV's shortcut) is polished likewise
//    where its E is zero to rounding (noise-free data).
//
// Cost: the O(N) pass (40 multiply-adds per point); where OpenCV's search is well defined, two
// LDL^T factorizations of Omega counting its small eigenvalues and giving its smallest
// eigenvector by inverse iteration, in place of a 9 x 9 eigendecomposition (which remains the
// fall-back, a 6 x 6 one for planar points); SQP steps in closed form (the constraint part
// (I - R R^T) R^-T / 2, a 3 x 3 solve in the tangent space) instead of OpenCV's 9 x 9
// projector; the nearest rotation by FOAM (Newton on a quartic) with an SVD only where it is
// ill-conditioned. No heap allocation.
//
// Returns false (never throws) on fewer than 3 points, sizes that differ, a non-finite
// coordinate, coincident or collinear points (the rotation about their line is free), an image
// spread (the variance of x plus that of y) below 1e-5, an Omega whose largest eigenvalue is
// below 1e-7 or with more than 6 eigenvalues below 1e-7 (the three as OpenCV refuses), or no
// minimum with the points in front. `rotation` and `translation` are written only on success.
//
// With SqPnpSearch::kFirstMinimum, non-planar points: the search stops after the smallest
// eigenvector's SQP where that found a pose with every point in front (the fast path above,
// without its test for further eigenvectors), and runs in full otherwise. Not the global minimum
// where a further eigenvector's is lower -- at times the pose turned by 180 degrees at many times
// the cost (tests/sqpnp_test.cc) -- so only for a start that least squares refines and keeps only
// where it ends lower than another (fit/refine.cc), where the intrinsics are a guess that the
// points need not fit and OpenCV's rule then searches every eigenvector (~4x the instructions).
enum class SqPnpSearch { kGlobal, kFirstMinimum };
bool SolveSqPnp(const std::vector<Eigen::Vector3d>& points_in_world,
                const std::vector<Eigen::Vector2d>& normalized, Eigen::Matrix3d* rotation,
                Eigen::Vector3d* translation, SqPnpSearch search = SqPnpSearch::kGlobal);

// The proper rotation nearest to m in the Frobenius norm, by SVD: U diag(1, 1, det(U V^T)) V^T;
// any of them where it is not unique. SQPnP's fall-back, and the homography start's
// (closed_form.cc).
Eigen::Matrix3d NearestRotationSvd(const Eigen::Matrix3d& m);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_SQPNP_H_

// Closed-form starts for the fitter (private). All work in the normalized world frame of the
// validated scene (scene.h): points centred on their centroid and scaled to unit RMS distance.
#ifndef CAMPROJ_SRC_FIT_CLOSED_FORM_H_
#define CAMPROJ_SRC_FIT_CLOSED_FORM_H_

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/intrinsics.h"
#include "fit/sqpnp.h"

namespace camproj {
namespace internal {

// A camera in the normalized world: point_in_cam = rotation * (point - center).
struct StartCamera {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Intrinsics intrinsics;  // kCenter, k1 = k2 = 0
  // DltStart only: the DLT's 3x3 part has det < 0 (its rotation factor does), i.e. the points
  // are seen as through a mirror. rotation and center are then those of the world with z
  // negated (z -> -z), where the same linear camera has a proper rotation.
  bool mirrored = false;
};

// Hartley-normalized DLT (>= 6 non-coplanar points) and RQ decomposition: K with positive
// diagonal, det(R) = +1; see StartCamera::mirrored for a left-handed reading. Throws SceneError
// kPointsBehindCamera when no camera has all points in front.
StartCamera DltStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels);

// DltStart without the exception: nullopt where it throws. For RANSAC's minimal samples, most of
// which have a point behind their camera: a thrown and caught SceneError (its message built,
// the stack unwound) cost more than the sample's DLT.
std::optional<StartCamera> DltStartIfInFront(const std::vector<Eigen::Vector3d>& points,
                                             const std::vector<Eigen::Vector2d>& pixels);

// The unit eigenvector of the smallest eigenvalue of a symmetric positive semidefinite `m` (the
// DLT's normal matrix), sign arbitrary: by inverse iteration where that settles and `m` is not
// singular to rounding, else Eigen's SelfAdjointEigenSolver's (closed_form.cc says when).
Eigen::Matrix<double, 12, 1> SmallestEigenvector(const Eigen::Matrix<double, 12, 12>& m);

// The 3x4 camera matrix fitted by the normalized DLT (scale arbitrary).
Eigen::Matrix<double, 3, 4> NormalizedDlt(const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<Eigen::Vector2d>& pixels);

// The planar homography H (plane coordinates -> pixels, scale arbitrary) by the Hartley-normalized
// DLT, >= 4 points in general position.
Eigen::Matrix3d NormalizedHomography(const std::vector<Eigen::Vector2d>& plane,
                                     const std::vector<Eigen::Vector2d>& pixels);

// M = K R with K upper triangular with positive diagonal, K(2,2) = 1 and R orthogonal (its
// determinant has the sign of det(M)).
void RqDecomposition(const Eigen::Matrix3d& m, Eigen::Matrix3d* k, Eigen::Matrix3d* r);

// The least-squares homography (Hartley and Zisserman's "gold standard" with the plane
// coordinates exact): the H (plane coordinates -> pixels, H(2, 2) > 0 in Hartley's frames)
// minimizing sum_i |pi(H x_i) - u_i|^2, by Levenberg-Marquardt from the normalized DLT. Nothing
// where the DLT or a step maps a point to the far side of the line at infinity (no camera has
// those points in front).
std::optional<Eigen::Matrix3d> LeastSquaresHomography(const std::vector<Eigen::Vector2d>& plane,
                                                      const std::vector<Eigen::Vector2d>& pixels);

// The points' in-plane coordinates: the first two of plane_basis^T * point.
std::vector<Eigen::Vector2d> PlaneCoordinates(const std::vector<Eigen::Vector3d>& points,
                                              const Eigen::Matrix3d& plane_basis);

// The camera that maps the plane by `h` (plane coordinates -> pixels): the focal length (and
// the aspect when aspect_free) from the two orthonormality constraints with the principal point
// and skew of `guess` (its focal length where focal_free is false), then the pose. Returns false
// where the constraints give no positive 1/fx^2, 1/fy^2.
bool StartFromHomography(const Eigen::Matrix3d& h, const Eigen::Matrix3d& plane_basis,
                         const Intrinsics& guess, bool focal_free, bool aspect_free,
                         StartCamera* start);

// Planar scene (>= 4 points): a homography from the plane to the image, then the focal length
// (and the aspect when aspect_free) from the two orthonormality constraints with the principal
// point and skew of `guess`, then the pose. `plane_basis` has the plane's in-plane axes as its
// first two columns and the normal as the third (a rotation). When focal_free is false the
// focal length of `guess` is used. Returns false where the constraints do not determine the
// focal length (e.g. a plane seen head-on).
bool HomographyStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels,
                     const Eigen::Matrix3d& plane_basis, const Intrinsics& guess, bool focal_free,
                     bool aspect_free, StartCamera* start);

// Pose from known intrinsics (distortion included) by SQPnP (fit/sqpnp.h: OpenCV's
// SOLVEPNP_SQPNP pose), >= 3 points. Returns false if SQPnP refuses. `search`: SolveSqPnp's
// (kFirstMinimum only for a start kept where it ends lower than another).
bool PnpStart(const std::vector<Eigen::Vector3d>& points,
              const std::vector<Eigen::Vector2d>& pixels, const Intrinsics& intrinsics,
              StartCamera* start, SqPnpSearch search = SqPnpSearch::kGlobal);

// The shortest focal length FocalSweepStart tries: a 175-degree view across the image width.
double SweepMinFocalPx(int image_width);

// Focal length unknown, everything else given: SQPnP over a log-spaced sweep of focal lengths
// (fields of view from 0.5 to 175 degrees across the image width), keeping the lowest RMS. With
// `other_minima`, also the sweep's other local minima of the RMS (best first): with few points
// the RMS over the focal length can have several valleys, and LM stays in the one it starts in.
bool FocalSweepStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels, const Intrinsics& guess,
                     double aspect, int image_width, StartCamera* start,
                     std::vector<StartCamera>* other_minima = nullptr);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_CLOSED_FORM_H_

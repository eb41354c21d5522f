#include "fit/closed_form.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <Eigen/Dense>

#include "camproj/fit.h"
#include "fit/small_solve.h"
#include "fit/sqpnp.h"

namespace camproj {
namespace internal {

namespace {

// Hartley's normalization of image points: centroid to the origin, mean distance sqrt(2).
Eigen::Matrix3d HartleyTransform(const std::vector<Eigen::Vector2d>& pixels) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : pixels) centroid += p;
  centroid /= static_cast<double>(pixels.size());
  double mean_distance = 0.0;
  for (const auto& p : pixels) mean_distance += (p - centroid).norm();
  mean_distance /= static_cast<double>(pixels.size());
  const double scale = mean_distance > 0.0 ? std::sqrt(2.0) / mean_distance : 1.0;
  Eigen::Matrix3d t = Eigen::Matrix3d::Identity();
  t(0, 0) = t(1, 1) = scale;
  t.block<2, 1>(0, 2) = -scale * centroid;
  return t;
}

// The DLT's homography between points already Hartley-normalized (x: plane, u: pixels; both
// homogeneous with w = 1), scale arbitrary.
Eigen::Matrix3d DltHomography(const std::vector<Eigen::Vector3d>& x,
                              const std::vector<Eigen::Vector3d>& u) {
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd a(2 * n, 9);
  for (int i = 0; i < n; ++i) {
    a.row(2 * i) << x[i].transpose(), Eigen::RowVector3d::Zero(), -u[i].x() * x[i].transpose();
    a.row(2 * i + 1) << Eigen::RowVector3d::Zero(), x[i].transpose(), -u[i].y() * x[i].transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return hn;
}

// The points of `p` through the Hartley transform `t`, homogeneous.
std::vector<Eigen::Vector3d> Transformed(const Eigen::Matrix3d& t,
                                         const std::vector<Eigen::Vector2d>& p) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(p.size());
  for (const Eigen::Vector2d& q : p) out.push_back(t * q.homogeneous());
  return out;
}

// The sum over the points of |pi(h x_i) - u_i|^2 (normalized units), or nothing where a point
// maps to w <= 0 (behind the camera of every reading of h with h(2, 2) > 0).
std::optional<double> HomographyCost(const Eigen::Matrix3d& h, const std::vector<Eigen::Vector3d>& x,
                                     const std::vector<Eigen::Vector3d>& u) {
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    const Eigen::Vector3d p = h * x[i];
    if (!(p.z() > 0.0)) return std::nullopt;
    sum += (p.head<2>() / p.z() - u[i].head<2>()).squaredNorm();
  }
  return sum;
}

}  // namespace

Eigen::Matrix3d NormalizedHomography(const std::vector<Eigen::Vector2d>& plane,
                                     const std::vector<Eigen::Vector2d>& pixels) {
  const Eigen::Matrix3d t_plane = HartleyTransform(plane);
  const Eigen::Matrix3d t_pixel = HartleyTransform(pixels);
  return t_pixel.inverse() *
         DltHomography(Transformed(t_plane, plane), Transformed(t_pixel, pixels)) * t_plane;
}

std::optional<Eigen::Matrix3d> LeastSquaresHomography(const std::vector<Eigen::Vector2d>& plane,
                                                      const std::vector<Eigen::Vector2d>& pixels) {
  // Levenberg-Marquardt (Marquardt's diagonal damping) on the eight entries other than h(2, 2),
  // held at 1, in Hartley's frames: there h(2, 2) is the depth scale of the plane's centroid,
  // which every camera with the points in front makes positive; the pixel frame's isotropic
  // scale leaves the minimizer the same. Stops where a step changes no entry by more than
  // kSettled (relative to |h|), or after kMaxIterations.
  constexpr int kMaxIterations = 50;
  constexpr double kSettled = 1e-12;
  constexpr double kMaxDamping = 1e12;
  const Eigen::Matrix3d t_plane = HartleyTransform(plane);
  const Eigen::Matrix3d t_pixel = HartleyTransform(pixels);
  const std::vector<Eigen::Vector3d> x = Transformed(t_plane, plane);
  const std::vector<Eigen::Vector3d> u = Transformed(t_pixel, pixels);
  Eigen::Matrix3d h = DltHomography(x, u);
  if (!(std::abs(h(2, 2)) > 1e-9 * h.norm())) return std::nullopt;
  h /= h(2, 2);
  std::optional<double> cost = HomographyCost(h, x, u);
  if (!cost) return std::nullopt;
  double damping = 1e-3;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    // Normal equations of the residuals pi(h x) - u in the entries h(0, 0..2), h(1, 0..2),
    // h(2, 0..1).
    Eigen::Matrix<double, 8, 8> jtj = Eigen::Matrix<double, 8, 8>::Zero();
    Eigen::Matrix<double, 8, 1> jtr = Eigen::Matrix<double, 8, 1>::Zero();
    for (size_t i = 0; i < x.size(); ++i) {
      const Eigen::Vector3d p = h * x[i];
      const double inv_w = 1.0 / p.z();
      const Eigen::Vector2d projected = p.head<2>() * inv_w;
      const Eigen::Vector2d r = projected - u[i].head<2>();
      Eigen::Matrix<double, 2, 8> j = Eigen::Matrix<double, 2, 8>::Zero();
      j.block<1, 3>(0, 0) = x[i].transpose() * inv_w;
      j.block<1, 3>(1, 3) = x[i].transpose() * inv_w;
      j.block<1, 2>(0, 6) = -projected.x() * inv_w * x[i].head<2>().transpose();
      j.block<1, 2>(1, 6) = -projected.y() * inv_w * x[i].head<2>().transpose();
      jtj.noalias() += j.transpose() * j;
      jtr.noalias() += j.transpose() * r;
    }
    bool stepped = false;
    while (damping <= kMaxDamping) {
      Eigen::Matrix<double, 8, 8> damped = jtj;
      damped.diagonal() += damping * jtj.diagonal();
      const Eigen::Matrix<double, 8, 1> step = -damped.ldlt().solve(jtr);
      if (!step.allFinite()) return std::nullopt;
      Eigen::Matrix3d trial = h;
      for (int k = 0; k < 8; ++k) trial(k / 3, k % 3) += step(k);
      const std::optional<double> trial_cost = HomographyCost(trial, x, u);
      if (trial_cost && *trial_cost <= *cost) {
        const bool settled = step.cwiseAbs().maxCoeff() <= kSettled * h.norm();
        h = trial;
        cost = trial_cost;
        damping = std::max(damping / 10.0, 1e-12);
        stepped = !settled;
        break;
      }
      damping *= 10.0;
    }
    if (!stepped) break;
  }
  return t_pixel.inverse() * h * t_plane;
}

namespace {

// SQPnP on normalized image coordinates (x, y) = (X/Z, Y/Z): K = I (fit/sqpnp.h).
bool SqPnp(const std::vector<Eigen::Vector3d>& points,
           const std::vector<Eigen::Vector2d>& normalized, StartCamera* start,
           SqPnpSearch search = SqPnpSearch::kGlobal) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  if (!SolveSqPnp(points, normalized, &rotation, &translation, search)) return false;
  start->rotation = rotation;
  start->center = -rotation.transpose() * translation;
  return true;
}

}  // namespace

Eigen::Matrix<double, 12, 1> SmallestEigenvector(const Eigen::Matrix<double, 12, 12>& m) {
  // Inverse iteration: each step multiplies the error by lambda_1 / lambda_2, which noisy
  // points in general position keep far below 1 (two or three steps). It stops where the unit
  // vector moves by less than kSettled, and hands over to Eigen's tridiagonal QR where it does
  // not within kMaxSteps (two eigenvalues close together) or where the matrix is singular to
  // rounding (v^T M v below kSingular of its trace: noise-free points, or a null space of two or
  // more dimensions -- six coplanar points of a RANSAC sample -- whose vectors are all minima and
  // Eigen's is the one the fitters were tuned with).
  constexpr int kMaxSteps = 8;
  constexpr double kSettled = 1e-13;
  constexpr double kSingular = 1e-12;
  Eigen::Matrix<double, 12, 12> l;
  if (FactorCholesky(m, &l)) {
    Eigen::Matrix<double, 12, 1> v = Eigen::Matrix<double, 12, 1>::Constant(1.0 / std::sqrt(12.0));
    for (int step = 0; step < kMaxSteps; ++step) {
      Eigen::Matrix<double, 12, 1> next = l.triangularView<Eigen::Lower>().solve(v);
      l.triangularView<Eigen::Lower>().transpose().solveInPlace(next);
      next.normalize();
      if (next.dot(v) < 0.0) next = -next;
      const double change = (next - v).norm();
      v = next;
      if (change < kSettled) {
        if (v.dot(m * v) > kSingular * m.trace()) return v;
        break;
      }
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(m);
  return eigen.eigenvectors().col(0);
}

Eigen::Matrix<double, 3, 4> NormalizedDlt(const std::vector<Eigen::Vector3d>& points,
                                          const std::vector<Eigen::Vector2d>& pixels) {
  // The 3D points arrive centred and unit-scaled (scene.h); the pixels are normalized here. With
  // both normalized, the 12 x 12 normal matrix A^T A is well conditioned enough that its
  // smallest eigenvector is the DLT solution to ~1e-12 at O(N) cost (A's SVD is O(N) too but
  // with a far larger constant).
  //
  // Each point adds the rows [x^T, 0, -u x^T] and [0, x^T, -v x^T] (x homogeneous, (u, v) the
  // normalized pixel), so A^T A = [[S, 0, -S_u], [0, S, -S_v], [-S_u, -S_v, S_uv]] with the 4 x 4
  // sums S = sum x x^T, S_u = sum u x x^T, S_v = sum v x x^T, S_uv = sum (u^2 + v^2) x x^T:
  // 4 x 10 distinct products per point instead of 2 x 144.
  const Eigen::Matrix3d t_pixel = HartleyTransform(pixels);
  // Column k: the upper triangle of x x^T (row by row) times weight k = 1, u, v, u^2 + v^2.
  Eigen::Matrix<double, 10, 4> sums = Eigen::Matrix<double, 10, 4>::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& x = points[i];
    const Eigen::Vector2d u = (t_pixel * pixels[i].homogeneous()).head<2>();
    Eigen::Matrix<double, 10, 1> outer;
    outer << x.x() * x.x(), x.x() * x.y(), x.x() * x.z(), x.x(),  //
        x.y() * x.y(), x.y() * x.z(), x.y(),                      //
        x.z() * x.z(), x.z(),                                     //
        1.0;
    const Eigen::RowVector4d weights(1.0, u.x(), u.y(), u.squaredNorm());
    sums.noalias() += outer * weights;
  }
  auto symmetric = [&](int k) {
    Eigen::Matrix4d m;
    int next = 0;
    for (int r = 0; r < 4; ++r) {
      for (int c = r; c < 4; ++c) m(r, c) = m(c, r) = sums(next++, k);
    }
    return m;
  };
  const Eigen::Matrix4d s = symmetric(0);
  Eigen::Matrix<double, 12, 12> normal = Eigen::Matrix<double, 12, 12>::Zero();
  normal.block<4, 4>(0, 0) = s;
  normal.block<4, 4>(4, 4) = s;
  normal.block<4, 4>(0, 8) = normal.block<4, 4>(8, 0) = -symmetric(1);
  normal.block<4, 4>(4, 8) = normal.block<4, 4>(8, 4) = -symmetric(2);
  normal.block<4, 4>(8, 8) = symmetric(3);
  const Eigen::Matrix<double, 12, 1> p = SmallestEigenvector(normal);
  Eigen::Matrix<double, 3, 4> pn;
  pn << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(), p.segment<4>(8).transpose();
  return t_pixel.inverse() * pn;
}

void RqDecomposition(const Eigen::Matrix3d& m, Eigen::Matrix3d* k, Eigen::Matrix3d* r) {
  // RQ from QR of the row-reversed transpose: with J the exchange matrix,
  // (J M)^T = Q U gives M = (J U^T J) (J Q^T), the first factor upper triangular.
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  j(0, 2) = j(1, 1) = j(2, 0) = 1.0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((j * m).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d u = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d upper = j * u.transpose() * j;
  Eigen::Matrix3d rotation = j * q.transpose();
  // Make K's diagonal positive: M = (K D)(D R) with D = diag(+-1), D^2 = I.
  const Eigen::Vector3d signs(upper(0, 0) < 0 ? -1.0 : 1.0, upper(1, 1) < 0 ? -1.0 : 1.0,
                              upper(2, 2) < 0 ? -1.0 : 1.0);
  upper = upper * signs.asDiagonal();
  rotation = signs.asDiagonal() * rotation;
  *k = upper / upper(2, 2);
  *r = rotation;
}

namespace {

// DltStart's camera, or nullopt with *behind the number of points behind the best linear camera.
std::optional<StartCamera> DltCameraOrBehind(const std::vector<Eigen::Vector3d>& points,
                                             const std::vector<Eigen::Vector2d>& pixels,
                                             int* behind) {
  Eigen::Matrix<double, 3, 4> p = NormalizedDlt(points, pixels);
  // P = lambda K [R | t]: the third row gives lambda * depth. Choose the sign that puts the
  // points in front; if no sign does, no camera sees them all.
  int in_front = 0;
  for (const auto& x : points) in_front += p.row(2).dot(x.homogeneous()) > 0.0 ? 1 : 0;
  const int n = static_cast<int>(points.size());
  if (in_front < n - in_front) {
    p = -p;
    in_front = n - in_front;
  }
  *behind = n - in_front;
  if (in_front != n) return std::nullopt;
  const Eigen::Matrix3d m = p.leftCols<3>();
  Eigen::Matrix3d k;
  Eigen::Matrix3d r;
  RqDecomposition(m, &k, &r);
  StartCamera start;
  start.rotation = r;
  start.center = -m.inverse() * p.col(3);
  start.intrinsics = IntrinsicsFromK(k);
  // det R has the sign of det M, but read from R: where M is nearly singular (the DLT does not
  // determine the camera, e.g. a plane and one point off it) det M's rounding can disagree with
  // the factor used.
  if (r.determinant() < 0.0) {
    // K R (X - C) = K (R F) (F X - F C) with F = diag(1, 1, -1): a proper rotation R F in the
    // world with z negated. Under noise a nearly degenerate scene can flip the sign, so the
    // fitter decides (start.cc) whether the world is really mirrored.
    const Eigen::Vector3d flip(1.0, 1.0, -1.0);
    start.rotation = r * flip.asDiagonal();
    start.center = flip.asDiagonal() * start.center;
    start.mirrored = true;
  }
  return start;
}

}  // namespace

StartCamera DltStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels) {
  int behind = 0;
  const std::optional<StartCamera> start = DltCameraOrBehind(points, pixels, &behind);
  if (!start) {
    throw SceneError(SceneError::Reason::kPointsBehindCamera,
                     "the correspondences fit no camera that has every point in front of it (" +
                         std::to_string(behind) + " of " + std::to_string(points.size()) +
                         " points behind the best linear camera)",
                     "Check the point order and look for mismatched or mis-clicked points");
  }
  return *start;
}

std::optional<StartCamera> DltStartIfInFront(const std::vector<Eigen::Vector3d>& points,
                                             const std::vector<Eigen::Vector2d>& pixels) {
  int behind = 0;
  return DltCameraOrBehind(points, pixels, &behind);
}

std::vector<Eigen::Vector2d> PlaneCoordinates(const std::vector<Eigen::Vector3d>& points,
                                              const Eigen::Matrix3d& plane_basis) {
  std::vector<Eigen::Vector2d> plane;
  plane.reserve(points.size());
  for (const auto& x : points) plane.push_back((plane_basis.transpose() * x).head<2>());
  return plane;
}

bool HomographyStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels,
                     const Eigen::Matrix3d& plane_basis, const Intrinsics& guess, bool focal_free,
                     bool aspect_free, StartCamera* start) {
  return StartFromHomography(NormalizedHomography(PlaneCoordinates(points, plane_basis), pixels),
                             plane_basis, guess, focal_free, aspect_free, start);
}

bool StartFromHomography(const Eigen::Matrix3d& h, const Eigen::Matrix3d& plane_basis,
                         const Intrinsics& guess, bool focal_free, bool aspect_free,
                         StartCamera* start) {
  // G = T^-1 H with T the principal point and skew part of K: G ~ diag(fx, fy, 1) [r1 r2 t].
  Eigen::Matrix3d t = Eigen::Matrix3d::Identity();
  t(0, 2) = guess.cx;
  t(1, 2) = guess.cy;
  const Eigen::Matrix3d g = t.inverse() * h;
  const Eigen::Vector3d g1 = g.col(0);
  const Eigen::Vector3d g2 = g.col(1);
  // r1 . r2 = 0 and |r1| = |r2| with r = (gx / fx, gy / fy, gz): linear in 1/fx^2, 1/fy^2.
  double fx = guess.fx;
  double fy = guess.fy;
  if (focal_free) {
    Eigen::Matrix2d a;
    Eigen::Vector2d b;
    a << g1.x() * g2.x(), g1.y() * g2.y(), g1.x() * g1.x() - g2.x() * g2.x(),
        g1.y() * g1.y() - g2.y() * g2.y();
    b << -g1.z() * g2.z(), g2.z() * g2.z() - g1.z() * g1.z();
    double wx = 0.0;
    double wy = 0.0;
    const double aspect = guess.fy / guess.fx;
    if (aspect_free) {
      const Eigen::Vector2d w = a.fullPivLu().solve(b);
      wx = w.x();
      wy = w.y();
    } else {
      // 1/fy^2 = 1/(aspect^2 fx^2): one unknown, least squares over both equations.
      const Eigen::Vector2d column = a.col(0) + a.col(1) / (aspect * aspect);
      const double denominator = column.squaredNorm();
      if (!(denominator > 0.0)) return false;
      wx = column.dot(b) / denominator;
      wy = wx / (aspect * aspect);
    }
    if (!(wx > 0.0 && wy > 0.0) || !std::isfinite(wx) || !std::isfinite(wy)) return false;
    fx = 1.0 / std::sqrt(wx);
    fy = 1.0 / std::sqrt(wy);
  }
  Intrinsics k = guess;
  k.fx = fx;
  k.fy = fy;
  k.k1 = k.k2 = 0.0;
  const Eigen::Matrix3d m = k.K().inverse() * h;
  double scale = 1.0 / std::sqrt(m.col(0).norm() * m.col(1).norm());
  // The plane's centroid (plane coordinates 0) is at m.col(2) in the camera: in front.
  if (m(2, 2) * scale < 0.0) scale = -scale;
  Eigen::Matrix3d r_plane;
  r_plane.col(0) = scale * m.col(0);
  r_plane.col(1) = scale * m.col(1);
  r_plane.col(2) = r_plane.col(0).cross(r_plane.col(1));
  r_plane = NearestRotationSvd(r_plane);
  const Eigen::Vector3d translation = scale * m.col(2);
  // point_in_cam = r_plane * plane_basis^T * point + translation.
  start->rotation = r_plane * plane_basis.transpose();
  start->center = -start->rotation.transpose() * translation;
  start->intrinsics = k;
  return start->rotation.allFinite() && start->center.allFinite() && std::isfinite(fx);
}

bool PnpStart(const std::vector<Eigen::Vector3d>& points,
              const std::vector<Eigen::Vector2d>& pixels, const Intrinsics& intrinsics,
              StartCamera* start, SqPnpSearch search) {
  std::vector<Eigen::Vector2d> normalized;
  normalized.reserve(pixels.size());
  try {
    for (const auto& pixel : pixels) {
      const Eigen::Vector3d ray = CamRayFromPixel(intrinsics, pixel);
      normalized.emplace_back(ray.x(), ray.y());
    }
  } catch (const std::domain_error&) {
    return false;
  }
  if (!SqPnp(points, normalized, start, search)) return false;
  start->intrinsics = intrinsics;
  return true;
}

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinFovDeg = 0.5;
constexpr double kMaxFovDeg = 175.0;

}  // namespace

double SweepMinFocalPx(int image_width) {
  return 0.5 * image_width / std::tan(0.5 * kMaxFovDeg * kPi / 180.0);
}

bool FocalSweepStart(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels, const Intrinsics& guess,
                     double aspect, int image_width, StartCamera* start,
                     std::vector<StartCamera>* other_minima) {
  constexpr int kSteps = 48;
  // Each coarse valley is looked at again on a grid this many times finer between its
  // neighbours: two valleys can lie within one coarse step (a factor 1.2 in focal length; seen:
  // 4 noise-free points with valleys at fx 2911 and 3132 px, LM from the coarse minimum ending
  // in the wrong one at RMS 0.04 px).
  constexpr int kFine = 4;
  const double f_min = SweepMinFocalPx(image_width);
  const double f_max = 0.5 * image_width / std::tan(0.5 * kMinFovDeg * kPi / 180.0);
  const double kNone = std::numeric_limits<double>::infinity();
  // The RMS of the SQPnP pose at focal length f_min (f_max / f_min)^(step / (kSteps - 1)).
  auto evaluate = [&](double step, StartCamera* candidate) {
    Intrinsics k = guess;
    k.fx = f_min * std::pow(f_max / f_min, step / (kSteps - 1.0));
    k.fy = aspect * k.fx;
    if (!PnpStart(points, pixels, k, candidate)) return kNone;
    double sum = 0.0;
    for (size_t j = 0; j < points.size(); ++j) {
      const Eigen::Vector3d p = candidate->rotation * (points[j] - candidate->center);
      if (!(p.z() > 0.0)) return kNone;
      sum += (PixelFromCam(k, p) - pixels[j]).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(points.size()));
  };
  // The local minima of `rms` (ascending): each one's index.
  auto local_minima = [](const std::vector<double>& rms) {
    std::vector<int> minima;
    const int size = static_cast<int>(rms.size());
    for (int i = 0; i < size; ++i) {
      const bool below_left = i == 0 || rms[i] < rms[i - 1];
      const bool below_right = i == size - 1 || rms[i] <= rms[i + 1];
      if (std::isfinite(rms[i]) && below_left && below_right) minima.push_back(i);
    }
    std::sort(minima.begin(), minima.end(), [&](int a, int b) { return rms[a] < rms[b]; });
    return minima;
  };
  std::vector<double> rms(kSteps, kNone);
  std::vector<StartCamera> candidates(kSteps);
  for (int i = 0; i < kSteps; ++i) rms[i] = evaluate(i, &candidates[i]);
  // Every valley's starts: the minima of the fine grid around each coarse minimum.
  std::vector<double> valley_rms;
  std::vector<StartCamera> valley_starts;
  for (const int i : local_minima(rms)) {
    const int size = 2 * kFine + 1;
    std::vector<double> fine_rms(size, kNone);
    std::vector<StartCamera> fine(size);
    for (int j = 0; j < size; ++j) {
      const int offset = j - kFine;  // in 1 / kFine of a coarse step
      if (offset == 0) {
        fine_rms[j] = rms[i];
        fine[j] = candidates[i];
      } else if (i + static_cast<double>(offset) / kFine >= 0.0 &&
                 i + static_cast<double>(offset) / kFine <= kSteps - 1.0) {
        fine_rms[j] = evaluate(i + static_cast<double>(offset) / kFine, &fine[j]);
      }
    }
    for (const int j : local_minima(fine_rms)) {
      valley_rms.push_back(fine_rms[j]);
      valley_starts.push_back(fine[j]);
    }
  }
  if (valley_starts.empty()) return false;
  std::vector<int> order(valley_starts.size());
  for (size_t v = 0; v < order.size(); ++v) order[v] = static_cast<int>(v);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return valley_rms[a] < valley_rms[b]; });
  *start = valley_starts[order[0]];
  if (other_minima != nullptr) {
    for (size_t v = 1; v < order.size(); ++v) other_minima->push_back(valley_starts[order[v]]);
  }
  return true;
}

}  // namespace internal
}  // namespace camproj

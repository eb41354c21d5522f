#include "camproj/intrinsics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "check.h"

namespace camproj {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

using internal::Require;
using internal::RequireFinite;

void Intrinsics::Check() const {
  // Every projection checks its intrinsics: one test for the valid case first (a sum is finite
  // only if every term is), the named refusals below otherwise.
  if (std::isfinite(fx + fy + cx + cy + skew + k1 + k2) && fx > 0.0 && fy > 0.0) return;
  RequireFinite(fx, "fx");
  RequireFinite(fy, "fy");
  RequireFinite(cx, "cx");
  RequireFinite(cy, "cy");
  RequireFinite(skew, "skew");
  RequireFinite(k1, "k1");
  RequireFinite(k2, "k2");
  Require(fx > 0.0, "fx must be positive, got ", fx);
  Require(fy > 0.0, "fy must be positive, got ", fy);
}

Eigen::Matrix3d Intrinsics::K() const {
  Eigen::Matrix3d k;
  k << fx, skew, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

Intrinsics Intrinsics::Pinhole() const {
  Intrinsics pinhole = *this;
  pinhole.k1 = 0.0;
  pinhole.k2 = 0.0;
  return pinhole;
}

Intrinsics IntrinsicsFromK(const Eigen::Matrix3d& K) {
  internal::RequireFiniteAll(K, "K");
  Require(K(1, 0) == 0.0 && K(2, 0) == 0.0 && K(2, 1) == 0.0,
          "K must be upper triangular, got K(1,0) = ", K(1, 0), ", K(2,0) = ", K(2, 0),
          ", K(2,1) = ", K(2, 1));
  Require(K(2, 2) != 0.0, "K(2,2) must be non-zero");
  const Eigen::Matrix3d k = K / K(2, 2);
  Intrinsics intrinsics;
  intrinsics.fx = k(0, 0);
  intrinsics.fy = k(1, 1);
  intrinsics.cx = k(0, 2);
  intrinsics.cy = k(1, 2);
  intrinsics.skew = k(0, 1);
  intrinsics.Check();
  return intrinsics;
}

Intrinsics ConvertPixelOrigin(const Intrinsics& intrinsics, PixelOrigin from, PixelOrigin to) {
  Intrinsics converted = intrinsics;
  const double shift = PixelOriginShift(from, to);
  converted.cx += shift;
  converted.cy += shift;
  return converted;
}

Eigen::Vector2d PixelFromCam(const Intrinsics& intrinsics, const Eigen::Vector3d& point_in_cam) {
  intrinsics.Check();
  internal::RequireFiniteAll(point_in_cam, "point_in_cam");
  Require(point_in_cam.z() > 0.0, "point is not in front of the camera: z = ", point_in_cam.z());
  const double params[7] = {intrinsics.fx, intrinsics.fy,   intrinsics.cx, intrinsics.cy,
                            intrinsics.skew, intrinsics.k1, intrinsics.k2};
  Eigen::Vector2d pixel;
  PixelFromNormalized(params, point_in_cam.x() / point_in_cam.z(),
                      point_in_cam.y() / point_in_cam.z(), pixel.data());
  return pixel;
}

double RadialFoldRadius(double k1, double k2) {
  RequireFinite(k1, "k1");
  RequireFinite(k2, "k2");
  // Smallest positive root s = r^2 of 5 k2 s^2 + 3 k1 s + 1.
  double s_fold = kInfinity;
  if (k2 == 0.0) {
    if (k1 < 0.0) s_fold = -1.0 / (3.0 * k1);
  } else {
    const double disc = 9.0 * k1 * k1 - 20.0 * k2;
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc);
      for (const double s : {(-3.0 * k1 - sq) / (10.0 * k2), (-3.0 * k1 + sq) / (10.0 * k2)}) {
        if (s > 0.0) s_fold = std::min(s_fold, s);
      }
    }
  }
  return std::sqrt(s_fold);
}

Eigen::Vector3d CamRayFromPixel(const Intrinsics& intrinsics, const Eigen::Vector2d& pixel) {
  intrinsics.Check();
  internal::RequireFiniteAll(pixel, "pixel");
  // Undo K first: (xd, yd) are the distorted normalized coordinates.
  const double yd = (pixel.y() - intrinsics.cy) / intrinsics.fy;
  const double xd = (pixel.x() - intrinsics.cx - intrinsics.skew * yd) / intrinsics.fx;
  if (!intrinsics.HasDistortion()) return {xd, yd, 1.0};

  // Radial distortion scales the radius: rd = g(r) = r (1 + k1 r^2 + k2 r^4). g is invertible
  // where it is increasing, on [0, r_fold) with r_fold the first zero of
  // g'(r) = 1 + 3 k1 r^2 + 5 k2 r^4; beyond g(r_fold) the image folds over and is refused.
  const double k1 = intrinsics.k1;
  const double k2 = intrinsics.k2;
  auto g = [&](double r) { return r * (1.0 + r * r * (k1 + r * r * k2)); };
  const double r_fold = RadialFoldRadius(k1, k2);
  const double rd = std::hypot(xd, yd);
  if (rd == 0.0) return {0.0, 0.0, 1.0};
  if (std::isfinite(r_fold) && !(rd < g(r_fold))) {
    throw std::domain_error(internal::Concat(
        "cannot undistort pixel (", pixel.x(), ", ", pixel.y(), "): radial distortion k1 = ", k1,
        ", k2 = ", k2, " folds over at normalized radius ", r_fold, " (distorted ", g(r_fold),
        "), this pixel is at distorted radius ", rd));
  }
  // Safeguarded Newton on the bracket [0, min(r_fold, upper)] where g is increasing.
  double lo = 0.0;
  double hi = r_fold;
  if (!std::isfinite(hi)) {
    hi = std::max(1.0, rd);
    while (g(hi) < rd) hi *= 2.0;
  }
  double r = std::min(rd, 0.5 * (lo + hi));
  constexpr int kMaxIterations = 200;
  constexpr double kRadiusTolerance = 1e-15;
  for (int i = 0; i < kMaxIterations; ++i) {
    const double f = g(r) - rd;
    if (f < 0.0) lo = r; else hi = r;
    const double r2 = r * r;
    const double slope = 1.0 + r2 * (3.0 * k1 + 5.0 * k2 * r2);
    double next = r - f / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - r) <= kRadiusTolerance * (1.0 + r);
    r = next;
    if (done || hi - lo <= kRadiusTolerance * (1.0 + r)) break;
  }
  return {xd * r / rd, yd * r / rd, 1.0};
}

}  // namespace camproj

#include "camproj/intrinsics.h"

#include <cmath>

#include "check.h"

namespace camproj {

using internal::Require;
using internal::RequireFinite;

void Intrinsics::Check() const {
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
  Require(point_in_cam.z() > 0.0, "point is not in front of the camera: z = ", point_in_cam.z());
  const double params[7] = {intrinsics.fx, intrinsics.fy,   intrinsics.cx, intrinsics.cy,
                            intrinsics.skew, intrinsics.k1, intrinsics.k2};
  Eigen::Vector2d pixel;
  PixelFromNormalized(params, point_in_cam.x() / point_in_cam.z(),
                      point_in_cam.y() / point_in_cam.z(), pixel.data());
  return pixel;
}

Eigen::Vector3d CamRayFromPixel(const Intrinsics& intrinsics, const Eigen::Vector2d& pixel) {
  intrinsics.Check();
  internal::RequireFiniteAll(pixel, "pixel");
  // Undo K first: (xd, yd) are the distorted normalized coordinates.
  const double yd = (pixel.y() - intrinsics.cy) / intrinsics.fy;
  const double xd = (pixel.x() - intrinsics.cx - intrinsics.skew * yd) / intrinsics.fx;
  if (!intrinsics.HasDistortion()) return {xd, yd, 1.0};

  // Radial distortion scales the radius: rd = r (1 + k1 r^2 + k2 r^4). Solve for r by Newton's
  // method from r = rd; the map must be increasing on [0, r] to be invertible.
  const double rd = std::hypot(xd, yd);
  if (rd == 0.0) return {0.0, 0.0, 1.0};
  const double k1 = intrinsics.k1;
  const double k2 = intrinsics.k2;
  double r = rd;
  constexpr int kMaxIterations = 100;
  constexpr double kRadiusTolerance = 1e-14;
  for (int i = 0; i < kMaxIterations; ++i) {
    const double r2 = r * r;
    const double f = r * (1.0 + r2 * (k1 + r2 * k2)) - rd;
    const double df = 1.0 + r2 * (3.0 * k1 + 5.0 * k2 * r2);
    if (!(df > 0.0)) break;
    const double step = f / df;
    r -= step;
    if (std::abs(step) <= kRadiusTolerance * (1.0 + r)) {
      const double r2_final = r * r;
      const double slope = 1.0 + r2_final * (3.0 * k1 + 5.0 * k2 * r2_final);
      if (r >= 0.0 && slope > 0.0) return {xd * r / rd, yd * r / rd, 1.0};
      break;
    }
  }
  throw std::domain_error(internal::Concat("cannot undistort pixel (", pixel.x(), ", ", pixel.y(),
                                           "): radial distortion k1 = ", k1, ", k2 = ", k2,
                                           " is not invertible at that radius"));
}

}  // namespace camproj

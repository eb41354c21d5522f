#include "camproj/intrinsics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>

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
  if (std::isfinite(fx + fy + cx + cy + skew + k1 + k2 + p1 + p2 + k3) && fx > 0.0 && fy > 0.0) {
    return;
  }
  RequireFinite(fx, "fx");
  RequireFinite(fy, "fy");
  RequireFinite(cx, "cx");
  RequireFinite(cy, "cy");
  RequireFinite(skew, "skew");
  RequireFinite(k1, "k1");
  RequireFinite(k2, "k2");
  RequireFinite(p1, "p1");
  RequireFinite(p2, "p2");
  RequireFinite(k3, "k3");
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
  pinhole.k1 = pinhole.k2 = pinhole.p1 = pinhole.p2 = pinhole.k3 = 0.0;
  return pinhole;
}

std::string DistortionText(const Intrinsics& k) {
  std::string text = internal::Concat("k1 = ", k.k1, ", k2 = ", k.k2);
  if (k.HasBeyondTwoRadial()) {
    text += internal::Concat(", p1 = ", k.p1, ", p2 = ", k.p2, ", k3 = ", k.k3);
  }
  return text;
}

std::array<double, kIntrinsicsArraySize> IntrinsicsArray(const Intrinsics& k) {
  return {k.fx, k.fy, k.cx, k.cy, k.skew, k.k1, k.k2, k.p1, k.p2, k.k3};
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
  const std::array<double, kIntrinsicsArraySize> params = IntrinsicsArray(intrinsics);
  Eigen::Vector2d pixel;
  const double x = point_in_cam.x() / point_in_cam.z();
  const double y = point_in_cam.y() / point_in_cam.z();
  PixelFromNormalized(params.data(), x, y, pixel.data());
  if (!pixel.allFinite() && !intrinsics.HasDistortion()) {
    // Without a lens the polynomial's zero terms still overflow (r^4 * 0 = inf * 0 = NaN beyond
    // |x| ~ 1e77) where the pinhole's pixel is finite: computed without them.
    pixel = Eigen::Vector2d(intrinsics.fx * x + intrinsics.skew * y + intrinsics.cx,
                            intrinsics.fy * y + intrinsics.cy);
  }
  return pixel;
}

namespace {

// Where the scaled fold search below stops looking: h's terms at s <= 2^339 stay within a
// double's range (|7 k3 s^3| < 2^1023 with the scaled |k3| < 8).
constexpr double kMaxScaledFoldRoot = 0x1p339;

// Bisection of h on [lo, hi] (h(lo) > 0 >= h(hi)) to adjacent doubles. Midpoint halvings reach
// adjacency within ~2100 steps from any bracket of finite doubles; the bound is a guard.
template <class H>
double BisectFold(const H& h, double lo, double hi) {
  for (int step = 0; step < 2200 && std::nextafter(lo, hi) < hi; ++step) {
    const double mid = 0.5 * (lo + hi);
    (h(mid) > 0.0 ? lo : hi) = mid;
  }
  return hi;
}

// The smallest root s > 0 of h(s) = 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3 (h(0) = 1), k3 != 0, for
// coefficients scaled to |k1| < 2, |k2| < 4, |k3| < 8 (RadialFoldRadius): h is monotone between its
// critical points (the roots of h'(s) = 3 k1 + 10 k2 s + 21 k3 s^2), so the first interval whose
// end has h <= 0 holds the root, found by bisection to the last bit. +infinity beyond
// kMaxScaledFoldRoot.
double SmallestCubicFoldRoot(double k1, double k2, double k3) {
  auto h = [&](double s) { return 1.0 + s * (3.0 * k1 + s * (5.0 * k2 + s * 7.0 * k3)); };
  std::vector<double> ends;
  const double disc = 100.0 * k2 * k2 - 252.0 * k1 * k3;
  if (disc >= 0.0) {
    const double sq = std::sqrt(disc);
    for (const double s : {(-10.0 * k2 - sq) / (42.0 * k3), (-10.0 * k2 + sq) / (42.0 * k3)}) {
      if (s > 0.0) ends.push_back(std::min(s, kMaxScaledFoldRoot));
    }
    std::sort(ends.begin(), ends.end());
  }
  double lo = 0.0;
  for (const double end : ends) {
    if (h(end) <= 0.0) return BisectFold(h, lo, end);
    lo = end;
  }
  if (k3 > 0.0) return kInfinity;  // h > 0 beyond the last critical point
  double hi = std::max(1.0, 2.0 * lo);
  while (h(hi) > 0.0) {
    if (hi >= kMaxScaledFoldRoot) return kInfinity;
    hi *= 2.0;
  }
  return BisectFold(h, lo, hi);
}

}  // namespace

double RadialFoldRadius(double k1, double k2, double k3) {
  RequireFinite(k1, "k1");
  RequireFinite(k2, "k2");
  RequireFinite(k3, "k3");
  // In units of s = r^2 scaled by a power of two c ~ max(|k1|, |k2|^1/2, |k3|^1/3), the
  // scaled coefficients a1 = k1 / c, a2 = k2 / c^2, a3 = k3 / c^3 are at most ~1: no square or
  // product below overflows (k1 = 1e160 made the discriminant infinite and the search never
  // ended) or loses the fold (k1 = -1e308 overflowed 3 k1 and answered 0). Powers of two scale
  // exactly: for moderate coefficients the roots are those of the unscaled formulas, bit for bit.
  const double scale = std::max({std::abs(k1), std::sqrt(std::abs(k2)), std::cbrt(std::abs(k3))});
  if (scale == 0.0) return kInfinity;  // no distortion
  const int e = std::ilogb(scale);
  const double a1 = std::ldexp(k1, -e);
  const double a2 = std::ldexp(k2, -2 * e);
  const double a3 = std::ldexp(k3, -3 * e);
  // The fold in scaled units t = s 2^e; s = t 2^-e (kInfinity stays so).
  const auto unscaled_radius = [&](double t) { return std::sqrt(std::ldexp(t, -e)); };
  if (a3 != 0.0) {
    const double t_fold = SmallestCubicFoldRoot(a1, a2, a3);
    // Not found below kMaxScaledFoldRoot: beyond r = 2^100 (s = 2^200) no image reaches (a
    // 179.99 degree field of view ends at r = 1.1e4), so there it is "no fold"; nearer, the
    // coefficients are too far apart in scale for a double to place it.
    if (std::isinf(t_fold) && a3 < 0.0 && std::ldexp(kMaxScaledFoldRoot, -e) < 0x1p200) {
      throw std::invalid_argument(internal::Concat(
          "radial distortion k1 = ", k1, ", k2 = ", k2, ", k3 = ", k3,
          ": the coefficients are too far apart in scale to place the lens's fold in double "
          "precision"));
    }
    return unscaled_radius(t_fold);
  }
  // Smallest positive root t of 5 a2 t^2 + 3 a1 t + 1, as q / (5 a2) and 1 / q with
  // q = -(3 a1 + sign(a1) sqrt(disc)) / 2: the textbook formula's -3 a1 - sqrt(disc) cancels
  // where a2 is small against a1^2 (k1 = -1e308, k2 = 1e308 lost the fold at 5.8e-155).
  double t_fold = kInfinity;
  const double disc = 9.0 * a1 * a1 - 20.0 * a2;
  if (disc >= 0.0) {
    const double q = -0.5 * (3.0 * a1 + std::copysign(std::sqrt(disc), a1));
    for (const double t : {a2 != 0.0 ? q / (5.0 * a2) : kInfinity, q != 0.0 ? 1.0 / q : kInfinity}) {
      if (t > 0.0) t_fold = std::min(t_fold, t);
    }
  }
  return unscaled_radius(t_fold);
}

Eigen::Vector3d CamRayFromPixel(const Intrinsics& intrinsics, const Eigen::Vector2d& pixel) {
  intrinsics.Check();
  internal::RequireFiniteAll(pixel, "pixel");
  // Undo K first: (xd, yd) are the distorted normalized coordinates.
  const double yd = (pixel.y() - intrinsics.cy) / intrinsics.fy;
  const double xd = (pixel.x() - intrinsics.cx - intrinsics.skew * yd) / intrinsics.fx;
  // A finite pixel far from a finite principal point (cx = -1e308) is beyond a double.
  if (!std::isfinite(xd) || !std::isfinite(yd)) {
    internal::ThrowInvalidArgument("the ray of pixel (", pixel.x(), ", ", pixel.y(),
                                   ") cannot be represented in a double (normalized ", xd, ", ", yd,
                                   ") for fx = ", intrinsics.fx, ", fy = ", intrinsics.fy,
                                   ", cx = ", intrinsics.cx, ", cy = ", intrinsics.cy);
  }
  if (!intrinsics.HasDistortion()) return {xd, yd, 1.0};

  // Radial distortion scales the radius: rd = g(r) = r d(r), d = 1 + k1 r^2 + k2 r^4 + k3 r^6.
  // g is invertible where it is increasing, on [0, r_fold) with r_fold the first zero of
  // g'(r) = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6; beyond g(r_fold) the image folds over and is
  // refused.
  const double k1 = intrinsics.k1, k2 = intrinsics.k2, k3 = intrinsics.k3;
  auto g = [&](double r) {
    const double r2 = r * r;
    return r * (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3)));
  };
  const double r_fold = RadialFoldRadius(k1, k2, k3);
  auto refuse = [&](double rd) {
    throw std::domain_error(internal::Concat(
        "cannot undistort pixel (", pixel.x(), ", ", pixel.y(), "): radial distortion k1 = ", k1,
        ", k2 = ", k2, ", k3 = ", k3, " folds over at normalized radius ", r_fold,
        " (distorted ", g(r_fold), "), this pixel is at distorted radius ", rd));
  };
  // The radial inverse of (xd, yd): exact without p1, p2, else Newton's start below.
  Eigen::Vector2d xy(xd, yd);
  const double rd = std::hypot(xd, yd);
  if (rd > 0.0) {
    if (std::isfinite(r_fold) && !(rd < g(r_fold))) {
      if (intrinsics.p1 == 0.0 && intrinsics.p2 == 0.0) refuse(rd);
    } else {
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
        const double slope = 1.0 + r2 * (3.0 * k1 + r2 * (5.0 * k2 + 7.0 * k3 * r2));
        double next = r - f / slope;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        const bool done = std::abs(next - r) <= kRadiusTolerance * (1.0 + r);
        r = next;
        if (done || hi - lo <= kRadiusTolerance * (1.0 + r)) break;
      }
      xy *= r / rd;
    }
  }
  if (intrinsics.p1 == 0.0 && intrinsics.p2 == 0.0) return {xy.x(), xy.y(), 1.0};

  // Tangential terms: Newton on the 2D map (x, y) -> (xd, yd) from the radial solution. Its
  // Jacobian (PixelFromNormalized's model):
  //   dxd/dx = d + x^2 d' + 2 p1 y + 6 p2 x    dxd/dy = x y d' + 2 p1 x + 2 p2 y
  //   dyd/dx = x y d' + 2 p1 x + 2 p2 y         dyd/dy = d + y^2 d' + 6 p1 y + 2 p2 x
  // with d' = 2 (k1 + 2 k2 r2 + 3 k3 r2^2).
  const double p1 = intrinsics.p1, p2 = intrinsics.p2;
  constexpr int kMaxNewton = 100;
  constexpr double kTolerance = 1e-15;
  for (int i = 0; i < kMaxNewton; ++i) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double d = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double d1 = 2.0 * (k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2));
    const Eigen::Vector2d f(d * x + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd,
                            d * y + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd);
    const double off = x * y * d1 + 2.0 * p1 * x + 2.0 * p2 * y;
    Eigen::Matrix2d jacobian;
    jacobian << d + x * x * d1 + 2.0 * p1 * y + 6.0 * p2 * x, off,  //
        off, d + y * y * d1 + 6.0 * p1 * y + 2.0 * p2 * x;
    const double det = jacobian.determinant();
    if (!(det > 0.0) || !(std::sqrt(r2) < r_fold)) break;
    const Eigen::Vector2d step = jacobian.inverse() * f;
    xy -= step;
    if (step.norm() <= kTolerance * (1.0 + xy.norm())) return {xy.x(), xy.y(), 1.0};
  }
  throw std::domain_error(internal::Concat(
      "cannot undistort pixel (", pixel.x(), ", ", pixel.y(), "): the lens (k1 = ", k1,
      ", k2 = ", k2, ", p1 = ", p1, ", p2 = ", p2, ", k3 = ", k3,
      ") folds over there (its Jacobian determinant reaches 0) or Newton did not converge"));
}

}  // namespace camproj

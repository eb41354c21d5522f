// Pinhole intrinsics with OpenCV's five-coefficient lens (k1, k2, p1, p2, k3; docs/conventions.md).
//
//   x = X/Z, y = Y/Z                          point_in_cam -> normalized image coordinates
//   r2 = x^2 + y^2
//   d = 1 + k1 r2 + k2 r2^2 + k3 r2^3         radial
//   xd = d x + 2 p1 x y + p2 (r2 + 2 x^2)     tangential (decentring), as cv::projectPoints
//   yd = d y + p1 (r2 + 2 y^2) + 2 p2 x y
//   u = fx xd + skew yd + cx                  pixel, in the pixel origin the intrinsics are in
//   v = fy yd + cy
//
// K = [fx skew cx; 0 fy cy; 0 0 1]. Unless a function takes a PixelOrigin, cx and cy are in the
// default kCenter convention; convert with ConvertPixelOrigin below.
#ifndef CAMPROJ_INTRINSICS_H_
#define CAMPROJ_INTRINSICS_H_

#include <array>
#include <string>

#include <Eigen/Core>

#include "camproj/conventions.h"

namespace camproj {

struct Intrinsics {
  double fx = 1.0;    // px
  double fy = 1.0;    // px
  double cx = 0.0;    // px
  double cy = 0.0;    // px
  double skew = 0.0;  // px; K(0,1)
  double k1 = 0.0;    // radial, on normalized coordinates
  double k2 = 0.0;
  double p1 = 0.0;    // tangential
  double p2 = 0.0;
  double k3 = 0.0;    // radial, r^6

  // Throws std::invalid_argument naming the field unless all are finite and fx, fy > 0.
  void Check() const;
  Eigen::Matrix3d K() const;
  bool HasDistortion() const { return k1 != 0.0 || k2 != 0.0 || HasBeyondTwoRadial(); }
  // p1, p2 or k3 non-zero: a lens beyond the two radial terms the GL lens exports handle.
  bool HasBeyondTwoRadial() const { return p1 != 0.0 || p2 != 0.0 || k3 != 0.0; }
  // The same camera without distortion (what a GL projection matrix can represent).
  Intrinsics Pinhole() const;
};

// Intrinsics from a 3x3 upper-triangular K with K(2,2) != 0 (scaled to 1); throws otherwise.
Intrinsics IntrinsicsFromK(const Eigen::Matrix3d& K);

// cx, cy shifted by PixelOriginShift(from, to); everything else unchanged.
Intrinsics ConvertPixelOrigin(const Intrinsics& intrinsics, PixelOrigin from, PixelOrigin to);

// Pixel of normalized image coordinates (x, y) = (X/Z, Y/Z). `intrinsics` points to
// [fx, fy, cx, cy, skew, k1, k2, p1, p2, k3] (kIntrinsicsArraySize). Templated so Ceres' Jets
// share the library's model.
inline constexpr int kIntrinsicsArraySize = 10;
template <typename T>
inline void PixelFromNormalized(const T* intrinsics, const T& x, const T& y, T* pixel) {
  const T xx = x * x, yy = y * y, xy = x * y;
  const T r2 = xx + yy;
  const T d = T(1.0) + r2 * (intrinsics[5] + r2 * (intrinsics[6] + r2 * intrinsics[9]));
  const T p1 = intrinsics[7], p2 = intrinsics[8];
  const T xd = d * x + T(2.0) * p1 * xy + p2 * (r2 + T(2.0) * xx);
  const T yd = d * y + p1 * (r2 + T(2.0) * yy) + T(2.0) * p2 * xy;
  pixel[0] = intrinsics[0] * xd + intrinsics[4] * yd + intrinsics[2];
  pixel[1] = intrinsics[1] * yd + intrinsics[3];
}

// "k1 = .., k2 = .." and, when p1, p2 or k3 is non-zero, ", p1 = .., p2 = .., k3 = .." (%.17g):
// how messages name a lens.
std::string DistortionText(const Intrinsics& intrinsics);

// The array PixelFromNormalized reads.
std::array<double, kIntrinsicsArraySize> IntrinsicsArray(const Intrinsics& intrinsics);

// Pixel of a point in the cam frame. Throws std::invalid_argument on invalid intrinsics,
// a non-finite point, or unless point_in_cam.z() > 0.
Eigen::Vector2d PixelFromCam(const Intrinsics& intrinsics, const Eigen::Vector3d& point_in_cam);

// The first fold of the radial map r -> g(r) = r (1 + k1 r^2 + k2 r^4 + k3 r^6) (r = normalized
// undistorted radius): the smallest r > 0 where g'(r) = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 = 0,
// i.e. the smallest positive root s = r^2 of 7 k3 s^3 + 5 k2 s^2 + 3 k1 s + 1; +infinity when there
// is none (g increases for ever, e.g. k1, k2, k3 >= 0). g is increasing on [0, r_fold): the model
// is a valid lens there only. Example: k2 = k3 = 0, k1 < 0 gives r_fold = 1 / sqrt(-3 k1).
// Computed in units scaled by a power of two to the coefficients' size, so extreme coefficients
// (1e+-300) neither overflow nor lose the fold. Also +infinity for a fold beyond r = 2^100, which
// no image reaches. Throws std::invalid_argument unless k1, k2, k3 are finite, and for k3 < 0 so
// much smaller in scale than k1 or k2 (k1 = 1e160, k3 = -1e160) that a double cannot place the
// fold.
double RadialFoldRadius(double k1, double k2, double k3 = 0.0);

// The ray through `pixel`, as (x, y, 1) in the cam frame: the inverse of PixelFromCam up to depth.
// With radial distortion alone it inverts the radial map by safeguarded Newton to ~1e-15 in
// normalized units: r -> r d(r) is invertible where it increases, up to its first fold r_fold
// (where d/dr [r d(r)] = 0); a pixel at or beyond the fold's distorted radius throws
// std::domain_error. With p1 or p2 it solves the 2D map by Newton from the radial solution, to
// ~1e-15, inside the radial fold; it throws std::domain_error where the map's Jacobian
// determinant reaches 0 or Newton does not converge (a pixel the lens folds over).
Eigen::Vector3d CamRayFromPixel(const Intrinsics& intrinsics, const Eigen::Vector2d& pixel);

}  // namespace camproj

#endif  // CAMPROJ_INTRINSICS_H_

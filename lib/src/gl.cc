#include "camproj/gl.h"

#include <cmath>
#include <utility>

#include <Eigen/Geometry>

#include "check.h"

namespace camproj {

using internal::Require;
using internal::ThrowInvalidArgument;
using internal::CheckedResult;
using internal::RequireFiniteAll;
using internal::RequireFiniteResult;

namespace {

// f n / (f - n) and (f + n) / (f - n) without the overflow of f n or f + n when the depths are
// huge, or the underflow of f n when they are tiny (a world in units of 2^-600 or 2^-1000): the
// plain forms wherever f n is a normal double, so that ordinary depths keep their rounding (and
// glm's); a factor 2 is exact, so 2 f n / (f - n) is 2 times it.
double ProductOverRange(double n, double f) {
  return std::isnormal(f * n) ? f * n / (f - n) : n * (f / (f - n));
}
double SumOverRange(double n, double f) {
  const double plain = (f + n) / (f - n);
  return std::isfinite(plain) ? plain : f / (f - n) + n / (f - n);
}

// The depth row (A, B) of a perspective projection: clip.z = A z_eye + B, clip.w = -z_eye.
// See the table in gl.h.
Eigen::Vector2d DepthRow(double n, double f, const GlDepth& depth) {
  const bool infinite = std::isinf(f);
  const bool zo = depth.clip_depth == ClipDepth::kZeroToOne;
  if (!depth.reversed_z) {
    if (zo) return infinite ? Eigen::Vector2d(-1.0, -n) : Eigen::Vector2d(-f / (f - n), -ProductOverRange(n, f));
    return infinite ? Eigen::Vector2d(-1.0, -2.0 * n)
                    : Eigen::Vector2d(-SumOverRange(n, f), -2.0 * ProductOverRange(n, f));
  }
  if (zo) return infinite ? Eigen::Vector2d(0.0, n) : Eigen::Vector2d(n / (f - n), ProductOverRange(n, f));
  return infinite ? Eigen::Vector2d(1.0, 2.0 * n)
                  : Eigen::Vector2d(SumOverRange(n, f), 2.0 * ProductOverRange(n, f));
}

Eigen::Matrix4d PerspectiveMatrix(double x_scale, double x_skew, double x_offset, double y_scale,
                                  double y_offset, const Eigen::Vector2d& depth_row) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = x_scale;
  m(0, 1) = x_skew;
  m(0, 2) = x_offset;
  m(1, 1) = y_scale;
  m(1, 2) = y_offset;
  m(2, 2) = depth_row(0);
  m(2, 3) = depth_row(1);
  m(3, 2) = -1.0;
  return m;
}

// Valid arguments can still give a matrix beyond a double: entries that overflow (near 1e308 over
// a width of 1e-300) or scales that underflow to 0 (every point mapped to the image centre, or
// every depth to one value). The depth scale is (2,3) in a perspective matrix (ndc z = -A - B /
// z_eye), (2,2) in an orthographic one.
template <typename... Args>
const Eigen::Matrix4d& CheckedProjection(const Eigen::Matrix4d& m, int depth_scale_col,
                                         const Args&... what) {
  RequireFiniteResult(m, what...);
  Require(m(0, 0) != 0.0 && m(1, 1) != 0.0 && m(2, depth_scale_col) != 0.0, what...,
          " cannot be represented in a double (a scale underflows to 0: (0,0) = ", m(0, 0),
          ", (1,1) = ", m(1, 1), ", (2,", depth_scale_col, ") = ", m(2, depth_scale_col), ")");
  return m;
}

// The matrix divided by its positive scale -m(3,2), after checking the perspective structure.
Eigen::Matrix4d NormalizedPerspective(const Eigen::Matrix4d& clip_from_gl_eye) {
  RequireFiniteAll(clip_from_gl_eye, "projection matrix");
  const Eigen::Matrix4d& m = clip_from_gl_eye;
  Require(m(3, 2) < 0.0, "not a perspective projection matrix: entry (row 3, col 2) must be < 0 "
          "(clip.w = -z_eye), got ", m(3, 2));
  const int zero_entries[][2] = {{0, 3}, {1, 0}, {1, 3}, {2, 0}, {2, 1}, {3, 0}, {3, 1}, {3, 3}};
  for (const auto& rc : zero_entries) {
    Require(m(rc[0], rc[1]) == 0.0, "not a perspective projection matrix of a pinhole camera: "
            "entry (row ", rc[0], ", col ", rc[1], ") must be 0, got ", m(rc[0], rc[1]));
  }
  return m / -m(3, 2);
}

}  // namespace

Eigen::Matrix4d ClipFromGlEye(const Frustum& frustum, const GlDepth& depth) {
  frustum.Check();
  const double width = frustum.right - frustum.left;
  const double height = frustum.top - frustum.bottom;
  return CheckedProjection(
      PerspectiveMatrix(2.0 * frustum.z_near / width, 0.0, (frustum.right + frustum.left) / width,
                        2.0 * frustum.z_near / height, (frustum.top + frustum.bottom) / height,
                        DepthRow(frustum.z_near, frustum.z_far, depth)),
      3, "the projection matrix of the frustum with near ", frustum.z_near, ", width ", width,
      ", height ", height);
}

Eigen::Matrix4d ClipFromGlEye(const Perspective& perspective, const GlDepth& depth) {
  return ClipFromGlEye(FrustumFromPerspective(perspective), depth);
}

Eigen::Matrix4d ClipFromGlEye(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                              double z_far, const GlDepth& depth, PixelOrigin origin) {
  intrinsics.Check();
  size.Check();
  // Validates near and far with the frustum's messages; the frustum itself ignores skew.
  Frustum{-1.0, 1.0, -1.0, 1.0, z_near, z_far}.Check();
  // The message's text only when it is thrown: DistortionText formats every coefficient.
  if (intrinsics.HasDistortion()) {
    ThrowInvalidArgument("distortion (", DistortionText(intrinsics),
                         ") cannot be represented by a projection matrix: pass "
                         "intrinsics.Pinhole() to drop it knowingly");
  }
  // Corner convention: x_win = u_corner, y_win = H - v_corner (docs/conventions.md).
  const Intrinsics k = ConvertPixelOrigin(intrinsics, origin, PixelOrigin::kCorner);
  const double w = size.width;
  const double h = size.height;
  // "+ 0.0" turns the -0 of a zero skew into +0, so printed matrices read as glFrustum's.
  return CheckedProjection(
      PerspectiveMatrix(2.0 * k.fx / w, -2.0 * k.skew / w + 0.0, 1.0 - 2.0 * k.cx / w,
                        2.0 * k.fy / h, 2.0 * k.cy / h - 1.0, DepthRow(z_near, z_far, depth)),
      3, "the projection matrix of fx = ", k.fx, ", fy = ", k.fy, " on a ", size.width, "x",
      size.height, " image with near ", z_near, ", far ", z_far);
}

Eigen::Matrix4d ClipFromGlEyeOrtho(const Ortho& ortho, ClipDepth clip_depth) {
  ortho.Check();
  const double width = ortho.right - ortho.left;
  const double height = ortho.top - ortho.bottom;
  const double depth = ortho.z_far - ortho.z_near;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2.0 / width;
  m(0, 3) = -(ortho.right + ortho.left) / width;
  m(1, 1) = 2.0 / height;
  m(1, 3) = -(ortho.top + ortho.bottom) / height;
  if (clip_depth == ClipDepth::kNegativeOneToOne) {
    m(2, 2) = -2.0 / depth;
    m(2, 3) = -(ortho.z_far + ortho.z_near) / depth;
  } else {
    m(2, 2) = -1.0 / depth;
    m(2, 3) = -ortho.z_near / depth;
  }
  return m;
}

Eigen::Matrix4d ClipFromGlEyeOrthographic(const Intrinsics& intrinsics, const ImageSize& size,
                                          double z_near, double z_far, const GlDepth& depth,
                                          PixelOrigin origin) {
  intrinsics.Check();
  size.Check();
  if (intrinsics.HasDistortion()) {
    ThrowInvalidArgument("an orthographic camera has no distortion, got ",
                         DistortionText(intrinsics));
  }
  Require(std::isfinite(z_near) && std::isfinite(z_far) && z_far > z_near,
          "an orthographic projection needs finite near < far, got near ", z_near, ", far ", z_far);
  Require(std::isfinite(z_far - z_near), "an orthographic projection's depth range far - near "
          "must be finite, got near ", z_near, ", far ", z_far);
  // Corner convention, x_eye = x_cam, y_eye = -y_cam, z_eye = -z_cam:
  //   u = fx x_cam + skew y_cam + cx,  x_ndc = 2 u / W - 1;
  //   v = fy y_cam + cy,               y_ndc = 1 - 2 v / H.
  const Intrinsics k = ConvertPixelOrigin(intrinsics, origin, PixelOrigin::kCorner);
  const double w = size.width;
  const double h = size.height;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2.0 * k.fx / w;
  m(0, 1) = -2.0 * k.skew / w + 0.0;
  m(0, 3) = 2.0 * k.cx / w - 1.0;
  m(1, 1) = 2.0 * k.fy / h;
  m(1, 3) = 1.0 - 2.0 * k.cy / h;
  // z_ndc = a z_eye + b through (-z_near, ndc_near) and (-z_far, ndc_far).
  const bool zo = depth.clip_depth == ClipDepth::kZeroToOne;
  double ndc_near = zo ? 0.0 : -1.0;
  double ndc_far = 1.0;
  if (depth.reversed_z) std::swap(ndc_near, ndc_far);
  const double a = (ndc_near - ndc_far) / (z_far - z_near);
  m(2, 2) = a;
  m(2, 3) = ndc_near + a * z_near;
  return CheckedProjection(m, 2, "the orthographic projection matrix of fx = ", k.fx, ", fy = ",
                           k.fy, " px per unit on a ", size.width, "x", size.height,
                           " image with near ", z_near, ", far ", z_far);
}

Ortho OrthoFromOrthographic(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                            double z_far, PixelOrigin origin) {
  Require(intrinsics.skew == 0.0, "skew ", intrinsics.skew, " has no glOrtho form");
  const Eigen::Matrix4d m = ClipFromGlEyeOrthographic(intrinsics, size, z_near, z_far, {}, origin);
  // x_ndc = m00 x + m03 = -1 at left, +1 at right; likewise y.
  Ortho ortho;
  ortho.left = (-1.0 - m(0, 3)) / m(0, 0);
  ortho.right = (1.0 - m(0, 3)) / m(0, 0);
  ortho.bottom = (-1.0 - m(1, 3)) / m(1, 1);
  ortho.top = (1.0 - m(1, 3)) / m(1, 1);
  ortho.z_near = z_near;
  ortho.z_far = z_far;
  return CheckedResult(ortho, "the glOrtho box of fx = ", intrinsics.fx, ", fy = ", intrinsics.fy,
                       " px per unit on a ", size.width, "x", size.height, " image");
}

Intrinsics IntrinsicsFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye,
                                       const ImageSize& size, PixelOrigin origin) {
  size.Check();
  const Eigen::Matrix4d m = NormalizedPerspective(clip_from_gl_eye);
  const double w = size.width;
  const double h = size.height;
  Intrinsics corner;
  corner.fx = 0.5 * w * m(0, 0);
  corner.skew = -0.5 * w * m(0, 1);
  corner.cx = 0.5 * w * (1.0 - m(0, 2));
  corner.fy = 0.5 * h * m(1, 1);
  corner.cy = 0.5 * h * (m(1, 2) + 1.0);
  Require(corner.fx > 0.0 && corner.fy > 0.0,
          "projection matrix gives non-positive focal lengths fx = ", corner.fx, ", fy = ",
          corner.fy);
  return CheckedResult(ConvertPixelOrigin(corner, PixelOrigin::kCorner, origin),
                       "the intrinsics of the projection matrix on a ", size.width, "x",
                       size.height, " image");
}

DepthRange DepthRangeFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye,
                                       const GlDepth& depth) {
  const Eigen::Matrix4d m = NormalizedPerspective(clip_from_gl_eye);
  const double a = m(2, 2);
  const double b = m(2, 3);
  const bool zo = depth.clip_depth == ClipDepth::kZeroToOne;
  // Invert the table in gl.h; the far plane is infinite where its denominator vanishes.
  auto ratio = [](double num, double den) { return den == 0.0 ? kInfinity : num / den; };
  DepthRange range;
  if (!depth.reversed_z) {
    range.z_near = zo ? b / a : b / (a - 1.0);
    range.z_far = ratio(b, a + 1.0);
  } else {
    range.z_near = b / (a + 1.0);
    range.z_far = zo ? ratio(b, a) : ratio(b, a - 1.0);
  }
  Require(range.z_near > 0.0 && range.z_far > range.z_near,
          "the projection matrix's depth row (", a, ", ", b, ") does not give 0 < near < far for "
          "depth ", ToString(depth.clip_depth), depth.reversed_z ? " reversed-Z" : "",
          ": near = ", range.z_near, ", far = ", range.z_far, " (wrong depth convention?)");
  return range;
}

Frustum FrustumFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye, const GlDepth& depth) {
  const Eigen::Matrix4d m = NormalizedPerspective(clip_from_gl_eye);
  Require(m(0, 1) == 0.0, "the projection matrix has skew (entry (0,1) = ", m(0, 1),
          "), which has no glFrustum form");
  const DepthRange range = DepthRangeFromClipFromGlEye(clip_from_gl_eye, depth);
  Require(m(0, 0) > 0.0 && m(1, 1) > 0.0, "projection matrix has non-positive scale (", m(0, 0),
          ", ", m(1, 1), ")");
  const double width = 2.0 * range.z_near / m(0, 0);
  const double height = 2.0 * range.z_near / m(1, 1);
  Frustum frustum;
  frustum.left = 0.5 * width * (m(0, 2) - 1.0);
  frustum.right = 0.5 * width * (m(0, 2) + 1.0);
  frustum.bottom = 0.5 * height * (m(1, 2) - 1.0);
  frustum.top = 0.5 * height * (m(1, 2) + 1.0);
  frustum.z_near = range.z_near;
  frustum.z_far = range.z_far;
  return CheckedResult(frustum, "the frustum of the projection matrix");
}

Eigen::Matrix4d GlEyeFromWorld(const Rigid3& cam_from_world) {
  cam_from_world.Check();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = GlEyeFromCam() * cam_from_world.rotation;
  m.topRightCorner<3, 1>() = GlEyeFromCam() * cam_from_world.translation;
  return m;
}

Rigid3 CamFromWorldFromGlEyeFromWorld(const Eigen::Matrix4d& gl_eye_from_world) {
  Rigid3 gl_eye_from_world_rigid = Rigid3FromMatrix(gl_eye_from_world);
  Rigid3 cam_from_gl_eye;
  cam_from_gl_eye.rotation = GlEyeFromCam();  // its own inverse
  return cam_from_gl_eye * gl_eye_from_world_rigid;
}

GlPixel GlPixelFromWorld(const Eigen::Matrix4d& clip_from_gl_eye,
                         const Eigen::Matrix4d& gl_eye_from_world,
                         const Eigen::Vector3d& point_in_world, const ImageSize& size,
                         ClipDepth clip_depth, PixelOrigin origin) {
  size.Check();
  RequireFiniteAll(clip_from_gl_eye, "projection matrix");
  RequireFiniteAll(gl_eye_from_world, "view matrix");
  RequireFiniteAll(point_in_world, "point_in_world");
  const Eigen::Vector4d clip =
      clip_from_gl_eye * (gl_eye_from_world * point_in_world.homogeneous());
  Require(clip.w() > 0.0, "point is not in front of the camera: clip.w = ", clip.w());
  const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
  const Eigen::Vector3d window = WindowFromNdc(ndc, Viewport{0, 0, size.width, size.height},
                                               clip_depth);
  return {PixelFromWindow(window.head<2>(), size, origin), window.z()};
}

}  // namespace camproj

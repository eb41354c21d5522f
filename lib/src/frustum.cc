#include "camproj/frustum.h"

#include <cmath>

#include "check.h"

namespace camproj {

using internal::CheckedResult;
using internal::Require;
using internal::ThrowInvalidArgument;
using internal::RequireFinite;

namespace {

constexpr double kPi = 3.14159265358979323846;

void CheckNearFar(double z_near, double z_far) {
  RequireFinite(z_near, "near");
  Require(z_near > 0.0, "near must be positive, got ", z_near);
  Require(!std::isnan(z_far), "far must not be NaN");
  Require(z_far > z_near, "far must be greater than near, got near = ", z_near, ", far = ", z_far);
}

void RequireNoSkewNoDistortion(const Intrinsics& intrinsics) {
  Require(intrinsics.skew == 0.0, "skew = ", intrinsics.skew,
          " has no glFrustum form (a frustum is an axis-aligned window): use the projection "
          "matrix, which carries skew");
  // The message's text only when it is thrown: DistortionText formats every coefficient.
  if (intrinsics.HasDistortion()) {
    ThrowInvalidArgument("distortion (", DistortionText(intrinsics),
                         ") has no frustum form: use Intrinsics::Pinhole() to drop it knowingly");
  }
}

}  // namespace

void Frustum::Check() const {
  RequireFinite(left, "frustum left");
  RequireFinite(right, "frustum right");
  RequireFinite(bottom, "frustum bottom");
  RequireFinite(top, "frustum top");
  Require(left < right, "frustum left must be less than right, got left = ", left,
          ", right = ", right);
  Require(bottom < top, "frustum bottom must be less than top, got bottom = ", bottom,
          ", top = ", top);
  // The projection divides by the extents: beyond the largest double they overflow to infinity
  // (and the matrix's scale entries to 0).
  Require(std::isfinite(right - left) && std::isfinite(top - bottom),
          "the frustum's width and height must be finite, got right - left = ", right - left,
          ", top - bottom = ", top - bottom);
  CheckNearFar(z_near, z_far);
}

void Perspective::Check() const {
  RequireFinite(fovy_deg, "fovy_deg");
  Require(fovy_deg > 0.0 && fovy_deg < 180.0, "fovy_deg must be in (0, 180), got ", fovy_deg);
  RequireFinite(aspect, "aspect");
  Require(aspect > 0.0, "aspect must be positive, got ", aspect);
  CheckNearFar(z_near, z_far);
}

void Ortho::Check() const {
  RequireFinite(left, "ortho left");
  RequireFinite(right, "ortho right");
  RequireFinite(bottom, "ortho bottom");
  RequireFinite(top, "ortho top");
  RequireFinite(z_near, "ortho near");
  RequireFinite(z_far, "ortho far");
  Require(left != right, "ortho left must differ from right, both ", left);
  Require(bottom != top, "ortho bottom must differ from top, both ", top);
  Require(z_near != z_far, "ortho near must differ from far, both ", z_near);
}

void Viewport::Check() const {
  Require(width > 0 && height > 0, "viewport size must be positive, got ", width, "x", height);
}

bool IsSymmetric(const Frustum& frustum) {
  frustum.Check();
  return std::abs(frustum.right + frustum.left) <=
             kSymmetryTolerance * (frustum.right - frustum.left) &&
         std::abs(frustum.top + frustum.bottom) <=
             kSymmetryTolerance * (frustum.top - frustum.bottom);
}

namespace {

double FovyDegOfFrustum(const Frustum& frustum) {
  return 2.0 * std::atan2(0.5 * (frustum.top - frustum.bottom), frustum.z_near) * 180.0 / kPi;
}

}  // namespace

bool HasPerspectiveForm(const Frustum& frustum) {
  return IsSymmetric(frustum) && FovyDegOfFrustum(frustum) < 180.0;
}

Frustum FrustumFromPerspective(const Perspective& perspective) {
  perspective.Check();
  Frustum frustum;
  frustum.top = perspective.z_near * std::tan(perspective.fovy_deg * kPi / 360.0);
  frustum.bottom = -frustum.top;
  frustum.right = frustum.top * perspective.aspect;
  frustum.left = -frustum.right;
  frustum.z_near = perspective.z_near;
  frustum.z_far = perspective.z_far;
  return CheckedResult(frustum, "the frustum of fovy_deg ", perspective.fovy_deg, ", aspect ",
                       perspective.aspect, ", near ", perspective.z_near);
}

Perspective PerspectiveFromFrustum(const Frustum& frustum) {
  frustum.Check();
  const double width = frustum.right - frustum.left;
  const double height = frustum.top - frustum.bottom;
  Require(IsSymmetric(frustum),
          "the frustum is off-axis and has no gluPerspective form: horizontal asymmetry "
          "(right + left) / (right - left) = ",
          (frustum.right + frustum.left) / width,
          ", vertical (top + bottom) / (top - bottom) = ", (frustum.top + frustum.bottom) / height,
          " (allowed ", kSymmetryTolerance, "); use the frustum or the projection matrix");
  Perspective perspective;
  perspective.fovy_deg = FovyDegOfFrustum(frustum);
  Require(perspective.fovy_deg < 180.0, "the frustum's vertical field of view rounds to 180 "
          "degrees in a double (height ", height, " at near ", frustum.z_near,
          ") and has no gluPerspective form; use the frustum or the projection matrix");
  perspective.aspect = width / height;
  perspective.z_near = frustum.z_near;
  perspective.z_far = frustum.z_far;
  return CheckedResult(perspective, "the perspective of the frustum");
}

Frustum FrustumFromIntrinsics(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                              double z_far, PixelOrigin origin) {
  intrinsics.Check();
  size.Check();
  CheckNearFar(z_near, z_far);
  RequireNoSkewNoDistortion(intrinsics);
  // In the corner convention the image spans [0, W] x [0, H] exactly.
  const Intrinsics k = ConvertPixelOrigin(intrinsics, origin, PixelOrigin::kCorner);
  Frustum frustum;
  frustum.left = -z_near * k.cx / k.fx;
  frustum.right = z_near * (size.width - k.cx) / k.fx;
  frustum.top = z_near * k.cy / k.fy;
  frustum.bottom = -z_near * (size.height - k.cy) / k.fy;
  frustum.z_near = z_near;
  frustum.z_far = z_far;
  // Extreme values (a principal point of 1e308 px) overflow or collapse the planes.
  frustum.Check();
  return frustum;
}

Intrinsics IntrinsicsFromFrustum(const Frustum& frustum, const ImageSize& size,
                                 PixelOrigin origin) {
  frustum.Check();
  size.Check();
  Intrinsics corner;
  corner.fx = frustum.z_near * size.width / (frustum.right - frustum.left);
  corner.fy = frustum.z_near * size.height / (frustum.top - frustum.bottom);
  corner.cx = -frustum.left * size.width / (frustum.right - frustum.left);
  corner.cy = frustum.top * size.height / (frustum.top - frustum.bottom);
  // A frustum narrower than the doubles can divide by gives an infinite focal length.
  Require(std::isfinite(corner.fx) && std::isfinite(corner.fy) && std::isfinite(corner.cx) &&
              std::isfinite(corner.cy),
          "the frustum's intrinsics are not finite (fx = ", corner.fx, ", fy = ", corner.fy,
          "): its extents are too small against near for a double");
  return CheckedResult(ConvertPixelOrigin(corner, PixelOrigin::kCorner, origin),
                       "the intrinsics of the frustum on a ", size.width, "x", size.height,
                       " image");
}

Perspective PerspectiveFromIntrinsics(const Intrinsics& intrinsics, const ImageSize& size,
                                      double z_near, double z_far, PixelOrigin origin) {
  return PerspectiveFromFrustum(FrustumFromIntrinsics(intrinsics, size, z_near, z_far, origin));
}

Eigen::Vector3d WindowFromNdc(const Eigen::Vector3d& ndc, const Viewport& viewport,
                              ClipDepth clip_depth) {
  viewport.Check();
  const double depth =
      clip_depth == ClipDepth::kNegativeOneToOne ? 0.5 * (ndc.z() + 1.0) : ndc.z();
  return {viewport.x + 0.5 * (ndc.x() + 1.0) * viewport.width,
          viewport.y + 0.5 * (ndc.y() + 1.0) * viewport.height, depth};
}

}  // namespace camproj

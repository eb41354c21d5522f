#include "camproj/world_origin.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "camproj/conventions.h"
#include "camproj/gl.h"
#include "camproj/number_text.h"
#include "check.h"
#include "exact_stream.h"

namespace camproj {

Eigen::Matrix4d GlEyeFromOriginWorld(const Rigid3& cam_from_world,
                                     const Eigen::Vector3d& world_origin) {
  cam_from_world.Check();
  internal::RequireFiniteAll(world_origin, "world origin");
  // R (X - O) + t = R X' - R (C - O) with C = -R^T t: the translation from C - O, a difference of
  // two doubles, rather than t + R O, which would cancel two numbers of the size of |O|.
  const Eigen::Vector3d center_from_origin = CameraCenterInWorld(cam_from_world) - world_origin;
  Rigid3 cam_from_origin_world;
  cam_from_origin_world.rotation = cam_from_world.rotation;
  cam_from_origin_world.translation = -(cam_from_world.rotation * center_from_origin);
  return GlEyeFromWorld(cam_from_origin_world);
}

Eigen::Vector3d RoundOrigin(const Eigen::Vector3d& center, double extent) {
  internal::RequireFiniteAll(center, "origin centre");
  internal::Require(std::isfinite(extent) && extent >= 0.0,
                    "origin extent must be finite and >= 0, got ", extent);
  // Below 1e-290 the power of ten's reciprocal would not be finite (10^-k for k < -308): no
  // rounding, the centre itself (a step this small shortens no decimal anyway).
  if (extent > 0.0 && extent < 1e-290) return center + Eigen::Vector3d::Zero();  // + 0: no "-0"
  // step = 10^k, the largest power of ten <= extent; log10 may be off by one ulp at a power of
  // ten, so k is corrected against the exact powers (10^k is exact in a double for |k| <= 22).
  int k = extent > 0.0 ? static_cast<int>(std::floor(std::log10(extent))) : 0;
  while (k < 308 && std::pow(10.0, k + 1) <= extent) ++k;
  while (k > -290 && std::pow(10.0, k) > extent && extent > 0.0) --k;
  const double step = std::pow(10.0, k);
  Eigen::Vector3d origin;
  for (int axis = 0; axis < 3; ++axis) {
    // A coordinate 2^53 steps from 0 is already a multiple of the step to within its ulp, and
    // scaling it by 10^-k could overflow (a camera at 1e10 with near 1e-300): kept as it is.
    // Dividing by 10^-k for k < 0 gives the double nearest to the decimal (0.03, not
    // 3 * 0.01 = 0.030000000000000002), which prints as users would type it.
    const double c = center[axis];
    if (std::abs(c) >= 0x1p53 * step) {
      origin[axis] = c;
    } else {
      origin[axis] = k >= 0 ? std::round(c / step) * step
                            : std::round(c * std::pow(10.0, -k)) / std::pow(10.0, -k);
      // Rounding up near the largest double (1.7e308 to a step of 1e308) can overflow.
      if (!std::isfinite(origin[axis])) origin[axis] = c;
    }
    origin[axis] += 0.0;  // no "-0"
  }
  return origin;
}

Eigen::Vector3d AutoOriginOfPoints(const std::vector<Eigen::Vector3d>& points_in_world) {
  internal::Require(!points_in_world.empty(), "the automatic world origin needs points, got none");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d low = points_in_world.front();
  Eigen::Vector3d high = points_in_world.front();
  for (const Eigen::Vector3d& point : points_in_world) {
    internal::RequireFiniteAll(point, "point");
    sum += point;
    low = low.cwiseMin(point);
    high = high.cwiseMax(point);
  }
  return RoundOrigin(sum / static_cast<double>(points_in_world.size()), (high - low).maxCoeff());
}

Eigen::Vector3d AutoOriginOfCamera(const Camera& camera) {
  camera.Check();
  return RoundOrigin(CameraCenterInWorld(camera.cam_from_world), camera.z_near);
}

// Derivation. The GL pipeline sees X' = float(X - O) (O = 0 without an origin) and computes
// x_eye = float(R_gl) X' + float(t') in float32, with t' = -R_gl (C - O), |t'| = |C - O| = d. A
// point at depth Z lies at |X - C| >= Z from the camera, Z on the axis, so |X'| ~ d + Z. With
// u = 2^-24 (float32's unit roundoff) the first-order errors in gl_eye are:
//   storing the vertex             u |X'|
//   storing R (9 entries)          u |X'|   (each row's entries rounded by u |R_ij|, |R_i| = 1)
//   the products and sums R X' + t u (|X'| + d): roundings at the size of the partial sums
//   storing t'                     u d
// i.e. u (3 |X'| + 2 d) ~ u (5 d + 3 Z) <= 3 u (2 d + Z); the projection (entries ~ f / W,
// relative rounding) adds u Z, which the last term covers. We use the rounder 3 u (d + Z) as the
// expected size: the terms are independent roundings that do not all reach their bound at once
// (tests/render_test.cc measures 0.3 to 1x of it). A displacement e across the ray at depth Z
// moves the pixel by f e / Z (perspective; f = max(fx, fy) + |skew| px) or by f e (orthographic,
// f in px per world unit).
double Float32PixelError(const Camera& camera, const std::optional<Eigen::Vector3d>& world_origin,
                         double depth) {
  camera.Check();
  internal::Require(std::isfinite(depth) && depth > 0.0, "depth must be finite and positive, got ",
                    depth);
  const Eigen::Vector3d origin = world_origin.value_or(Eigen::Vector3d::Zero());
  internal::RequireFiniteAll(origin, "world origin");
  const double d = (CameraCenterInWorld(camera.cam_from_world) - origin).norm();
  const Intrinsics& k = camera.intrinsics;
  const double f = std::max(k.fx, k.fy) + std::abs(k.skew);
  const double eye_error = 3.0 * kFloat32Roundoff * (d + depth);
  return camera.projection == Projection::kOrthographic ? f * eye_error : f * eye_error / depth;
}

std::string WorldOriginNote(const Camera& camera) {
  auto out = internal::ExactStream();
  const Eigen::Vector3d auto_origin = AutoOriginOfCamera(camera);
  const double error_without = Float32PixelError(camera, std::nullopt, camera.z_near);
  if (camera.world_origin) {
    const Eigen::Vector3d& o = *camera.world_origin;
    out << "world origin (" << o.x() << ", " << o.y() << ", " << o.z()
        << "): the view matrix is gl_eye_from_origin_world: give vertices as point_in_world - ("
        << o.x() << ", " << o.y() << ", " << o.z()
        << "), subtracted in double before the cast to float; expected float32 error at the near "
           "plane "
        << GeneralBound(Float32PixelError(camera, camera.world_origin, camera.z_near), 2) << " px ("
        << GeneralBound(error_without, 2) << " px without the origin)";
  } else {
    out << "world origin: none: the view matrix takes world coordinates as they are; expected "
           "float32 error at the near plane "
        << GeneralBound(error_without, 2) << " px ("
        << GeneralBound(Float32PixelError(camera, auto_origin, camera.z_near), 2)
        << " px with camproj export --origin auto)";
  }
  return out.str();
}

}  // namespace camproj

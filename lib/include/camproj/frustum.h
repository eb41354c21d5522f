// The fixed-function viewing volumes, as the OpenGL man pages define them, and their relation to
// pinhole intrinsics for a given image size (docs/conventions.md).
//
// Frustum (glFrustum): the near-plane window [left, right] x [bottom, top] in gl_eye at distance
// z_near; z_far > z_near, or +infinity for an infinite far plane. For intrinsics in kCenter:
//   left  = -z_near (cx + 0.5) / fx      right = z_near (W - cx - 0.5) / fx
//   top   =  z_near (cy + 0.5) / fy      bottom = -z_near (H - cy - 0.5) / fy
// i.e. the near-plane rectangle is exactly the image's outer pixel edges. Skew has no glFrustum
// form (the frustum is an axis-aligned box section); it lives only in the projection matrix (gl.h).
// Perspective (gluPerspective): symmetric frustum, top = z_near tan(fovy/2), right = top * aspect.
// Ortho (glOrtho): a box; z_near and z_far are signed distances along -z, z_far != z_near.
// Viewport (glViewport): x_win = x + (x_ndc + 1) width / 2, y_win = y + (y_ndc + 1) height / 2.
#ifndef CAMPROJ_FRUSTUM_H_
#define CAMPROJ_FRUSTUM_H_

#include <limits>

#include "camproj/conventions.h"
#include "camproj/intrinsics.h"

namespace camproj {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Frustum {
  double left = -1.0;
  double right = 1.0;
  double bottom = -1.0;
  double top = 1.0;
  double z_near = 1.0;  // distance to the near plane, > 0
  double z_far = 10.0;  // distance to the far plane, > z_near, or kInfinity
  // Throws std::invalid_argument naming the value unless left < right, bottom < top,
  // 0 < z_near < z_far, all finite but z_far (which may be +infinity).
  void Check() const;
};

struct Perspective {
  double fovy_deg = 60.0;  // full vertical field of view, degrees, in (0, 180)
  double aspect = 1.0;     // width / height of the near-plane window, > 0
  double z_near = 1.0;
  double z_far = 10.0;     // > z_near, or kInfinity
  void Check() const;
};

struct Ortho {
  double left = -1.0;
  double right = 1.0;
  double bottom = -1.0;
  double top = 1.0;
  double z_near = -1.0;  // as glOrtho: signed, z_near != z_far
  double z_far = 1.0;
  void Check() const;
};

struct Viewport {
  int x = 0;
  int y = 0;
  int width = 0;   // > 0
  int height = 0;  // > 0
  void Check() const;
};

// Relative asymmetry |right + left| / (right - left) (and the same for top/bottom) below which a
// frustum counts as symmetric: a centred principal point, cx = (W - 1)/2, rounds to ~1e-16 here.
inline constexpr double kSymmetryTolerance = 1e-9;

// Throws on an invalid frustum (Frustum::Check).
bool IsSymmetric(const Frustum& frustum);

// Throws if the frustum cannot be represented in doubles (right - left overflows).
Frustum FrustumFromPerspective(const Perspective& perspective);

// Whether PerspectiveFromFrustum succeeds: the frustum is symmetric and its vertical field of view
// is below 180 degrees in a double (one about 2e16 times taller than near rounds to 180). Throws
// on an invalid frustum.
bool HasPerspectiveForm(const Frustum& frustum);

// Throws std::invalid_argument saying which side is off-centre (and by how much) unless
// IsSymmetric(frustum): an off-axis frustum has no gluPerspective form; nor has one whose field
// of view rounds to 180 degrees.
Perspective PerspectiveFromFrustum(const Frustum& frustum);

// The frustum whose near-plane window maps exactly onto the image (see the file comment).
// `origin` is the convention of intrinsics.cx, cy. Throws if skew != 0 (no frustum form: use the
// projection matrix from gl.h) or distortion is set (not linear), or on invalid arguments.
Frustum FrustumFromIntrinsics(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                              double z_far, PixelOrigin origin = PixelOrigin::kCenter);

// The inverse: fx, fy, cx, cy (skew 0, no distortion), cx and cy in `origin`.
Intrinsics IntrinsicsFromFrustum(const Frustum& frustum, const ImageSize& size,
                                 PixelOrigin origin = PixelOrigin::kCenter);

// Perspective of a centred camera; throws like PerspectiveFromFrustum for an off-centre one.
Perspective PerspectiveFromIntrinsics(const Intrinsics& intrinsics, const ImageSize& size,
                                      double z_near, double z_far,
                                      PixelOrigin origin = PixelOrigin::kCenter);

// Window coordinates (x, y, depth) of normalized device coordinates, as glViewport and
// glDepthRange(0, 1) map them: depth = (z_ndc + 1) / 2 for kNegativeOneToOne, z_ndc for kZeroToOne.
Eigen::Vector3d WindowFromNdc(const Eigen::Vector3d& ndc, const Viewport& viewport,
                              ClipDepth clip_depth = ClipDepth::kNegativeOneToOne);

}  // namespace camproj

#endif  // CAMPROJ_FRUSTUM_H_

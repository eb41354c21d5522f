// OpenGL matrices (docs/conventions.md): the projection matrix clip_from_gl_eye and the view
// matrix gl_eye_from_world, column-major (Matrix4d::data() uploads with transpose = GL_FALSE).
//
// Perspective projection of a frustum (l, r, b, t, n, f), as glFrustum for kNegativeOneToOne:
//   [2n/(r-l)  0         (r+l)/(r-l)  0]
//   [0         2n/(t-b)  (t+b)/(t-b)  0]
//   [0         0         A            B]     clip.w = -z_eye
//   [0         0         -1           0]
// with the depth row (A, B) chosen so that ndc z at z_eye = -n and z_eye = -f is:
//   NO:            -1, +1   A = -(f+n)/(f-n)  B = -2fn/(f-n)   (infinite f: A = -1, B = -2n)
//   ZO:             0,  1   A = -f/(f-n)      B = -fn/(f-n)    (infinite f: A = -1, B = -n)
//   NO reversed-Z: +1, -1   A = (f+n)/(f-n)   B = 2fn/(f-n)    (infinite f: A = 1,  B = 2n)
//   ZO reversed-Z:  1,  0   A = n/(f-n)       B = fn/(f-n)     (infinite f: A = 0,  B = n)
// From intrinsics (kCenter), the first two rows are, for an image W x H:
//   [2fx/W  -2skew/W  1 - 2(cx+0.5)/W  0]
//   [0       2fy/H    2(cy+0.5)/H - 1  0]
// so that GL's viewport maps every point onto the pixel K [R|t] gives it (skew included, which
// glFrustum cannot express).
#ifndef CAMPROJ_GL_H_
#define CAMPROJ_GL_H_

#include <Eigen/Core>

#include "camproj/conventions.h"
#include "camproj/frustum.h"
#include "camproj/intrinsics.h"
#include "camproj/pose.h"

namespace camproj {

// How the depth row is built. An infinite far plane is requested by z_far = kInfinity.
struct GlDepth {
  ClipDepth clip_depth = ClipDepth::kNegativeOneToOne;
  bool reversed_z = false;
};

// The projection matrix of a frustum (glFrustum for the default GlDepth). Throws on an invalid
// frustum.
Eigen::Matrix4d ClipFromGlEye(const Frustum& frustum, const GlDepth& depth = {});

// The projection matrix of a perspective (gluPerspective for the default GlDepth).
Eigen::Matrix4d ClipFromGlEye(const Perspective& perspective, const GlDepth& depth = {});

// The projection matrix of pinhole intrinsics for an image, skew included. `origin` is the
// convention of cx, cy. Throws if the intrinsics have distortion (GL projection is linear: pass
// intrinsics.Pinhole() to drop it knowingly, and render it with lens_gl.h), or on invalid
// arguments.
Eigen::Matrix4d ClipFromGlEye(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                              double z_far, const GlDepth& depth = {},
                              PixelOrigin origin = PixelOrigin::kCenter);

// The orthographic projection matrix (glOrtho for kNegativeOneToOne; z_ndc = 0 at -z_near and 1
// at -z_far for kZeroToOne).
Eigen::Matrix4d ClipFromGlEyeOrtho(const Ortho& ortho,
                                   ClipDepth clip_depth = ClipDepth::kNegativeOneToOne);

// The projection matrix of an orthographic camera (camera.h): fx, fy, skew in px per world unit,
// cx, cy where the optical axis meets the image (in `origin`). x_ndc, y_ndc are affine in the
// eye coordinates; z_ndc is linear in depth, -1 (0 for kZeroToOne) at -z_near and +1 at -z_far,
// swapped by reversed_z. Equals ClipFromGlEyeOrtho of OrthoFromOrthographic's box when skew is
// 0 and not reversed. Throws on distortion, an infinite far plane (no orthographic limit) or
// z_far <= z_near.
Eigen::Matrix4d ClipFromGlEyeOrthographic(const Intrinsics& intrinsics, const ImageSize& size,
                                          double z_near, double z_far, const GlDepth& depth = {},
                                          PixelOrigin origin = PixelOrigin::kCenter);

// The glOrtho box of an orthographic camera without skew (the eye-space extents the image
// covers, pixel edges included). Throws if skew != 0.
Ortho OrthoFromOrthographic(const Intrinsics& intrinsics, const ImageSize& size, double z_near,
                            double z_far, PixelOrigin origin = PixelOrigin::kCenter);

// Intrinsics (fx, fy, skew; cx, cy in `origin`) of a perspective projection matrix built as
// above for the image size. The matrix may carry any positive overall scale (clip.w > 0 in front
// of the camera). Throws
// std::invalid_argument naming the entry if it is not of that form (e.g. an orthographic matrix).
Intrinsics IntrinsicsFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye,
                                       const ImageSize& size,
                                       PixelOrigin origin = PixelOrigin::kCenter);

struct DepthRange {
  double z_near = 0.0;
  double z_far = 0.0;  // kInfinity for an infinite far plane
};

// z_near, z_far of a perspective projection matrix built with `depth`. Throws if the depth row
// does not describe 0 < z_near < z_far.
DepthRange DepthRangeFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye,
                                       const GlDepth& depth = {});

// The frustum of a perspective projection matrix (inverse of ClipFromGlEye(Frustum)); throws if
// the matrix has skew (no frustum form) or is not a perspective projection.
Frustum FrustumFromClipFromGlEye(const Eigen::Matrix4d& clip_from_gl_eye,
                                 const GlDepth& depth = {});

// The view matrix: gl_eye_from_world = gl_eye_from_cam * cam_from_world, as a 4x4.
Eigen::Matrix4d GlEyeFromWorld(const Rigid3& cam_from_world);

// The inverse: cam_from_world of a view matrix; throws unless it is rigid ([R t; 0 0 0 1]).
Rigid3 CamFromWorldFromGlEyeFromWorld(const Eigen::Matrix4d& gl_eye_from_world);

// The pixel (in `origin`) and window depth of a point in world seen through GL matrices and a
// full-image viewport, following GL's pipeline: clip = P V X, ndc = clip.xyz / clip.w,
// WindowFromNdc, PixelFromWindow. Throws unless clip.w > 0 (the point is in front).
struct GlPixel {
  Eigen::Vector2d pixel;
  double window_depth = 0.0;
};
GlPixel GlPixelFromWorld(const Eigen::Matrix4d& clip_from_gl_eye,
                         const Eigen::Matrix4d& gl_eye_from_world,
                         const Eigen::Vector3d& point_in_world, const ImageSize& size,
                         ClipDepth clip_depth = ClipDepth::kNegativeOneToOne,
                         PixelOrigin origin = PixelOrigin::kCenter);

}  // namespace camproj

#endif  // CAMPROJ_GL_H_

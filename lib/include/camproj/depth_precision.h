// Depth-buffer precision of a perspective projection (docs/exports.md, "Depth precision"): how
// finely a depth buffer resolves distance for a near and far plane and a depth convention, and
// the warnings and advice `camproj export` prints. Conventions (GlDepth, the window depth of each
// depth row) are those of docs/conventions.md, section 6.
//
// A GL perspective projection stores a window depth that is linear in 1/z:
//   standard:   depth = f(z-n)/((f-n)z)    (infinite f: 1 - n/z)   near -> 0, far -> 1
//   reversed-Z: depth = n(f-z)/((f-n)z)    (infinite f: n/z)       near -> 1, far -> 0
// (NO and ZO give the same window depth; they differ in z_ndc = 2 depth - 1 (NO) or depth (ZO)).
// A buffer stores depth with finitely many values, so a band of distances around each z stores the
// same value. Example, near 0.1 and far 1000 at z = 500: a 24-bit buffer with the
// standard NO projection resolves about 0.15 world units; float32 with reversed-Z ZO about 1.8e-5.
#ifndef CAMPROJ_DEPTH_PRECISION_H_
#define CAMPROJ_DEPTH_PRECISION_H_

#include <string>
#include <vector>

#include "camproj/gl.h"

namespace camproj {

// The depth buffer's storage format.
enum class DepthBuffer {
  kFixed24,  // GL_DEPTH_COMPONENT24 / GL_DEPTH24_STENCIL8: round(depth * (2^24 - 1))
  kFloat32,  // GL_DEPTH_COMPONENT32F: the nearest float; denormals flushed to 0 (as D3D requires
             // and most GPUs do), so the smallest positive value is FLT_MIN
};

// The depth step at distance z: the width of the band of distances (world units, along the view
// axis, z_near <= z <= z_far) that store the same depth value as z, i.e. how far z must move for
// the stored value to change; for a projection with z_near and z_far (kInfinity allowed) and
// `depth`, into `buffer`.
//
// Computed exactly from the representable values, not from a derivative: q is the stored value
// at z (window depth rounded to the buffer format), the band's ends are the midpoints between q
// and its representable neighbours, mapped back through the inverse of the window-depth mapping
// above. (At a plane, where q has a neighbour on one side only, the band is twice its half
// inside.) Two quantizations are taken into account and the coarser one is returned: the
// buffer's, and z_ndc as a float32 (GL computes z_ndc in floating point, whatever the buffer).
// The second is what keeps NO reversed-Z near 24-bit precision: far depths have z_ndc near -1,
// where floats are 6e-8 apart.
//
// This is the storage limit. Float32 vertex arithmetic adds rounding of the order of the float
// spacing of z itself (6e-8 z to 1.2e-7 z); where the step is smaller than that (reversed-Z float
// ZO, far from the camera), the arithmetic, not the buffer, sets the precision. At a distance
// whose float depth is exactly 0 (reversed-Z at the far plane) the storage step is that of
// FLT_MIN, i.e. about 0.
//
// With an infinite far plane the step is kInfinity at distances so far that their depth rounds
// to that of infinity (about 3e7 z_near for the standard mapping).
//
// Throws std::invalid_argument unless 0 < z_near < z_far (finite z_near; z_far finite or
// kInfinity) and z is finite with z_near <= z <= z_far.
double DepthStepAt(double z, double z_near, double z_far, const GlDepth& depth,
                   DepthBuffer buffer);

// What `camproj export` reports about the depth range of a camera exported with `depth`.
struct DepthAdvice {
  // Each a one-line sentence without a prefix; empty for an unremarkable range:
  //  - far/near > kDepthRatioWarning (finite far), naming the 24-bit standard step at far;
  //  - an infinite far plane without ZO reversed-Z, naming the float32 step of `depth` at
  //    1000 near (it grows as z^2 / near).
  // Each advises reversed-Z with a float buffer and glClipControl(GL_LOWER_LEFT,
  // GL_ZERO_TO_ONE), or, if `depth` is already ZO reversed-Z, a float depth buffer.
  std::vector<std::string> warnings;
  // A table of DepthStepAt, several lines each ending in '\n': a header line, then one row per
  // distance (near, sqrt(near far), far/2, far for a finite far, keeping those in [near, far]
  // once; near, 10 near, 100 near, 1000 near for an infinite far) with the columns 24-bit NO,
  // float32 NO, float32 ZO reversed-Z, and float32 with `depth` when that is none of those
  // (NO reversed-Z, ZO). Steps in world units with two significant digits ("0.15", "1.8e-05",
  // "370"), "~0" where the stored float is 0 (reversed-Z at far), "overflow" where the step is
  // beyond a double (far/near near the doubles' range); a '*' marks steps finer than
  // the float32 spacing of z itself (see DepthStepAt), explained by a footnote line.
  std::string table;
  // One line: use reversed-Z with ZO, glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE),
  // glDepthFunc(GL_GREATER), glClearDepth(0) and GL_DEPTH_COMPONENT32F where precision matters;
  // or, for a ZO reversed-Z `depth`, a reminder to use the float buffer.
  std::string advice;
};

// far/near above which AdviseDepth warns.
inline constexpr double kDepthRatioWarning = 1e5;

// Whose calls the advice names: OpenGL's (glClipControl, glDepthFunc, GL_DEPTH_COMPONENT32F) or
// three.js's, where those calls are the renderer's (WebGLRenderer's reversedDepthBuffer, which
// three r187 has, and logarithmicDepthBuffer).
enum class DepthAdviceTarget { kOpenGl, kThreeJs };

// The advice for a projection with z_near, z_far (kInfinity allowed) and `depth`, for `target`
// (kThreeJs: the remedies in warnings and `advice` are three's renderer options instead of GL
// calls; the table is the same). Throws std::invalid_argument unless 0 < z_near < z_far, z_near
// finite.
DepthAdvice AdviseDepth(double z_near, double z_far, const GlDepth& depth = {},
                        DepthAdviceTarget target = DepthAdviceTarget::kOpenGl);

}  // namespace camproj

#endif  // CAMPROJ_DEPTH_PRECISION_H_

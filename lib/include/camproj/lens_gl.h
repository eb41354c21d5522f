// Rendering a camera's lens (radial k1, k2 of docs/conventions.md section 3) with OpenGL, which
// a projection matrix cannot hold. Three ways (docs/exports.md, "Rendering the lens";
// conventions: docs/conventions.md section 11):
//  1. per vertex: LensGlslText, a GLSL function that distorts gl_eye positions before the
//     pinhole projection matrix; exact at vertices, linear in between, so meshes must be
//     tessellated (LensMaxEdgePx says how finely);
//  2. post-process: render the pinhole camera into LensRenderTargetOf's buffer (the image's
//     undistorted footprint plus a margin, same fx, fy, skew), then warp it onto the image with
//     the STMap of LensStMap(kDistort) or the triangle mesh of LensDistortionMeshJson;
//  3. the inverse: LensStMap(kUndistort) warps the (distorted) plate onto the render target's
//     pinhole image, for overlaying CG rendered with the render target's projection.
// Every function requires a perspective camera whose lens covers the image: every image pixel
// (outer corners included) inside the first fold's distorted radius (RequireLensCoversImage).
#ifndef CAMPROJ_LENS_GL_H_
#define CAMPROJ_LENS_GL_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "camproj/camera.h"
#include "camproj/conventions.h"
#include "camproj/gl.h"
#include "camproj/intrinsics.h"

namespace camproj {

// Throws std::invalid_argument unless `camera` is valid, perspective and its lens covers the
// image: the largest distorted normalized radius of the 4 outer image corners (kCenter (-0.5,
// -0.5) ... (W - 0.5, H - 0.5)) is below g(r_fold) = the distorted radius of RadialFoldRadius.
// The message names k1, k2, the fold and the corner. A camera without distortion passes, unless
// a corner's normalized radius is kLensMaxNormalizedRadius or more (fx = 1e-300 px: the image
// spans 180 degrees to within a double, and the lens polynomial's r^4 overflows).
inline constexpr double kLensMaxNormalizedRadius = 1e50;
void RequireLensCoversImage(const Camera& camera);

// The largest undistorted normalized radius r = |(X/Z, Y/Z)| the image sees (at an outer corner).
double LensImageRadius(const Camera& camera);

// Normalized radius beyond which the GLSL function holds the radial scale d constant:
// min(RadialFoldRadius, 2 LensImageRadius). Inside it the function is the model; beyond it (never
// inside the image) r -> d(r_limit) r keeps increasing, so nothing folds back into the image.
double LensRadiusLimit(const Camera& camera);

// The pinhole buffer a post-process lens pass renders into: a pixel of the camera's pinhole image
// (Intrinsics::Pinhole(), kCenter) is pixel + (offset_x, offset_y) here. It covers the undistorted
// footprint of the whole image (the preimage of its outer edges) plus kLensRenderTargetMarginPx on
// every side, so bilinear taps at any map sample stay inside. Larger than the image for barrel
// (k1 < 0), possibly smaller for pincushion: same px per normalized unit, not the same size.
struct LensRenderTarget {
  ImageSize size;         // px
  Intrinsics intrinsics;  // pinhole (k1 = k2 = 0), kCenter: fx, fy, skew of the camera,
                          // cx + offset_x, cy + offset_y
  int offset_x = 0;       // px
  int offset_y = 0;       // px
};

// Margin around the preimage's bounding box: 1 px for the bilinear taps (texel centres on either
// side of a sample) and 1 px for the boundary between its samples (taken every 1/4 px).
inline constexpr int kLensRenderTargetMarginPx = 2;
// Largest render target side accepted (a lens near its fold needs a large one).
inline constexpr int kLensRenderTargetMaxSidePx = 16384;

// Throws std::invalid_argument as RequireLensCoversImage, and when a side would exceed
// kLensRenderTargetMaxSidePx (naming it).
LensRenderTarget LensRenderTargetOf(const Camera& camera);

// The render target's projection matrix (clip_from_gl_eye for its size and intrinsics, the
// camera's near and far); the view matrix is the camera's own GlEyeFromWorld.
Eigen::Matrix4d LensRenderTargetClipFromGlEye(const Camera& camera, const GlDepth& depth = {});

// Interpolation error of the per-vertex lens (docs/exports.md, "Tessellation"). GL interpolates
// between distorted vertices linearly on screen, i.e. replaces the lens map D (pinhole pixel ->
// distorted pixel, docs/conventions.md section 11) on each triangle by its linear interpolant.
// With M = max |d^2 D / dt^2| over unit directions t and the image's footprint, the error inside a
// triangle is at most (M / 2) rho^2, rho = radius of the smallest disc holding the triangle on the
// pinhole image: M L^2 / 8 for right and obtuse triangles, M L^2 / 6 for any triangle (rho <=
// L / sqrt 3), L = its longest edge in pinhole px. Samples the footprint (the preimage of the
// image's edges every px, and the render target's pixels inside it, every one up to 250 000 of
// them, else every stride-th) and 64 directions. px per px^2; 0 without distortion.
double LensSecondDerivativePx(const Camera& camera);

// Longest edge (pinhole px) for an interpolation error <= error_px in any triangle:
// sqrt(6 error_px / M); +infinity without distortion. Throws unless error_px > 0.
double LensMaxEdgePx(const Camera& camera, double error_px);

// GLSL (1.30+, ES 3.00) source: constants camproj_k1, camproj_k2, camproj_r2_limit,
// camproj_projection (the pinhole projection matrix with `depth`), camproj_view and the function
// vec4 camproj_lens(vec4 eye) that distorts a gl_eye position:
//   gl_Position = camproj_projection * camproj_lens(camproj_view * vec4(world_position, 1.0));
// Comments give the pixel convention, the fold handling and LensMaxEdgePx for 0.1, 0.01 and
// 0.001 px. Throws as RequireLensCoversImage.
std::string LensGlslText(const Camera& camera, const GlDepth& depth = {});

// Direction of a lens map.
enum class LensMapDirection {
  kDistort,    // output = the camera's (distorted) image W x H; source = the render target
  kUndistort,  // output = the render target's pinhole image; source = the camera's image (plate)
};

// An STMap in Nuke's convention (docs/conventions.md section 11): for each output pixel, where to
// sample the source, red = x / source width, green = y / source height with x, y the source's
// window coordinates (origin at its bottom-left corner, y up: pixel centres at half-integers).
// rgba holds width * height * 4 floats, row 0 = the output's TOP row (as image files store it),
// per pixel (red, green, 0, alpha). kDistort: alpha 1 everywhere. kUndistort: alpha 1 where the
// source point lies in the plate (its outer edges included), 0 elsewhere; beyond the fold (no
// distorted point) red = green = -1, alpha 0.
struct StMap {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;
};

// Throws as LensRenderTargetOf.
StMap LensStMap(const Camera& camera, LensMapDirection direction);

// The STMap as a 32-bit float RGBA image file: `extension` ".tif", ".tiff" or ".exr" (OpenCV's
// writers; channels R, G, B, A in that order in the file). Throws std::invalid_argument naming
// another extension.
std::string EncodeStMap(const StMap& map, const std::string& extension);

// A JSON distortion mesh for the post-process pass (docs/exports.md, "distortion-mesh"): a grid
// over the render target with vertices every step_px px of its window coordinates (edges
// included), two triangles per cell (counter-clockwise in window coordinates), each vertex with
// its undistorted_uv (source: the render target's window / its size, the STMap's convention) and
// distorted_uv (output: the camera's window / (W, H) of the lens's pixel of that source, with
// LensGlslText's rule beyond LensRadiusLimit; outside [0, 1] off the image). The grid is over the
// source because the forward lens is a polynomial, smooth up to the fold, while its inverse
// steepens without bound there. Also: the render target (size, intrinsics, projection with
// `depth`, view) and the largest interpolation error found (output px: at the 12 points
// (i, j, l) / 4 of every triangle other than its vertices that the GL draws inside the image,
// the distance from where it draws them to where the lens images their source).
// step_px = 0: LensMeshStepPx(camera, kLensMeshErrorPx). Throws unless step_px >= 0, and as
// LensRenderTargetOf.
inline constexpr double kLensMeshErrorPx = 0.01;
inline constexpr int kLensMeshMaxStepPx = 64;
std::string LensDistortionMeshJson(const Camera& camera, int step_px, const GlDepth& depth = {});

// The same mesh as a Wavefront OBJ: `v x y 0` = distorted_uv * 2 - 1 (the camera image's NDC),
// `vt u v` = undistorted_uv, `f a/a b/b c/c` (1-based, counter-clockwise), the render target, step
// and error in '#' comments. Throws as LensDistortionMeshJson.
std::string LensDistortionMeshObj(const Camera& camera, int step_px, const GlDepth& depth = {});

// The largest mesh step of kLensMeshMaxStepPx, its halves, ..., 2 whose interpolation error (as
// above) is <= error_px; 1 if none is. Throws unless error_px > 0, and as LensRenderTargetOf.
int LensMeshStepPx(const Camera& camera, double error_px);

// Comment lines ("# ...") and `projection` / `view` lines (16 numbers, column-major) describing
// the render target a map export goes with, for stdout next to the STMap file.
std::string LensRenderTargetText(const Camera& camera, LensMapDirection direction,
                                 const GlDepth& depth = {});

}  // namespace camproj

#endif  // CAMPROJ_LENS_GL_H_

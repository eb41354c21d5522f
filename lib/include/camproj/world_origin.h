// Camera-relative rendering for large coordinates (survey / UTM worlds): a world origin that GL
// users subtract from their vertices (in double) before float32 sees them, the view matrix that
// goes with it, the rule `--origin auto` uses, and the float32 error expected with and without
// one. Conventions, the rounding rule and the error model: docs/conventions.md, section 12.
#ifndef CAMPROJ_WORLD_ORIGIN_H_
#define CAMPROJ_WORLD_ORIGIN_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/pose.h"

namespace camproj {

// float32's unit roundoff 2^-24: storing x as a float moves it by at most kFloat32Roundoff |x|.
constexpr double kFloat32Roundoff = 5.9604644775390625e-08;

// The view matrix for vertices given relative to `world_origin`: gl_eye_from_origin_world maps
// point_in_world - world_origin to gl_eye, i.e. gl_eye_from_world * Translation(world_origin).
// Its translation is -R_gl (C - world_origin) computed in double from the camera centre C, so it
// holds |C - world_origin|, not |t|. Throws std::invalid_argument for an invalid pose (Rigid3::
// Check) or a non-finite origin.
Eigen::Matrix4d GlEyeFromOriginWorld(const Rigid3& cam_from_world,
                                     const Eigen::Vector3d& world_origin);

// The rounding of `--origin auto`: each coordinate of `center` rounded to the nearest multiple of
// step = 10^floor(log10(extent)), the largest power of ten not above `extent` (step 1 when extent
// is 0), so that the origin is a number users can type and lies within step * sqrt(3) / 2 of
// `center`. Example: center (412345.67, 5612345.67, 123.4), extent 87 -> step 10 ->
// (412350, 5612350, 120). A coordinate of 2^53 steps or more, or an extent below 1e-290, is kept
// as it is (rounding would not shorten it, and 10^-k would overflow). Throws
// std::invalid_argument for a non-finite center or a negative or non-finite extent.
Eigen::Vector3d RoundOrigin(const Eigen::Vector3d& center, double extent);

// `camproj fit --origin auto`: the points' centroid rounded by RoundOrigin with extent = the
// longest side of their bounding box. Throws std::invalid_argument for no points or a
// non-finite one.
Eigen::Vector3d AutoOriginOfPoints(const std::vector<Eigen::Vector3d>& points_in_world);

// `camproj export --origin auto` (no points at hand): the camera centre C rounded by RoundOrigin
// with extent = z_near, so |C - origin| <= z_near sqrt(3) / 2: every point beyond the near plane is
// then further from the camera than the origin is, which is what camera-relative rendering needs
// (Float32PixelError below). Throws on an invalid camera.
Eigen::Vector3d AutoOriginOfCamera(const Camera& camera);

// The float32 error (px) expected where a GL pipeline draws a point at cam depth `depth` (> 0)
// from float32 vertices given relative to `world_origin` (absent: to (0, 0, 0), raw world
// coordinates) and the float32 view matrix GlEyeFromOriginWorld:
//   3 * kFloat32Roundoff * f * (|C - origin| + depth) / depth      perspective
//   3 * kFloat32Roundoff * f * (|C - origin| + depth)              orthographic (f in px per unit)
// with f = max(fx, fy) + |skew| and C the camera centre. The derivation is in world_origin.cc; it
// is the size of the error, not a strict bound (tests/render_test.cc measures it). Throws
// std::invalid_argument for an invalid camera, a non-positive depth or a non-finite origin.
double Float32PixelError(const Camera& camera, const std::optional<Eigen::Vector3d>& world_origin,
                         double depth);

// The GL-facing exports' sentence on the world origin (gl, glm, glsl, three): with one, that
// their view matrix is gl_eye_from_origin_world and what to subtract from vertices, with the
// float32 error at the near plane with and without it; without, that the view matrix takes world
// coordinates as they are, with the error with and without `--origin auto`. No trailing period.
// Throws as Float32PixelError.
std::string WorldOriginNote(const Camera& camera);

// Above this expected error (px) at the near plane `camproj export` warns that the camera needs a
// world origin (docs/exports.md).
constexpr double kFloat32ErrorWarningPx = 0.1;

}  // namespace camproj

#endif  // CAMPROJ_WORLD_ORIGIN_H_

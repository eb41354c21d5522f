// The validated scene, the fitter's first stage (private). CheckCorrespondences refuses
// mismatched sizes and non-finite values; ValidateScene builds the intrinsic Model the options
// ask for, puts the pixels in kCenter and the world in a normalized frame -- centred on the
// points' centroid and scaled to unit RMS distance, so that neither units nor offsets reach the
// numerics -- and reads the cloud's shape from its singular values. It refuses too few points for
// the model, collinear points, and a plane that cannot determine the free intrinsics. Every later
// stage (RANSAC, start, refinement, assessment) works on the Scene it returns.
#ifndef CAMPROJ_SRC_FIT_SCENE_H_
#define CAMPROJ_SRC_FIT_SCENE_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "camproj/intrinsics.h"
#include "fit/model.h"

namespace camproj {
namespace internal {

struct DltReading;  // fit/start.h

struct Scene {
  // The points in the normalized world (point_in_world = centroid + scale * point) and their
  // observed pixels in kCenter, in input order.
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double scale = 1.0;
  // From the centred cloud's singular values s1 >= s2 >= s3 (see scene.cc): exactly planar, for
  // counting what the scene determines (FitResult::planar), and planar enough that the start
  // trusts a homography rather than the DLT.
  bool planar = false;
  bool planar_start = false;
  // The cloud's principal axes as a rotation: for a plane, its in-plane axes, then its normal.
  Eigen::Matrix3d plane_basis = Eigen::Matrix3d::Identity();
  // Points given more than once count once: the equations they add (the closed-form starts
  // need 4 or 6 distinct points).
  int num_distinct_points = 0;
  // The model the options ask for, before the closed-form start sets its free values.
  Model model;
  ImageSize image_size;
  // The DLT of `points` and `pixels`, read at most once for this scene and its copies (fit/start.h,
  // DltStartOf): every model fitted to the same points starts from the same linear camera. Set by
  // PrepareScene.
  std::shared_ptr<DltReading> dlt;

  int NumPoints() const { return static_cast<int>(points.size()); }
};

// A point's name in messages: "point 5" for a bare number (a points file without ids numbers
// its rows so), else the name itself ("c4", or FitCameraAuto's own "point 5").
std::string PointName(const std::string& name);

// Throws std::invalid_argument when the numbers of points and pixels differ, and SceneError
// kNonFiniteInput naming the first point with a non-finite coordinate (X or pixel): by
// PointName(point_names[i]), or "point i + 1" without names.
void CheckCorrespondences(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& observed_pixels,
                          const std::vector<std::string>& point_names = {});

// The refusal of finite coordinates whose centroid or spread overflows a double (|X| near
// 1e308): kNonFiniteInput, with the advice to change units.
SceneError TooLargeForDouble();
// The same, for a fitted camera whose GL matrices overflow (`overflow`: what overflowed).
SceneError TooLargeForDouble(const std::string& overflow);

// Refuses (kNonFiniteInput) points so far from the origin against their spread (`scale`, their
// RMS distance from their centroid) that double precision's rounding of their coordinates moves
// their pixels (kCenter) by more than a tenth of kMinNoisePx: the camera, written in these
// coordinates, could not reproduce the fit. (Pixels spread over a 4000 px square: offsets
// above ~5e7 times the points' spread.) The message says to subtract an offset.
void CheckOffset(const std::vector<Eigen::Vector3d>& points_in_world, double scale,
                 const std::vector<Eigen::Vector2d>& pixels);

// What ValidateScene reads from the correspondences alone, whatever the model: computed once
// for every model fitted to the same points (the model selection's candidates). `refusal`
// (coordinates too large, collinear points) and `offset_refusal` (CheckOffset) are thrown by
// ValidateScene in the order one scene's checks run.
struct SceneGeometry {
  Scene scene;  // without its model
  PixelOrigin pixel_origin = PixelOrigin::kCenter;
  int num_points = 0;
  std::optional<SceneError> refusal;
  std::optional<SceneError> offset_refusal;
};

// The geometry of correspondences that passed CheckCorrespondences, pixels in `pixel_origin`.
// Never throws a SceneError (it keeps them); fewer than 4 points: only the count.
SceneGeometry PrepareScene(const std::vector<Eigen::Vector3d>& points_in_world,
                           const std::vector<Eigen::Vector2d>& observed_pixels,
                           const ImageSize& image_size, PixelOrigin pixel_origin);

// The scene for `options`' model from the prepared geometry (options.pixel_origin must be the
// geometry's): the refusals of the overload below, in the same order, with the same messages.
// (By value: the overload below moves its geometry in; a candidate's is copied.)
Scene ValidateScene(SceneGeometry geometry, const FitOptions& options);

// The scene of correspondences that passed CheckCorrespondences, for a perspective fit with
// `options` (checked; pixels in options.pixel_origin). Throws SceneError kTooFewPoints when
// 2N < 6 + free intrinsics or N < 4 (N: distinct points), kCollinearPoints when the points are
// collinear or coincide, kPlanarUnderdetermined when coplanar points must determine more than 2
// of focal, aspect, principal point and skew, TooLargeForDouble() when the coordinates overflow,
// and as CheckOffset when they are too far from the origin.
Scene ValidateScene(const std::vector<Eigen::Vector3d>& points_in_world,
                    const std::vector<Eigen::Vector2d>& observed_pixels,
                    const ImageSize& image_size, const FitOptions& options);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_SCENE_H_

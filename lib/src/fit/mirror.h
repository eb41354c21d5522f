// The mirrored readings of a fitted camera (private), for the default path's mirror test: the
// same data read as a left-handed world (the points with z negated). Where the perspective is
// weak the two readings explain the image about equally well and either may win the closed form
// by noise: the camera's depth reversal (the Necker reading) refined finds the mirrored one.
// Where it is strong, only a few points let a mirrored world fit a proper camera at all, far
// from the reversal: a start of that world's own finds it.
#ifndef CAMPROJ_SRC_FIT_MIRROR_H_
#define CAMPROJ_SRC_FIT_MIRROR_H_

#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/fit.h"
#include "fit/reading.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// `camera` (perspective) with its depths reversed about the depth of the points' centroid and
// the world's z negated: point_in_cam = D * cam_from_world(x) + (0, 0, 2 z_c) for the mirrored
// point M x (D = M = diag(1, 1, -1)), a proper rotation D R M. Under an affine camera the two
// give the same pixels; under perspective they differ at second order in depth / distance.
Camera NeckerReversal(const Camera& camera, const std::vector<Eigen::Vector3d>& points_in_world);

// The model name of a mirrored reading where it is a rival (DeterminationCheck::rival).
inline constexpr char kMirroredReadingName[] = "the same model with one world axis flipped";

// A proper camera of the mirrored world (the points with z negated, MirroredZ) and its RMS: its
// camera sees MirroredZ(points_in_world), the pixel of x is PixelFromWorld(camera, M x).
using MirroredReading = Reading;

// `model` fitted by least squares (at most 10 LM iterations) to the points with z negated, from
// NeckerReversal(camera, points): a proper camera of the mirrored world whose RMS is at or above
// the best one near the reversal. Nothing when that refinement ends with a point behind the
// camera or a non-positive focal length or aspect. `mirrored_world`: MirroredZ(points_in_world)
// and the pixels as PrepareScene prepares them for model.pixel_origin (shared with
// FitMirroredWorld), or null (prepared here). `read_below_px2`: the sum of squares (px^2) above
// which the caller does not read the reading (infinite: always read); the refinement stops
// where it is far out of reach (kReversalOutOfReach in mirror.cc), and the reading's RMS is then
// only known to be above it.
std::optional<MirroredReading> FitMirroredReading(
    const Camera& camera, const FitOptions& model,
    const std::vector<Eigen::Vector3d>& points_in_world,
    const std::vector<Eigen::Vector2d>& observed_pixels,
    const SceneGeometry* mirrored_world = nullptr,
    double read_below_px2 = std::numeric_limits<double>::infinity());

// Each of `models` fitted to the points with z negated from a start of that world's own, by LM
// (one round of at most 20 iterations): at few points a mirrored world can fit a proper camera
// within the noise far from any depth reversal. The start is the mirrored world's closed form
// where that reads it as proper (the DLT's det > 0, or a plane's homography), else SQPnP with
// `intrinsics` (the fitted camera's: the closed form would refine both readings and refuse,
// start.cc), solved once for every model. Per model, in order: nothing where no start or no
// proper camera with every point in front is found. `mirrored_world` as for FitMirroredReading:
// prepared once, the mirrored world's DLT is read once for every model. `read_below_px2` as for
// FitMirroredReading (kFreshStartOutOfReach in mirror.cc).
std::vector<std::optional<MirroredReading>> FitMirroredWorld(
    const std::vector<Eigen::Vector3d>& points_in_world,
    const std::vector<Eigen::Vector2d>& observed_pixels, const ImageSize& image_size,
    const std::vector<FitOptions>& models, const Intrinsics& intrinsics,
    const SceneGeometry* mirrored_world = nullptr,
    double read_below_px2 = std::numeric_limits<double>::infinity());

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_MIRROR_H_

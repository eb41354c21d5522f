// The options of `camproj fit` as one struct, and the one mapping from them to the fitter's
// options (FitOptions / AutoFitOptions), shared by the command line and the Python module so
// that both give the same camera and the same messages for the same options.
#ifndef CAMPROJ_FIT_REQUEST_H_
#define CAMPROJ_FIT_REQUEST_H_

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/camera.h"
#include "camproj/camera_file.h"
#include "camproj/conventions.h"
#include "camproj/fit.h"
#include "camproj/intrinsics.h"
#include "camproj/model_select.h"

namespace camproj {

// One field per option of `camproj fit` (its --help describes each); messages name the option
// as the command line spells it ("--model", "--fovy"). Unset numbers (0 or NaN) mean "not given".
struct FitArguments {
  std::string model = "auto";  // auto | pose | a '+' list of intrinsics | orthographic[+aspect][+skew]
  std::string criterion = "bic";  // aic | bic
  std::vector<std::string> free;  // among focal, aspect, principal-point, skew, k1, k2
  std::vector<std::string> fix;
  double focal = 0.0;     // px, fixes fx when > 0
  double fovy_deg = 0.0;  // degrees, fixes fy = H / (2 tan(fovy / 2)) when > 0
  double aspect = 0.0;    // fy / fx, fixed when > 0
  std::optional<Eigen::Vector2d> principal_point;  // fixed cx, cy (px, in pixel_origin)
  double skew = NAN;      // px, fixed when not NaN
  double k1 = NAN;
  double k2 = NAN;
  std::optional<Intrinsics> known_intrinsics;  // in kCenter (as ReadIntrinsicsFile returns them)
  // The image the known intrinsics are for (their file's image_size; ReadIntrinsicsFile) and
  // that file, named in the message: another --image-size is refused.
  std::optional<ImageSize> known_intrinsics_image_size;
  std::string known_intrinsics_path;
  std::string pixel_origin = "center";         // of the pixels and of the values above
  std::string loss = "none";                   // none | huber:SCALE | cauchy:SCALE (px)
  std::string refiner = "lm";                  // lm | ceres: FitOptions::refiner
  bool keep_all = false;
  double ransac_px = 0.0;        // RANSAC inlier threshold (px) when > 0
  double sigma = 0.0;            // pixel noise per axis (px) when > 0
  double max_uncertainty = 0.0;  // px; 0: AutoFitOptions' default
  std::vector<Eigen::Vector3d> object_points_in_world;
  double z_near = 0.0;  // GL depth range when > 0
  double z_far = 0.0;
  // --bounds: near and far (those not given above) cover this box, e.g. the whole model, instead
  // of the fitted points only (DepthRangeCoveringBox, camera.h).
  std::optional<BoxInWorld> bounds_in_world;
  // --bounds-mesh: the vertices of the model being mapped (ReadMeshVertices). Near and far cover
  // their bounding box, as bounds_in_world would (give one of the two); and the default path
  // judges the camera at them, as object_points_in_world would (unless those are given): the
  // model is where the camera must be right, and the clicks alone leave the rest of it to
  // extrapolation (JudgedRegionNote).
  std::vector<Eigen::Vector3d> mesh_vertices_in_world;
  // --origin: the camera's world_origin (world_origin.h): as given, or with auto_world_origin the
  // fitted points' centroid rounded (AutoOriginOfPoints over the points the fit kept). Neither:
  // no origin.
  std::optional<Eigen::Vector3d> world_origin;
  bool auto_world_origin = false;
  int max_iterations = 100;
};

// What `camproj fit` runs: FitCameraAuto (automatic) or FitCamera with the given model (a robust
// loss, which the selection cannot compare).
struct FitRequest {
  bool automatic = true;
  AutoFitOptions auto_options;  // its `fit` is the options in both cases
  std::optional<BoxInWorld> bounds_in_world;  // applied by RunFitRequest after the fit
  std::optional<Eigen::Vector3d> world_origin;  // also applied after the fit (FitArguments)
  bool auto_world_origin = false;
  // The intrinsics a forced --model holds at their defaults (FixedParameter names: "aspect",
  // "principal point", ...), which RunFitRequest reports as `held_why` ("default: not in --model
  // focal"), not as "given": no value was.
  std::vector<std::string> held_by_model;
  std::string held_why;
  const FitOptions& options() const { return auto_options.fit; }
};

// The request for `arguments` and an image of `size`. Throws std::invalid_argument naming the
// option (the command line reports it as a usage error).
FitRequest FitRequestFrom(const FitArguments& arguments, const ImageSize& size);

// Runs the request: FitCameraAuto with `ids` as the point names (when one per point), or
// FitCamera. Throws like them (SceneError for a refusal, std::invalid_argument for bad input).
// With bounds_in_world, the fitted camera's near and far (those not given as --near / --far)
// then cover the box (DepthRangeCoveringBox), and its views are rederived; a box that reaches
// behind the camera without --near, or lies wholly behind it, throws std::invalid_argument
// naming --bounds, the corner and its depth. With world_origin or auto_world_origin the camera
// gets that world origin (auto: AutoOriginOfPoints of the points not among result.outliers) and
// views.gl_eye_from_origin_world matches it; the fit itself does not depend on it. The
// intrinsics held_by_model are reported with held_why.
FitResult RunFitRequest(const std::vector<Eigen::Vector3d>& points_in_world,
                        const std::vector<Eigen::Vector2d>& pixels,
                        const std::vector<std::string>& ids, const ImageSize& size,
                        const FitRequest& request);

// One line (ending in '\n') saying where the fitted camera's near and far come from: the fitted
// points' depths only (the default; with how to cover the whole model), the box, or the options.
std::string NearFarNote(const FitRequest& request, const FitResult& fit);

// A line (ending in '\n') for each of the fitted camera's near and far planes -- given (--near,
// --far) or covering the --bounds box -- that clips points the fit kept, which an OpenGL render
// of the camera then draws nowhere: how many, the farthest beyond the plane first by id and
// depth, and what to give to keep them. `points_in_world` and `ids` are the fit's input (ids may be empty: rows
// numbered from 1). Empty where every kept point lies between the planes, as it always does
// with the planes a fit sets itself.
std::string ClippedPointsNote(const FitRequest& request, const FitResult& fit,
                              const std::vector<Eigen::Vector3d>& points_in_world,
                              const std::vector<std::string>& ids);

// One line (ending in '\n') where the fit's determination check judged the camera over the box
// the fitted points span alone (no --object-points or --bounds-mesh): beyond that box the camera is
// extrapolated, and what to give to have it judged there too. Empty otherwise.
std::string JudgedRegionNote(const FitRequest& request, const FitResult& fit);

// --bounds-mesh: the vertex positions of a mesh file, a PLY file's (`.ply`, any case: ascii or
// binary, the vertex element's x, y, z) or else a Wavefront OBJ's (`v x y z` lines). Throws
// InputError naming the file (and line) for an unreadable file, a bad vertex or no vertices.
std::vector<Eigen::Vector3d> ReadMeshVertices(const std::string& path);

// The camera file `camproj fit -o` writes for a fit: cx, cy in `pixel_origin`, the look-at target
// at the fit's distance, and the `fit` record (fit_report.h).
std::string FitCameraFileText(const FitResult& fit, PixelOrigin pixel_origin);

}  // namespace camproj

#endif  // CAMPROJ_FIT_REQUEST_H_

#include "fit/start.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/pose.h"
#include "check.h"
#include "fit/common.h"
#include "fit/least_squares.h"
#include "fit/reading.h"

namespace camproj {
namespace internal {

namespace {

// Re-solve the DLT's pose by PnP when projecting its K onto the model moves an intrinsic by more
// than this fraction of the focal length (below it, LM corrects the pose in an iteration or two).
constexpr double kPoseResolveChange = 0.02;
// A DLT that sees the world mirrored is believed when the mirrored reading's refined cost is
// below the best proper camera's (both have the same parameters). Below kMirroredAmbiguousRatio
// times the mirrored cost the refusal says the data cannot tell (add points) rather than that
// the frame is left-handed. Measured on 400 six-point projector scenes: a right-handed world
// flips the DLT in 4 / 12 scenes at sigma 2 / 5 px, with cost ratios (proper / mirrored)
// 0.03-70; 1 / 7 of them are refused as "cannot tell" (all 4 / 13 were refused as left-handed
// before); a left-handed world's ratios are above 10 in all but a few percent of scenes.
constexpr double kMirroredAmbiguousRatio = 100.0;

// The DLT saw the points as through a mirror. A truly left-handed world fits no proper camera;
// a right-handed one whose DLT flipped under noise (few points, nearly degenerate) fits one at
// least about as well as the mirrored reading. Refine both (the same parameters) and refuse
// unless a proper camera fits better; return the best proper camera found. The DLT's K belongs
// to the mirrored reading, so the proper side also starts from the image centre (focal sweep).
StartCamera ProperStartOrRefuse(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Vector2d>& pixels, const StartCamera& dlt,
                                const Model& start_model, const ImageSize& image_size,
                                const FitOptions& options, Clock::time_point start_time) {
  const Model dlt_model = ProjectOntoModel(start_model, dlt.intrinsics);
  double proper_cost = std::numeric_limits<double>::infinity();
  StartCamera proper;
  auto refine = [&](const std::vector<Eigen::Vector3d>& x, const StartCamera& s,
                    const Model& model, StartCamera* best) {
    const LeastSquaresOutcome outcome =
        RefineLeastSquares(x, pixels, s.rotation, s.center, model, options, start_time);
    if (!outcome.ok) return std::numeric_limits<double>::infinity();
    if (best != nullptr && outcome.normal.cost < proper_cost) {
      proper_cost = outcome.normal.cost;
      best->rotation = outcome.rotation;
      best->center = outcome.center;
      best->intrinsics = outcome.model.ToIntrinsics();
    }
    return outcome.normal.cost;
  };
  const double mirrored_cost = refine(MirroredZ(points), dlt, dlt_model, nullptr);
  StartCamera start;
  if (PnpStart(points, pixels, dlt_model.ToIntrinsics(), &start)) {
    refine(points, start, dlt_model, &proper);
  }
  if (start_model.free[0] &&
      FocalSweepStart(points, pixels, start_model.ToIntrinsics(), start_model.value[1],
                      image_size.width, &start)) {
    refine(points, start, ProjectOntoModel(start_model, start.intrinsics), &proper);
  }
  if (!(proper_cost <= mirrored_cost)) {
    const std::string fits = Concat(
        "the best right-handed camera's RMS is ", std::sqrt(proper_cost / points.size()),
        " px, the mirrored one's ", std::sqrt(mirrored_cost / points.size()), " px");
    if (proper_cost <= kMirroredAmbiguousRatio * mirrored_cost) {
      throw SceneError(SceneError::Reason::kAmbiguous,
                       "the points fit a camera seen through a mirror (a left-handed world frame) "
                       "somewhat better than a proper one (" + fits + "): too few points or too "
                       "much noise to tell",
                       "Add points spread in depth, or check the world frame's handedness");
    }
    throw SceneError(SceneError::Reason::kMirroredWorld,
                     "the points are seen as through a mirror: the world frame is left-handed (" +
                         fits + ")",
                     kFlipAnAxis);
  }
  return proper;
}

// The closed form for the scene: its camera (K as the closed form found it) and *method.
StartCamera SolveClosedForm(const Scene& scene, const FitOptions& options,
                            Clock::time_point start_time, std::string* method,
                            std::vector<StartCamera>* other_sweep_minima) {
  const std::vector<Eigen::Vector3d>& points = scene.points;
  const std::vector<Eigen::Vector2d>& pixels = scene.pixels;
  const Model& start_model = scene.model;
  const int n = scene.num_distinct_points;  // a repeated point adds no equation
  StartCamera start;
  const Intrinsics guess = start_model.ToIntrinsics();
  if (options.known_intrinsics) {
    if (!PnpStart(points, pixels, guess, &start)) {
      throw SceneError(SceneError::Reason::kDegenerate,
                       "SQPnP found no pose for the known intrinsics",
                       "Check the correspondences and the intrinsics' pixel convention");
    }
    *method = "pnp";
  } else if (scene.planar_start) {
    if (n < 4) {
      throw SceneError(SceneError::Reason::kTooFewPoints,
                       Concat("a planar scene needs at least 4 points, got ", n),
                       "Add points (at least 4)");
    }
    Intrinsics plane_guess = guess;
    const bool focal_free = start_model.free[0];
    if (HomographyStart(points, pixels, scene.plane_basis, plane_guess, focal_free,
                        start_model.free[1], &start)) {
      *method = "homography";
    } else if (start_model.free[1] && HomographyStart(points, pixels, scene.plane_basis,
                                                      plane_guess, focal_free, false, &start)) {
      // The homography's two equations give no pair of focal lengths (a plane tilted about an
      // image axis does not determine the aspect): its one focal length at the aspect's start
      // value is the start, as for a model with the aspect fixed.
      *method = "homography";
    } else if (focal_free && FocalSweepStart(points, pixels, guess, start_model.value[1],
                                             scene.image_size.width, &start,
                                             other_sweep_minima)) {
      *method = "pnp-focal-sweep";
    } else {
      throw SceneError(SceneError::Reason::kDegenerate,
                       "the plane's homography does not determine the focal length (the plane "
                       "is seen nearly head-on, or the points are mismatched)",
                       "Fix the focal length (--focal / --fovy) or add points off the plane");
    }
  } else if (n >= 6) {
    start = DltStartOf(scene);
    *method = "dlt";
    if (start.mirrored) {
      start = ProperStartOrRefuse(points, pixels, start, start_model, scene.image_size, options,
                                  start_time);
    } else if (start_model.free[0] &&
               !(start.intrinsics.fx >= SweepMinFocalPx(scene.image_size.width))) {
      // A DLT with a view wider than any the sweep tries (at 6-7 nearly coplanar points its K
      // can be degenerate: a focal length of 6e-10 px seen) is no start: LM from it runs to
      // the orthographic limit or crawls 190-260 iterations through a flat valley. The focal
      // sweep (the start at 4-5 points) starts it instead.
      StartCamera sweep;
      if (FocalSweepStart(points, pixels, guess, start_model.value[1], scene.image_size.width,
                          &sweep, other_sweep_minima)) {
        start = sweep;
        *method = "pnp-focal-sweep";
      }
    }
  } else if (start_model.NumFreeLinear() <= 1 && !start_model.free[1] && !start_model.free[2] &&
             !start_model.free[4]) {
    const bool ok = start_model.free[0]
                        ? FocalSweepStart(points, pixels, guess, start_model.value[1],
                                          scene.image_size.width, &start, other_sweep_minima)
                        : PnpStart(points, pixels, guess, &start);
    if (!ok) {
      throw SceneError(SceneError::Reason::kDegenerate,
                       "no camera found for these few points", "Check the correspondences");
    }
    *method = start_model.free[0] ? "pnp-focal-sweep" : "pnp";
  } else {
    throw SceneError(SceneError::Reason::kTooFewPoints,
                     Concat("the linear start (DLT) needs 6 non-coplanar points to free ",
                            FreeLinearNames(start_model), "; got ", n),
                     "Add points or fix all but the focal length");
  }
  return start;
}

}  // namespace

StartCamera DltStartOf(const Scene& scene) {
  if (scene.dlt == nullptr) return DltStart(scene.points, scene.pixels);
  DltReading& reading = *scene.dlt;
  if (!reading.camera && !reading.refusal) {
    try {
      reading.camera = DltStart(scene.points, scene.pixels);
    } catch (const SceneError& refusal) {
      reading.refusal = refusal;
    }
  }
  if (reading.refusal) throw *reading.refusal;
  return *reading.camera;
}

Start ClosedFormStart(const Scene& scene, const FitOptions& options,
                      Clock::time_point start_time) {
  Start start;
  start.camera =
      SolveClosedForm(scene, options, start_time, &start.method, &start.other_sweep_minima);
  // Start values of the free slots from the closed form, fixed ones as given. DLT's K is
  // projected onto the model (square pixels: geometric mean of fx, fy).
  const Intrinsics& k0 = start.camera.intrinsics;
  start.model = options.known_intrinsics ? scene.model : ProjectOntoModel(scene.model, k0);
  const Intrinsics projected = start.model.ToIntrinsics();
  const double projection_change =
      std::max({std::abs(projected.fx - k0.fx), std::abs(projected.fy - k0.fy),
                std::abs(projected.cx - k0.cx), std::abs(projected.cy - k0.cy),
                std::abs(projected.skew - k0.skew)}) / k0.fx;
  if (start.method == "dlt" && projection_change > kPoseResolveChange) {
    // Holding intrinsics moved K away from the DLT's: its pose belongs to another K. Re-solve
    // the pose for this one and keep whichever reprojects better.
    StartCamera pnp;
    if (PnpStart(scene.points, scene.pixels, projected, &pnp)) {
      auto sum_squares = [&](const StartCamera& camera) {
        double sum = 0.0;
        for (int i = 0; i < scene.NumPoints(); ++i) {
          const std::optional<Eigen::Vector2d> pixel = PixelOfCamPoint(
              start.model, camera.rotation * (scene.points[i] - camera.center));
          if (!pixel) return std::numeric_limits<double>::infinity();
          sum += (*pixel - scene.pixels[i]).squaredNorm();
        }
        return sum;
      };
      if (sum_squares(pnp) < sum_squares(start.camera)) {
        start.camera.rotation = pnp.rotation;
        start.camera.center = pnp.center;
      }
    }
  }
  return start;
}

std::optional<Start> PlaneAspectStart(const Scene& scene, const FitOptions& options) {
  const Model& model = scene.model;
  bool homography_model = scene.planar && !options.known_intrinsics &&
                          options.loss == LossType::kNone && model.free[0] && model.free[1] &&
                          !model.free[2] && !model.free[3] && !model.free[4] &&
                          model.value[4] == 0.0;
  for (int slot = 5; slot < kFitIntrinsicsSize; ++slot) {
    homography_model = homography_model && !model.free[slot] && model.value[slot] == 0.0;
  }
  if (!homography_model) return std::nullopt;
  const std::optional<Eigen::Matrix3d> h =
      LeastSquaresHomography(PlaneCoordinates(scene.points, scene.plane_basis), scene.pixels);
  if (!h) return std::nullopt;
  Start start;
  if (!StartFromHomography(*h, scene.plane_basis, model.ToIntrinsics(), /*focal_free=*/true,
                           /*aspect_free=*/true, &start.camera)) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "one view of this plane does not determine the aspect: no camera with the "
                     "principal point given and fx, fy free maps the plane as the homography "
                     "that fits the points best (its constraints on fx and fy have no solution: "
                     "the plane is seen tilted about nearly one image axis, where they "
                     "coincide), so the fit would only grow the focal lengths without end",
                     "Fix the aspect (e.g. --model focal), or add points off the plane");
  }
  start.method = "homography";
  start.model = ProjectOntoModel(model, start.camera.intrinsics);
  start.at_minimum = true;
  return start;
}

Start WarmStart(const Scene& scene, const Camera& fitted) {
  Start start;
  start.method = "warm";
  start.camera.rotation = fitted.cam_from_world.rotation;
  start.camera.center =
      (CameraCenterInWorld(fitted.cam_from_world) - scene.centroid) / scene.scale;
  start.camera.intrinsics = fitted.intrinsics;
  start.model = ModelAt(scene.model, fitted.intrinsics);
  return start;
}

}  // namespace internal
}  // namespace camproj

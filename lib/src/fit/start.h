// The closed-form start, the fitter's second stage (private): a camera to refine from, in the
// scene's normalized world. SQPnP for known intrinsics; for a plane, the constrained homography
// (a focal sweep when it does not determine the focal length); for 6 or more points, the DLT --
// when it reads the world as mirrored, both readings are refined and the fit refused unless a
// proper camera fits better -- and for 4 or 5, a focal sweep or SQPnP with at most the focal
// length free. The closed form's K is projected onto the scene's model and, for the DLT, the pose
// re-solved when that moved K. Takes the validated scene; returns the start camera, the method
// that found it and the model with its start values.
#ifndef CAMPROJ_SRC_FIT_START_H_
#define CAMPROJ_SRC_FIT_START_H_

#include <optional>
#include <string>
#include <vector>

#include "camproj/fit.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/model.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

struct Start {
  // rotation and center: the start pose; intrinsics: the closed form's K, before projection.
  StartCamera camera;
  // FitResult::start_method: "pnp", "homography", "pnp-focal-sweep", "dlt"; "warm" (WarmStart)
  // only in the model selection's candidates, never in a fit it returns.
  std::string method;
  Model model;         // the scene's model, its free slots from the closed form
  // "pnp-focal-sweep" only: the sweep's other local minima, best first (FocalSweepStart).
  std::vector<StartCamera> other_sweep_minima;
  // The start is the model's least-squares minimum itself (PlaneAspectStart): the refinement
  // begins with Gauss-Newton steps.
  bool at_minimum = false;
};

// The DLT of one scene's points (Scene::dlt): DltStart's camera or its refusal, once read.
struct DltReading {
  std::optional<StartCamera> camera;
  std::optional<SceneError> refusal;
};

// DltStart(scene.points, scene.pixels) (fit/closed_form.h), read once for the scene and every
// copy of it: the model selection fits several models to the same prepared points
// (SceneGeometry), and the mirror test reads the mirrored world's DLT before its start does.
// Throws DltStart's SceneError each time it is asked. Not for concurrent use of one scene's
// copies (a fit's stages run in one thread).
StartCamera DltStartOf(const Scene& scene);

// Throws SceneError where no start exists: kDegenerate (no pose, focal length or camera found),
// kTooFewPoints (fewer than 6 points with more than the focal length free), kMirroredWorld (a
// mirrored reading fits much better than any proper camera), kAmbiguous (it fits better, but
// not by enough to tell), kPointsBehindCamera (the DLT finds no camera with every point in
// front). start_time: for the traces of the refinements that decide a mirrored DLT (discarded).
Start ClosedFormStart(const Scene& scene, const FitOptions& options,
                      Clock::time_point start_time);

// On a plane, pose + focal + aspect with the principal point given and neither skew nor
// distortion has the plane's homography's 8 degrees of freedom, and its cameras map the plane by
// exactly the homographies whose two orthonormality constraints (fit/closed_form.h,
// StartFromHomography) give a positive 1/fx^2 and 1/fy^2. So its least-squares minimum is the
// least-squares homography's camera where that has them (the start returned, at_minimum), and
// otherwise it has no minimum at finite focal lengths: the refinement would crawl after one
// that grows without bound (seen: 221 iterations to fx 3210 px, aspect 4.2, then refused; the
// plane tilted about nearly an image axis, where the two constraints nearly coincide), and
// this throws SceneError kDegenerate instead. Nothing for any other model or scene, or where the
// least-squares homography is not found (the closed form then starts as before).
std::optional<Start> PlaneAspectStart(const Scene& scene, const FitOptions& options);

// The start at a camera already fitted to the same points with a nested model (the model
// selection's current model, of which the scene's model frees one more group): its pose in the
// scene's normalized world and the scene's model at its intrinsics, distortion included.
// Method "warm". No closed form, no second start (refine.cc): the candidate's least squares
// start where the nested model's ended.
Start WarmStart(const Scene& scene, const Camera& fitted);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_START_H_

// The model selection stage (private): the ladders of model_select.h on a fixed set of points.
// FitCameraAuto runs it on every point, and again on the inliers the outlier stage finds.
#ifndef CAMPROJ_SRC_FIT_SELECTION_H_
#define CAMPROJ_SRC_FIT_SELECTION_H_

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"
#include "camproj/model_select.h"
#include "fit/normal_equations.h"
#include "fit/scene.h"

namespace camproj {
namespace internal {

// A fitted model the selection did not choose, with its camera: the assessment asks whether
// one that fits about as well predicts the scene differently.
struct Rival {
  std::string model;
  FitOptions options;
  Camera camera;
  double criterion = 0.0;
  // The camera sees the world with z negated (fit/mirror.h): the same data read as a mirrored
  // world. It counts when it fits about as well or better (a better one by more than the
  // mirror test's margin is refused before).
  bool mirrored_world = false;
  // The chosen model itself at another of its minima (fit/other_minima.h): it too counts when it
  // fits better, as then the chosen camera is not the least-squares optimum.
  bool same_model = false;
  // Its sum of squared residuals (px^2) over the selection's points, where the selection fitted
  // it (a ladder's model); negative where not recorded.
  double sum_squares_px2 = -1.0;
  // Its fit's normal equations at its answer, where the selection fitted it in perspective.
  std::shared_ptr<const ChartLinearization> linearization = nullptr;
};

struct Selection {
  // The chosen model's fit (FitCamera's result, with ::model, ::candidates, ::criterion,
  // ::selection_sigma_px and every left-out group's reason in ::fixed_parameters).
  FitResult fit;
  FitOptions options;             // the chosen model (pixel_sigma: the noise its sigmas use)
  double sigma_px = 0.0;          // the noise the criterion used
  double criterion = 0.0;         // the chosen model's
  double penalty = 0.0;  // the criterion's per parameter: sum_squares / sigma_px^2 + penalty * k
  std::vector<Rival> rivals;      // every other model fitted, either family
  // The chosen fit's normal equations at its answer (fit.camera), where it is perspective and
  // fitted to at least kLinearizationFromPoints points; null otherwise.
  std::shared_ptr<const ChartLinearization> linearization = nullptr;
};

// From this many points on a perspective fit of the selection keeps its normal equations at its
// answer (Selection::linearization, Rival::linearization), and the determination check reads a
// model's uncertainty from them (unless they are a predicted step back:
// ChartLinearization::predicted_step_back) instead of a pass over the points for J in its own
// parameterization: there keeping them costs less than that pass (bench --stage-cost: 0.5 % more
// instructions at 6-12 points; for the rivals 2.6 / 6.2 / 8.4 % fewer at 20 / 100 / 1000).
inline constexpr size_t kLinearizationFromPoints = 20;

// Where a fit of `num_points` points keeps its normal equations (kLinearizationFromPoints): an
// empty ChartLinearization for the fit to fill (CandidateReuse::linearization), else null.
inline std::shared_ptr<ChartLinearization> LinearizationSlot(size_t num_points) {
  return num_points >= kLinearizationFromPoints ? std::make_shared<ChartLinearization>()
                                                : nullptr;
}

// `slot` once the fit ran: itself where the fit filled it (a perspective fit), else null.
inline std::shared_ptr<const ChartLinearization> Filled(std::shared_ptr<ChartLinearization> slot) {
  if (slot == nullptr || slot->jtj.size() == 0) return nullptr;
  return slot;
}

// The noise the criterion uses without a given sigma: the prior combined with the residuals
// (sum_squares over dof degrees of freedom) of the richest model the scene supports:
// sqrt((prior_weight * prior^2 + sum_squares) / (prior_weight + dof)), floored at kMinNoisePx.
double CombinedNoise(const AutoFitOptions& options, double sum_squares, double dof);

// The number of parameters of `options`' model: pose (6; orthographic 5) + free intrinsics.
int NumParameters(const FitOptions& options);

// A model already fitted to the same points (the screen's, ScreenPoints): the selection reads
// its fit where the ladder reaches that model instead of fitting it again, and the points as it
// prepared them (their DLT included) instead of preparing them again. Its noise and covariance
// settings may differ from the selection's (they do not change the camera).
struct Prefit {
  FitOptions model;
  FitResult fit;
  SceneGeometry geometry;  // for model.pixel_origin
  // The fit's normal equations at its answer, kept as a candidate's are (kLinearizationFromPoints),
  // or null.
  std::shared_ptr<const ChartLinearization> linearization = nullptr;
};

// Selects and fits the model for these points (the caller's, in options.fit.pixel_origin;
// options.fit.ransac must be off). `prefit`: a fit of these same points, or nullptr. Throws
// SceneError when no model fits (the simplest model's refusal), or kMirroredWorld when only a
// mirrored perspective camera beats an orthographic one, and within the noise.
Selection SelectModel(const std::vector<Eigen::Vector3d>& points_in_world,
                      const std::vector<Eigen::Vector2d>& observed_pixels,
                      const ImageSize& image_size, const AutoFitOptions& options,
                      const Prefit* prefit = nullptr);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_SELECTION_H_

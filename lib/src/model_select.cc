#include "camproj/model_select.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "check.h"
#include "fit_common.h"

namespace camproj {

using internal::Require;

namespace {

// A group of intrinsics the ladder frees together, in ladder order.
enum Group { kPrincipalPoint, kAspect, kSkew, kK1, kK2, kNumGroups };

const char* const kGroupNames[kNumGroups] = {"principal-point", "aspect", "skew", "k1", "k2"};
// FitResult::fixed_parameters' name of each group.
const char* const kFixedNames[kNumGroups] = {"principal point", "aspect", "skew", "k1", "k2"};

ParameterMode& ModeOf(FitOptions& options, int group) {
  switch (group) {
    case kPrincipalPoint: return options.principal_point;
    case kAspect: return options.aspect;
    case kSkew: return options.skew;
    case kK1: return options.k1;
    default: return options.k2;
  }
}

// The free parameters' names in FitResult::sigmas that belong to a group.
std::vector<std::string> SigmaNamesOf(int group) {
  switch (group) {
    case kPrincipalPoint: return {"cx", "cy"};
    case kAspect: return {"fy"};
    case kSkew: return {"skew"};
    case kK1: return {"k1"};
    default: return {"k2"};
  }
}

struct Evaluation {
  std::optional<FitResult> fit;  // empty: refused
  std::string refusal;           // SceneError's message
  double sum_squares = 0.0;
  int num_params = 0;
};

Evaluation Evaluate(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                    const FitOptions& options) {
  Evaluation e;
  try {
    e.fit = FitCamera(points, pixels, size, options);
    e.sum_squares = e.fit->rms_px * e.fit->rms_px * static_cast<double>(points.size());
    e.num_params = static_cast<int>(e.fit->free_parameters.size());
  } catch (const SceneError& error) {
    e.refusal = error.what();
  }
  return e;
}

// Pixels that 1 sigma of the parameter moves the image corner by: the principal point shifts
// every pixel; focal, fy and skew scale offsets from the centre (fx: the half-diagonal, fy and
// skew: the half-height); k1, k2 the radial displacement k r^2 (r^4) * r at the corner.
double CornerEffectPx(const ParameterSigma& s, const Intrinsics& k, const ImageSize& size) {
  const double half_width = 0.5 * size.width;
  const double half_height = 0.5 * size.height;
  const double corner_px = std::hypot(half_width, half_height);
  const double corner_normalized = corner_px / std::sqrt(k.fx * k.fy);
  const double r2 = corner_normalized * corner_normalized;
  if (s.name == "fx") return s.sigma * corner_px / k.fx;
  if (s.name == "fy" || s.name == "skew") return s.sigma * half_height / k.fy;
  if (s.name == "k1") return s.sigma * r2 * corner_px;
  if (s.name == "k2") return s.sigma * r2 * r2 * corner_px;
  return s.sigma;  // cx, cy
}

// Whether the caller's options allow an orthographic camera: nothing only a perspective camera
// has is forced or given (principal point free, distortion), no RANSAC, no known intrinsics.
bool OrthographicIsPossible(const FitOptions& options) {
  auto zero_or_default = [](const ParameterMode& mode) {
    return mode.kind == ParameterMode::Kind::kDefault ||
           (mode.kind == ParameterMode::Kind::kFixed && mode.value == 0.0);
  };
  return !options.principal_point.IsFree() && zero_or_default(options.k1) &&
         zero_or_default(options.k2) && !options.ransac && !options.known_intrinsics;
}

std::string Fixed(double value, int digits = 3) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
  return buffer;
}

// A criterion difference with its sign: "+3.3", "-128".
std::string Signed(double value) { return (value >= 0.0 ? "+" : "") + Fixed(value); }

}  // namespace

void AutoFitOptions::Check() const {
  fit.Check();
  Require(fit.loss == LossType::kNone,
          "automatic model selection compares least-squares fits: use RANSAC for outliers, or "
          "give the model explicitly to use a robust loss");
  Require(std::isfinite(max_corner_sigma_fraction) && max_corner_sigma_fraction > 0.0,
          "max_corner_sigma_fraction must be positive, got ", max_corner_sigma_fraction);
}

FitResult FitCameraAuto(const std::vector<Eigen::Vector3d>& points_in_world,
                        const std::vector<Eigen::Vector2d>& observed_pixels,
                        const ImageSize& image_size, const AutoFitOptions& options) {
  options.Check();
  if (options.fit.known_intrinsics) {
    FitResult fit = FitCamera(points_in_world, observed_pixels, image_size, options.fit);
    fit.candidates.push_back({fit.model, static_cast<int>(fit.free_parameters.size()), true,
                              fit.rms_px * fit.rms_px * points_in_world.size(), fit.rms_px, 0.0,
                              "chosen (intrinsics given)"});
    return fit;
  }

  // RANSAC once, with the richest candidate model, then select on its consensus.
  std::vector<Eigen::Vector3d> points = points_in_world;
  std::vector<Eigen::Vector2d> pixels = observed_pixels;
  FitOptions base = options.fit;
  if (base.focal.kind == ParameterMode::Kind::kDefault) base.focal = ParameterMode::Free();
  std::vector<int> candidates;  // groups the ladder may free
  for (int g = 0; g < kNumGroups; ++g) {
    if (ModeOf(base, g).kind == ParameterMode::Kind::kDefault) candidates.push_back(g);
  }
  std::vector<int> outliers;
  if (base.ransac) {
    FitOptions consensus = base;
    for (const int g : candidates) {
      if (g == kPrincipalPoint || g == kAspect) ModeOf(consensus, g) = ParameterMode::Free();
    }
    FitResult ransac_fit;
    try {
      ransac_fit = FitCamera(points, pixels, image_size, consensus);
    } catch (const SceneError&) {
      // Too much freedom for the scene (a plane, few points): RANSAC on the simplest model.
      ransac_fit = FitCamera(points, pixels, image_size, base);
    }
    outliers = ransac_fit.outliers;
    points.clear();
    pixels.clear();
    for (size_t i = 0; i < points_in_world.size(); ++i) {
      if (std::binary_search(outliers.begin(), outliers.end(), static_cast<int>(i))) continue;
      points.push_back(points_in_world[i]);
      pixels.push_back(observed_pixels[i]);
    }
    base.ransac = false;
  }
  const double num_equations = 2.0 * static_cast<double>(points.size());
  const bool aic = options.criterion == ModelCriterion::kAic;
  const double penalty = aic ? 2.0 : std::log(num_equations);  // per parameter

  // The affine camera (orthographic with aspect and skew free unless the caller fixed them): the
  // orthographic family's best fit, evaluated at most once.
  std::optional<Evaluation> affine;
  auto affine_evaluation = [&]() -> const Evaluation& {
    if (!affine) {
      FitOptions affine_options = base;
      affine_options.projection = Projection::kOrthographic;
      affine_options.compute_uncertainty = false;
      for (const int g : {kAspect, kSkew}) {
        if (ModeOf(affine_options, g).kind == ParameterMode::Kind::kDefault) {
          ModeOf(affine_options, g) = ParameterMode::Free();
        }
      }
      affine = Evaluate(points, pixels, image_size, affine_options);
    }
    return *affine;
  };

  // The pixel noise: given, or from the richest model the scene supports (dropping groups from
  // the top of the ladder until one is fitted with residual degrees of freedom to spare).
  double sigma = base.pixel_sigma.value_or(0.0);
  if (!base.pixel_sigma) {
    for (int top = static_cast<int>(candidates.size()); top >= 0 && sigma == 0.0; --top) {
      FitOptions richest = base;
      richest.compute_uncertainty = false;
      for (int i = 0; i < top; ++i) ModeOf(richest, candidates[i]) = ParameterMode::Free();
      const Evaluation e = Evaluate(points, pixels, image_size, richest);
      if (e.fit && num_equations > e.num_params) {
        sigma = std::max(kMinNoisePx, std::sqrt(e.sum_squares / (num_equations - e.num_params)));
      }
    }
    if (sigma == 0.0 && options.allow_orthographic && OrthographicIsPossible(base)) {
      // No perspective model fits (a nearly parallel projection): the affine camera's noise.
      const Evaluation& e = affine_evaluation();
      if (e.fit && num_equations > e.num_params) {
        sigma = std::max(kMinNoisePx, std::sqrt(e.sum_squares / (num_equations - e.num_params)));
      }
    }
    if (sigma == 0.0) sigma = kMinNoisePx;  // no model leaves a residual: the simplest decides
  }
  const char* criterion_name = aic ? "AIC" : "BIC";
  auto criterion_of = [&](const Evaluation& e) {
    return e.sum_squares / (sigma * sigma) + penalty * e.num_params;
  };
  const double corner_bound_px = options.max_corner_sigma_fraction *
                                 std::hypot(0.5 * image_size.width, 0.5 * image_size.height);

  std::vector<ModelCandidate> tried;
  auto record = [&](const Evaluation& e, const std::string& name, const std::string& verdict) {
    ModelCandidate c;
    c.name = name;
    c.fitted = e.fit.has_value();
    if (e.fit) {
      c.name = e.fit->model;
      c.num_params = e.num_params;
      c.sum_squares_px2 = e.sum_squares;
      c.rms_px = e.fit->rms_px;
      c.criterion = criterion_of(e);
    }
    c.verdict = verdict;
    tried.push_back(c);
    return tried.size() - 1;
  };

  // Every model of the ladder is judged at the selection's noise (its sigmas then follow).
  base.pixel_sigma = sigma;
  base.compute_uncertainty = true;

  // "" when 1 sigma of each named parameter moves the image corner by at most the bound, else
  // what moves it most and by how much.
  auto undetermined = [&](const FitResult& fit, const std::vector<std::string>& sigma_names) {
    double worst_effect = 0.0;
    std::string worst_name;
    for (const ParameterSigma& s : fit.sigmas) {
      if (std::find(sigma_names.begin(), sigma_names.end(), s.name) == sigma_names.end()) continue;
      const double effect = CornerEffectPx(s, fit.camera.intrinsics, image_size);
      if (!(effect <= worst_effect)) {
        worst_effect = effect;
        worst_name = s.name;
      }
    }
    if (worst_effect <= corner_bound_px) return std::string();
    return "1 sigma of " + worst_name + " would move the image corner by " + Fixed(worst_effect) +
           " px (bound " + Fixed(corner_bound_px) + " px)";
  };

  // One family's ladder: from `base_options`, free one of `groups` at a time while the criterion
  // improves and the scene determines it. A refused base is a model of infinite criterion that any
  // fitted trial improves on (so a perspective camera whose principal point is far from the
  // centre is still found). Records every model tried and why each group was left out.
  struct Ladder {
    Evaluation final;
    FitOptions final_options;
    size_t final_index = 0;
    std::vector<int> included;
    std::string why_left_out[kNumGroups];
  };
  auto criterion_or_inf = [&](const Evaluation& e) {
    return e.fit ? criterion_of(e) : std::numeric_limits<double>::infinity();
  };
  auto run_ladder = [&](const FitOptions& base_options, const std::string& base_name,
                        const std::vector<int>& groups) {
    Ladder ladder;
    ladder.final_options = base_options;
    ladder.final = Evaluate(points, pixels, image_size, base_options);
    ladder.final_index = record(ladder.final, base_name,
                                ladder.final.fit ? "simplest model"
                                                 : "not determined: " + ladder.final.refusal);
    for (;;) {
      const std::string current_name = ladder.final.fit ? ladder.final.fit->model : base_name;
      int best_group = -1;
      size_t best_index = 0;
      Evaluation best;
      FitOptions best_options;
      for (const int g : groups) {
        if (std::find(ladder.included.begin(), ladder.included.end(), g) != ladder.included.end()) {
          continue;
        }
        if (g == kK2 &&
            std::find(ladder.included.begin(), ladder.included.end(), kK1) == ladder.included.end() &&
            std::find(groups.begin(), groups.end(), kK1) != groups.end()) {
          ladder.why_left_out[g] = "left out: not tried, k1 is not in the model";
          continue;
        }
        FitOptions trial_options = ladder.final_options;
        ModeOf(trial_options, g) = ParameterMode::Free();
        Evaluation trial = Evaluate(points, pixels, image_size, trial_options);
        const std::string name = current_name + "+" + kGroupNames[g];
        if (!trial.fit) {
          ladder.why_left_out[g] = "left out: not determined (the fit with it is refused: " +
                                   trial.refusal + ")";
          record(trial, name, "not determined: refused");
          continue;
        }
        const std::string problem = undetermined(*trial.fit, SigmaNamesOf(g));
        if (!problem.empty()) {
          ladder.why_left_out[g] = "left out: not determined: " + problem;
          record(trial, name, "not determined: " + problem);
          continue;
        }
        const double delta = criterion_of(trial) - criterion_or_inf(ladder.final);
        ladder.why_left_out[g] = "left out: delta " + std::string(criterion_name) + " " +
                                 Signed(delta) + " against " + current_name +
                                 ": not supported by the data";
        const size_t index =
            record(trial, name, "delta " + std::string(criterion_name) + " " + Signed(delta));
        if (delta < 0.0 && (best_group < 0 || criterion_of(trial) < criterion_of(best))) {
          best_group = g;
          best_index = index;
          best = std::move(trial);
          best_options = trial_options;
        }
      }
      if (best_group < 0) break;
      ladder.included.push_back(best_group);
      ladder.final = std::move(best);
      ladder.final_options = best_options;
      ladder.final_index = best_index;
      tried[best_index].verdict += ": kept";
    }
    return ladder;
  };

  // The perspective ladder from pose + focal, and the orthographic one (scale, then aspect and
  // skew); the family whose final model has the lower criterion wins.
  Ladder chosen = run_ladder(base, "pose+focal", candidates);
  if (options.allow_orthographic && OrthographicIsPossible(base)) {
    FitOptions ortho_options = base;
    ortho_options.projection = Projection::kOrthographic;
    std::vector<int> ortho_groups;
    for (const int g : candidates) {
      if (g == kAspect || g == kSkew) ortho_groups.push_back(g);
    }
    // No orthographic model fits better than the affine camera (all of them free), so when even
    // its sum of squares with the fewest orthographic parameters' penalty cannot beat the best
    // perspective model, the orthographic ladder cannot win: skip it (one fit, not up to four).
    const Evaluation& affine_fit = affine_evaluation();
    const double ortho_lower_bound =
        affine_fit.fit ? affine_fit.sum_squares / (sigma * sigma) + penalty * 6
                       : std::numeric_limits<double>::infinity();
    Ladder ortho;
    if (ortho_lower_bound < criterion_or_inf(chosen.final)) {
      ortho = run_ladder(ortho_options, "orthographic", ortho_groups);
    } else {
      ModelCandidate c;
      c.name = "orthographic";  // with the forced groups, as its ladder would name it
      if (ortho_options.aspect.IsFree()) c.name += "+aspect";
      if (ortho_options.skew.IsFree()) c.name += "+skew";
      c.verdict = affine_fit.fit ? "not supported: even the affine camera's residual (rms " +
                                       Fixed(affine_fit.fit->rms_px) + " px) puts every "
                                       "orthographic model above the best perspective one"
                                 : "not determined: " + affine_fit.refusal;
      tried.push_back(c);
    }
    if (criterion_or_inf(ortho.final) < criterion_or_inf(chosen.final)) {
      const std::string against =
          chosen.final.fit ? "delta " + std::string(criterion_name) + " " +
                                 Signed(criterion_of(ortho.final) - criterion_of(chosen.final)) +
                                 " against the best perspective model, " + chosen.final.fit->model
                           : std::string("no perspective model fits");
      for (const int g : candidates) {
        // (The orthographic fit says itself why it has no principal point.)
        if (g != kAspect && g != kSkew && g != kPrincipalPoint) {
          ortho.why_left_out[g] = "left out: not part of an orthographic camera (" + against + ")";
        }
      }
      chosen = std::move(ortho);
    }
  }
  if (!chosen.final.fit) {
    FitCamera(points, pixels, image_size, base);  // rethrows the simplest model's refusal
    throw SceneError(SceneError::Reason::kDegenerate,
                     "no model of the ladder fits these points: check the correspondences");
  }
  FitOptions current_options = chosen.final_options;
  const size_t current_index = chosen.final_index;
  const std::vector<int>& included = chosen.included;
  const std::string* why_left_out = chosen.why_left_out;

  // The chosen model again with the caller's noise setting, so that its sigmas are reported as
  // FitCamera reports them.
  current_options.pixel_sigma = options.fit.pixel_sigma;
  current_options.compute_uncertainty = options.fit.compute_uncertainty;
  FitResult result = FitCamera(points, pixels, image_size, current_options);
  tried[current_index].verdict = "chosen";
  for (const int g : candidates) {
    if (std::find(included.begin(), included.end(), g) != included.end()) continue;
    for (FixedParameter& p : result.fixed_parameters) {
      if (p.name == kFixedNames[g] && !why_left_out[g].empty()) p.why = why_left_out[g];
    }
  }
  result.candidates = std::move(tried);
  result.criterion = criterion_name;
  result.selection_sigma_px = sigma;
  if (options.fit.ransac) {
    // Report every input point against the chosen camera, as FitCamera's RANSAC does.
    result.residuals_px = internal::ResidualsAgainst(result.camera, points_in_world,
                                                     observed_pixels, options.fit.pixel_origin);
    result.outliers = outliers;
  }
  return result;
}

}  // namespace camproj

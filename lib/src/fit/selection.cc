#include "fit/selection.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "camproj/number_text.h"
#include "fit/candidate.h"
#include "fit/common.h"
#include "fit/gate.h"
#include "fit/orthographic_fit.h"
#include "fit/statistics.h"

namespace camproj {
namespace internal {

namespace {

// A group of intrinsics the ladder frees together, in ladder order.
enum Group { kPrincipalPoint, kAspect, kSkew, kK1, kK2, kNumGroups };

const char* const kGroupNames[kNumGroups] = {"principal-point", "aspect", "skew", "k1", "k2"};
// FitResult::fixed_parameters' name of each group.
const char* const kFixedNames[kNumGroups] = {"principal point", "aspect", "skew", "k1", "k2"};

// Below this many points the chosen model is refitted with its covariance from its own closed
// form, restarts included; from there on from the ladder's camera (fit/candidate.h, FitReusing).
// Measured on the click benchmark (bench --clicks): at 6-12 clicks the refit from scratch is
// what refuses two mirrored 6-point scenes as mirrored (the DLT's two readings, fit/start.h)
// rather than as undetermined, and the second start from the image centre runs only below 20
// points (refine.cc). From 20 points on, the same answers and refusals on the benchmark's
// 60-300-point bands but one (a refusal at 100 points, 50 % outliers, now answered 0.6 px
// off), and 10-14 % fewer instructions for the default path at 20-1000 points
// (docs/bench/stage_cost.md); the refit then returns the ladder's own minimum, the camera the
// criterion was computed for. (Where the chosen model is the screen's, its fit from scratch is
// already at hand: the refit starts there at any count; on the click benchmark the same answers
// and refusals, 6-7 % fewer instructions at 6-12 points. Nor where the chosen model fixes the
// principal point: the second start is the principal point's, and the ladder's fit of such a
// model ran the same closed form and refinement; on the click benchmark every row the same, the
// stage-cost scenes' cameras the same to 1e-13 relative, 1.3-1.6 % fewer instructions at 6-12
// points.)
constexpr size_t kFromScratchBelowPoints = 20;

// How far `with` (a model that frees a distortion group) puts the image's border from where
// `without` (the same model without that group) does: the largest pixel distance over the
// image's corners and edge midpoints, each taken as the point on `without`'s ray through it at
// the depth of the points' centroid; infinite where `with` has such a point behind it. `where`:
// that place in words ("top-left corner"). Perspective cameras; a pixel beyond the fold of
// `without`'s distortion (no ray) is skipped.
double BorderShiftPx(const Camera& without, const Camera& with,
                     const std::vector<Eigen::Vector3d>& points, std::string* where) {
  const double depth = (without.cam_from_world * Centroid(points)).z();
  const Rigid3 world_from_cam = Inverse(without.cam_from_world);
  const double right = without.image_size.width - 1.0;
  const double bottom = without.image_size.height - 1.0;
  const char* const columns[3] = {"left", "", "right"};
  const char* const rows[3] = {"top", "", "bottom"};
  double largest = 0.0;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      if (row == 1 && column == 1) continue;  // the image centre
      const Eigen::Vector2d pixel(0.5 * column * right, 0.5 * row * bottom);
      Eigen::Vector3d ray;
      try {
        ray = CamRayFromPixel(without.intrinsics, pixel);
      } catch (const std::domain_error&) {
        continue;
      }
      const std::optional<Eigen::Vector2d> moved =
          PixelFromWorld(with, world_from_cam * (depth * ray));
      const double d = moved ? (*moved - pixel).norm() : std::numeric_limits<double>::infinity();
      if (!(d <= largest)) {
        largest = d;
        *where = row != 1 && column != 1
                     ? std::string(rows[row]) + "-" + columns[column] + " corner"
                     : std::string(row == 1 ? columns[column] : rows[row]) + " edge's midpoint";
      }
    }
  }
  return largest;
}

ParameterMode& ModeOf(FitOptions& options, int group) {
  switch (group) {
    case kPrincipalPoint: return options.principal_point;
    case kAspect: return options.aspect;
    case kSkew: return options.skew;
    case kK1: return options.k1;
    default: return options.k2;
  }
}

// One model fitted, or refused. Any failure is caught: one candidate never aborts the selection.
struct Evaluation {
  std::optional<FitResult> fit;
  FitOptions options;   // the model
  // Where not fitted, why: the fit's SceneError, or kNumerical for any other failure.
  std::optional<SceneError> refusal;
  double sum_squares = 0.0;
  int num_params = 0;
  // The fit's normal equations at its answer (perspective fits; null otherwise).
  std::shared_ptr<const ChartLinearization> linearization = nullptr;
};

// An evaluation's refusal in words and its reason (kDegenerate where it has none).
std::string RefusalOf(const Evaluation& e) { return e.refusal ? e.refusal->what() : ""; }
SceneError::Reason ReasonOf(const Evaluation& e) {
  return e.refusal ? e.refusal->reason() : SceneError::Reason::kDegenerate;
}

// `consistent_at_px`: the noise at which the candidate's fit may skip its restarts
// (fit/candidate.h).
Evaluation Evaluate(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                    const FitOptions& options, double consistent_at_px,
                    const CandidateReuse& reuse = {}) {
  Evaluation e;
  e.options = options;
  e.num_params = NumParameters(options);
  try {
    // The fit's normal equations for the determination check, which reads a fitted rival's
    // uncertainty from them (selection.h, kLinearizationFromPoints).
    std::shared_ptr<ChartLinearization> linearization = LinearizationSlot(points.size());
    CandidateReuse with = reuse;
    with.linearization = linearization.get();
    e.fit = FitCandidate(points, pixels, size, options, consistent_at_px, with);
    e.sum_squares = e.fit->rms_px * e.fit->rms_px * static_cast<double>(points.size());
    e.num_params = static_cast<int>(e.fit->free_parameters.size());
    e.linearization = Filled(std::move(linearization));
  } catch (const SceneError& error) {
    e.refusal = error;
  } catch (const std::exception& error) {
    e.refusal = SceneError(SceneError::Reason::kNumerical,
                           std::string("numerical failure (") + error.what() + ")",
                           kReportNumericalFailure);
  }
  return e;
}

// Whether two options, made from the same caller's options, fit the same model: the projection
// and every intrinsic's mode (the noise and the covariance do not change a fit). Known
// intrinsics are not compared: never the same.
bool SameModel(const FitOptions& a, const FitOptions& b) {
  auto same = [](const ParameterMode& x, const ParameterMode& y) {
    return x.kind == y.kind && x.value == y.value && x.value2 == y.value2;
  };
  return !a.known_intrinsics && !b.known_intrinsics && a.projection == b.projection &&
         a.ransac == b.ransac && same(a.focal, b.focal) && same(a.aspect, b.aspect) &&
         same(a.principal_point, b.principal_point) && same(a.skew, b.skew) &&
         same(a.k1, b.k1) && same(a.k2, b.k2);
}

// Whether the caller's options allow an orthographic camera: nothing only a perspective camera
// has is forced or given (principal point free, distortion), no RANSAC, no known intrinsics.
bool OrthographicIsPossible(const FitOptions& options) {
  auto zero_or_default = [](const ParameterMode& mode) {
    return mode.kind == ParameterMode::Kind::kDefault ||
           (mode.kind == ParameterMode::Kind::kFixed && mode.value == 0.0);
  };
  return options.projection == Projection::kPerspective && !options.principal_point.IsFree() &&
         zero_or_default(options.k1) && zero_or_default(options.k2) && !options.ransac &&
         !options.known_intrinsics;
}

std::string Fixed(double value, int digits = 3) { return GeneralDouble(value, digits); }

// A criterion difference in words: "BIC 2.15 above pose+focal+principal-point's: its better
// fit does not pay for its extra parameters".
std::string Versus(const char* criterion, double delta, const std::string& against) {
  // Against a refused model (criterion +inf) there is no difference to print.
  if (std::isinf(delta)) {
    return delta < 0.0 ? "determined where " + against + " is not"
                       : std::string("not determined");
  }
  return std::string(criterion) + " " + Fixed(std::abs(delta)) + (delta < 0.0 ? " below " : " above ") +
         against + "'s: " + (delta < 0.0 ? "its better fit pays for its extra parameters"
                                           : "its better fit does not pay for its extra parameters");
}

// Why a model was not tried: "2N - p = 2 redundant equations, fewer than 3 (its residuals could
// not show it is wrong)".
std::string TooFewRedundant(int redundancy, int minimum) {
  return "2N - p = " + std::to_string(redundancy) + " redundant equations, fewer than " +
         std::to_string(minimum) + " (its residuals could not show it is wrong)";
}

}  // namespace

int NumParameters(const FitOptions& options) {
  if (options.known_intrinsics) return 6;
  int n = options.projection == Projection::kOrthographic ? 5 : 6;
  n += options.focal.IsFree() + options.aspect.IsFree() + 2 * options.principal_point.IsFree() +
       options.skew.IsFree() + options.k1.IsFree() + options.k2.IsFree();
  return n;
}

double CombinedNoise(const AutoFitOptions& options, double sum_squares, double dof) {
  const double prior_variance = options.prior_sigma_px * options.prior_sigma_px;
  return std::max(kMinNoisePx, std::sqrt((options.prior_weight * prior_variance + sum_squares) /
                                         (options.prior_weight + std::max(0.0, dof))));
}

namespace {

// One family's ladder as RunLadder leaves it: the model it ended at, and why each group it did
// not take was left out.
struct Ladder {
  Evaluation final;
  FitOptions final_options;
  size_t final_index = 0;  // in ModelSelector::tried_
  std::vector<int> included;
  std::string why_left_out[kNumGroups];
  // The closed form the ladder's chain of fits began at (each later one started where the
  // last ended: its method "warm").
  std::string start_method;
};

// SelectModel's stages over the state they share: the points and their preparation, the noise
// the criterion uses, and every model tried.
class ModelSelector {
 public:
  ModelSelector(const std::vector<Eigen::Vector3d>& points,
                const std::vector<Eigen::Vector2d>& pixels, const ImageSize& image_size,
                const AutoFitOptions& options, const Prefit* prefit)
      : points_(points), pixels_(pixels), image_size_(image_size), options_(options),
        prefit_(prefit),
        // The noise at which a candidate's fit is consistent enough to skip its restarts: the
        // given one, else the prior until the selection's own noise is known.
        candidate_sigma_(options.fit.pixel_sigma.value_or(options.prior_sigma_px)),
        geometry_(prefit != nullptr
                      ? prefit->geometry
                      : PrepareScene(points, pixels, image_size, options.fit.pixel_origin)),
        n_(static_cast<int>(points.size())),
        num_equations_(2.0 * n_),
        aic_(options.criterion == ModelCriterion::kAic),
        penalty_(aic_ ? 2.0 : std::log(num_equations_)),
        criterion_name_(aic_ ? "AIC" : "BIC") {}

  Selection Run();

 private:
  Evaluation FitModel(const FitOptions& model, const Camera* warm_start = nullptr) const;
  const Evaluation& Affine(const FitOptions& base);
  double Noise(const FitOptions& base, const std::vector<int>& candidates,
               const Evaluation& base_fit, bool orthographic_allowed);
  double CriterionOf(const Evaluation& e) const {
    return e.sum_squares / (sigma_ * sigma_) + penalty_ * e.num_params;
  }
  double CriterionOrInf(const Evaluation& e) const {
    return e.fit ? CriterionOf(e) : std::numeric_limits<double>::infinity();
  }
  size_t Record(const Evaluation& e, const std::string& name, const std::string& verdict);
  Ladder RunLadder(const FitOptions& base_options, const std::string& base_name,
                   const std::vector<int>& groups, const Evaluation* evaluated_base);
  bool AffineExplains(const FitOptions& base) const;
  bool ChooseOrthographic(const FitOptions& base, const std::vector<int>& candidates,
                          Ladder* chosen);
  void RefuseMirroredIfPerspectiveFits(const FitOptions& base, const Ladder& chosen) const;
  Selection Refit(const Ladder& chosen, const std::vector<int>& candidates);

  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  const ImageSize& image_size_;
  const AutoFitOptions& options_;
  const Prefit* prefit_;
  double candidate_sigma_;
  const SceneGeometry geometry_;  // the points prepared once for every candidate (fit/scene.h)
  const int n_;
  const double num_equations_;
  const bool aic_;
  const double penalty_;  // per parameter
  const char* const criterion_name_;
  double sigma_ = 0.0;  // the criterion's noise (Noise)
  std::optional<Evaluation> affine_;
  std::vector<ModelCandidate> tried_;
  std::vector<Rival> rivals_;  // every fitted model
};

// One model fitted, from `warm_start` if not null (fit/candidate.h): the prefit's fit where it
// is that model.
Evaluation ModelSelector::FitModel(const FitOptions& model, const Camera* warm_start) const {
  if (prefit_ == nullptr || !SameModel(prefit_->model, model)) {
    return Evaluate(points_, pixels_, image_size_, model, candidate_sigma_,
                    CandidateReuse{warm_start, &geometry_});
  }
  Evaluation e;
  e.options = model;
  e.fit = prefit_->fit;
  e.sum_squares = e.fit->rms_px * e.fit->rms_px * static_cast<double>(points_.size());
  e.num_params = static_cast<int>(e.fit->free_parameters.size());
  e.linearization = prefit_->linearization;
  return e;
}

// The affine camera (orthographic with aspect and skew free unless the caller fixed them): the
// orthographic family's best fit, evaluated at most once.
const Evaluation& ModelSelector::Affine(const FitOptions& base) {
  if (!affine_) {
    FitOptions affine_options = base;
    affine_options.projection = Projection::kOrthographic;
    for (const int g : {kAspect, kSkew}) {
      if (ModeOf(affine_options, g).kind == ParameterMode::Kind::kDefault) {
        ModeOf(affine_options, g) = ParameterMode::Free();
      }
    }
    affine_ = FitModel(affine_options);
  }
  return *affine_;
}

// The criterion's noise: given, or the prior combined with the residuals of the richest model
// the scene supports (groups dropped from the top of the ladder until one is fitted with
// residual degrees of freedom to spare).
double ModelSelector::Noise(const FitOptions& base, const std::vector<int>& candidates,
                            const Evaluation& base_fit, bool orthographic_allowed) {
  if (base.pixel_sigma) return *base.pixel_sigma;
  // The richest model is fitted from its closed form. Started where the screen's or the
  // base's fit ended (five groups richer) it stopped in higher minima (bench --clicks, 54 kept
  // points: a sum of squares of 57 px^2 for the closed form's 36), which changed the model
  // chosen in 18 of the 2700 scenes at 60-300 points.
  for (int top = static_cast<int>(candidates.size()); top >= 0; --top) {
    FitOptions richest = base;
    for (int i = 0; i < top; ++i) ModeOf(richest, candidates[i]) = ParameterMode::Free();
    // Only its sum of squares is used.
    if (num_equations_ - NumParameters(richest) < 1) continue;
    const Evaluation e = top == 0 ? base_fit : FitModel(richest);
    if (e.fit && num_equations_ > e.num_params) {
      return CombinedNoise(options_, e.sum_squares, num_equations_ - e.num_params);
    }
  }
  if (orthographic_allowed) {
    const Evaluation& e = Affine(base);
    if (e.fit && num_equations_ > e.num_params) {
      return CombinedNoise(options_, e.sum_squares, num_equations_ - e.num_params);
    }
  }
  return CombinedNoise(options_, 0.0, 0.0);  // the prior alone
}

size_t ModelSelector::Record(const Evaluation& e, const std::string& name,
                             const std::string& verdict) {
  ModelCandidate c;
  c.name = name;
  c.fitted = e.fit.has_value();
  c.num_params = e.num_params;
  if (e.fit) {
    c.name = e.fit->model;
    c.sum_squares_px2 = e.sum_squares;
    c.rms_px = e.fit->rms_px;
    c.criterion = CriterionOf(e);
    rivals_.push_back({e.fit->model, e.options, e.fit->camera, c.criterion,
                       /*mirrored_world=*/false, /*same_model=*/false, e.sum_squares,
                       e.linearization});
  }
  c.verdict = verdict;
  tried_.push_back(c);
  return tried_.size() - 1;
}

// One family's ladder: from `base_options`, free one of `groups` at a time while the criterion
// improves, the fit with it is not refused and the model keeps min_redundancy equations to
// spare (whether the chosen camera is determined well enough is the assessment's question:
// leaving out a group the residuals ask for only hides its uncertainty in a biased camera).
// A refused base is a model of infinite criterion that any fitted trial improves on (so a
// perspective camera whose principal point is far from the centre is still found). Records
// every model tried and why each group was left out.
Ladder ModelSelector::RunLadder(const FitOptions& base_options, const std::string& base_name,
                                const std::vector<int>& groups, const Evaluation* evaluated_base) {
  Ladder ladder;
  ladder.final_options = base_options;
  // The base fitted before the noise was known has the same camera and residuals (the noise
  // only scales its sigmas, which the ladder does not read for the base).
  ladder.final = evaluated_base != nullptr ? *evaluated_base : FitModel(base_options);
  if (ladder.final.fit) ladder.start_method = ladder.final.fit->start_method;
  ladder.final_index = Record(ladder.final, base_name,
                              ladder.final.fit ? "simplest model"
                                               : "not determined: " + RefusalOf(ladder.final));
  auto in_groups = [&](int g) { return std::find(groups.begin(), groups.end(), g) != groups.end(); };
  for (;;) {
    const std::string current_name = ladder.final.fit ? ladder.final.fit->model : base_name;
    int best_group = -1;
    size_t best_index = 0;
    Evaluation best;
    FitOptions best_options;
    auto included = [&](int g) {
      return std::find(ladder.included.begin(), ladder.included.end(), g) != ladder.included.end();
    };
    for (const int g : groups) {
      if (included(g)) continue;
      if (g == kK2 && !included(kK1) && in_groups(kK1)) {
        ladder.why_left_out[g] = "left out: not tried, k1 is not in the model";
        continue;
      }
      if (g == kSkew && !included(kPrincipalPoint) && in_groups(kPrincipalPoint)) {
        // Skew only describes resampled or cropped pixels; before the principal point it
        // stands in for a lens shift at a few points and bends the camera to match.
        ladder.why_left_out[g] = "left out: not tried, the principal point is not in the model";
        continue;
      }
      FitOptions trial_options = ladder.final_options;
      ModeOf(trial_options, g) = ParameterMode::Free();
      const std::string name = current_name + "+" + kGroupNames[g];
      const int redundancy = 2 * n_ - NumParameters(trial_options);
      if (redundancy < options_.min_redundancy) {
        const std::string why = TooFewRedundant(redundancy, options_.min_redundancy);
        ladder.why_left_out[g] = "left out: not tried: " + why;
        ModelCandidate c;
        c.name = name;
        c.num_params = NumParameters(trial_options);
        c.verdict = "not tried: " + why;
        tried_.push_back(c);
        continue;
      }
      Evaluation trial =
          FitModel(trial_options, ladder.final.fit ? &ladder.final.fit->camera : nullptr);
      if (!trial.fit) {
        ladder.why_left_out[g] = "left out: not determined (the fit with it is refused: " +
                                 RefusalOf(trial) + ")";
        Record(trial, name, "not determined: refused");
        continue;
      }
      const double delta = CriterionOf(trial) - CriterionOrInf(ladder.final);
      std::string verdict = Versus(criterion_name_, delta, current_name);
      // A distortion is a claim about the lens over the whole image, and beyond the points that
      // determine it its error grows as the cube of the distance from the image centre: a k1 or
      // k2 that the criterion takes only weakly (by at most kEqualFitCriterion) and that moves
      // the image's border by more than the determination bound is the noise of the points
      // extrapolated, not a lens (seen: k1 = 0.91 +- 0.34 taken by 2.8 on 30 points near the
      // image centre, 10 px off on the object beyond them and ~900 px at the image's corner;
      // tests/fit_auto_test.cc, AWeakDistortionThatBendsTheImageBorderIsLeftOut).
      bool undetermined_distortion = false;
      if ((g == kK1 || g == kK2) && delta < 0.0 && delta >= -kEqualFitCriterion &&
          ladder.final.fit && trial_options.projection == Projection::kPerspective) {
        std::string where;
        const double shift =
            BorderShiftPx(ladder.final.fit->camera, trial.fit->camera, points_, &where);
        if (!(shift <= options_.max_uncertainty_px)) {
          undetermined_distortion = true;
          verdict = "not determined over the image: " + std::string(criterion_name_) + " only " +
                    Fixed(-delta) + " below " + current_name + "'s (weak evidence: at most " +
                    Fixed(kEqualFitCriterion) + "), and it moves the image's " + where + " by " +
                    Fixed(shift) + " px (bound " + Fixed(options_.max_uncertainty_px) + " px)";
        }
      }
      ladder.why_left_out[g] = "left out: " + verdict;
      const size_t index = Record(trial, name, verdict);
      if (delta < 0.0 && !undetermined_distortion &&
          (best_group < 0 || CriterionOf(trial) < CriterionOf(best))) {
        best_group = g;
        best_index = index;
        best = std::move(trial);
        best_options = trial_options;
      }
    }
    if (best_group < 0) break;
    ladder.included.push_back(best_group);
    if (best.fit->start_method != "warm") ladder.start_method = best.fit->start_method;
    ladder.final = std::move(best);
    ladder.final_options = best_options;
    ladder.final_index = best_index;
    tried_[best_index].verdict += ": kept";
  }
  return ladder;
}

// Whether the affine camera (the orthographic family's best) explains every point within the
// noise as the gate's first test asks it: its sum of squares within the chi-square quantile of
// 2N - 8 degrees of freedom at the gate's significance, in units of noise_tolerance times the
// noise given or the prior. A perspective fit refused with points behind it is contamination (a
// mis-click, a mirrored world: no orthographic answer then) -- or a perspective the points cannot
// show, whose fit ran through the orthographic limit (seen: 30 clean points at a 0.03 deg view, 3
// of 2000 seeds), where the affine camera fits them.
bool ModelSelector::AffineExplains(const FitOptions& base) const {
  FitOptions affine = base;
  affine.projection = Projection::kOrthographic;
  const double dof = num_equations_ - 8.0;
  if (dof < 1.0) return false;
  try {
    const double sigma = options_.noise_tolerance * NoiseReferenceOf(options_).sigma_px;
    return AffineSumSquaresPx2(points_, pixels_, affine) / (sigma * sigma) <=
           ChiSquareQuantile(dof, 1.0 - options_.significance);
  } catch (const SceneError&) {
    return false;
  }
}

// The orthographic ladder (scale, then aspect and skew) against the perspective one's answer
// in `chosen`: replaces it, and returns true, if its final model has the lower criterion.
bool ModelSelector::ChooseOrthographic(const FitOptions& base, const std::vector<int>& candidates,
                                       Ladder* chosen) {
  FitOptions ortho_options = base;
  ortho_options.projection = Projection::kOrthographic;
  std::vector<int> ortho_groups;
  for (const int g : candidates) {
    if (g == kAspect || g == kSkew) ortho_groups.push_back(g);
  }
  // No orthographic model fits better than the affine camera (every A), so when even its sum
  // of squares with the fewest orthographic parameters' penalty cannot beat the best
  // perspective model, the orthographic ladder cannot win: skip it (one closed-form solve,
  // not up to four Ceres fits of 2N residuals each).
  std::optional<double> affine_sum_squares;
  std::string affine_refusal;
  try {
    affine_sum_squares = AffineSumSquaresPx2(points_, pixels_, ortho_options);
  } catch (const SceneError& error) {
    affine_refusal = error.what();
  }
  const double ortho_lower_bound =
      affine_sum_squares ? *affine_sum_squares / (sigma_ * sigma_) + penalty_ * 6
                         : std::numeric_limits<double>::infinity();
  Ladder ortho;
  if (ortho_lower_bound < CriterionOrInf(chosen->final)) {
    ortho = RunLadder(ortho_options, "orthographic", ortho_groups, nullptr);
  } else {
    ModelCandidate c;
    c.name = "orthographic";  // with the forced groups, as its ladder would name it
    if (ortho_options.aspect.IsFree()) c.name += "+aspect";
    if (ortho_options.skew.IsFree()) c.name += "+skew";
    c.verdict = affine_sum_squares
                    ? "not supported: even the affine camera's residual (rms " +
                          Fixed(std::sqrt(*affine_sum_squares / n_)) + " px) puts every "
                          "orthographic model above the best perspective one"
                    : "not determined: " + affine_refusal;
    tried_.push_back(c);
  }
  if (!(CriterionOrInf(ortho.final) < CriterionOrInf(chosen->final))) return false;
  const std::string against =
      chosen->final.fit ? Versus(criterion_name_,
                                 CriterionOf(ortho.final) - CriterionOf(chosen->final),
                                 "the best perspective model, " + chosen->final.fit->model)
                        : std::string("no perspective model is determined");
  for (const int g : candidates) {
    // (The orthographic fit says itself why it has no principal point.)
    if (g != kAspect && g != kSkew && g != kPrincipalPoint) {
      ortho.why_left_out[g] = "left out: not part of an orthographic camera (" + against + ")";
    }
  }
  *chosen = std::move(ortho);
  return true;
}

// An orthographic image cannot show a mirrored world (its depth order is a choice), but a
// perspective camera can: if the mirrored world fits a perspective camera better than the
// orthographic one chosen, and within the noise (the gate's test), the world frame is
// left-handed (kMirroredWorld).
void ModelSelector::RefuseMirroredIfPerspectiveFits(const FitOptions& base,
                                                    const Ladder& chosen) const {
  FitOptions mirrored = base;
  mirrored.compute_uncertainty = false;
  const Evaluation e = Evaluate(MirroredZ(points_), pixels_, image_size_, mirrored, sigma_);
  if (!e.fit || !(CriterionOf(e) < CriterionOf(chosen.final))) return;
  // Only a mirrored camera that explains the points says the world is mirrored: one that fits
  // better than the orthographic camera but not within the noise (a mis-click at 6 points: rms
  // 37 px against the orthographic camera's 40) says only that neither explains them, which
  // the gate says with the points to check.
  std::vector<double> lengths;
  lengths.reserve(e.fit->residuals_px.size());
  for (const Eigen::Vector2d& r : e.fit->residuals_px) lengths.push_back(r.norm());
  if (CheckConsistency(lengths, Repeats(points_, pixels_), e.num_params,
                       NoiseReferenceOf(options_), options_)
          .passed) {
    throw SceneError(SceneError::Reason::kMirroredWorld,
                     "the points fit a perspective camera only with one world axis flipped "
                     "(rms " + Fixed(e.fit->rms_px) + " px; the best camera of this world is "
                     "orthographic with rms " + Fixed(chosen.final.fit->rms_px) + " px): they "
                     "are seen as through a mirror, i.e. the world frame is left-handed",
                     kFlipAnAxis);
  }
}

// The chosen model refitted with its covariance and views, and what the selection reports with
// it.
Selection ModelSelector::Refit(const Ladder& chosen, const std::vector<int>& candidates) {
  Selection selection;
  selection.sigma_px = sigma_;
  selection.options = chosen.final_options;
  // The reported sigmas: the noise given, else the prior combined with the chosen model's own
  // residuals (at 6-12 points its 2N - p alone says little).
  selection.options.pixel_sigma =
      options_.fit.pixel_sigma
          ? *options_.fit.pixel_sigma
          : CombinedNoise(options_, chosen.final.sum_squares,
                          num_equations_ - chosen.final.num_params);
  selection.options.compute_uncertainty = options_.fit.compute_uncertainty;
  // From its closed form below kFromScratchBelowPoints where it frees the principal point, else
  // where the ladder's fit of it ended. Where the chosen model is the prefit's (the screen's
  // pose + focal + principal point), the ladder's fit of it is already the fit from its closed
  // form on these points, restarts included: the refit starts at that minimum at any count.
  const bool from_scratch = points_.size() < kFromScratchBelowPoints &&
                            chosen.final_options.principal_point.IsFree() &&
                            !(prefit_ != nullptr && SameModel(prefit_->model, chosen.final_options));
  std::shared_ptr<ChartLinearization> linearization = LinearizationSlot(points_.size());
  selection.fit = FitReusing(points_, pixels_, image_size_, selection.options,
                             CandidateReuse{from_scratch ? nullptr : &chosen.final.fit->camera,
                                            &geometry_, linearization.get()});
  selection.linearization = Filled(std::move(linearization));
  if (selection.fit.start_method == "warm") selection.fit.start_method = chosen.start_method;
  if (!options_.fit.pixel_sigma) selection.fit.pixel_sigma_estimated = true;
  tried_[chosen.final_index].verdict = "chosen";
  for (const int g : candidates) {
    if (std::find(chosen.included.begin(), chosen.included.end(), g) != chosen.included.end()) {
      continue;
    }
    for (FixedParameter& p : selection.fit.fixed_parameters) {
      if (p.name == kFixedNames[g] && !chosen.why_left_out[g].empty()) p.why = chosen.why_left_out[g];
    }
  }
  selection.criterion = tried_[chosen.final_index].criterion;
  selection.penalty = penalty_;
  for (Rival& r : rivals_) {
    if (r.model != selection.fit.model) selection.rivals.push_back(std::move(r));
  }
  selection.fit.candidates = std::move(tried_);
  selection.fit.criterion = criterion_name_;
  selection.fit.selection_sigma_px = sigma_;
  return selection;
}

// The stages in order: the base model, the noise, the perspective ladder, the orthographic
// family against it, the refit of the chosen model.
Selection ModelSelector::Run() {
  FitOptions base = options_.fit;
  base.ransac = false;
  if (base.focal.kind == ParameterMode::Kind::kDefault) base.focal = ParameterMode::Free();
  std::vector<int> candidates;  // groups the ladder may free
  if (base.projection == Projection::kPerspective && !base.known_intrinsics) {
    for (int g = 0; g < kNumGroups; ++g) {
      if (ModeOf(base, g).kind == ParameterMode::Kind::kDefault) candidates.push_back(g);
    }
  }
  // The perspective base (pose + focal and whatever the caller forced) decides whether an
  // orthographic camera may answer: only where the perspective is fitted, not determined or
  // ambiguous (the depth spread too small against the distance to show it, or to tell a
  // mirrored world from a proper one), never where it was refused as mirrored, behind the
  // points, or short of points.
  base.compute_uncertainty = false;
  const Evaluation base_fit = FitModel(base);
  const bool orthographic_allowed =
      options_.allow_orthographic && OrthographicIsPossible(base) &&
      (base_fit.fit || ReasonOf(base_fit) == SceneError::Reason::kDegenerate ||
       ReasonOf(base_fit) == SceneError::Reason::kAmbiguous ||
       (ReasonOf(base_fit) == SceneError::Reason::kPointsBehindCamera && AffineExplains(base)));
  sigma_ = Noise(base, candidates, base_fit, orthographic_allowed);

  // Every model of the ladder is judged at the selection's noise (its sigmas then follow).
  base.pixel_sigma = sigma_;
  candidate_sigma_ = sigma_;
  base.compute_uncertainty = true;

  // The perspective ladder from pose + focal, and the orthographic one (scale, then aspect and
  // skew); the family whose final model has the lower criterion wins.
  const std::string base_name =
      base.projection == Projection::kOrthographic ? "orthographic" : "pose+focal";
  Ladder chosen = RunLadder(base, base_name, candidates, &base_fit);
  bool orthographic_chosen = base.projection == Projection::kOrthographic;
  if (orthographic_allowed && ChooseOrthographic(base, candidates, &chosen)) {
    orthographic_chosen = true;
  }
  if (!chosen.final.fit) {
    // The simplest model's refusal says what to fix.
    const Evaluation& refused = base_fit.fit ? chosen.final : base_fit;
    throw refused.refusal ? *refused.refusal
                          : SceneError(SceneError::Reason::kNumerical, "no model was fitted",
                                       kReportNumericalFailure);
  }
  if (orthographic_chosen && base.projection == Projection::kPerspective) {
    RefuseMirroredIfPerspectiveFits(base, chosen);
  }
  return Refit(chosen, candidates);
}

}  // namespace

Selection SelectModel(const std::vector<Eigen::Vector3d>& points,
                      const std::vector<Eigen::Vector2d>& pixels, const ImageSize& image_size,
                      const AutoFitOptions& options, const Prefit* prefit) {
  return ModelSelector(points, pixels, image_size, options, prefit).Run();
}

}  // namespace internal
}  // namespace camproj

// FitCameraAuto: the default path as a pipeline of stages (lib/src/fit/): screen -> (outlier
// stage) -> model selection on the points kept -> assessment of the returned camera (mirror
// test, consistency gate). The order and why: model_select.h, docs/model-selection.md.
#include "camproj/model_select.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "check.h"
#include "fit/assess.h"
#include "fit/candidate.h"
#include "fit/closed_form.h"
#include "fit/common.h"
#include "fit/determination.h"
#include "fit/gate.h"
#include "fit/mirror.h"
#include "fit/other_minima.h"
#include "fit/outliers.h"
#include "fit/scene.h"
#include "fit/selection.h"
#include "fit/statistics.h"
#include "fit/verdicts.h"

namespace camproj {

using internal::Require;

namespace {

using Clock = std::chrono::steady_clock;

using internal::Px;

// The points' names in messages: the caller's (not copied), else "point 1", "point 2", ...
// made in `made`.
const std::vector<std::string>& NamesOf(const AutoFitOptions& options, size_t n,
                                        std::vector<std::string>* made) {
  if (!options.point_names.empty()) return options.point_names;
  made->resize(n);
  for (size_t i = 0; i < n; ++i) (*made)[i] = "point " + std::to_string(i + 1);
  return *made;
}

// The points not in `left_out` (sorted).
template <typename T>
std::vector<T> Kept(const std::vector<T>& values, const std::vector<int>& left_out) {
  std::vector<T> kept;
  kept.reserve(values.size() - std::min(values.size(), left_out.size()));
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::binary_search(left_out.begin(), left_out.end(), static_cast<int>(i))) {
      kept.push_back(values[i]);
    }
  }
  return kept;
}

// `values` itself when nothing is left out (no copy: the points can be millions), else the
// points not in `left_out`, held in `storage`.
template <typename T>
const std::vector<T>& KeptOrAll(const std::vector<T>& values, const std::vector<int>& left_out,
                                std::vector<T>* storage) {
  if (left_out.empty()) return values;
  *storage = Kept(values, left_out);
  return *storage;
}

// Lengths of the residuals of the points not in `left_out` (sorted).
std::vector<double> KeptLengths(const std::vector<Eigen::Vector2d>& residuals,
                                const std::vector<int>& left_out) {
  std::vector<double> lengths;
  for (const Eigen::Vector2d& r : Kept(residuals, left_out)) lengths.push_back(r.norm());
  return lengths;
}

// "c4 (118 px), c2 (3.1 px), c7 (2.9 px)": the largest residuals among the kept points.
std::string WorstPoints(const std::vector<Eigen::Vector2d>& residuals,
                        const std::vector<int>& left_out, const std::vector<std::string>& names,
                        int count = 3) {
  std::vector<int> order;
  for (size_t i = 0; i < residuals.size(); ++i) {
    if (!std::binary_search(left_out.begin(), left_out.end(), static_cast<int>(i))) {
      order.push_back(static_cast<int>(i));
    }
  }
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return residuals[a].norm() > residuals[b].norm(); });
  std::string text;
  for (int i = 0; i < std::min<int>(count, static_cast<int>(order.size())); ++i) {
    const double r = residuals[order[i]].norm();
    text += (i == 0 ? "" : ", ") + internal::PointName(names[order[i]]) + " (" +
            (std::isfinite(r) ? Px(r) : std::string("behind the camera")) + ")";
  }
  return text;
}

// Refusals that no choice of points can change: the outlier stage is not tried.
bool Final(SceneError::Reason reason) {
  return reason == SceneError::Reason::kNonFiniteInput ||
         reason == SceneError::Reason::kTooFewPoints ||
         reason == SceneError::Reason::kCollinearPoints ||
         reason == SceneError::Reason::kPlanarUnderdetermined;
}

// A scene that no camera explains may be a mirrored world whose reading the fit could not
// tell: if the screen's model fits every point consistently once the world's z is negated,
// throws kMirroredWorld with the advice to flip an axis.
void MirrorDiagnosis(const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                     const AutoFitOptions& options, const internal::NoiseReference& noise) {
  if (options.fit.projection != Projection::kPerspective) return;
  const internal::Screen screen =
      internal::ScreenPoints(internal::MirroredZ(points), pixels, size, options, noise);
  if (screen.consistent) {
    throw SceneError(SceneError::Reason::kMirroredWorld,
                     "no camera explains these points, but with one world axis flipped they fit "
                     "one (" + screen.summary + "): the points are seen as through a mirror, "
                     "i.e. the world frame is left-handed",
                     internal::kFlipAnAxis);
  }
}

// A right-handed world fits its proper camera better than any proper camera fits the world with
// z negated -- unless the perspective is weak (a Necker-cube reading: the two fit about equally
// well and either may win by noise), or the points are too few for the difference to show (at
// 6-12 points a mirrored world can fit a proper camera within the noise). The mirror test fits
// the mirrored world twice: the chosen model from the camera's depth reversal (fit/mirror.h),
// and, at up to kMirrorScreenMaxPoints points, the screen's model from its own closed-form start
// (the reversal is no start for a strong perspective, where only few points let the mirrored
// world fit at all). Refuses as mirrored when the reversal's refinement fits significantly
// better: by more than the chi-square 99.9 % quantile of one degree of freedom (10.83) in units
// of the noise. Otherwise returns the better reading by the selection's criterion as a rival for
// the determination check, which refuses when it fits about as well (criterion within
// kEqualFitCriterion, or lower) and puts the scene elsewhere. Nothing for an orthographic camera:
// its depth reversal has the same pixels everywhere.
// The selection's criterion of another reading of the `num_points` kept points: its sum of
// squares at the selection's noise plus the penalty for `model`'s parameters.
double CriterionOf(const internal::Selection& selection, const FitOptions& model, double rms_px,
                   size_t num_points) {
  return static_cast<double>(num_points) * rms_px * rms_px /
             (selection.sigma_px * selection.sigma_px) +
         selection.penalty * internal::NumParameters(model);
}

std::optional<internal::Rival> MirrorTest(const internal::Selection& selection, double rms_px,
                                          const std::vector<Eigen::Vector3d>& kept_points,
                                          const std::vector<Eigen::Vector2d>& kept_pixels,
                                          const ImageSize& size, const AutoFitOptions& options,
                                          const internal::NoiseReference& noise) {
  constexpr double kSignificantChi2 = 10.83;
  // Measured on the click benchmark (bench --clicks, 100 scenes per band): the fresh start
  // refuses 2 mirrored worlds at 6 points that were answered 90-140 px off, and none at 12 was
  // answered without it; at 12 points it would cost a third of a clean fit (SQPnP).
  constexpr size_t kMirrorScreenMaxPoints = 8;
  if (selection.options.projection != Projection::kPerspective) return std::nullopt;
  const double n = static_cast<double>(kept_points.size());
  std::optional<internal::Rival> rival;
  auto consider = [&](const Camera& camera, const FitOptions& model, double mirrored_rms_px) {
    const double criterion = CriterionOf(selection, model, mirrored_rms_px, kept_points.size());
    if (rival && !(criterion < rival->criterion)) return;
    rival = internal::Rival{internal::kMirroredReadingName, model, camera, criterion,
                            /*mirrored_world=*/true};
  };
  // The mirrored world prepared once for every reading of it below.
  const internal::SceneGeometry mirrored_world = internal::PrepareScene(
      internal::MirroredZ(kept_points), kept_pixels, size, selection.options.pixel_origin);
  // A reading counts where it fits about as well or better (the rival check's
  // kEqualFitCriterion) or significantly better (the refusal's, a lower sum of squares); one
  // with more parameters (the off-axis model below) only further below.
  const double read_below_px2 =
      n * rms_px * rms_px + kEqualFitCriterion * selection.sigma_px * selection.sigma_px;
  const std::optional<internal::MirroredReading> reversed =
      internal::FitMirroredReading(selection.fit.camera, selection.options, kept_points,
                                   kept_pixels, &mirrored_world, read_below_px2);
  if (reversed) {
    const double gain = n * (rms_px * rms_px - reversed->rms_px * reversed->rms_px);
    if (gain / (noise.sigma_px * noise.sigma_px) > kSignificantChi2) {
      throw SceneError(SceneError::Reason::kMirroredWorld,
                       "the points fit a camera better with one world axis flipped (rms " +
                           Px(reversed->rms_px) + " against " + Px(rms_px) +
                           "): they are seen as through a mirror, i.e. the world frame is "
                           "left-handed",
                       internal::kFlipAnAxis);
    }
    consider(reversed->camera, selection.options, reversed->rms_px);
  }
  if (kept_points.size() <= kMirrorScreenMaxPoints) {
    // The chosen model, and with the principal point free where the selection left it out: a
    // mirrored projector's lens shift is what a proper reading at few points may trade away.
    std::vector<FitOptions> models = {selection.options};
    FitOptions off_axis = selection.options;
    off_axis.principal_point = ParameterMode::Free();
    if (options.fit.principal_point.kind == ParameterMode::Kind::kDefault &&
        selection.options.principal_point.kind != ParameterMode::Kind::kFree &&
        2 * static_cast<int>(n) - internal::NumParameters(off_axis) >= options.min_redundancy) {
      models.push_back(off_axis);
    }
    const std::vector<std::optional<internal::MirroredReading>> readings =
        internal::FitMirroredWorld(kept_points, kept_pixels, size, models,
                                   selection.fit.camera.intrinsics, &mirrored_world,
                                   read_below_px2);
    for (size_t i = 0; i < models.size(); ++i) {
      if (readings[i]) consider(readings[i]->camera, models[i], readings[i]->rms_px);
    }
  }
  return rival;
}

// At six points (fit/other_minima.h) the chosen perspective model with the principal point free,
// refitted from each edge midpoint's principal point: every camera found, as a rival that the
// determination check refuses when it fits about as well or better and puts the scene elsewhere.
std::vector<internal::Rival> OtherMinima(const internal::Selection& selection,
                                         const std::vector<Eigen::Vector3d>& kept_points,
                                         const std::vector<Eigen::Vector2d>& kept_pixels,
                                         const ImageSize& size) {
  constexpr size_t kOtherMinimaMaxPoints = 6;  // the DLT's one redundant equation
  std::vector<internal::Rival> rivals;
  if (kept_points.size() > kOtherMinimaMaxPoints ||
      selection.options.projection != Projection::kPerspective ||
      !selection.options.principal_point.IsFree()) {
    return rivals;
  }
  for (const internal::Reading& reading :
       internal::FitFromEdgePrincipalPoints(kept_points, kept_pixels, size, selection.options,
                                            selection.fit.camera, selection.fit.rms_px)) {
    internal::Rival rival{internal::kOtherMinimumName, selection.options, reading.camera,
                          CriterionOf(selection, selection.options, reading.rms_px,
                                      kept_points.size())};
    rival.same_model = true;
    rivals.push_back(rival);
  }
  return rivals;
}

// A selection with every point's residual against its camera, recomputed in world coordinates
// from the camera as returned (and as the camera file stores it), and the gate on the points
// kept: computed once per selection, read by the pipeline and by the assessment.
struct Gated {
  internal::Selection selection;
  std::vector<Eigen::Vector2d> residuals_px;  // every point, in the caller's order
  ConsistencyCheck check;                     // over the points kept
};

Gated Gate(internal::Selection selection, const std::vector<int>& left_out,
           const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels,
           const AutoFitOptions& options, const internal::NoiseReference& noise) {
  Gated gated;
  gated.residuals_px = internal::ResidualsAgainst(selection.fit.camera, points, pixels,
                                                  options.fit.pixel_origin);
  std::vector<Eigen::Vector3d> kept_points;
  std::vector<Eigen::Vector2d> kept_pixels;
  gated.check = internal::CheckConsistency(
      KeptLengths(gated.residuals_px, left_out),
      internal::Repeats(KeptOrAll(points, left_out, &kept_points),
                        KeptOrAll(pixels, left_out, &kept_pixels)),
      static_cast<int>(selection.fit.free_parameters.size()), noise, options);
  gated.selection = std::move(selection);
  return gated;
}

// The model selection on the points not in `left_out`, gated. `screen`: the screen's fit, read
// by the selection when no point is left out (the same points), or nullptr.
Gated SelectOn(const std::vector<Eigen::Vector3d>& points,
               const std::vector<Eigen::Vector2d>& pixels, const std::vector<int>& left_out,
               const ImageSize& size, const AutoFitOptions& options,
               const internal::NoiseReference& noise, const internal::Screen* screen = nullptr) {
  const internal::Prefit* prefit =
      screen != nullptr && screen->fit && left_out.empty() ? &*screen->fit : nullptr;
  std::vector<Eigen::Vector3d> kept_points;
  std::vector<Eigen::Vector2d> kept_pixels;
  return Gate(internal::SelectModel(KeptOrAll(points, left_out, &kept_points),
                                    KeptOrAll(pixels, left_out, &kept_pixels), size, options,
                                    prefit),
              left_out, points, pixels, options, noise);
}

// The assessment of the gated selection: the statistics over the kept points, the mirror test,
// the gate's verdict (kInconsistent when it failed: only the forced-RANSAC path gets here with a
// failed gate), and the left-out points' report.
FitResult Assess(Gated gated, const std::vector<int>& left_out, const std::string& method,
                 const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                 const AutoFitOptions& options, const std::vector<std::string>& names) {
  // The refusals first, in order (mirror, gate, determination), on the selection as gated.
  std::vector<Eigen::Vector3d> kept_points_storage;
  std::vector<Eigen::Vector2d> kept_pixels_storage;
  const std::vector<Eigen::Vector3d>& kept_points =
      KeptOrAll(points, left_out, &kept_points_storage);
  const std::vector<Eigen::Vector2d>& kept_pixels =
      KeptOrAll(pixels, left_out, &kept_pixels_storage);
  const internal::NoiseReference noise = internal::NoiseReferenceOf(options);
  const std::optional<internal::Rival> mirrored = MirrorTest(
      gated.selection, gated.check.rms_px, kept_points, kept_pixels, size, options, noise);
  if (!gated.check.passed) {
    throw SceneError(SceneError::Reason::kInconsistent,
                     "no camera explains these points: " + gated.check.summary +
                         ". Largest residuals: " + WorstPoints(gated.residuals_px, left_out, names),
                     std::string("Check the points with the largest residuals") +
                         (noise.given ? std::string()
                                      : "; if your points are this noisy, give --sigma PX"));
  }
  if (mirrored) gated.selection.rivals.push_back(*mirrored);
  for (internal::Rival& rival : OtherMinima(gated.selection, kept_points, kept_pixels, size)) {
    gated.selection.rivals.push_back(std::move(rival));
  }
  const std::string left_out_text = internal::LeftOutText(gated.residuals_px, left_out, names);
  if (options.fit.projection == Projection::kPerspective) {
    // Chosen, not forced: orthographic only where the perspective is not observable.
    internal::RefuseIfPerspectiveShows(
        internal::TestPerspectiveStrength(gated.selection, kept_points, options), left_out_text);
  }
  PointReliability least_checked;
  const DeterminationCheck determination =
      internal::CheckDetermination(gated.selection, kept_points, options, &least_checked);
  internal::RefuseIfUndetermined(determination, gated.selection.fit.model, left_out_text,
                                 options.fit.pixel_origin);
  const PointReliability reliability = internal::WordReliability(least_checked, left_out, names);
  if (std::isfinite(options.max_uncertainty_px)) {
    internal::RefuseIfRegionUnbounded(gated.selection.fit, left_out_text);
    internal::RefuseIfUnchecked(reliability, names, size, noise.sigma_px, left_out_text);
  }

  FitResult result = std::move(gated.selection.fit);
  result.residuals_px = std::move(gated.residuals_px);
  result.outliers = left_out;
  result.outlier_method = left_out.empty() ? "" : method;
  result.rms_px = gated.check.rms_px;
  result.median_px = internal::Median(KeptLengths(result.residuals_px, left_out));
  result.max_px = gated.check.max_residual_px;
  result.consistency = gated.check;
  result.determination = determination;
  result.reliability = reliability;
  constexpr size_t kMaxRefits = 10;  // beyond, rms_with_px is not computed (0)
  FitOptions refit = gated.selection.options;
  refit.compute_uncertainty = false;
  for (const int i : left_out) {
    LeftOutPoint p;
    p.index = i;
    p.residual_px = result.residuals_px[i].norm();
    if (left_out.size() <= kMaxRefits) {
      std::vector<int> others;
      for (const int j : left_out) {
        if (j != i) others.push_back(j);
      }
      try {
        // From the returned camera, the minimum the point pulls the answer to: a fit from
        // scratch starts from a closed form the point contaminates (with 10 of 100 points left
        // out, 8 M instructions per refit and 80 % of the default path; from the answer LM
        // takes 10-40 iterations and 1.2 M; bench --clicks).
        const internal::CandidateReuse from_answer{&result.camera, nullptr};
        p.rms_with_px = internal::FitCandidate(Kept(points, others), Kept(pixels, others), size,
                                               refit, std::nullopt, from_answer)
                            .rms_px;
      } catch (const std::exception&) {
        p.rms_with_px = std::numeric_limits<double>::infinity();  // no camera with it
      }
    }
    result.left_out.push_back(p);
  }
  return result;
}

// --ransac PX: RANSAC at the caller's threshold, with the principal point and aspect free where
// they are candidates (the simplest model if the scene cannot determine them), then the
// selection on its consensus. Sets `left_out`.
Gated ForcedRansac(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                   const AutoFitOptions& options, const internal::NoiseReference& noise,
                   std::vector<int>* left_out) {
  FitOptions consensus = options.fit;
  if (consensus.focal.kind == ParameterMode::Kind::kDefault) consensus.focal = ParameterMode::Free();
  FitOptions simplest = consensus;
  for (ParameterMode* mode : {&consensus.principal_point, &consensus.aspect}) {
    if (mode->kind == ParameterMode::Kind::kDefault) *mode = ParameterMode::Free();
  }
  consensus.compute_uncertainty = simplest.compute_uncertainty = false;
  try {
    *left_out = FitCamera(points, pixels, size, consensus).outliers;
  } catch (const SceneError&) {
    *left_out = FitCamera(points, pixels, size, simplest).outliers;
  }
  return SelectOn(points, pixels, *left_out, size, options, noise);
}

// Whether the fit assumes the principal point at the image's centre (nor given nor known): a
// plane does not show it.
bool PrincipalPointAssumed(const AutoFitOptions& options) {
  return options.fit.principal_point.kind == ParameterMode::Kind::kDefault &&
         !options.fit.known_intrinsics;
}

// What to check on a plane, which does not show the principal point: where the fit assumed it
// (at the image's centre) unless it was given.
std::string PlanePrincipalPointAdvice(const ImageSize& size, const AutoFitOptions& options) {
  if (!PrincipalPointAssumed(options)) return "Check the principal point given and the image size";
  return "The principal point is assumed at the image's centre " +
         internal::PixelText(Eigen::Vector2d(0.5 * (size.width - 1), 0.5 * (size.height - 1)),
                             options.fit.pixel_origin) +
         ": check that the image size is the image's, or give --principal-point";
}

// The refusal of a scene no selection explained, with what the pipeline saw: a mirror if that
// explains it, else the selection's own refusal or the gate's verdict and the search's outcome.
[[noreturn]] void Refuse(const std::vector<Eigen::Vector3d>& points,
                         const std::vector<Eigen::Vector2d>& pixels, const ImageSize& size,
                         const AutoFitOptions& options, const internal::NoiseReference& noise,
                         const std::optional<SceneError>& refusal, const std::string& problem,
                         const internal::Screen& screen, const std::vector<int>& left_out,
                         const std::optional<internal::OutlierSearch>& search,
                         bool no_outlier_shows) {
  // A failed screen was diagnosed before the outlier search (Pipeline).
  if (screen.consistent) MirrorDiagnosis(points, pixels, size, options, noise);
  if (refusal && (problem.empty() || left_out.empty())) throw *refusal;
  std::string text =
      problem.empty() ? "the points do not fit one camera (" + screen.summary + ")" : problem;
  if (!options.find_outliers) {
    throw SceneError(SceneError::Reason::kInconsistent, text,
                     "Check the points with the largest residuals, or drop --keep-all to let the "
                     "fit find and leave out the points that disagree");
  }
  if (search && !search->found) text += "; and " + search->why_not;
  if (no_outlier_shows) {
    text += "; no point stands out (their median residual says the same noise as their RMS, as "
            "Gaussian noise's would), and no point left out could bring that noise within the "
            "bound: none was left out";
  }
  // On a plane the principal point is not fitted but assumed at the image's centre, so an image
  // size that is not the image's moves every point alike (data/plane at 1920 x 1080 for its
  // 1280 x 720: 320 px off); a scene in depth would show it.
  // (The screen's geometry where it fitted a model; where every screen model was refused, the
  // points' own.)
  const bool planar =
      screen.fit ? screen.fit->geometry.scene.planar
                 : internal::PrepareScene(points, pixels, size, options.fit.pixel_origin).scene.planar;
  const bool assumed = planar && PrincipalPointAssumed(options);
  throw SceneError(search && !search->found ? SceneError::Reason::kContaminated
                                            : SceneError::Reason::kInconsistent,
                   text + (assumed ? ". The points are on a plane, which does not show the "
                                     "principal point"
                                   : ""),
                   (assumed ? PlanePrincipalPointAdvice(size, options) + ". " : std::string()) +
                       (search && !search->found && search->too_few_points
                            ? "Add points (with more, the one that disagrees can be found and "
                              "left out), or check the correspondences (ids, order, mis-clicks) "
                              "and refit"
                            : "Check the correspondences (ids, order, mis-clicks) and refit") +
                       (noise.given ? std::string()
                                    : "; if your points are this noisy, give --sigma PX"));
}

// The default path's stages over the state they share: the screen of every point, the outlier
// search, the selection on the points kept with its gate, and the refusal where none passes.
class Pipeline {
 public:
  Pipeline(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels,
           const ImageSize& size, const AutoFitOptions& options)
      : points_(points), pixels_(pixels), size_(size), options_(options),
        names_(NamesOf(options, points.size(), &made_names_)),
        noise_(internal::NoiseReferenceOf(options)) {}

  FitResult Run(Clock::time_point start) {
    if (options_.fit.ransac) {
      gated_ = ForcedRansac(points_, pixels_, size_, options_, noise_, &left_out_);
      method_ = "ransac";
    } else {
      SelectAfterTheScreen();
    }
    FitResult result =
        Assess(std::move(*gated_), left_out_, method_, points_, pixels_, size_, options_, names_);
    result.time_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    return result;
  }

 private:
  // Screens every point with the simplest model that can show a mis-click; if it fails, the
  // outlier stage looks for the points to leave out. Then the model selection on the rest, and
  // its gate; a clean screen whose selection still fails the gate gets the search too. Leaves
  // gated_ set, or throws the refusal.
  void SelectAfterTheScreen() {
    screen_ = internal::ScreenPoints(points_, pixels_, size_, options_, noise_);
    // A refusal of every point that no choice of points should change is the answer: leaving
    // points out could only find a subset that escapes it (coordinates whose offset leaves too
    // few digits pass the check once a point with a far pixel is dropped).
    if (screen_->refusal && Final(screen_->refusal->reason())) throw *screen_->refusal;
    // A failed screen that the mirrored world passes is a mirror, not outliers: refuse it
    // before the outlier search, which would crawl through samples that no proper camera fits
    // (or find a subset that one does).
    if (!screen_->consistent) MirrorDiagnosis(points_, pixels_, size_, options_, noise_);
    if (!screen_->consistent && options_.find_outliers) {
      if (MayBeOutliers(screen_->check)) SearchOutliers();
    } else if (options_.find_outliers) {
      // A screen that passes may still hold a mis-click its fit absorbed (fit/outliers.h).
      internal::OutlierSearch absorbed =
          internal::FindAbsorbedOutlier(points_, pixels_, size_, options_, noise_, *screen_);
      if (absorbed.found) {
        left_out_ = absorbed.outliers;
        method_ = absorbed.method;
        search_ = std::move(absorbed);
      }
    }
    // The options as the selection reads them, without the names (which names_ holds): each
    // selection copies them, and the names are as many as the points.
    unnamed_ = options_;
    std::vector<std::string>().swap(unnamed_.point_names);
    Select();
    if (!gated_ && left_out_.empty() && options_.find_outliers && !search_ &&
        (!failed_gate_ || MayBeOutliers(failed_gate_->check))) {
      SearchOutliers();
      if (!left_out_.empty()) Select();
    }
    if ((gated_ || failed_gate_) && method_ == "lo-ransac") RereadTheConsensus();
    if (gated_ && 2 * left_out_.size() > points_.size()) RefuseAMinority();
    if (gated_ && method_ == "lo-ransac") RefuseIfTheLeftOutAreNotRandom();
    if (gated_ && !left_out_.empty()) RefuseIfThePlaneFitsEveryPoint();
    if (!gated_) {
      Refuse(points_, pixels_, size_, options_, noise_, refusal_, problem_, *screen_, left_out_,
             search_, no_outlier_shows_);
    }
  }

  // internal::MayBeOutliers for a gate failure over every point; where not (no_outlier_shows_),
  // the points look like Gaussian noise larger than the gate accepts and are not searched:
  // LO-RANSAC's consensus would be about every point (at 1000 points with 2 px noise against
  // the 1 px prior, 11 % of the refusal's instructions), and whatever it left out would be the
  // noise's tails.
  bool MayBeOutliers(const ConsistencyCheck& check) {
    no_outlier_shows_ = !internal::MayBeOutliers(check, options_, noise_);
    return !no_outlier_shows_;
  }

  void SearchOutliers() {
    search_ = internal::FindOutliers(points_, pixels_, size_, options_, noise_, names_);
    if (search_->found) {
      left_out_ = search_->outliers;
      method_ = search_->method;
    }
  }

  // The selection on the points not left out: gated_ where its gate passes, else failed_gate_
  // and problem_ (what the gate found), or refusal_ where the selection refused.
  void Select() {
    refusal_.reset();
    gated_.reset();
    failed_gate_.reset();
    // After a failed screen that no outliers explain, a richer model must leave N equations
    // to spare (model_select.h, min_redundancy).
    AutoFitOptions guarded = unnamed_;
    if (!screen_->consistent && left_out_.empty()) {
      guarded.min_redundancy = std::max(options_.min_redundancy, static_cast<int>(points_.size()));
    }
    try {
      gated_ = SelectOn(points_, pixels_, left_out_, size_, guarded, noise_, &*screen_);
    } catch (const SceneError& e) {
      if (Final(e.reason())) throw;
      refusal_ = e;
      return;
    }
    if (!gated_->check.passed) {
      problem_ = "the best camera for " +
                 (left_out_.empty() ? "all " + std::to_string(points_.size()) + " points"
                                    : "the " + std::to_string(points_.size() - left_out_.size()) +
                                          " points kept") +
                 " (" + gated_->selection.fit.model + ", rms " + Px(gated_->check.rms_px) +
                 ") does not explain them: " + gated_->check.summary + "; largest residuals " +
                 WorstPoints(gated_->residuals_px, left_out_, names_);
      failed_gate_ = std::move(gated_);
      gated_.reset();
    }
  }

  // A camera that most points disagree with is not what the points say: a minority consensus
  // can be any systematic error's (seen: a plane fitted at the wrong image size, its principal
  // point assumed 320 px off, answered with 16 of its 30 points left out and k1 -0.25). Random
  // pixels leave the good points the largest consensus up to half of them (the click
  // benchmark's 50 % bands: exactly half left out, never more).
  [[noreturn]] void RefuseAMinority() const {
    throw SceneError(
        SceneError::Reason::kContaminated,
        "the camera of the largest consensus " + method_ + " found (" +
            gated_->selection.fit.model + ") leaves out " + std::to_string(left_out_.size()) +
            " of the " + std::to_string(points_.size()) +
            " points, more than half: so few agreeing points do not say which camera it is",
        "Check the image size (a wrong --image-size moves every point alike) and the "
        "correspondences (ids, order)");
  }

  // Points left out by LO-RANSAC are outliers where they could be random pixels; a quarter or
  // more of the points lying nearer to where the camera puts them than random pixels would is a
  // systematic error instead -- a wrong image size, points of two objects that moved apart, a
  // lens the models lack -- which leaving them out hides (seen: a plane shot at 1280 x 720
  // fitted as 1920 x 1080, answered with 10-15 of its 30 points left out, 9-41 px from the
  // camera's pixels). Under random pixels (uniform over the image) each lands within
  // kNearFraction of the image's diagonal of its prediction with probability at most
  // pi R^2 / (W H); the count within R is then at most Binomial(left out, that), and a count
  // whose tail probability is under kLevel refuses. Not below a quarter: a few mismatched
  // detections near their corners are outliers that are not random either.
  void RefuseIfTheLeftOutAreNotRandom() const {
    constexpr double kNearFraction = 0.05;
    // Far below the gate's significance: at 1e-3 one of the click benchmark's 4500 scenes with
    // random pixels among 60-300 points was refused (8 of its 90 within 110 px, tail 3e-4), and
    // a systematic error puts most of those left out near (the planes: tails under 1e-12).
    constexpr double kLevel = 1e-7;
    const int left_out = static_cast<int>(left_out_.size());
    if (4 * left_out < static_cast<int>(points_.size())) return;
    const double radius_px = kNearFraction * std::hypot(size_.width, size_.height);
    const double p = std::min(1.0, M_PI * radius_px * radius_px / (size_.width * size_.height));
    int near = 0;
    for (const int i : left_out_) near += gated_->residuals_px[i].norm() <= radius_px ? 1 : 0;
    if (!(internal::BinomialTailAtLeast(left_out, p, near) < kLevel)) return;
    throw SceneError(
        SceneError::Reason::kContaminated,
        "the " + std::to_string(left_out) + " of " + std::to_string(points_.size()) +
            " points the outlier stage leaves out lie nearer to where the camera (" +
            gated_->selection.fit.model + ") puts them than random pixels would (" +
            std::to_string(near) + " within " + internal::Px(radius_px) +
            "): they look like a systematic error, not outliers",
        "Check the image size (a wrong --image-size moves every point alike), whether the "
        "points belong to one rigid object, and the correspondences (ids, order)");
  }

  // Points left out of a plane are outliers only where the plane's least-squares homography --
  // 8 degrees of freedom, as much as any camera without distortion can do with one plane --
  // cannot fit them with the rest. Where it fits every point within the noise (the gate's test,
  // 8 parameters), those left out disagree only with what the camera model assumes and a plane
  // does not show (the principal point, square pixels): a systematic error that leaving them out
  // hides (seen: a plane shot at 1280 x 720 fitted as 1920 x 1080, answered with 5-7 of its 30
  // points left out and k1 -0.23 to -0.84, too few for RefuseIfTheLeftOutAreNotRandom's quarter:
  // 10 of 3020 scenes of FitAutoTest.AMinorityConsensusIsRefused's kind at seed offsets
  // 0-150000). A mis-click on the plane fails the homography's gate as it fails the camera's.
  void RefuseIfThePlaneFitsEveryPoint() const {
    const internal::SceneGeometry geometry =
        screen_->fit ? screen_->fit->geometry
                     : internal::PrepareScene(points_, pixels_, size_, options_.fit.pixel_origin);
    const internal::Scene& scene = geometry.scene;
    if (!scene.planar || scene.points.size() != points_.size()) return;
    const std::vector<Eigen::Vector2d> plane =
        internal::PlaneCoordinates(scene.points, scene.plane_basis);
    const std::optional<Eigen::Matrix3d> h = internal::LeastSquaresHomography(plane, scene.pixels);
    if (!h) return;
    std::vector<double> lengths;
    lengths.reserve(plane.size());
    for (size_t i = 0; i < plane.size(); ++i) {
      const Eigen::Vector3d p = *h * plane[i].homogeneous();
      lengths.push_back((p.head<2>() / p.z() - scene.pixels[i]).norm());
    }
    constexpr int kHomographyParameters = 8;
    const ConsistencyCheck check = internal::CheckConsistency(
        lengths, internal::Repeats(points_, pixels_), kHomographyParameters, noise_, options_);
    if (!check.passed) return;
    throw SceneError(
        SceneError::Reason::kInconsistent,
        "the " + std::to_string(left_out_.size()) + " of " + std::to_string(points_.size()) +
            " points the outlier stage leaves out are no outliers: with the rest they fit one "
            "homography of their plane within the noise (rms " + Px(check.rms_px) +
            "), which no camera of the models tried does (" + gated_->selection.fit.model +
            " fits only the others). The points are on a plane, which does not show the "
            "principal point",
        PlanePrincipalPointAdvice(size_, options_));
  }

  // RANSAC's threshold is the widest the noise tolerance allows: re-read the consensus at the
  // noise the inliers show, and select once more if it changed. Also where the gate failed on
  // the consensus: a random pixel that lands within RANSAC's threshold of its point's
  // projection but beyond the gate's bound for the rest (seen: 5.4 px against 4.8 px among 91
  // kept points, 3 of 6000 scenes of FitAutoTest.OutliersAreLeftOutWithoutOptions' kind) is the
  // outlier the gate names. The selection before stays where the new one fails.
  void RereadTheConsensus() {
    const Gated& read = gated_ ? *gated_ : *failed_gate_;
    const std::vector<int> reread =
        internal::OutliersAgainst(read.residuals_px, read.check, noise_, options_);
    // Never a minority of the points (RefuseAMinority).
    if (reread == left_out_ || 2 * reread.size() > points_.size()) return;
    const std::vector<int> before = left_out_;
    std::optional<Gated> kept = std::move(gated_);
    const std::optional<SceneError> kept_refusal = refusal_;
    const std::string kept_problem = problem_;
    left_out_ = reread;
    Select();
    if (!gated_) {
      left_out_ = before;
      gated_ = std::move(kept);
      refusal_ = kept_refusal;
      problem_ = kept_problem;
    }
  }

  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector2d>& pixels_;
  const ImageSize& size_;
  const AutoFitOptions& options_;
  std::vector<std::string> made_names_;  // where options_ names no point (NamesOf)
  const std::vector<std::string>& names_;
  const internal::NoiseReference noise_;
  AutoFitOptions unnamed_;
  std::optional<internal::Screen> screen_;
  std::vector<int> left_out_;
  std::string method_;  // how left_out_ was found
  std::optional<internal::OutlierSearch> search_;
  bool no_outlier_shows_ = false;  // a failed gate's residuals showed no outlier: not searched
  std::optional<Gated> gated_;        // the selection whose gate passed
  std::optional<Gated> failed_gate_;  // the last selection whose gate failed, and why:
  std::string problem_;
  std::optional<SceneError> refusal_;  // the last selection's refusal
};

// A camera whose GL matrices overflow a double (a world scaled by 2^600) could not be written
// or exported (RequireFiniteViews): refused as too large, with the advice to change units.
void RequireRepresentableCamera(const Camera& camera) {
  try {
    RequireFiniteViews(camera);
  } catch (const std::invalid_argument& e) {
    throw internal::TooLargeForDouble(e.what());
  }
}

}  // namespace

void AutoFitOptions::Check() const {
  fit.Check();
  Require(fit.loss == LossType::kNone,
          "automatic model selection compares least-squares fits: use RANSAC for outliers, or "
          "give the model explicitly to use a robust loss");
  Require(max_uncertainty_px > 0.0, "max_uncertainty_px must be positive, got ",
          max_uncertainty_px);
  for (size_t i = 0; i < object_points_in_world.size(); ++i) {
    Require(object_points_in_world[i].allFinite(), "object_points_in_world[", i,
            "] must be finite");
  }
  Require(exhaustive_max_points >= 0 && exhaustive_max_points <= 40,
          "exhaustive_max_points must be in [0, 40], got ", exhaustive_max_points);
  Require(std::isfinite(prior_sigma_px) && prior_sigma_px > 0.0,
          "prior_sigma_px must be positive, got ", prior_sigma_px);
  Require(std::isfinite(prior_weight) && prior_weight >= 0.0,
          "prior_weight must be >= 0, got ", prior_weight);
  Require(significance > 0.0 && significance < 0.5, "significance must be in (0, 0.5), got ",
          significance);
  Require(std::isfinite(noise_tolerance) && noise_tolerance >= 1.0,
          "noise_tolerance must be >= 1, got ", noise_tolerance);
  Require(screen_noise_tolerance >= 1.0 && screen_noise_tolerance <= noise_tolerance,
          "screen_noise_tolerance must be in [1, noise_tolerance = ", noise_tolerance, "], got ",
          screen_noise_tolerance);
  Require(min_redundancy >= 0, "min_redundancy must be >= 0, got ", min_redundancy);
}

FitResult FitCameraAuto(const std::vector<Eigen::Vector3d>& points_in_world,
                        const std::vector<Eigen::Vector2d>& observed_pixels,
                        const ImageSize& image_size, const AutoFitOptions& options) {
  const Clock::time_point start = Clock::now();
  options.Check();
  image_size.Check();
  Require(options.point_names.empty() || options.point_names.size() == points_in_world.size(),
          "got ", options.point_names.size(), " point names for ", points_in_world.size(),
          " points");
  internal::CheckCorrespondences(points_in_world, observed_pixels, options.point_names);
  try {
    FitResult result;
    if (options.fit.z_near || options.fit.z_far) {
      // The given planes are the answer's: the candidates are judged with tight ones (a given
      // plane refused those whose depths it did not hold, and named their depths).
      AutoFitOptions tight = options;
      tight.fit.z_near.reset();
      tight.fit.z_far.reset();
      result = Pipeline(points_in_world, observed_pixels, image_size, tight).Run(start);
      internal::SetGivenDepthRange(options.fit, Kept(points_in_world, result.outliers), &result);
    } else {
      result = Pipeline(points_in_world, observed_pixels, image_size, options).Run(start);
    }
    RequireRepresentableCamera(result.camera);
    return result;
  } catch (const SceneError&) {
    throw;
  } catch (const std::bad_alloc&) {
    // Not a property of the values: the caller says which input was too large.
    throw;
  } catch (const std::exception& e) {
    // Well-formed input never reaches here by design; if it does, it is still a refusal of
    // these values (exit 3), named as what it is.
    throw SceneError(SceneError::Reason::kNumerical,
                     std::string("a numerical failure on these values (") + e.what() + ")",
                     internal::kReportNumericalFailure);
  }
}

}  // namespace camproj

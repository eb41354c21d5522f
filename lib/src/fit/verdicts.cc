#include "fit/verdicts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "camproj/fit_report.h"
#include "camproj/number_text.h"
#include "fit/gate.h"
#include "fit/mirror.h"

namespace camproj {
namespace internal {

namespace {

// A refusal's fix (SceneError::fix): "Add <what>", or with points left out by the outlier stage
// "Fix or drop <them>, left out as disagreeing ...; then add <what>".
std::string LeftOutThenAdd(const std::string& left_out, const std::string& what) {
  return (left_out.empty() ? std::string("Add ")
                           : "Fix or drop " + left_out +
                                 ", left out as disagreeing with the rest by far more than the "
                                 "noise; then add ") +
         what;
}

// A unit direction in the image as "(0.30, 0.95)".
std::string DirectionText(const Eigen::Vector2d& direction) {
  char text[48];
  std::snprintf(text, sizeof text, "(%.2f, %.2f)", direction.x(), direction.y());
  return text;
}

}  // namespace

std::string LeftOutText(const std::vector<Eigen::Vector2d>& residuals,
                        const std::vector<int>& left_out, const std::vector<std::string>& names) {
  std::string text;
  for (const int i : left_out) {
    const double r = residuals[i].norm();
    text += (text.empty() ? "" : ", ") + PointName(names[i]) + " (" +
            (std::isfinite(r) ? Px(r) + " from where the camera puts it"
                              : std::string("behind the camera")) + ")";
  }
  return text;
}

void RefuseIfUndetermined(const DeterminationCheck& check, const std::string& model,
                          const std::string& left_out, PixelOrigin pixel_origin) {
  if (check.passed) return;
  // The advice names the pixel where the camera is least determined (the fix stands alone).
  auto advice = [&](const Eigen::Vector2d& pixel) {
    return LeftOutThenAdd(left_out, "points where the image has none (toward pixel " +
                                        PixelText(pixel, pixel_origin) +
                                        ") and spread in depth, or fix the intrinsics you know "
                                        "(--model, or their values)");
  };
  if (check.rival == kMirroredReadingName && check.rival_shift_px > check.bound_px) {
    throw SceneError(SceneError::Reason::kAmbiguous,
                     "the points fit about as well with one world axis flipped, and the two "
                     "readings put the scene up to " + Px(check.rival_shift_px) +
                         " apart (bound " + Px(check.bound_px) +
                         ", --max-uncertainty): the points cannot tell whether the world frame "
                         "is right- or left-handed",
                     "If it may be left-handed, flip one world axis (e.g. negate Z of every "
                     "point) and refit; otherwise add points spread in depth");
  }
  if (check.max_sigma_px > check.bound_px) {
    throw SceneError(SceneError::Reason::kDegenerate,
                     "the points do not determine the camera well enough: it is " +
                         check.summary + " (--max-uncertainty)",
                     advice(check.worst_pixel));
  }
  if (check.rival_shift_px <= check.bound_px) {
    throw SceneError(
        SceneError::Reason::kAmbiguous,
        "the points cannot tell which model is right well enough: " + model + " and the models "
        "that fit them nearly as well (" + check.averaged_rival + " most), averaged with weights "
        "from their BIC, " +
        (std::isfinite(check.averaged_sigma_px)
             ? "put the scene " + Px(check.averaged_sigma_px) + " apart (1 sigma)"
             : std::string("disagree: one puts a point of the scene behind its camera")) +
        " near pixel " + PixelText(check.averaged_worst_pixel, pixel_origin) +
        " (bound " + Px(check.bound_px) + ", --max-uncertainty)",
        advice(check.averaged_worst_pixel));
  }
  // "both fit about as well, but they put the scene up to 8.88 px apart near pixel (445, 673)
  // (bound 5 px, --max-uncertainty). "
  const std::string parted =
      std::string("both fit about as well") +
      (check.rival_predicts_better
           ? " (and the latter predicts each point from the others better)"
           : "") +
      ", but they put the scene up to " + Px(check.rival_shift_px) + " apart near pixel " +
      PixelText(check.rival_worst_pixel, pixel_origin) + " (bound " +
      Px(check.bound_px) + ", --max-uncertainty)";
  if (check.rival_frees_lens_shift) {
    throw SceneError(
        SceneError::Reason::kAmbiguous,
        "the points cannot tell where the principal point is: " + model +
            " leaves it at the image centre and " + check.rival + " frees it; " + parted +
            ". A few points cannot tell a projector's lens shift from a longer focal length and "
            "a tilt",
        "If the principal point is at the image centre (a camera, or a projector without lens "
        "shift), give --fix principal-point; if you know where it is, --principal-point CX,CY. " +
            advice(check.rival_worst_pixel));
  }
  throw SceneError(SceneError::Reason::kAmbiguous,
                   "the points cannot tell " + model + " from " + check.rival + ": " + parted,
                   advice(check.rival_worst_pixel));
}

void RefuseIfPerspectiveShows(const PerspectiveTest& test, const std::string& left_out) {
  if (!test.observable) return;
  auto g3 = [](double value) { return GeneralDouble(value, 3); };
  throw SceneError(
      SceneError::Reason::kDegenerate,
      "the points show perspective, which the orthographic camera chosen leaves out: freeing "
      "its perspective strength would remove " + g3(test.removed_px2) + " of its " +
          g3(test.sum_squares_px2) + " px^2 squared residuals, " + g3(test.statistic) +
          " times the noise's square (" + Px(test.sigma_px) + " with it free; at most " +
          g3(test.bound) + " where the depth spread is too small against the distance to "
          "show perspective), and no perspective model was determined by them or fitted better",
      LeftOutThenAdd(left_out,
                     "points spread in depth and across the image, or give the intrinsics you "
                     "know (e.g. --principal-point for a projector's lens shift), so that a "
                     "perspective camera can be fitted"));
}

// No edge: within the chosen fit's kLinearityLevel region (its linearity check, fit/assess.cc) a
// point crosses behind the camera, or the sum of squares along some direction never rises to the
// region's level; the determination check propagates sigmas that describe nothing.
void RefuseIfRegionUnbounded(const FitResult& fit, const std::string& left_out) {
  if (!fit.linearity.checked || std::isfinite(fit.linearity.worst_deviation)) return;
  std::string along = fit.linearity.worst_direction;
  for (const ParameterSigma& s : fit.sigmas) {
    if (s.name == along) along = ParameterSigmaText(s);
  }
  const std::string level = GeneralDouble(100.0 * fit.linearity.level, 4);
  throw SceneError(
      SceneError::Reason::kDegenerate,
      "the points do not determine the camera: within its " + level +
          " % confidence region, along " +
          along + ", a camera sees some of them from behind or fits them as well, so how far "
          "it is off beyond them cannot be told",
      LeftOutThenAdd(left_out,
                     "points where the image has none and spread in depth, or give the "
                     "intrinsics you know (--model, or their values)"));
}

PointReliability WordReliability(PointReliability least, const std::vector<int>& left_out,
                                 const std::vector<std::string>& names) {
  // Below this a point's residual keeps under 1 % of a mis-click: say what would check it.
  constexpr double kWeakRedundancy = 0.01;
  // Redundancy at the hat matrix's rounding (its eigenvalues to ~1e-12 of 1): none.
  constexpr double kNoRedundancy = 1e-9;
  if (!least.checked || least.point < 0) return least;
  int kept = -1;
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    if (std::binary_search(left_out.begin(), left_out.end(), i)) continue;
    if (++kept == least.point) {
      least.point = i;
      break;
    }
  }
  const std::string direction = DirectionText(least.direction);
  const std::string kept_percent = GeneralDouble(100.0 * least.redundancy, 2) + " %";
  const std::string name = PointName(names[least.point]);
  least.summary = "least checked: " + name +
                  (least.redundancy < kNoRedundancy
                       ? std::string(", which alone fixes the camera along ") + direction +
                             ": a mis-click of it that way would not show in any residual"
                       : ", whose residual keeps " + kept_percent +
                             " of a mis-click along " + direction);
  if (least.redundancy < kWeakRedundancy) {
    least.summary += "; the other points barely check it: add points (near it), or fix "
                     "intrinsics you know (e.g. --fix principal-point)";
  }
  return least;
}

// The camera then stands on that click alone: right if it is, and nothing could show it is not.
// Measured on the click benchmark's scenes 0-499 (docs/model-selection.md, "A
// click no other point checks"): the three 6-click scenes whose mis-click the fit absorbed
// (53-189 px off) are refused, and 63 of 10135 answers, 38 of them at 6 clicks.
void RefuseIfUnchecked(const PointReliability& least, const std::vector<std::string>& names,
                       const ImageSize& size, double sigma_px, const std::string& left_out) {
  if (!least.checked || least.point < 0) return;
  const double diagonal_px = std::hypot(size.width, size.height);
  if (!(least.redundancy * diagonal_px < sigma_px)) return;
  throw SceneError(SceneError::Reason::kDegenerate,
                   PointName(names[least.point]) + " is checked by no other point" +
                       ": the camera follows it along " + DirectionText(least.direction) +
                       ", and a mis-click of it anywhere in the image would leave less than the "
                       "noise (" + Px(sigma_px) + ") in its residual",
                   LeftOutThenAdd(left_out, "a point near " + PointName(names[least.point]) +
                                                ", or fix intrinsics you know (e.g. --fix "
                                                "principal-point)"));
}

}  // namespace internal
}  // namespace camproj

// Human- and file-facing reports of a fit: the camera file's `fit` record, a short summary, and
// the per-iteration error-against-time table.
#ifndef CAMPROJ_FIT_REPORT_H_
#define CAMPROJ_FIT_REPORT_H_

#include <string>
#include <vector>

#include "camproj/camera_file.h"
#include "camproj/fit.h"

namespace camproj {

FitRecord FitRecordOf(const FitResult& fit);

// FitResult::linearity in words: "the sigmas hold (...)" or what the curvature means and what to
// do about it.
std::string LinearityText(const LinearityCheck& check);

// One parameter with its sigma as the summary writes it: "fx = 2653 +- 628 px", enough digits
// to show the sigma's second; "eye_x = 13.5 +- 3.1 (world units)".
std::string ParameterSigmaText(const ParameterSigma& parameter);

// A few lines: the model (free and fixed parameters and why), each parameter +- sigma in its
// unit, fovy in degrees, eye and look-at, RMS / median / max residual, the linearity check, the
// `worst` largest residuals by id (ids[i] names point i; numbers from 1 when empty), and the fit
// time. cx, cy and pixels in fit.pixel_origin, the input's convention.
std::string FitSummaryText(const FitResult& fit, const std::vector<std::string>& ids,
                           int worst = 5);

// The trace as a table: iteration, elapsed microseconds, RMS px.
std::string FitTraceText(const FitResult& fit);

}  // namespace camproj

#endif  // CAMPROJ_FIT_REPORT_H_

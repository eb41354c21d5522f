// Plots of a fit, drawn by camproj itself (no Python at run time): `camproj fit --report
// report.svg` (or .html: the same plots with the summary text beside them).
//   1. the residual of each point (bars coloured on viridis, the fit's outliers in vermillion,
//      those beyond the axis cut and labelled with their length), with the RMS marked;
//   2. the residuals over the image: an arrow from each observed pixel, magnified so that the
//      largest kept one is 15 % of the image's smaller side (the factor is printed);
//   3. the model-selection ladder: each model tried, its criterion (AIC or BIC) and RMS, the
//      chosen one marked, the refused ones with their reason.
// Pixels in kCenter (docs/conventions.md).
#ifndef CAMPROJ_FIT_PLOTS_H_
#define CAMPROJ_FIT_PLOTS_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"

namespace camproj {

// `observed_pixels` (kCenter) and `ids` are the fitted points, in the order of
// fit.residuals_px. Throws std::invalid_argument when their sizes differ from it.
std::string FitReportSvg(const FitResult& fit, const std::vector<Eigen::Vector2d>& observed_pixels,
                         const std::vector<std::string>& ids);

// An HTML page holding FitReportSvg and `summary_text` (FitSummaryText), self-contained.
std::string FitReportHtml(const FitResult& fit, const std::vector<Eigen::Vector2d>& observed_pixels,
                          const std::vector<std::string>& ids, const std::string& summary_text,
                          const std::string& title);

// "svg" or "html" by the extension of `path` (.svg, .html, .htm; any case); throws
// std::invalid_argument naming the path otherwise.
std::string FitReportFormatOfPath(const std::string& path);

}  // namespace camproj

#endif  // CAMPROJ_FIT_PLOTS_H_

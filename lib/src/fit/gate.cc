#include "fit/gate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fit/statistics.h"

namespace camproj {
namespace internal {

std::string Px(double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3g px", value);
  return buffer;
}

std::string NoiseReference::Source() const {
  return given ? "given" : "assumed: the default for clicked points; set it with --sigma";
}

NoiseReference NoiseReferenceOf(const AutoFitOptions& options) {
  NoiseReference noise;
  noise.given = options.fit.pixel_sigma.has_value();
  noise.sigma_px = options.fit.pixel_sigma.value_or(options.prior_sigma_px);
  return noise;
}

ConsistencyCheck CheckConsistency(const std::vector<double>& residual_lengths_px, int num_params,
                                  const NoiseReference& noise, const AutoFitOptions& options) {
  ConsistencyCheck check;
  check.checked = true;
  check.noise_px = noise.sigma_px;
  check.noise_source = noise.Source();
  check.significance = options.significance;
  const int n = static_cast<int>(residual_lengths_px.size());
  double sum_squares = 0.0;
  for (const double r : residual_lengths_px) {
    sum_squares += r * r;
    check.max_residual_px = std::max(check.max_residual_px, r);
  }
  check.rms_px = n > 0 ? std::sqrt(sum_squares / n) : 0.0;
  const int dof = 2 * n - num_params;
  if (dof <= 0) {
    check.passed = std::isfinite(sum_squares);
    check.summary = "not tested: as many unknowns as equations (add points to check the fit)";
    return check;
  }
  check.noise_estimate_px = std::sqrt(sum_squares / dof);
  const double tolerance = options.noise_tolerance * noise.sigma_px;
  const double chi2_bound = ChiSquareQuantile(dof, 1.0 - options.significance);
  check.noise_bound_px = tolerance * std::sqrt(chi2_bound / dof);
  check.robust_noise_px =
      Median(residual_lengths_px) / kRayleighMedian * std::sqrt(2.0 * n / dof);
  check.max_residual_bound_px = MaxResidualBound(n, options.significance) *
                                std::max(check.robust_noise_px, noise.sigma_px);
  const bool noise_ok = check.noise_estimate_px <= check.noise_bound_px;
  const bool max_ok = check.max_residual_px <= check.max_residual_bound_px;
  check.passed = noise_ok && max_ok;
  char alpha[32];
  std::snprintf(alpha, sizeof alpha, "%g %%", 100.0 * options.significance);
  if (check.passed) {
    check.summary = "consistent with " + Px(noise.sigma_px) + " pixel noise (" +
                    (noise.given ? "given" : "assumed") + "): noise estimate " +
                    Px(check.noise_estimate_px) + " (at most " + Px(check.noise_bound_px) +
                    "), largest residual " + Px(check.max_residual_px) + " (at most " +
                    Px(check.max_residual_bound_px) + "), tests at " + alpha;
  } else if (!noise_ok) {
    check.summary = "the residuals (noise estimate " + Px(check.noise_estimate_px) +
                    ") are larger than " + Px(noise.sigma_px) + " pixel noise (" +
                    (noise.given ? "given" : "assumed") + ") allows (at most " +
                    Px(check.noise_bound_px) + " at " + alpha + ")";
  } else {
    check.summary = "one point is far from the rest: largest residual " +
                    Px(check.max_residual_px) + ", at most " + Px(check.max_residual_bound_px) +
                    " for the others' noise (" + Px(check.robust_noise_px) + ") at " + alpha;
  }
  return check;
}

}  // namespace internal
}  // namespace camproj

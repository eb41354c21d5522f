#include "fit/gate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>

#include "camproj/number_text.h"
#include "fit/statistics.h"

namespace camproj {
namespace internal {

std::string Px(double value) { return GeneralDouble(value, 3) + " px"; }

std::string PixelText(const Eigen::Vector2d& pixel_center, PixelOrigin origin) {
  const Eigen::Vector2d u = ConvertPixelOrigin(pixel_center, PixelOrigin::kCenter, origin);
  return "(" + std::to_string(static_cast<long>(std::lround(u.x()))) + ", " +
         std::to_string(static_cast<long>(std::lround(u.y()))) + ")";
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

std::vector<bool> Repeats(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& pixels) {
  // A point repeats one of lower index with the same five coordinates. Sorted by x alone (one
  // comparison of doubles, not of five-tuples: at 100 points the tuples' sort was ~1 % of the
  // default path, which tests every fit it gates), then compared in full within each run of
  // equal x, where copies meet; the runs of distinct points are one long.
  std::vector<int> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return points[a].x() < points[b].x() || (points[a].x() == points[b].x() && a < b);
  });
  auto same = [&](int a, int b) { return points[a] == points[b] && pixels[a] == pixels[b]; };
  std::vector<bool> repeats(points.size(), false);
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin + 1;
    while (end < order.size() && points[order[end]].x() == points[order[begin]].x()) ++end;
    // In index order within the run: each point against the earlier ones.
    for (size_t k = begin + 1; k < end; ++k) {
      for (size_t j = begin; j < k && !repeats[order[k]]; ++j) {
        repeats[order[k]] = same(order[k], order[j]);
      }
    }
    begin = end;
  }
  return repeats;
}

ConsistencyCheck CheckConsistency(const std::vector<double>& residual_lengths_px,
                                  const std::vector<bool>& repeats, int num_params,
                                  const NoiseReference& noise, const AutoFitOptions& options) {
  ConsistencyCheck check;
  check.checked = true;
  check.noise_px = noise.sigma_px;
  check.noise_source = noise.Source();
  check.significance = options.significance;
  double sum_squares_all = 0.0;
  std::vector<double> observed;  // one residual per observation
  for (size_t i = 0; i < residual_lengths_px.size(); ++i) {
    const double r = residual_lengths_px[i];
    sum_squares_all += r * r;
    check.max_residual_px = std::max(check.max_residual_px, r);
    if (repeats.empty() || !repeats[i]) observed.push_back(r);
  }
  if (!residual_lengths_px.empty()) {
    check.rms_px = std::sqrt(sum_squares_all / static_cast<double>(residual_lengths_px.size()));
  }
  const int n = static_cast<int>(observed.size());
  check.observations = n;
  double sum_squares = 0.0;
  for (const double r : observed) sum_squares += r * r;
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
  check.robust_noise_px = Median(observed) / kRayleighMedian * std::sqrt(2.0 * n / dof);
  check.max_residual_bound_px = MaxResidualBound(n, options.significance) *
                                std::max(check.robust_noise_px, noise.sigma_px);
  const bool noise_ok = check.noise_estimate_px <= check.noise_bound_px;
  const bool max_ok = check.max_residual_px <= check.max_residual_bound_px;
  check.passed = noise_ok && max_ok;
  const std::string alpha = GeneralDouble(100.0 * options.significance, 6) + " %";
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

namespace {

// z_{1 - alpha}, the standard normal's upper quantile.
double NormalUpperQuantile(double alpha) {
  return std::sqrt(ChiSquareQuantile(1.0, 1.0 - 2.0 * alpha));
}

// N times the variance of the log of the median-based noise estimate, for Gaussian residuals
// per axis (|r| Rayleigh): 1 / (4 (f(m) m)^2) with f(m) m = ln 2 at the median m.
double MedianLogVarianceTimesN() {
  const double ln2 = std::log(2.0);
  return 0.25 / (ln2 * ln2);
}

}  // namespace

bool RobustNoiseBeyondTheBound(const ConsistencyCheck& check, const AutoFitOptions& options) {
  if (!check.checked || check.observations < 1) return false;
  const double margin = std::exp(NormalUpperQuantile(options.significance) *
                                 std::sqrt(MedianLogVarianceTimesN() / check.observations));
  return check.robust_noise_px > margin * check.noise_bound_px;
}

bool ShowsOutliers(const ConsistencyCheck& check, const AutoFitOptions& options) {
  // The variance of log(noise estimate / robust noise) times N for Gaussian residuals per axis
  // (|r| Rayleigh): 1/4 for the log of the RMS, ln(2)^-2 / 4 = 0.520 for the log of the median
  // (its density f(m) m = ln 2 at the median m), covariance 1/4 (Bahadur's representation of
  // the median; E[r^2; r <= m] = (1 - ln 2) sigma^2): 0.25 + 0.520 - 0.5. Simulated: 0.27 at
  // 100-3000 observations, 0.24-0.26 at 13-30.
  const double kNoiseRatioLogVariance = 0.25 + MedianLogVarianceTimesN() - 0.5;
  if (!(check.max_residual_px <= check.max_residual_bound_px)) return true;
  if (!(check.robust_noise_px > 0.0) || check.observations < 1) return true;
  const double bound = std::exp(NormalUpperQuantile(options.significance) *
                                std::sqrt(kNoiseRatioLogVariance / check.observations));
  return !(check.noise_estimate_px <= bound * check.robust_noise_px);
}

}  // namespace internal
}  // namespace camproj

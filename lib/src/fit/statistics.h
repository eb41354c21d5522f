// Distribution functions the fitter's tests need (private): the chi-square quantile for the
// consistency gate and the Rayleigh median for the robust noise estimate.
#ifndef CAMPROJ_SRC_FIT_STATISTICS_H_
#define CAMPROJ_SRC_FIT_STATISTICS_H_

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace camproj {
namespace internal {

// P(a, x), the regularized lower incomplete gamma function, a > 0, x >= 0: the series for
// x < a + 1, else the continued fraction of Q = 1 - P (modified Lentz); Numerical Recipes 6.2.
// Both converge to double precision within a few hundred terms for the a, x the gate uses.
inline double RegularizedLowerGamma(double a, double x) {
  if (!(x > 0.0)) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  constexpr double kEpsilon = 1e-15;
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * kEpsilon) break;
    }
    return std::min(1.0, sum * std::exp(log_prefactor));
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEpsilon) break;
  }
  return std::max(0.0, 1.0 - std::exp(log_prefactor) * h);
}

// The p-quantile of the chi-square distribution with nu > 0 degrees of freedom, 0 < p < 1, by
// bisection on its CDF P(nu / 2, x / 2) to 1e-12 relative.
inline double BisectChiSquareQuantile(double nu, double p) {
  double lo = 0.0;
  double hi = std::max(1.0, nu);
  while (RegularizedLowerGamma(0.5 * nu, 0.5 * hi) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (RegularizedLowerGamma(0.5 * nu, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// BisectChiSquareQuantile, remembered: one fit of the default path asks for the same few
// quantiles (the gates' at 2N - p degrees of freedom, the linearity level's at p) several times,
// and each bisection costs about 40 evaluations of the CDF (~30 thousand instructions at 8
// points). The last kRemembered (nu, p) of each thread are kept.
inline double ChiSquareQuantile(double nu, double p) {
  struct Remembered {
    double nu = 0.0;
    double p = 0.0;
    double quantile = 0.0;  // 0: empty (every quantile for p > 0 is positive)
  };
  constexpr size_t kRemembered = 8;
  thread_local Remembered remembered[kRemembered];
  thread_local size_t next = 0;
  for (const Remembered& r : remembered) {
    if (r.quantile > 0.0 && r.nu == nu && r.p == p) return r.quantile;
  }
  const double quantile = BisectChiSquareQuantile(nu, p);
  remembered[next] = {nu, p, quantile};
  next = (next + 1) % kRemembered;
  return quantile;
}

// The largest of N residual lengths |r| of a 2D Gaussian with sigma 1 per axis exceeds
// sqrt(2 ln(N / alpha)) with probability at most alpha (P(|r| > t) = exp(-t^2 / 2), union bound).
inline double MaxResidualBound(int num_points, double alpha) {
  return std::sqrt(2.0 * std::log(std::max(1, num_points) / alpha));
}

// P(X >= k) for X ~ Binomial(n, p), summed term by term in log space (n up to millions: the
// terms fall off geometrically beyond the mean, and the sum stops when they no longer count).
inline double BinomialTailAtLeast(int n, double p, int k) {
  if (k <= 0) return 1.0;
  if (k > n || p <= 0.0) return 0.0;
  if (p >= 1.0) return 1.0;
  double tail = 0.0;
  for (int j = k; j <= n; ++j) {
    const double term = std::exp(std::lgamma(n + 1.0) - std::lgamma(j + 1.0) -
                                 std::lgamma(n - j + 1.0) + j * std::log(p) +
                                 (n - j) * std::log1p(-p));
    tail += term;
    if (j > n * p && term < 1e-17 * tail) break;
  }
  return std::min(1.0, tail);
}

// The median of |r| for a 2D Gaussian with sigma 1 per axis (Rayleigh): sqrt(2 ln 2).
inline constexpr double kRayleighMedian = 1.1774100225154747;

inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double median = values[mid];
  if (values.size() % 2 == 0) {
    median = 0.5 * (median + *std::max_element(values.begin(), values.begin() + mid));
  }
  return median;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_STATISTICS_H_

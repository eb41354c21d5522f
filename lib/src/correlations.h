// Strongly correlated parameter pairs of a covariance (private; both fitters report them).
#ifndef CAMPROJ_SRC_CORRELATIONS_H_
#define CAMPROJ_SRC_CORRELATIONS_H_

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camproj/fit.h"

namespace camproj {
namespace internal {

// Every pair (a < b) whose |correlation| is at least `threshold`, named by `names` (the
// covariance's order).
inline std::vector<Correlation> StrongCorrelations(const Eigen::MatrixXd& covariance,
                                                   const std::vector<std::string>& names,
                                                   double threshold) {
  std::vector<Correlation> strong;
  for (int a = 0; a < covariance.rows(); ++a) {
    for (int b = a + 1; b < covariance.rows(); ++b) {
      const double rho = covariance(a, b) / std::sqrt(covariance(a, a) * covariance(b, b));
      if (std::abs(rho) >= threshold) strong.push_back({names[a], names[b], rho});
    }
  }
  return strong;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_CORRELATIONS_H_

// Solving the fitters' small symmetric systems (private): normal equations of at most
// kMaxParams parameters, factored once and solved for one or more right-hand sides. At these
// sizes Eigen's pivoted LDL^T spends most of its instructions in its general kernels (a
// matrix-vector product per column); a plain Cholesky on the fixed-capacity storage does the
// same n^3 / 6 multiply-adds without them (docs/bench/stage_cost.md).
//
// A positive definite system (LM's damped normal equations; a determined fit's J^T J) factors
// by Cholesky. One whose Cholesky meets a pivot that is not positive and finite -- semidefinite
// or indefinite to rounding: an undetermined direction -- is factored by Eigen's pivoted LDL^T
// instead, as every such system was before, so that those cases keep their answers.
#ifndef CAMPROJ_SRC_FIT_SMALL_SOLVE_H_
#define CAMPROJ_SRC_FIT_SMALL_SOLVE_H_

#include <cmath>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "fit/normal_equations.h"

namespace camproj {
namespace internal {

// a = L L^T for a symmetric `a` (only its lower triangle is read), column by column: L(j, j) =
// sqrt(a(j, j) - sum_k<j L(j, k)^2), L(i, j) for i > j by the same sums over row i; only L's
// lower triangle is written. False at the first pivot that is not positive and finite.
template <typename Matrix>
bool FactorCholesky(const Matrix& a, Matrix* l) {
  const int n = static_cast<int>(a.rows());
  l->resize(n, n);
  for (int j = 0; j < n; ++j) {
    double pivot = a(j, j);
    for (int k = 0; k < j; ++k) pivot -= (*l)(j, k) * (*l)(j, k);
    if (!(pivot > 0.0 && std::isfinite(pivot))) return false;
    const double diagonal = std::sqrt(pivot);
    (*l)(j, j) = diagonal;
    for (int i = j + 1; i < n; ++i) {
      double sum = a(i, j);
      for (int k = 0; k < j; ++k) sum -= (*l)(i, k) * (*l)(j, k);
      (*l)(i, j) = sum / diagonal;
    }
  }
  return true;
}

namespace small_solve_detail {

// FactorCholesky on n x n column-major storage with n = N known to the compiler, which unrolls the
// loops: the same multiply-adds in the same order (so the same bits), without the loop and index
// overhead that dominates at these sizes (a 10 x 10 factorization: 1.6 k instructions generic).
template <int N>
bool FactorCholeskyOfSize(const double* a, double* l) {
#pragma GCC unroll 16
  for (int j = 0; j < N; ++j) {
    double pivot = a[j + j * N];
#pragma GCC unroll 16
    for (int k = 0; k < j; ++k) pivot -= l[j + k * N] * l[j + k * N];
    if (!(pivot > 0.0 && std::isfinite(pivot))) return false;
    const double diagonal = std::sqrt(pivot);
    l[j + j * N] = diagonal;
#pragma GCC unroll 16
    for (int i = j + 1; i < N; ++i) {
      double sum = a[i + j * N];
#pragma GCC unroll 16
      for (int k = 0; k < j; ++k) sum -= l[i + k * N] * l[j + k * N];
      l[i + j * N] = sum / diagonal;
    }
  }
  return true;
}

template <int... Sizes>
bool FactorCholeskyDispatch(int n, const double* a, double* l,
                            std::integer_sequence<int, Sizes...>) {
  bool factored = false;
  // The one size that matches runs; a fold over the sizes (C++17).
  (void)((n == Sizes + 1 && ((factored = FactorCholeskyOfSize<Sizes + 1>(a, l)), true)) || ...);
  return factored;
}

}  // namespace small_solve_detail

// FactorCholesky for the fitters' run-time-sized matrices (at most kMaxParams): dispatched to
// the size's unrolled factorization. The same result as the generic one above, bit for bit.
inline bool FactorCholesky(const ParamMatrix& a, ParamMatrix* l) {
  const int n = static_cast<int>(a.rows());
  l->resize(n, n);
  if (n == 0) return true;
  return small_solve_detail::FactorCholeskyDispatch(n, a.data(), l->data(),
                                                    std::make_integer_sequence<int, kMaxParams>());
}

class SymmetricSolver {
 public:
  // Factors `a` (square, symmetric: only its lower triangle is read by the Cholesky).
  explicit SymmetricSolver(const ParamMatrix& a) : n_(static_cast<int>(a.rows())) {
    if (!FactorCholesky(a, &l_)) {
      cholesky_ = false;
      ldlt_.compute(a);
    }
  }

  // a^-1 b.
  ParamVector Solve(const ParamVector& b) const {
    if (!cholesky_) return ldlt_.solve(b);
    ParamVector x = b;
    for (int i = 0; i < n_; ++i) {  // L y = b
      double sum = x(i);
      for (int k = 0; k < i; ++k) sum -= l_(i, k) * x(k);
      x(i) = sum / l_(i, i);
    }
    for (int i = n_ - 1; i >= 0; --i) {  // L^T x = y
      double sum = x(i);
      for (int k = i + 1; k < n_; ++k) sum -= l_(k, i) * x(k);
      x(i) = sum / l_(i, i);
    }
    return x;
  }

 private:
  int n_ = 0;
  bool cholesky_ = true;
  ParamMatrix l_;  // lower triangle: the Cholesky factor
  Eigen::LDLT<ParamMatrix> ldlt_;
};

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_FIT_SMALL_SOLVE_H_

// Private helpers for argument checks: messages that name the offending value.
#ifndef CAMPROJ_SRC_CHECK_H_
#define CAMPROJ_SRC_CHECK_H_

#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <Eigen/Core>

#include "camproj/number_text.h"

namespace camproj {
namespace internal {

// A value as a message shows it: a double (or float) in its shortest form that reads back to
// the same value (-0.15, not max_digits10's -0.14999999999999999); an Eigen vector or matrix
// entry by entry, one space apart, rows separated by "; " (Eigen's own << pads every entry to
// the widest, "(1e-07                      0                      1)").
template <typename T>
void AppendToMessage(std::ostringstream& out, const T& value) {
  if constexpr (std::is_same_v<T, double>) {
    out << ShortestDouble(value);
  } else if constexpr (std::is_same_v<T, float>) {
    char text[16];  // any float's shortest form
    out.write(text, std::to_chars(text, text + sizeof(text), value).ptr - text);
  } else if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
    for (Eigen::Index i = 0; i < value.rows(); ++i) {
      if (i > 0) out << "; ";
      for (Eigen::Index j = 0; j < value.cols(); ++j) {
        if (j > 0) out << ' ';
        out << ShortestDouble(static_cast<double>(value(i, j)));
      }
    }
  } else {
    out << value;
  }
}

template <typename... Args>
std::string Concat(const Args&... args) {
  std::ostringstream out;
  (AppendToMessage(out, args), ...);
  return out.str();
}

// Require's throw, out of line: Require itself then inlines to one test, which matters where
// every projection checks its inputs (PixelFromCam, CamRayFromPixel).
template <typename... Args>
[[noreturn, gnu::cold, gnu::noinline]] void ThrowInvalidArgument(const Args&... message) {
  throw std::invalid_argument(Concat(message...));
}

// Throws std::invalid_argument with the concatenated message unless `condition`.
template <typename... Args>
void Require(bool condition, const Args&... message) {
  if (!condition) ThrowInvalidArgument(message...);
}

// Throws unless `value` is finite; the message names it: "<name> must be finite, got nan".
inline void RequireFinite(double value, const char* name) {
  Require(std::isfinite(value), name, " must be finite, got ", value);
}

template <typename Derived>
void RequireFiniteAll(const Derived& m, const char* name) {
  for (int i = 0; i < m.size(); ++i) {
    Require(std::isfinite(m.data()[i]), name, " must be finite, got ", m.data()[i],
            " at index ", i);
  }
}

// Throws unless every entry of a computed result is finite: arguments that pass their own checks
// can still give a result beyond a double (a frustum with near 1e308 and a width of 1e-300). The
// message is `what`, then the first entry that is not finite.
template <typename Derived, typename... Args>
void RequireFiniteResult(const Derived& m, const Args&... what) {
  for (int i = 0; i < m.size(); ++i) {
    if (!std::isfinite(m.data()[i])) {
      ThrowInvalidArgument(what..., " cannot be represented in a double (", m.data()[i],
                           " at index ", i, ")");
    }
  }
}

// `result` after its own Check(), whose message is prefixed by `what`: a conversion whose
// arguments are valid can still produce a value its type refuses (an intrinsics' fx that
// underflows to 0, a frustum plane that overflows).
template <typename Result, typename... Args>
const Result& CheckedResult(const Result& result, const Args&... what) {
  try {
    result.Check();
  } catch (const std::invalid_argument& error) {
    ThrowInvalidArgument(what..., " cannot be represented (", error.what(), ")");
  }
  return result;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_CHECK_H_

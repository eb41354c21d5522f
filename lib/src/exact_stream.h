// Private: the stream the exports and their notes write doubles with.
#ifndef CAMPROJ_SRC_EXACT_STREAM_H_
#define CAMPROJ_SRC_EXACT_STREAM_H_

#include <iomanip>
#include <limits>
#include <sstream>

namespace camproj {
namespace internal {

// A stream that prints doubles at max_digits10, so that they read back bit for bit (the exports'
// numbers; messages use check.h's shortest form instead).
inline std::ostringstream ExactStream() {
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  return out;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_EXACT_STREAM_H_

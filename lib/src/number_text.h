// Private: numbers in messages, as printf writes them, without printf's cost.
#ifndef CAMPROJ_SRC_NUMBER_TEXT_H_
#define CAMPROJ_SRC_NUMBER_TEXT_H_

#include <charconv>
#include <string>

namespace camproj {
namespace internal {

// printf's "%.<digits>g" of `value` in the "C" locale (std::to_chars with a precision is
// specified as that conversion, [charconv.to.chars]), at a fraction of snprintf's ~1500
// instructions: the default path words its gate and criterion lines on every fit it scores.
inline std::string GeneralText(double value, int digits) {
  char text[64];
  const char* end =
      std::to_chars(text, text + sizeof text, value, std::chars_format::general, digits).ptr;
  return std::string(static_cast<const char*>(text), end);
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_NUMBER_TEXT_H_

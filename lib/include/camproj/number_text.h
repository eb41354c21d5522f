// Numbers as text: that reads back exactly, or as printf's %g writes it.
#ifndef CAMPROJ_NUMBER_TEXT_H_
#define CAMPROJ_NUMBER_TEXT_H_

#include <charconv>
#include <limits>
#include <string>

namespace camproj {

// The shortest decimal text that strtod reads back to the same double (std::to_chars), e.g.
// "0.1", "1e+300", "-0"; "inf" and "nan" for those.
inline std::string ShortestDouble(double value) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  (void)error;  // 32 bytes hold any double's shortest form
  return std::string(buffer, end);
}

// printf's "%.<significant_digits>g" of `value` in the "C" locale, e.g. "0.483", "1e+03" at 3
// digits (std::to_chars with a precision is specified as that conversion,
// [charconv.to.chars]), at a fraction of snprintf's cost (~1500 instructions a call, where the
// default path words the gate's and the criterion's lines of every fit it scores).
// significant_digits: 1-17.
inline std::string GeneralDouble(double value, int significant_digits) {
  char buffer[64];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value,
                                          std::chars_format::general, significant_digits);
  (void)error;  // 64 bytes hold 17 digits, the sign, the point and the exponent
  return std::string(buffer, end);
}

// GeneralDouble of a non-negative bound, or "more than 1.8e+308" for +infinity: a bound beyond a
// double (the float32 error of a camera float32 cannot hold at all) said in words, not "inf".
inline std::string GeneralBound(double value, int significant_digits) {
  if (value == std::numeric_limits<double>::infinity()) {
    return "more than " + GeneralDouble(std::numeric_limits<double>::max(), 2);
  }
  return GeneralDouble(value, significant_digits);
}

}  // namespace camproj

#endif  // CAMPROJ_NUMBER_TEXT_H_

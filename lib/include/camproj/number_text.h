// Numbers as text that reads back exactly.
#ifndef CAMPROJ_NUMBER_TEXT_H_
#define CAMPROJ_NUMBER_TEXT_H_

#include <charconv>
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

}  // namespace camproj

#endif  // CAMPROJ_NUMBER_TEXT_H_

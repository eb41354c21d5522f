// The exceptions camproj throws, by who must act (see docs/conventions.md, "Errors"):
//   std::invalid_argument  a bad argument to a library function (names the value).
//   InputError             a malformed input file (names the file, line, column or field).
//   SceneError             the data cannot determine the requested camera (a refusal: says
//                          why and what to change). Declared with the fitter.
// The library never aborts; the command line maps these to documented exit codes.
#ifndef CAMPROJ_ERRORS_H_
#define CAMPROJ_ERRORS_H_

#include <stdexcept>
#include <string>

namespace camproj {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace camproj

#endif  // CAMPROJ_ERRORS_H_

// Small helpers the drawn outputs share (private): the overlay PNG (overlay.cc), the fit report's
// SVG (fit_plots.cc) and the view page (view.cc).
#ifndef CAMPROJ_SRC_DRAWING_H_
#define CAMPROJ_SRC_DRAWING_H_

#include <cmath>
#include <string>

namespace camproj {
namespace internal {

// `text` for HTML or SVG text and attribute values: & < > " as entities, other control
// characters but newline and tab as '?'.
inline std::string MarkupEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default:
        out += (static_cast<unsigned char>(c) < 32 && c != '\n' && c != '\t') ? '?' : c;
    }
  }
  return out;
}

// 1, 2 or 5 times a power of ten, at most `x`, at least 1: a magnification a legend can state.
inline double NiceFloor(double x) {
  if (!(x > 1.0)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * decade <= x) return m * decade;
  }
  return decade;
}

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_DRAWING_H_

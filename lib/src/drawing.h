// Small helpers the drawn outputs share (private): the overlay PNG (overlay.cc), the fit report's
// SVG (fit_plots.cc) and the view page (view.cc).
#ifndef CAMPROJ_SRC_DRAWING_H_
#define CAMPROJ_SRC_DRAWING_H_

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Core>

namespace camproj {
namespace internal {

// The length of the UTF-8 character (RFC 3629: shortest form, no surrogates, at most U+10FFFF)
// that begins at text[i], or 0 where none does (a stray continuation byte, a cut or overlong
// sequence, or another encoding's byte: "S\xFCd", Latin-1 as spreadsheets write it).
inline size_t Utf8CharLength(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the second byte's range
  if (c >= 0xC2 && c <= 0xDF) {
    length = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    length = 3;
    if (c == 0xE0) low = 0xA0;
    if (c == 0xED) high = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    length = 4;
    if (c == 0xF0) low = 0x90;
    if (c == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  if (byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (size_t k = 2; k < length; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return length;
}

// At most `max_chars` characters of `text` from its start, cut between characters (a byte
// count cut "s\xC3\xBC" in the middle of its u-umlaut, and the SVG holding it was not XML).
inline std::string Utf8Prefix(const std::string& text, size_t max_chars) {
  size_t end = 0;
  for (size_t chars = 0; end < text.size() && chars < max_chars; ++chars) {
    end += std::max<size_t>(1, Utf8CharLength(text, end));
  }
  return text.substr(0, end);
}

// `text` for HTML or SVG text and attribute values: & < > " as entities, other control
// characters but newline and tab as '?', and each byte that begins no UTF-8 character as U+FFFD
// (XML admits no malformed UTF-8: a browser shows nothing after it).
inline std::string MarkupEscape(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const size_t length = Utf8CharLength(text, i);
    if (length == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
      continue;
    }
    if (length > 1) {
      out.append(text, i, length);
      i += length;
      continue;
    }
    const char c = text[i++];
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

// An arrow `length` long inside a w x h image's border, pointing at `target` (outside the image,
// kCenter px): its tail and tip. The tip is `length` from the border, or at the image's middle
// where it is smaller than twice that.
inline std::pair<Eigen::Vector2d, Eigen::Vector2d> BorderArrow(const Eigen::Vector2d& target,
                                                               int w, int h, double length) {
  // At most half the image: std::clamp's bounds must not cross (below 2 x length + 1 px they did).
  const double margin_x = std::min(length, 0.5 * (w - 1));
  const double margin_y = std::min(length, 0.5 * (h - 1));
  const Eigen::Vector2d tip(std::clamp(target.x(), margin_x, w - 1 - margin_x),
                            std::clamp(target.y(), margin_y, h - 1 - margin_y));
  const Eigen::Vector2d direction = (target - tip).normalized();
  return {tip - length * direction, tip};
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

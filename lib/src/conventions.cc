#include "camproj/conventions.h"

#include "check.h"

namespace camproj {

using internal::Require;

void ImageSize::Check() const {
  Require(width > 0 && height > 0, "image size must be positive, got ", width, "x", height);
  Require(width <= kMaxImageSide && height <= kMaxImageSide, "image size must be at most ",
          kMaxImageSide, " px per side, got ", width, "x", height);
}

Eigen::Matrix3d GlEyeFromCam() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }

double PixelOriginShift(PixelOrigin from, PixelOrigin to) {
  if (from == to) return 0.0;
  return to == PixelOrigin::kCorner ? 0.5 : -0.5;
}

Eigen::Vector2d ConvertPixelOrigin(const Eigen::Vector2d& pixel, PixelOrigin from,
                                   PixelOrigin to) {
  const double shift = PixelOriginShift(from, to);
  return pixel + Eigen::Vector2d(shift, shift);
}

Eigen::Vector2d WindowFromPixel(const Eigen::Vector2d& pixel, const ImageSize& size,
                                PixelOrigin origin) {
  size.Check();
  // In the corner convention the pixel grid and the window grid share their corners.
  const Eigen::Vector2d corner = ConvertPixelOrigin(pixel, origin, PixelOrigin::kCorner);
  return {corner.x(), size.height - corner.y()};
}

Eigen::Vector2d PixelFromWindow(const Eigen::Vector2d& window, const ImageSize& size,
                                PixelOrigin origin) {
  size.Check();
  const Eigen::Vector2d corner(window.x(), size.height - window.y());
  return ConvertPixelOrigin(corner, PixelOrigin::kCorner, origin);
}

const char* ToString(PixelOrigin origin) {
  return origin == PixelOrigin::kCenter ? "center" : "corner";
}

const char* ToString(ClipDepth depth) {
  return depth == ClipDepth::kNegativeOneToOne ? "no" : "zo";
}

PixelOrigin PixelOriginFromString(const std::string& text) {
  if (text == "center") return PixelOrigin::kCenter;
  if (text == "corner") return PixelOrigin::kCorner;
  throw std::invalid_argument("pixel origin must be \"center\" or \"corner\", got \"" + text + "\"");
}

ClipDepth ClipDepthFromString(const std::string& text) {
  if (text == "no") return ClipDepth::kNegativeOneToOne;
  if (text == "zo") return ClipDepth::kZeroToOne;
  throw std::invalid_argument("clip depth must be \"no\" ([-1,1]) or \"zo\" ([0,1]), got \"" + text +
                              "\"");
}

}  // namespace camproj

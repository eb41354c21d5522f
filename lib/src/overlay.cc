#include "camproj/overlay.h"

#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/image_header.h"
#include "check.h"

namespace camproj {

namespace {

// OpenCV draws with integer coordinates in 1/16 px (shift = 4); its pixel centres are at integers,
// as in kCenter.
constexpr int kShift = 4;
cv::Point Fixed(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * 16.0)), static_cast<int>(std::lround(p.y() * 16.0))};
}

}  // namespace

void OverlayOptions::Check() const {
  internal::Require(std::isfinite(magnify) && magnify > 0.0, "magnify must be positive, got ",
                    magnify);
}

namespace {

// A PNG or JPEG of kMaxImagePixels is far smaller than this; a bigger file is not a photo.
constexpr size_t kMaxImageFileBytes = size_t{256} << 20;

// The background, decoded only after its header states the camera's size (for a JPEG, either
// way round: OpenCV turns it by its EXIF orientation while decoding).
cv::Mat ReadBackground(const std::string& path, int w, int h) {
  const std::string bytes = ReadWholeFile(path, kMaxImageFileBytes);
  const ImageHeader header = ReadImageHeader(bytes, path);
  const bool turned = header.format == ImageFormat::kJpeg && header.width == h && header.height == w;
  if ((header.width != w || header.height != h) && !turned) {
    throw InputError(internal::Concat(path, ": image is ", header.width, "x", header.height,
                                      " but the camera's image size is ", w, "x", h));
  }
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U,
                                 const_cast<char*>(bytes.data())),
                         cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot decode the image: " + e.what());
  }
  if (image.empty()) throw InputError(path + ": cannot decode the image (corrupt or unsupported)");
  if (image.cols != w || image.rows != h) {
    throw InputError(internal::Concat(path, ": image is ", image.cols, "x", image.rows,
                                      " after its EXIF orientation, but the camera's image size is ",
                                      w, "x", h));
  }
  return image;
}

}  // namespace

OverlayStats WriteOverlayImage(const Camera& camera, const Correspondences& correspondences,
                               const OverlayOptions& options, const std::string& output_path) {
  options.Check();
  camera.Check();
  const ImageFormat format = ImageFormatOfPath(output_path);
  const int w = camera.image_size.width;
  const int h = camera.image_size.height;
  if (int64_t{w} * h > kMaxImagePixels) {
    throw std::invalid_argument(internal::Concat(
        "the camera's image size ", w, "x", h, " is beyond the ", kMaxImagePixels,
        " pixels an overlay may have (8192 x 8192)"));
  }
  cv::Mat image;
  if (options.background_path.empty()) {
    image = cv::Mat(h, w, CV_8UC3, cv::Scalar(40, 40, 40));
  } else {
    image = ReadBackground(options.background_path, w, h);
  }
  const double scale = std::max(1.0, std::max(w, h) / 1000.0);
  const int thickness = static_cast<int>(std::lround(scale));
  const int radius = static_cast<int>(std::lround(4 * scale * 16));
  const cv::Scalar observed_colour(0, 220, 255);   // yellow: observed
  const cv::Scalar predicted_colour(255, 160, 0);  // blue: reprojected
  const cv::Scalar residual_colour(60, 60, 255);   // red: residual x magnify
  OverlayStats stats;
  for (size_t i = 0; i < correspondences.pixels.size(); ++i) {
    const Eigen::Vector2d& observed = correspondences.pixels[i];
    const std::optional<Eigen::Vector2d> predicted = PixelFromWorld(camera, correspondences.points_in_world[i]);
    cv::circle(image, Fixed(observed), radius, observed_colour, thickness, cv::LINE_AA, kShift);
    if (!predicted) {
      ++stats.behind;
      continue;
    }
    const Eigen::Vector2d tip = observed + options.magnify * (*predicted - observed);
    cv::line(image, Fixed(observed), Fixed(tip), residual_colour, thickness, cv::LINE_AA, kShift);
    cv::drawMarker(image, cv::Point(static_cast<int>(std::lround(predicted->x())),
                                    static_cast<int>(std::lround(predicted->y()))),
                   predicted_colour, cv::MARKER_CROSS, static_cast<int>(8 * scale), thickness);
    ++stats.drawn;
  }
  char legend[160];
  std::snprintf(legend, sizeof legend,
                "o observed   + reprojected   line: residual x %g%s", options.magnify,
                stats.behind > 0 ? "   (some points behind the camera)" : "");
  const double font = 0.5 * scale;
  cv::putText(image, legend, cv::Point(10, static_cast<int>(20 * scale)), cv::FONT_HERSHEY_SIMPLEX,
              font, cv::Scalar(0, 0, 0), 3 * thickness, cv::LINE_AA);
  cv::putText(image, legend, cv::Point(10, static_cast<int>(20 * scale)), cv::FONT_HERSHEY_SIMPLEX,
              font, cv::Scalar(255, 255, 255), thickness, cv::LINE_AA);
  std::vector<uchar> encoded;
  const char* extension = format == ImageFormat::kPng ? ".png" : ".jpg";
  if (!cv::imencode(extension, image, encoded)) {
    throw InputError(internal::Concat(output_path, ": cannot encode the image as ", extension));
  }
  WriteFileAtomically(output_path, std::string(encoded.begin(), encoded.end()));
  return stats;
}

}  // namespace camproj

// A photo of a camera's image (private): `camproj overlay`'s background and `camproj view`'s
// image. One policy for both: a photo is taken as displayed -- a JPEG turned or mirrored by its
// EXIF orientation, as OpenCV's decoder and browsers show it -- and must then have the camera's
// image size.
#ifndef CAMPROJ_SRC_PHOTO_H_
#define CAMPROJ_SRC_PHOTO_H_

#include <string>

#include <opencv2/core.hpp>

#include "camproj/image_header.h"

namespace camproj {
namespace internal {

struct Photo {
  std::string path;
  std::string bytes;  // the file
  ImageHeader header;
};

// Reads the file (at most 256 MiB: a PNG or JPEG of kMaxImagePixels is far smaller) and its
// header. Throws InputError naming the path unless it is a PNG or JPEG whose size as displayed
// (ImageHeader::DisplayedWidth, DisplayedHeight) is width x height, or if it is cut short
// (RequireWholeImage); the file's own errors as ReadWholeFile throws them.
Photo ReadPhoto(const std::string& path, int width, int height);

// The photo's pixels as displayed, 8-bit BGR: decoded as stored and turned by the header's EXIF
// orientation. Throws InputError naming the path if OpenCV cannot decode it, or decodes it to
// another size than the header's as displayed.
cv::Mat DecodePhoto(const Photo& photo);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_PHOTO_H_

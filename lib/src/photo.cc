#include "photo.h"

#include <opencv2/imgcodecs.hpp>

#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "check.h"
#include "image_codecs.h"

namespace camproj {
namespace internal {

namespace {

constexpr size_t kMaxImageFileBytes = size_t{256} << 20;

// "1920x1080", with the stored size where an EXIF orientation turns it.
std::string DisplayedSize(const ImageHeader& header) {
  std::string text = Concat(header.DisplayedWidth(), "x", header.DisplayedHeight());
  if (header.exif_orientation != 1) {
    text += Concat(" as displayed (its EXIF orientation ", header.exif_orientation,
                   header.Turned() ? Concat(" turns its stored ", header.width, "x", header.height)
                                   : std::string(" mirrors or turns it half round"),
                   ")");
  }
  return text;
}

}  // namespace

Photo ReadPhoto(const std::string& path, int width, int height) {
  Photo photo;
  photo.path = path;
  photo.bytes = ReadWholeFile(path, kMaxImageFileBytes);
  photo.header = ReadImageHeader(photo.bytes, path);
  if (photo.header.DisplayedWidth() != width || photo.header.DisplayedHeight() != height) {
    throw InputError(Concat(path, ": image is ", DisplayedSize(photo.header),
                            " but the camera's image size is ", width, "x", height));
  }
  // libpng refuses a truncated file too, but prints its own error line first; a browser shows
  // the rest grey.
  RequireWholeImage(photo.bytes, photo.header.format, path);
  return photo;
}

cv::Mat DecodePhoto(const Photo& photo) {
  cv::Mat image;
  try {
    // Decoded as stored, then turned by the header's orientation: OpenCV's own EXIF reading
    // takes a JPEG's first APP1 whatever it holds and any type of the tag, where camproj's
    // header and browsers take the Exif one and a SHORT (an XMP segment before the EXIF one
    // made overlay refuse a photo its header accepted).
    image = DecodeImage(cv::Mat(1, static_cast<int>(photo.bytes.size()), CV_8U,
                                const_cast<char*>(photo.bytes.data())),
                        cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception& e) {
    throw InputError(photo.path + ": cannot decode the image: " + e.what());
  }
  if (image.empty()) {
    throw InputError(photo.path + ": cannot decode the image (corrupt or unsupported)");
  }
  // EXIF 2.32, 4.6.4 (as OpenCV's ExifTransform applies them).
  switch (photo.header.exif_orientation) {
    case 2: cv::flip(image, image, 1); break;
    case 3: cv::flip(image, image, -1); break;
    case 4: cv::flip(image, image, 0); break;
    case 5: cv::transpose(image, image); break;
    case 6: cv::transpose(image, image); cv::flip(image, image, 1); break;
    case 7: cv::transpose(image, image); cv::flip(image, image, -1); break;
    case 8: cv::transpose(image, image); cv::flip(image, image, 0); break;
    default: break;
  }
  if (image.cols != photo.header.DisplayedWidth() || image.rows != photo.header.DisplayedHeight()) {
    throw InputError(Concat(photo.path, ": image decodes to ", image.cols, "x", image.rows,
                            " but its header states ", DisplayedSize(photo.header)));
  }
  return image;
}

}  // namespace internal
}  // namespace camproj

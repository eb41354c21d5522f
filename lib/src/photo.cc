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
    image = DecodeImage(cv::Mat(1, static_cast<int>(photo.bytes.size()), CV_8U,
                                const_cast<char*>(photo.bytes.data())),
                        cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw InputError(photo.path + ": cannot decode the image: " + e.what());
  }
  if (image.empty()) {
    throw InputError(photo.path + ": cannot decode the image (corrupt or unsupported)");
  }
  if (image.cols != photo.header.DisplayedWidth() || image.rows != photo.header.DisplayedHeight()) {
    throw InputError(Concat(photo.path, ": image decodes to ", image.cols, "x", image.rows,
                            " but its header states ", DisplayedSize(photo.header)));
  }
  return image;
}

}  // namespace internal
}  // namespace camproj

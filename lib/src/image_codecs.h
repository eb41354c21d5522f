// OpenCV's image codecs (private): cv::imdecode and cv::imencode, from libopencv_imgcodecs loaded
// the first time an image is decoded or encoded, not when the program starts.
//
// Debian builds libopencv_imgcodecs with GDAL, DICOM, HEIF and OpenEXR: linking it loads ~140
// libraries and runs their static initializers at every start, ~0.12 s of each `camproj` command
// (0.01 s without it; ~0.35 s under the sanitizers), though only `camproj overlay` and the lens
// maps of `camproj export` touch an image. The library is opened by the soname this build was
// compiled against (CAMPROJ_IMGCODECS_SONAME, lib/CMakeLists.txt) and the two functions looked up
// by their C++ (Itanium) symbol names, which encode the parameter types;
// tests/image_codecs_test.cc checks that the functions found round-trip a PNG exactly.
#ifndef CAMPROJ_SRC_IMAGE_CODECS_H_
#define CAMPROJ_SRC_IMAGE_CODECS_H_

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace camproj {
namespace internal {

// cv::imdecode(buffer, flags). Throws std::runtime_error naming the library if it cannot be
// loaded; cv::Exception as cv::imdecode does.
cv::Mat DecodeImage(const cv::Mat& buffer, int flags);

// cv::imencode(extension, image, *bytes): false if OpenCV cannot encode it. Throws as DecodeImage.
bool EncodeImage(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes);

// Where the two functions are looked up: the library's soname and their symbol names.
struct ImageCodecSymbols {
  const char* library;
  const char* imdecode;
  const char* imencode;
};
ImageCodecSymbols ImageCodecSymbolNames();

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_IMAGE_CODECS_H_

#include "image_codecs.h"

#include <dlfcn.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace camproj {
namespace internal {

namespace {

// The Itanium C++ ABI names (GCC and clang on Linux) of
//   cv::Mat cv::imdecode(cv::InputArray buf, int flags);
//   bool cv::imencode(const cv::String& ext, cv::InputArray img, std::vector<uchar>& buf,
//                     const std::vector<int>& params);
// in OpenCV 4 with libstdc++'s C++11 string ABI.
constexpr char kImdecodeSymbol[] = "_ZN2cv8imdecodeERKNS_11_InputArrayEi";
constexpr char kImencodeSymbol[] =
    "_ZN2cv8imencodeERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEERKNS_11_InputArrayERSt"
    "6vectorIhSaIhEERKSB_IiSaIiEE";

using ImdecodeFunction = cv::Mat (*)(const cv::_InputArray&, int);
using ImencodeFunction = bool (*)(const std::string&, const cv::_InputArray&,
                                  std::vector<uchar>&, const std::vector<int>&);

struct Codecs {
  ImdecodeFunction imdecode = nullptr;
  ImencodeFunction imencode = nullptr;
  std::string error;  // why they are not there
};

// Opened once (a function-local static: thread-safe) and never closed.
Codecs Load() {
  Codecs codecs;
  void* library = dlopen(CAMPROJ_IMGCODECS_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    codecs.error = dlerror();
    return codecs;
  }
  codecs.imdecode = reinterpret_cast<ImdecodeFunction>(dlsym(library, kImdecodeSymbol));
  codecs.imencode = reinterpret_cast<ImencodeFunction>(dlsym(library, kImencodeSymbol));
  if (codecs.imdecode == nullptr || codecs.imencode == nullptr) {
    codecs.error = "cv::imdecode or cv::imencode not found in it";
  }
  return codecs;
}

const Codecs& LoadedCodecs() {
  static const Codecs codecs = Load();
  if (!codecs.error.empty()) {
    throw std::runtime_error(std::string("cannot load OpenCV's image codecs (") +
                             CAMPROJ_IMGCODECS_SONAME + "): " + codecs.error +
                             "; is OpenCV's imgcodecs installed (scripts/install-deps.sh)?");
  }
  return codecs;
}

}  // namespace

cv::Mat DecodeImage(const cv::Mat& buffer, int flags) {
  return LoadedCodecs().imdecode(buffer, flags);
}

bool EncodeImage(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes) {
  return LoadedCodecs().imencode(extension, image, *bytes, std::vector<int>());
}

ImageCodecSymbols ImageCodecSymbolNames() {
  return {CAMPROJ_IMGCODECS_SONAME, kImdecodeSymbol, kImencodeSymbol};
}

}  // namespace internal
}  // namespace camproj

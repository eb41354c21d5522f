// OpenCV's image codecs, opened when an image is first encoded or decoded (lib/src/image_codecs.h).
// This binary does not link libopencv_imgcodecs, and ctest runs each test in its own process.
#include "image_codecs.h"

#include <dlfcn.h>

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>  // the flags only

namespace camproj {
namespace {

bool CodecsLoaded() {
  void* library = dlopen(internal::ImageCodecSymbolNames().library, RTLD_NOW | RTLD_NOLOAD);
  if (library == nullptr) return false;
  dlclose(library);  // NOLOAD took a reference
  return true;
}

// A 3 x 2 BGR image whose every byte differs.
cv::Mat DistinctImage() {
  cv::Mat image(2, 3, CV_8UC3);
  for (int i = 0; i < 18; ++i) image.data[i] = static_cast<uchar>(10 * i + 7);
  return image;
}

TEST(ImageCodecsTest, LoadedOnlyWhenAnImageIsFirstEncoded) {
  EXPECT_FALSE(CodecsLoaded()) << internal::ImageCodecSymbolNames().library
                               << " is loaded before any image is encoded";
  std::vector<uchar> bytes;
  ASSERT_TRUE(internal::EncodeImage(".png", DistinctImage(), &bytes));
  EXPECT_TRUE(CodecsLoaded());
}

// The symbol names encode the parameter types (Itanium ABI), so functions found by them are
// cv::imencode and cv::imdecode; PNG is lossless, so the round trip is exact.
TEST(ImageCodecsTest, PngRoundTripIsExact) {
  const cv::Mat image = DistinctImage();
  std::vector<uchar> bytes;
  ASSERT_TRUE(internal::EncodeImage(".png", image, &bytes));
  ASSERT_GT(bytes.size(), 8u);
  const cv::Mat decoded = internal::DecodeImage(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()), cv::IMREAD_COLOR);
  ASSERT_EQ(decoded.type(), CV_8UC3);
  ASSERT_EQ(decoded.size(), image.size());
  EXPECT_EQ(cv::norm(decoded, image, cv::NORM_INF), 0.0);
}

TEST(ImageCodecsTest, AnUnknownExtensionIsAnOpenCvError) {
  std::vector<uchar> bytes;
  EXPECT_THROW(internal::EncodeImage(".not-an-image-format", DistinctImage(), &bytes),
               cv::Exception);
}

}  // namespace
}  // namespace camproj

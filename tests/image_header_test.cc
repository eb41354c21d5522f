#include "camproj/image_header.h"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camproj/errors.h"

namespace camproj {
namespace {

std::string Encoded(const char* extension, int width, int height) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(extension, cv::Mat(height, width, CV_8UC3, cv::Scalar(1, 2, 3)), bytes));
  return std::string(bytes.begin(), bytes.end());
}

// The header agrees with what OpenCV encoded, for both formats and a non-square size.
TEST(ImageHeaderTest, SizeOfImagesOpenCvEncoded) {
  const ImageHeader png = ReadImageHeader(Encoded(".png", 37, 11), "a.png");
  EXPECT_EQ(png.format, ImageFormat::kPng);
  EXPECT_EQ(png.width, 37);
  EXPECT_EQ(png.height, 11);
  const ImageHeader jpeg = ReadImageHeader(Encoded(".jpg", 37, 11), "a.jpg");
  EXPECT_EQ(jpeg.format, ImageFormat::kJpeg);
  EXPECT_EQ(jpeg.width, 37);
  EXPECT_EQ(jpeg.height, 11);
}

// Every prefix of an encoded file is short of its end; the whole file, or with bytes after it,
// reaches it. An APP1 segment holding a thumbnail's EOI (FF D9) is skipped with its length.
TEST(ImageHeaderTest, ReachesItsEndOnlyWhenWhole) {
  for (const auto& [extension, format] : {std::pair{".png", ImageFormat::kPng},
                                          std::pair{".jpg", ImageFormat::kJpeg}}) {
    const std::string whole = Encoded(extension, 37, 11);
    EXPECT_TRUE(ImageReachesItsEnd(whole, format)) << extension;
    EXPECT_TRUE(ImageReachesItsEnd(whole + "appended", format)) << extension;
    for (size_t cut = 0; cut < whole.size(); ++cut) {
      EXPECT_FALSE(ImageReachesItsEnd(whole.substr(0, cut), format)) << extension << " " << cut;
    }
  }
  const std::string jpeg = Encoded(".jpg", 37, 11);
  const std::string app1("\xff\xe1\x00\x06\xff\xd9\x00\x00", 8);  // length 6: FF D9 inside
  EXPECT_TRUE(ImageReachesItsEnd(jpeg.substr(0, 2) + app1 + jpeg.substr(2), ImageFormat::kJpeg));
  EXPECT_FALSE(ImageReachesItsEnd(jpeg.substr(0, 2) + app1 + jpeg.substr(2, 100), ImageFormat::kJpeg));
}

// Hand-made: SOI, an APP1 segment of 4 bytes, fill bytes, then SOF2 (progressive) 4000 x 3000.
TEST(ImageHeaderTest, JpegFrameAfterOtherSegmentsAndFillBytes) {
  const std::string bytes("\xFF\xD8" "\xFF\xE1\x00\x04\xAB\xCD" "\xFF\xFF"
                          "\xFF\xC2\x00\x11\x08\x0B\xB8\x0F\xA0\x03", 20);
  const ImageHeader header = ReadImageHeader(bytes, "p.jpg");
  EXPECT_EQ(header.width, 4000);
  EXPECT_EQ(header.height, 3000);
}

// Only the first bytes are read: a 30000^2 PNG's header alone gives its size.
TEST(ImageHeaderTest, HugeSizeFromTheHeaderAlone) {
  const std::string png = Encoded(".png", 1, 1).substr(0, 24);
  std::string huge = png;
  const char size[8] = {0, 0, 0x75, 0x30, 0, 0, 0x75, 0x30};  // 30000, 30000
  huge.replace(16, 8, size, 8);
  const ImageHeader header = ReadImageHeader(huge, "huge.png");
  EXPECT_EQ(header.width, 30000);
  EXPECT_EQ(header.height, 30000);
  EXPECT_GT(int64_t{header.width} * header.height, kMaxImagePixels);
}

TEST(ImageHeaderTest, CutShortOrOtherFormatsAreRefusedNamingTheSource) {
  const std::string png = Encoded(".png", 4, 4);
  const std::string jpeg = Encoded(".jpg", 4, 4);
  for (const std::string& bytes : {png.substr(0, 20), jpeg.substr(0, 4), std::string("BM\x36\x00", 4),
                                   std::string(), std::string("\xFF\xD8\xFF\xD9", 4)}) {
    try {
      ReadImageHeader(bytes, "x.img");
      ADD_FAILURE() << "accepted " << bytes.size() << " bytes";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("x.img: ", 0), 0u) << e.what();
    }
  }
}

TEST(ImageHeaderTest, FormatOfPathByExtension) {
  EXPECT_EQ(ImageFormatOfPath("out/a.png"), ImageFormat::kPng);
  EXPECT_EQ(ImageFormatOfPath("A.PNG"), ImageFormat::kPng);
  EXPECT_EQ(ImageFormatOfPath("a.jpg"), ImageFormat::kJpeg);
  EXPECT_EQ(ImageFormatOfPath("a.JPEG"), ImageFormat::kJpeg);
  for (const char* path : {"a.bmp", "a", "dir.png/a", "a.png.tmp", ".png/x"}) {
    EXPECT_THROW(ImageFormatOfPath(path), std::invalid_argument) << path;
  }
}

}  // namespace
}  // namespace camproj

#include "camproj/image_header.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camproj/errors.h"
#include "photo.h"

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

// An APP1 "Exif" segment holding IFD0 with the given entries (tag, type, count, value), in
// either byte order, inserted after a JPEG's SOI.
std::string WithExif(const std::string& jpeg, bool big_endian,
                     const std::vector<std::array<uint32_t, 4>>& entries) {
  std::string tiff = big_endian ? "MM" : "II";
  const auto put = [&](uint32_t value, int size) {
    for (int i = 0; i < size; ++i) {
      const int shift = 8 * (big_endian ? size - 1 - i : i);
      tiff += static_cast<char>((value >> shift) & 0xff);
    }
  };
  put(42, 2);
  put(8, 4);
  put(static_cast<uint32_t>(entries.size()), 2);
  for (const auto& [tag, type, count, value] : entries) {
    put(tag, 2);
    put(type, 2);
    put(count, 4);
    put(value, 2);  // a SHORT sits in the first two bytes of the value field
    put(0, 2);
  }
  put(0, 4);
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  return jpeg.substr(0, 2) + "\xff\xe1" + static_cast<char>(length >> 8) +
         static_cast<char>(length & 0xff) + payload + jpeg.substr(2);
}

// The EXIF orientation (TIFF tag 0x0112, one SHORT in IFD0), in both byte orders, after other
// tags; what is displayed turned a quarter (5-8) swaps width and height. Anything malformed or
// out of range reads as upright (1), as does a PNG or a JPEG without EXIF.
TEST(ImageHeaderTest, JpegExifOrientation) {
  const std::string jpeg = Encoded(".jpg", 37, 11);
  EXPECT_EQ(ReadImageHeader(jpeg, "a.jpg").exif_orientation, 1);
  EXPECT_EQ(ReadImageHeader(Encoded(".png", 37, 11), "a.png").exif_orientation, 1);
  for (const bool big_endian : {false, true}) {
    for (uint32_t orientation = 1; orientation <= 8; ++orientation) {
      const ImageHeader header = ReadImageHeader(
          WithExif(jpeg, big_endian, {{0x010f, 2, 4, 0x4142}, {0x0112, 3, 1, orientation}}),
          "a.jpg");
      EXPECT_EQ(header.exif_orientation, static_cast<int>(orientation)) << big_endian;
      EXPECT_EQ(header.width, 37);
      EXPECT_EQ(header.DisplayedWidth(), orientation >= 5 ? 11 : 37);
      EXPECT_EQ(header.DisplayedHeight(), orientation >= 5 ? 37 : 11);
    }
    EXPECT_EQ(ReadImageHeader(WithExif(jpeg, big_endian, {{0x0112, 3, 1, 9}}), "a.jpg")
                  .exif_orientation, 1);
    EXPECT_EQ(ReadImageHeader(WithExif(jpeg, big_endian, {{0x0112, 4, 1, 6}}), "a.jpg")
                  .exif_orientation, 1);  // a LONG, not a SHORT
    EXPECT_EQ(ReadImageHeader(WithExif(jpeg, big_endian, {{0x0112, 3, 2, 6}}), "a.jpg")
                  .exif_orientation, 1);  // two values
  }
  // IFD0 claims more entries than the segment holds: read up to its end, no further.
  std::string claims = WithExif(jpeg, false, {{0x010f, 2, 4, 0x4142}});
  claims[2 + 4 + 6 + 8] = 100;
  EXPECT_EQ(ReadImageHeader(claims, "a.jpg").exif_orientation, 1);
  EXPECT_EQ(ReadImageHeader(claims, "a.jpg").width, 37);
}

// A PNG's eXIf chunk (after IHDR, before IDAT) carries the orientation too.
TEST(ImageHeaderTest, PngExifOrientation) {
  const std::string png = Encoded(".png", 37, 11);
  for (const bool big_endian : {false, true}) {
    // The TIFF data WithExif builds for a JPEG, as an eXIf chunk (its CRC is not checked).
    const std::string jpeg_with = WithExif(Encoded(".jpg", 1, 1), big_endian, {{0x0112, 3, 1, 6}});
    const std::string tiff = jpeg_with.substr(2 + 4 + 6, jpeg_with.size() - Encoded(".jpg", 1, 1).size() - 4 - 6);
    const uint32_t n = static_cast<uint32_t>(tiff.size());
    const std::string chunk = std::string{static_cast<char>(n >> 24), static_cast<char>(n >> 16),
                                          static_cast<char>(n >> 8), static_cast<char>(n)} +
                              "eXIf" + tiff + std::string(4, '\0');
    const std::string with = png.substr(0, 33) + chunk + png.substr(33);  // after IHDR's 25 bytes
    const ImageHeader header = ReadImageHeader(with, "a.png");
    EXPECT_EQ(header.exif_orientation, 6) << big_endian;
    EXPECT_EQ(header.DisplayedWidth(), 11);
    // Cut inside the chunk: upright, not a read beyond it.
    EXPECT_EQ(ReadImageHeader(with.substr(0, 33 + 8 + 4), "a.png").exif_orientation, 1);
  }
}

// A photo is decoded as OpenCV shows it: for each EXIF orientation the pixels OpenCV's own
// decode turns (cv::IMREAD_COLOR applies it for these files) are DecodePhoto's, exactly.
TEST(ImageHeaderTest, PhotosDecodeAsDisplayed) {
  cv::Mat stored(11, 37, CV_8UC3);
  cv::randu(stored, 0, 255);
  std::vector<uchar> bytes;
  ASSERT_TRUE(cv::imencode(".jpg", stored, bytes));
  const std::string jpeg(bytes.begin(), bytes.end());
  for (uint32_t orientation = 1; orientation <= 8; ++orientation) {
    internal::Photo photo;
    photo.path = "a.jpg";
    photo.bytes = WithExif(jpeg, false, {{0x0112, 3, 1, orientation}});
    photo.header = ReadImageHeader(photo.bytes, "a.jpg");
    const cv::Mat ours = internal::DecodePhoto(photo);
    const cv::Mat opencv = cv::imdecode(
        cv::Mat(1, static_cast<int>(photo.bytes.size()), CV_8U, photo.bytes.data()), cv::IMREAD_COLOR);
    ASSERT_EQ(ours.size(), opencv.size()) << orientation;
    EXPECT_EQ(cv::norm(ours, opencv, cv::NORM_INF), 0.0) << orientation;
  }
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

#include "camproj/image_header.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "camproj/errors.h"

namespace camproj {

namespace {

uint32_t BigEndian(std::string_view bytes, size_t at, int size) {
  uint32_t value = 0;
  for (int i = 0; i < size; ++i) value = value << 8 | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

// The Orientation of EXIF data: a TIFF header (byte order "II" or "MM", 42, IFD0's offset) whose
// IFD0 holds tag 0x0112 as one SHORT (EXIF 2.32, 4.6.4). 1 for anything else or out of range.
int TiffOrientation(std::string_view tiff) {
  if (tiff.size() < 8) return 1;
  const bool little = tiff.substr(0, 2) == "II";
  if (!little && tiff.substr(0, 2) != "MM") return 1;
  const auto read = [&](size_t at, int size) -> uint32_t {
    uint32_t value = 0;
    for (int i = 0; i < size; ++i) {
      const uint32_t b = static_cast<unsigned char>(tiff[at + i]);
      value |= little ? b << (8 * i) : b << (8 * (size - 1 - i));
    }
    return value;
  };
  if (read(2, 2) != 42) return 1;
  const size_t ifd = read(4, 4);
  if (ifd > tiff.size() || tiff.size() - ifd < 2) return 1;
  const size_t entries = read(ifd, 2);
  for (size_t e = 0; e < entries; ++e) {
    const size_t at = ifd + 2 + 12 * e;
    if (at > tiff.size() || tiff.size() - at < 12) return 1;
    if (read(at, 2) != 0x0112) continue;
    if (read(at + 2, 2) != 3 || read(at + 4, 4) != 1) return 1;  // one SHORT
    const uint32_t orientation = read(at + 8, 2);
    return orientation >= 1 && orientation <= 8 ? static_cast<int>(orientation) : 1;
  }
  return 1;
}

// The Orientation of a JPEG's APP1 payload (after its length): "Exif\0\0", then TIFF data.
int ExifOrientation(std::string_view payload) {
  if (payload.size() < 6 || payload.substr(0, 6) != std::string_view("Exif\0\0", 6)) return 1;
  return TiffOrientation(payload.substr(6));
}

// The Orientation of a PNG's eXIf chunk (PNG 1.5 extensions: TIFF data, before IDAT), 1 without
// one. Chunks are walked by their lengths from the one after IHDR.
int PngOrientation(std::string_view bytes) {
  size_t at = 8;  // the signature
  while (at + 8 <= bytes.size()) {
    const size_t length = BigEndian(bytes, at, 4);
    const std::string_view type = bytes.substr(at + 4, 4);
    if (type == "IDAT" || type == "IEND" || length > bytes.size() - at - 8) return 1;
    if (type == "eXIf") return TiffOrientation(bytes.substr(at + 8, length));
    if (bytes.size() - at - 8 - length < 4) return 1;  // its CRC cut off
    at += 12 + length;
  }
  return 1;
}

// JPEG (ITU T.81, B.1.1): after SOI (FF D8), segments FF <marker> <16-bit length incl. itself>;
// SOF0..SOF15 except DHT (C4), JPG (C8), DAC (CC) hold precision, height, width.
ImageHeader JpegHeader(std::string_view bytes, const std::string& source) {
  int orientation = 1;
  bool exif_seen = false;  // the first Exif APP1 holds the image's own tags
  size_t at = 2;
  while (at + 4 <= bytes.size()) {
    if (static_cast<unsigned char>(bytes[at]) != 0xff) break;
    const unsigned char marker = static_cast<unsigned char>(bytes[at + 1]);
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) {  // no length
      at += 2;
      continue;
    }
    const size_t length = BigEndian(bytes, at + 2, 2);
    if (length < 2) break;
    const bool frame = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (frame) {
      if (at + 9 > bytes.size() || length < 7) break;
      ImageHeader header;
      header.format = ImageFormat::kJpeg;
      header.height = static_cast<int>(BigEndian(bytes, at + 5, 2));
      header.width = static_cast<int>(BigEndian(bytes, at + 7, 2));
      header.exif_orientation = orientation;
      if (header.width == 0 || header.height == 0) {
        throw InputError(source + ": the JPEG header states a zero width or height");
      }
      return header;
    }
    if (marker == 0xda || marker == 0xd9) break;  // image data or end before any frame header
    if (marker == 0xe1 && !exif_seen && at + 2 + length <= bytes.size()) {
      const std::string_view payload = bytes.substr(at + 4, length - 2);
      if (payload.substr(0, 4) == "Exif") {
        exif_seen = true;
        orientation = ExifOrientation(payload);
      }
    }
    at += 2 + length;
  }
  throw InputError(source + ": a JPEG without a readable frame header (cut short or corrupt)");
}

bool PngReachesItsEnd(std::string_view bytes) {
  size_t at = 8;  // the signature
  while (at + 12 <= bytes.size()) {
    const size_t length = BigEndian(bytes, at, 4);
    if (length > bytes.size() - at - 12) return false;
    if (bytes.substr(at + 4, 4) == "IEND") return true;
    at += 12 + length;
  }
  return false;
}

bool JpegReachesItsEnd(std::string_view bytes) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(bytes[i]); };
  const size_t n = bytes.size();
  if (n < 4 || byte(0) != 0xff || byte(1) != 0xd8) return false;
  size_t at = 2;
  bool in_scan = false;
  while (at < n) {
    if (in_scan) {
      // Entropy-coded data until a marker other than a restart.
      if (byte(at) != 0xff) {
        ++at;
        continue;
      }
      if (at + 1 >= n) return false;
      const unsigned char next = byte(at + 1);
      if (next == 0x00 || (next >= 0xd0 && next <= 0xd7) || next == 0xff) {
        at += next == 0xff ? 1 : 2;
        continue;
      }
      in_scan = false;  // a marker: read below
    }
    if (byte(at) != 0xff) return false;
    while (at < n && byte(at) == 0xff) ++at;  // fill bytes before a marker
    if (at >= n) return false;
    const unsigned char marker = byte(at++);
    if (marker == 0xd9) return true;
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) continue;  // no length
    if (at + 2 > n) return false;
    const size_t length = BigEndian(bytes, at, 2);
    if (length < 2 || at + length > n) return false;
    at += length;
    in_scan = marker == 0xda;  // SOS: its scan's data follows the header
  }
  return false;
}

}  // namespace

bool ImageReachesItsEnd(std::string_view bytes, ImageFormat format) {
  return format == ImageFormat::kPng ? PngReachesItsEnd(bytes) : JpegReachesItsEnd(bytes);
}

void RequireWholeImage(std::string_view bytes, ImageFormat format, const std::string& path) {
  if (ImageReachesItsEnd(bytes, format)) return;
  throw InputError(path + (format == ImageFormat::kJpeg
                               ? ": the JPEG ends before its end-of-image marker"
                               : ": the PNG ends before its IEND chunk") +
                   ": the file is truncated");
}

ImageHeader ReadImageHeader(std::string_view bytes, const std::string& source) {
  static constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);
  if (bytes.substr(0, 8) == kPngSignature) {
    // The first chunk must be IHDR (PNG spec 5.6): length 13, "IHDR", width, height.
    if (bytes.size() < 24 || bytes.substr(12, 4) != "IHDR") {
      throw InputError(source + ": a PNG without its IHDR header (cut short or corrupt)");
    }
    const uint32_t width = BigEndian(bytes, 16, 4);
    const uint32_t height = BigEndian(bytes, 20, 4);
    // PNG allows up to 2^31 - 1 per side.
    if (width == 0 || height == 0 || width > 0x7fffffffu || height > 0x7fffffffu) {
      throw InputError(source + ": the PNG header states an invalid size " + std::to_string(width) +
                       "x" + std::to_string(height));
    }
    ImageHeader header{ImageFormat::kPng, static_cast<int>(width), static_cast<int>(height)};
    header.exif_orientation = PngOrientation(bytes);
    return header;
  }
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xff &&
      static_cast<unsigned char>(bytes[1]) == 0xd8) {
    return JpegHeader(bytes, source);
  }
  throw InputError(source + ": not a PNG or JPEG file (camproj reads images of these formats only)");
}

ImageFormat ImageFormatOfPath(const std::string& path) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.rfind('/');
  std::string extension;
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    extension = path.substr(dot + 1);
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  if (extension == "png") return ImageFormat::kPng;
  if (extension == "jpg" || extension == "jpeg") return ImageFormat::kJpeg;
  throw std::invalid_argument(path + ": the image format is chosen by the extension: .png, .jpg or .jpeg");
}

}  // namespace camproj

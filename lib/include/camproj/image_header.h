// Image dimensions read from a PNG or JPEG file's header, before anything is decoded.
#ifndef CAMPROJ_IMAGE_HEADER_H_
#define CAMPROJ_IMAGE_HEADER_H_

#include <cstdint>
#include <string>
#include <string_view>

namespace camproj {

// The most pixels camproj decodes or draws: 8192 x 8192 (about 200 MB as 8-bit BGR). An image or
// an overlay canvas beyond it is refused before memory is allocated for it.
constexpr int64_t kMaxImagePixels = int64_t{8192} * 8192;

enum class ImageFormat { kPng, kJpeg };

struct ImageHeader {
  ImageFormat format = ImageFormat::kPng;
  int width = 0;   // px, as stored (before any EXIF orientation)
  int height = 0;  // px
  // The EXIF Orientation (TIFF tag 0x0112 in IFD0) of a JPEG's first APP1 "Exif" segment before
  // its frame header, or of a PNG's eXIf chunk: 1 upright, 2-4 mirrored or turned 180 degrees,
  // 5-8 turned a quarter (the image is displayed height x width). 1 where absent, unreadable, or
  // out of 1-8. Browsers apply it, and camproj shows photos as displayed (photo.h: by this value,
  // not OpenCV's own reading, which differs on odd files).
  int exif_orientation = 1;
  bool Turned() const { return exif_orientation >= 5; }  // displayed as height x width
  int DisplayedWidth() const { return Turned() ? height : width; }
  int DisplayedHeight() const { return Turned() ? width : height; }
};

// The format and size stated by the file's first bytes: a PNG's IHDR chunk, or a JPEG's first
// start-of-frame segment (any SOFn), with the EXIF orientation. `source` names the bytes in messages. Throws InputError
// naming `source` if the bytes are neither format, or the header is cut short or states a zero
// size. Reads only the header: cost and memory do not depend on the stated size.
ImageHeader ReadImageHeader(std::string_view bytes, const std::string& source);

// Whether the file's structure runs whole to its end marker, walked without decoding: a PNG's
// chunks (length, type, data, CRC) from the signature to IEND; a JPEG's segments from SOI
// skipped by their lengths (an EXIF thumbnail's own EOI inside APP1 is not taken for the end),
// each scan's entropy-coded data walked over stuffed FF 00 bytes, restart markers and fill
// bytes, to EOI (FF D9). Data after the end (a phone's appended motion video) is allowed. False
// for a file cut short. `bytes` begin with the signature ReadImageHeader found for `format`.
bool ImageReachesItsEnd(std::string_view bytes, ImageFormat format);

// Throws InputError ("photo.jpg: the JPEG ends before its end-of-image marker: the file is
// truncated") unless ImageReachesItsEnd: libjpeg decodes a truncated file with only a warning,
// filling the rest with grey, and a browser shows it the same way.
void RequireWholeImage(std::string_view bytes, ImageFormat format, const std::string& path);

// The image format an output path asks for by its extension (case-insensitive): .png, or .jpg /
// .jpeg. Throws std::invalid_argument naming the path and the extensions accepted otherwise.
ImageFormat ImageFormatOfPath(const std::string& path);

}  // namespace camproj

#endif  // CAMPROJ_IMAGE_HEADER_H_

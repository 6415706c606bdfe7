#include "core/frame/image_header.h"

#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/base/strings.h"

namespace fovea {
namespace {

// Signature (8) + IHDR length (4) + type (4) + width, height, bit depth,
// colour type (10): the bytes ReadPngFileHeader looks at.
constexpr size_t kPngHeaderBytes = 26;

uint32_t ReadBigEndian32(const unsigned char* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) |
         (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

uint32_t ReadBigEndian16(const unsigned char* p) {
  return (uint32_t{p[0]} << 8) | uint32_t{p[1]};
}

bool IsJpegStartOfFrame(unsigned char marker) {
  // SOF0-SOF15 except DHT (C4), JPG (C8) and DAC (CC).
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
         marker != 0xCC;
}

}  // namespace

bool IsPngFile(std::string_view file) {
  return file.substr(0, kPngSignature.size()) == kPngSignature;
}

bool IsJpegFile(std::string_view file) {
  return file.size() >= 2 && static_cast<unsigned char>(file[0]) == 0xFF &&
         static_cast<unsigned char>(file[1]) == 0xD8;
}

absl::StatusOr<ImageFileHeader> ReadPngFileHeader(std::string_view file,
                                                  std::string_view field) {
  const auto* p = reinterpret_cast<const unsigned char*>(file.data());
  if (file.size() < kPngHeaderBytes || std::memcmp(p + 12, "IHDR", 4) != 0 ||
      ReadBigEndian32(p + 8) != 13) {
    return absl::InvalidArgumentError(
        absl::StrCat(AbslView(field), ": not a decodable PNG (no IHDR in ",
                     file.size(), " bytes)"));
  }
  ImageFileHeader header;
  header.width = ReadBigEndian32(p + 16);
  header.height = ReadBigEndian32(p + 20);
  header.bit_depth = p[24];
  header.channels = p[25];
  return header;
}

// Walks the JPEG markers up to the first start-of-frame segment.
absl::StatusOr<ImageFileHeader> ReadJpegFileHeader(std::string_view file,
                                                   std::string_view field) {
  const auto* p = reinterpret_cast<const unsigned char*>(file.data());
  const size_t size = file.size();
  size_t pos = 2;  // after FF D8
  while (pos + 4 <= size) {
    if (p[pos] != 0xFF) break;
    const unsigned char marker = p[pos + 1];
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) {
      pos += 2;  // stand-alone marker
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA) break;  // EOI / SOS before a frame
    const size_t length = ReadBigEndian16(p + pos + 2);
    if (length < 2) break;
    if (IsJpegStartOfFrame(marker)) {
      if (length < 8 || pos + 2 + 8 > size) break;
      ImageFileHeader header;
      header.bit_depth = p[pos + 4];
      header.height = ReadBigEndian16(p + pos + 5);
      header.width = ReadBigEndian16(p + pos + 7);
      header.channels = p[pos + 9];
      return header;
    }
    pos += 2 + length;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      AbslView(field), ": not a decodable JPEG (no frame header in ",
      file.size(), " bytes)"));
}

}  // namespace fovea

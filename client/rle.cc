#include "client/rle.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace fovea::client {

absl::StatusOr<ByteMask> DecodeRle(const fovea::v1::RleMask& rle) {
  const uint64_t total = uint64_t{rle.height()} * rle.width();
  uint64_t covered = 0;
  for (uint32_t run : rle.counts()) covered += run;
  if (covered != total) {
    return absl::InvalidArgumentError(
        absl::StrCat("counts: runs cover ", covered, " pixels, mask is ",
                     rle.height(), "x", rle.width(), " = ", total));
  }
  ByteMask mask;
  mask.width = rle.width();
  mask.height = rle.height();
  mask.pixels.assign(total, 0);
  uint64_t index = 0;  // column-major position: column * height + row
  uint8_t value = 0;
  for (uint32_t run : rle.counts()) {
    if (value != 0) {
      for (uint64_t i = index; i < index + run; ++i) {
        const uint64_t column = i / mask.height;
        const uint64_t row = i % mask.height;
        mask.pixels[row * mask.width + column] = 1;
      }
    }
    index += run;
    value ^= 1;
  }
  return mask;
}

absl::StatusOr<fovea::v1::RleMask> EncodeRle(const ByteMask& mask) {
  const uint64_t total = uint64_t{mask.height} * mask.width;
  if (mask.pixels.size() != total) {
    return absl::InvalidArgumentError(
        absl::StrCat("pixels: ", mask.pixels.size(), " bytes for a ",
                     mask.height, "x", mask.width, " mask"));
  }
  fovea::v1::RleMask rle;
  rle.set_height(mask.height);
  rle.set_width(mask.width);
  if (total == 0) return rle;
  uint8_t value = 0;
  uint32_t run = 0;
  for (uint32_t column = 0; column < mask.width; ++column) {
    for (uint32_t row = 0; row < mask.height; ++row) {
      const uint8_t inside = mask.pixels[uint64_t{row} * mask.width + column];
      if ((inside != 0) != (value != 0)) {
        rle.add_counts(run);
        run = 0;
        value ^= 1;
      }
      ++run;
    }
  }
  rle.add_counts(run);
  return rle;
}

}  // namespace fovea::client

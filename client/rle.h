#ifndef FOVEA_CLIENT_RLE_H_
#define FOVEA_CLIENT_RLE_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "fovea/v1/segment.pb.h"

namespace fovea::client {

// A binary mask, row-major, one byte per pixel: 1 inside, 0 outside.
struct ByteMask {
  uint32_t width = 0;           // pixels
  uint32_t height = 0;          // pixels
  std::vector<uint8_t> pixels;  // height * width, pixel (u, v) at v * width + u

  uint8_t at(uint32_t u, uint32_t v) const { return pixels[v * width + u]; }
};

// Decodes COCO run-length encoding (segment.proto RleMask): run lengths
// over the mask in column-major order (down the first column, then the
// next), alternating zeros and ones, starting with a run of zeros that may
// have length 0. An empty `counts` is a valid all-zero mask only when the
// mask has no pixels; otherwise the runs must cover height * width exactly.
// Errors (INVALID_ARGUMENT): runs summing to more or fewer pixels than
// height * width.
absl::StatusOr<ByteMask> DecodeRle(const fovea::v1::RleMask& rle);

// The inverse of DecodeRle: any non-zero byte counts as inside.
// `mask.pixels` must hold width * height bytes (INVALID_ARGUMENT otherwise).
absl::StatusOr<fovea::v1::RleMask> EncodeRle(const ByteMask& mask);

}  // namespace fovea::client

#endif  // FOVEA_CLIENT_RLE_H_

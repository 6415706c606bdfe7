#ifndef FOVEA_CORE_FRAME_LZF_H_
#define FOVEA_CORE_FRAME_LZF_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace fovea {

// Decompresses an LZF stream (the format of Marc Lehmann's liblzf, which PCL
// uses for `DATA binary_compressed` PCD bodies) that must expand to exactly
// `size` bytes. Debian's liblzf decodes it; a stream it refuses is walked
// run by run to say why (below).
//
// The stream is a sequence of runs, each starting with a control byte c:
//   c < 32   a literal run: the next c + 1 bytes are copied to the output.
//   c >= 32  a back-reference: length l = c >> 5, plus the next byte when
//            l is 7; then the next byte b gives the distance
//            d = ((c & 31) << 8) + b + 1 back from the end of the output,
//            and l + 2 bytes are copied from there one at a time (so they
//            may overlap the bytes being written: d = 1 repeats a byte).
//
// Every read and write is bounds-checked (liblzf's CHECK_INPUT). The output
// of `size` bytes is allocated up front: the caller bounds `size`
// (LzfMaxExpansion). Errors
// are INVALID_ARGUMENT and name the byte offset of the offending run in
// `compressed`: a run that reads past the end of the input, a
// back-reference before the start of the output, output beyond `size`
// bytes, or a stream that ends before `size` bytes. An empty stream
// expands to zero bytes.
absl::StatusOr<std::vector<uint8_t>> LzfDecompress(absl::string_view compressed,
                                                   size_t size);

// The most bytes `compressed_size` bytes of LZF can expand to: a
// back-reference of three bytes yields 7 + 255 + 2 = 264 bytes.
constexpr uint64_t LzfMaxExpansion(uint64_t compressed_size) {
  return (compressed_size / 3 + 1) * 264;
}

}  // namespace fovea

#endif  // FOVEA_CORE_FRAME_LZF_H_

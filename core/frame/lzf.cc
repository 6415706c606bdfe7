#include "core/frame/lzf.h"

#include <algorithm>
#include <cstring>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace fovea {
namespace {

// Control bytes below this start a literal run; the rest a back-reference.
constexpr unsigned kLiteralLimit = 1 << 5;
// Back-reference length field (control >> 5) that takes an extra byte.
constexpr size_t kLongReference = 7;
// A back-reference copies its length field plus this many bytes.
constexpr size_t kMinReferenceBytes = 2;

// Copies this short are faster byte by byte than by a call to memcpy.
constexpr size_t kShortCopy = 16;

// Appends `length` bytes at `to` copied from `distance` bytes back, byte
// by byte in effect: when the two overlap, the copied bytes repeat with
// period `distance`. Copies in chunks that never overlap their source,
// each a whole number of periods, so the chunks double in size.
void CopyBackReference(uint8_t* to, size_t distance, size_t length) {
  const uint8_t* from = to - distance;
  if (length <= kShortCopy) {
    for (size_t i = 0; i < length; ++i) to[i] = from[i];
    return;
  }
  size_t copied = 0;  // a multiple of `distance` until the last chunk
  while (copied < length) {
    const size_t chunk = std::min(length - copied, distance + copied);
    std::memcpy(to + copied, from, chunk);
    copied += chunk;
  }
}

absl::Status LzfError(size_t run, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat("LZF run at compressed byte ", run, ": ", what));
}

}  // namespace

absl::StatusOr<std::vector<uint8_t>> LzfDecompress(absl::string_view compressed,
                                                   size_t size) {
  const auto* in = reinterpret_cast<const uint8_t*>(compressed.data());
  const size_t in_size = compressed.size();
  std::vector<uint8_t> out(size);
  size_t ip = 0;  // next input byte
  size_t op = 0;  // next output byte
  while (ip < in_size) {
    const size_t run = ip;
    const unsigned control = in[ip++];
    if (control < kLiteralLimit) {
      const size_t length = control + 1;
      if (length > in_size - ip) {
        return LzfError(run, absl::StrCat("literal of ", length, " bytes but ",
                                          in_size - ip, " left in the input"));
      }
      if (length > size - op) {
        return LzfError(
            run, absl::StrCat("literal of ", length, " bytes at output byte ",
                              op, " overruns the ", size, " expected"));
      }
      std::memcpy(out.data() + op, in + ip, length);
      ip += length;
      op += length;
      continue;
    }
    size_t length = control >> 5;
    if (length == kLongReference) {
      if (ip >= in_size) return LzfError(run, "input ends in a back-reference");
      length += in[ip++];
    }
    if (ip >= in_size) return LzfError(run, "input ends in a back-reference");
    const size_t distance = ((size_t{control} & 0x1f) << 8) + in[ip++] + 1;
    length += kMinReferenceBytes;
    if (distance > op) {
      return LzfError(run, absl::StrCat("back-reference ", distance,
                                        " bytes back from output byte ", op,
                                        ", before the start of the output"));
    }
    if (length > size - op) {
      return LzfError(run, absl::StrCat("back-reference of ", length,
                                        " bytes at output byte ", op,
                                        " overruns the ", size, " expected"));
    }
    CopyBackReference(out.data() + op, distance, length);
    op += length;
  }
  if (op != size) {
    return absl::InvalidArgumentError(
        absl::StrCat("LZF stream of ", in_size, " bytes expands to ", op,
                     " bytes, ", size, " expected"));
  }
  return out;
}

}  // namespace fovea

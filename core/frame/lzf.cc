#include "core/frame/lzf.h"

#include <liblzf/lzf.h>

#include <limits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/base/status_macros.h"

namespace fovea {
namespace {

// Control bytes below this start a literal run; the rest a back-reference.
constexpr unsigned kLiteralLimit = 1 << 5;
// Back-reference length field (control >> 5) that takes an extra byte.
constexpr size_t kLongReference = 7;
// A back-reference copies its length field plus this many bytes.
constexpr size_t kMinReferenceBytes = 2;

absl::Status LzfError(size_t run, absl::string_view what) {
  return absl::InvalidArgumentError(
      absl::StrCat("LZF run at compressed byte ", run, ": ", what));
}

// What is wrong with a stream liblzf refused: the same walk over its runs,
// without copying, stopping at the first that cannot be (OK when none).
absl::Status DiagnoseLzf(absl::string_view compressed, size_t size) {
  const auto* in = reinterpret_cast<const uint8_t*>(compressed.data());
  const size_t in_size = compressed.size();
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
    op += length;
  }
  if (op != size) {
    return absl::InvalidArgumentError(
        absl::StrCat("LZF stream of ", in_size, " bytes expands to ", op,
                     " bytes, ", size, " expected"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<uint8_t>> LzfDecompress(absl::string_view compressed,
                                                   size_t size) {
  constexpr size_t kMaxBytes = std::numeric_limits<unsigned int>::max();
  if (compressed.size() > kMaxBytes || size > kMaxBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("LZF stream of ", compressed.size(), " bytes to ", size,
                     " bytes: liblzf takes at most ", kMaxBytes));
  }
  std::vector<uint8_t> out(size);
  // Debian's liblzf checks every read and write (CHECK_INPUT) and returns 0
  // for a stream it refuses; then the walk says why.
  const unsigned int written = lzf_decompress(
      compressed.data(), static_cast<unsigned int>(compressed.size()),
      out.data(), static_cast<unsigned int>(size));
  if (written == size && (size > 0 || compressed.empty())) return out;
  FOVEA_RETURN_IF_ERROR(DiagnoseLzf(compressed, size));
  return absl::InvalidArgumentError(absl::StrCat(
      "LZF stream of ", compressed.size(), " bytes refused by liblzf"));
}

}  // namespace fovea
